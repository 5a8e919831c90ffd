#include "framework/experiment/JUnit.h"

#include "framework/core/Text.h"

#include <cstdio>

namespace shadowlab {

std::string junitXml(const std::string& suite, const std::vector<JUnitCase>& cases, double seconds) {
    size_t failures = 0;
    std::string body;
    for (const JUnitCase& c : cases) {
        body += "    <testcase classname=\"" + xmlText(c.classname) + "\" name=\"" + xmlText(c.name) + "\" time=\"0\"";
        if (c.failure.empty()) {
            body += "/>\n";
            continue;
        }
        ++failures;
        body += ">\n      <failure message=\"" + xmlText(c.failure) + "\">" + xmlText(c.failure) + "</failure>\n    </testcase>\n";
    }
    char time[32];
    std::snprintf(time, sizeof time, "%.6g", seconds);
    const std::string counts = "tests=\"" + std::to_string(cases.size()) + "\" failures=\"" + std::to_string(failures) + "\"";
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites " + counts + ">\n  <testsuite name=\"" + xmlText(suite) + "\" " + counts +
           " errors=\"0\" time=\"" + time + "\">\n" + body + "  </testsuite>\n</testsuites>\n";
}

} // namespace shadowlab
