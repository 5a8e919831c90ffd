#include "framework/core/Text.h"

#include <cctype>

#include <cstdint>
#include <cstdio>
#include <ctime>

namespace shadowlab {

bool isFileName(const std::string& name) {
    return name != "." && name != ".." && name.find_first_of("/\\") == std::string::npos;
}

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

namespace {
/// The code point of the well-formed UTF-8 sequence of `n` bytes at text[i].
uint32_t codePoint(const std::string& text, size_t i, size_t n) {
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
    if (n == 1) return byte(i);
    uint32_t cp = byte(i) & (n == 2 ? 0x1F : n == 3 ? 0x0F : 0x07);
    for (size_t k = 1; k < n; ++k) cp = (cp << 6) | (byte(i + k) & 0x3F);
    return cp;
}

/// Characters that change how a line reads without being seen (userTextProblem's list): C1
/// controls, every format character of Unicode's general category Cf (bidirectional controls,
/// zero-width characters, soft hyphen, invisible operators, tags, ...), the line and paragraph
/// separators, and the characters that render as nothing (Hangul fillers, the combining grapheme
/// joiner, Mongolian variation selectors, Khmer inherent vowels).
bool isInvisibleFormatting(uint32_t cp) {
    const auto in = [cp](uint32_t lo, uint32_t hi) { return cp >= lo && cp <= hi; };
    return in(0x80, 0x9F) || cp == 0xAD || cp == 0x34F || in(0x600, 0x605) || cp == 0x61C || cp == 0x6DD || cp == 0x70F ||
           in(0x890, 0x891) || cp == 0x8E2 || in(0x115F, 0x1160) || in(0x17B4, 0x17B5) || in(0x180B, 0x180F) ||
           in(0x200B, 0x200F) || in(0x2028, 0x202E) || in(0x2060, 0x206F) || cp == 0x3164 || cp == 0xFEFF || cp == 0xFFA0 ||
           in(0xFFF9, 0xFFFB) || cp == 0x110BD || cp == 0x110CD || in(0x13430, 0x1343F) || in(0x1BCA0, 0x1BCA3) ||
           in(0x1D173, 0x1D17A) || in(0xE0000, 0xE0FFF);
}

bool isAsciiAlnum(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
} // namespace

std::string shortText(const std::string& text, size_t maxChars) {
    std::string out;
    for (size_t i = 0; i < text.size();) {
        if (out.size() >= maxChars) return out + "...";
        const size_t n = utf8Length(text, i);
        // Controls and invisible formatting (a U+2028 that ends the line for a Unicode-aware
        // reader, a U+202E that reverses the terminal's text) are masked: an error line echoes
        // what was refused, and stays one plain line.
        if (n == 0 || (n == 1 && isControl(static_cast<unsigned char>(text[i]))) || isInvisibleFormatting(codePoint(text, i, n))) {
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



namespace {
std::string invisibleProblem(const std::string& text) {
    for (size_t i = 0; i < text.size();) {
        const size_t n = utf8Length(text, i);
        if (const uint32_t cp = codePoint(text, i, n); isInvisibleFormatting(cp)) {
            char hex[16];
            std::snprintf(hex, sizeof hex, "U+%04X", unsigned(cp));
            return std::string("holds the invisible formatting character ") + hex +
                   " (a bidirectional control, zero-width or other invisible formatting character, a line separator or a C1 control)";
        }
        i += n;
    }
    return "";
}
} // namespace

std::string userTextProblem(const std::string& text) {
    if (std::string why = textProblem(text, kMaxLabelChars); !why.empty()) return why;
    return invisibleProblem(text);
}

std::string pathTextProblem(const std::string& path) {
    if (std::string why = textProblem(path, 0); !why.empty()) return why;
    return invisibleProblem(path);
}

std::string markdownLiteral(const std::string& text) {
    static const std::string kMarkup = "\\`*[]()!|<>#~&{}+-.=$:";
    std::string out;
    out.reserve(text.size() + text.size() / 4);
    for (size_t i = 0; i < text.size();) {
        const size_t n = utf8Length(text, i);
        if (n == 0 || (n == 1 && isControl(static_cast<unsigned char>(text[i])))) {
            out += "\xEF\xBF\xBD"; // U+FFFD: a line break or stray byte would end the cell or the line
            i += n ? n : 1;
            continue;
        }
        const char c = text[i];
        const bool intraword = c == '_' && i > 0 && i + 1 < text.size() && isAsciiAlnum(text[i - 1]) && isAsciiAlnum(text[i + 1]);
        if (n == 1 && (kMarkup.find(c) != std::string::npos || (c == '_' && !intraword))) out += '\\';
        out.append(text, i, n);
        i += n;
    }
    return out;
}

std::string shortNumber(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

std::string utcTimestamp() {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &utc);
    return buf;
}

std::string xmlText(const std::string& text) {
    std::string out;
    for (char c : validUtf8(text)) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (c == '&') out += "&amp;";
        else if (c == '<') out += "&lt;";
        else if (c == '>') out += "&gt;";
        else if (c == '"') out += "&quot;";
        else if (c == '\'') out += "&apos;";
        else if (u < 0x20 && c != '\t' && c != '\n') out += '?';
        else out += c;
        // U+FFFE and U+FFFF are not XML 1.0 characters either (eleventh probe: an id holding
        // U+FFFE made compare.junit.xml unreadable); well-formed UTF-8 spells them EF BF BE/BF.
        const size_t n = out.size();
        if (n >= 3 && out.compare(n - 3, 2, "\xEF\xBF") == 0 && (out[n - 1] == '\xBE' || out[n - 1] == '\xBF')) out.replace(n - 3, 3, "?");
    }
    return out;
}

/// Whether `s` is a plain decimal number: sign, digits, an optional fraction and exponent. Not
/// strtod's wider set, whose "-nan(HYPERLINK)", "+INF" and "-0x1p3" a spreadsheet reads as text
/// or a name (tenth probe).
bool plainDecimal(const std::string& s) {
    size_t i = 0;
    auto digits = [&] {
        const size_t start = i;
        while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
        return i > start;
    };
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    bool any = digits();
    if (i < s.size() && s[i] == '.') {
        ++i;
        any = digits() || any;
    }
    if (!any) return false;
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
        if (!digits()) return false;
    }
    return i == s.size();
}

std::string asciiLowerCase(std::string text) {
    for (char& ch : text) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return text;
}

} // namespace shadowlab
