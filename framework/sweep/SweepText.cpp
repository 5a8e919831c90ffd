#include "framework/sweep/SweepText.h"

#include "framework/core/Error.h"

#include <cstdint>

namespace shadowlab {

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
