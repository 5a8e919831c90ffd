#include "framework/sweep/SweepText.h"

#include "framework/core/Error.h"

#include <cstdint>

namespace shadowlab {

namespace {

/// Length of the UTF-8 sequence starting at text[i], 0 when it is malformed there.
size_t utf8Length(const std::string& text, size_t i) {
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char c = byte(i);
    if (c < 0x80) return 1;
    size_t n = 0;
    uint32_t cp = 0;
    if (c >= 0xC2 && c <= 0xDF) n = 2, cp = c & 0x1F;
    else if (c >= 0xE0 && c <= 0xEF) n = 3, cp = c & 0x0F;
    else if (c >= 0xF0 && c <= 0xF4) n = 4, cp = c & 0x07;
    else return 0;
    if (i + n > text.size()) return 0;
    for (size_t k = 1; k < n; ++k) {
        if ((byte(i + k) & 0xC0) != 0x80) return 0;
        cp = (cp << 6) | (byte(i + k) & 0x3F);
    }
    // Overlong forms, UTF-16 surrogates and code points past U+10FFFF are not UTF-8.
    if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF)) || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
    return n;
}

bool isControl(unsigned char c) { return c < 0x20 || c == 0x7F; }

} // namespace

bool isValidUtf8(const std::string& text) {
    for (size_t i = 0; i < text.size();) {
        const size_t n = utf8Length(text, i);
        if (n == 0) return false;
        i += n;
    }
    return true;
}

int firstControlChar(const std::string& text) {
    for (char c : text)
        if (isControl(static_cast<unsigned char>(c))) return static_cast<unsigned char>(c);
    return -1;
}

std::string textProblem(const std::string& text, size_t maxChars) {
    if (maxChars && text.size() > maxChars)
        return "is " + std::to_string(text.size()) + " bytes long, more than " + std::to_string(maxChars);
    if (!isValidUtf8(text)) return "is not valid UTF-8";
    if (const int c = firstControlChar(text); c >= 0) {
        const char* names[] = {"NUL", "a newline", "a tab", "a carriage return"};
        const char* name = c == 0 ? names[0] : c == '\n' ? names[1] : c == '\t' ? names[2] : c == '\r' ? names[3] : nullptr;
        return std::string("holds a control character (") + (name ? name : ("byte " + std::to_string(c)).c_str()) + ")";
    }
    return "";
}

std::string shortText(const std::string& text, size_t maxChars) {
    std::string out;
    for (size_t i = 0; i < text.size();) {
        if (out.size() >= maxChars) return out + "...";
        const size_t n = utf8Length(text, i);
        if (n == 0 || (n == 1 && isControl(static_cast<unsigned char>(text[i])))) {
            out += '?';
            i += n ? n : 1;
        } else {
            out.append(text, i, n);
            i += n;
        }
    }
    return out;
}

std::string validUtf8(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (size_t i = 0; i < text.size();) {
        const size_t n = utf8Length(text, i);
        if (n == 0) {
            out += '?';
            ++i;
        } else {
            out.append(text, i, n);
            i += n;
        }
    }
    return out;
}

size_t parseCount(const std::string& text, const std::string& option, size_t minValue, size_t maxValue) {
    std::string range = "[";
    range += std::to_string(minValue) + ", " + std::to_string(maxValue) + "]";
    const std::string cause = "expected a whole number in " + range + ", got \"" + shortText(text, 40) + "\"";
    // Digits only: std::stoul would take "-1" (wrapping to 2^64 - 1), "+3", " 3" and "0x10".
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) throw InputError(shortText(option, 40), "", cause);
    size_t v = 0;
    for (char c : text) {
        const size_t d = size_t(c - '0');
        // Past maxValue is refused before the multiplication could wrap.
        if (v > maxValue / 10 || d > maxValue - v * 10) throw InputError(shortText(option, 40), "", cause);
        v = v * 10 + d;
    }
    if (v < minValue) throw InputError(shortText(option, 40), "", cause);
    return v;
}

std::string dottedPathProblem(const std::string& path) {
    if (std::string p = textProblem(path, 1000); !p.empty()) return p;
    size_t start = 0;
    while (true) {
        const size_t dot = path.find('.', start);
        const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
        if (key.empty()) return "is not a dotted path like scene.objects.1.object.triangles (an empty component)";
        if (key.find_first_not_of("0123456789") == std::string::npos && key.size() > 9)
            return "has the array index " + shortText(key, 30) + ", past any array a config can hold";
        if (dot == std::string::npos) return "";
        start = dot + 1;
    }
}

} // namespace shadowlab
