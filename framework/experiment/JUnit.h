#pragma once
// JUnit XML, the test report GitLab, GitHub and Jenkins read: one suite of cases, a case failed
// when it has a failure message. Every text is escaped (xmlText), so any id or name is data.
#include <string>
#include <vector>

namespace shadowlab {

struct JUnitCase {
    std::string classname, name;
    std::string failure;  ///< "" when it passed
};

std::string junitXml(const std::string& suite, const std::vector<JUnitCase>& cases, double seconds);

} // namespace shadowlab
