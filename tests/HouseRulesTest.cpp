// Rules of the source tree that no compiler checks (docs/architecture.md): a plugin depends on the
// framework, never on another plugin, in C++ and in GLSL; one concept keeps one name, so the
// retired names of the statistics pass come back nowhere; and a test cannot read a counter that
// was not reported.
#include "tests/AlgorithmHarness.h"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

const fs::path kRoot = SHADOWLAB_SOURCE_DIR;

std::string slurp(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::set<std::string> pluginNames() {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(kRoot / "algorithms"))
        if (e.is_directory()) names.insert(e.path().filename().string());
    return names;
}

std::vector<fs::path> filesUnder(const fs::path& dir) {
    std::vector<fs::path> files;
    if (!fs::exists(dir)) return files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

/// The plugin an include names: "algorithms/NAME/…" in C++, "NAME/…" (relative to shaders/) in GLSL.
std::string pluginOfInclude(const std::string& include, const std::set<std::string>& plugins) {
    std::string path = include;
    if (path.rfind("algorithms/", 0) == 0) path = path.substr(11);
    else if (path.rfind("shaders/", 0) == 0) path = path.substr(8);
    const size_t slash = path.find('/');
    if (slash == std::string::npos) return "";
    const std::string head = path.substr(0, slash);
    return plugins.count(head) ? head : "";
}

TEST(HouseRulesTest, NoPluginIncludesAnother) {
    const std::set<std::string> plugins = pluginNames();
    ASSERT_GE(plugins.size(), 9u);
    const std::regex include(R"re(^\s*#\s*include\s*"([^"]+)")re");
    size_t checked = 0;
    for (const std::string& plugin : plugins)
        for (const fs::path& dir : {kRoot / "algorithms" / plugin, kRoot / "shaders" / plugin})
            for (const fs::path& file : filesUnder(dir)) {
                std::istringstream lines(slurp(file));
                int n = 0;
                for (std::string line; std::getline(lines, line);) {
                    ++n;
                    std::smatch m;
                    if (!std::regex_search(line, m, include)) continue;
                    ++checked;
                    const std::string other = pluginOfInclude(m[1].str(), plugins);
                    EXPECT_TRUE(other.empty() || other == plugin)
                        << fs::relative(file, kRoot).string() << ":" << n << " includes " << m[1].str() << ", a file of the plugin "
                        << other << ": shared code belongs in framework/ or shaders/common/";
                }
            }
    EXPECT_GT(checked, 100u);
}

/// The statistics pass has one name ("statistics", AlgorithmOptions::statistics, SHADOWLAB_STATISTICS)
/// and timed frames are "the timed pass". "Timing mode" (the removed `timing_mode` key) and
/// "instrumentation" named the same things; only the refusal of the old key and its test say them.
TEST(HouseRulesTest, RetiredNamesOfTheStatisticsPassAppearNowhere) {
    const std::set<std::string> allowed = {"framework/experiment/Config.cpp", "tests/HonestTimingGLTest.cpp",
                                           "tests/HouseRulesTest.cpp"};
    const std::vector<std::string> retired = {"timing mode", "timing_mode", "timingmode", "instrumentation"};
    std::vector<fs::path> files;
    for (const char* dir : {"algorithms", "framework", "shaders", "tests", "scripts", "configs", "examples", "docs", "cmake"})
        for (const fs::path& f : filesUnder(kRoot / dir)) files.push_back(f);
    files.push_back(kRoot / "README.md");
    files.push_back(kRoot / "CMakeLists.txt");
    size_t checked = 0;
    for (const fs::path& file : files) {
        const std::string rel = fs::relative(file, kRoot).string();
        if (allowed.count(rel) || rel.rfind("tests/data/", 0) == 0) continue;
        std::string text = slurp(file);
        std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
        ++checked;
        for (const std::string& word : retired) {
            const size_t at = text.find(word);
            if (at == std::string::npos) continue;
            const size_t line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
            ADD_FAILURE() << rel << ":" << line << " says \"" << word << "\": the statistics pass (config `statistics`, "
                          << "AlgorithmOptions::statistics, SHADOWLAB_STATISTICS) and the timed pass have one name each";
        }
    }
    EXPECT_GT(checked, 300u);
}

/// The tests read an algorithm's counters by name: one it did not report (misspelt, renamed, or
/// compiled out of the timed pass) fails the test instead of reading as 0.
TEST(HouseRulesTest, ACounterTheAlgorithmDidNotReportFailsTheTest) {
    test::ReportedCounters counters;
    counters.set("nodes_visited_mean", 3.0);
    EXPECT_EQ(counters["nodes_visited_mean"], 3.0);
    EXPECT_NONFATAL_FAILURE(counters["node_visited_mean"], "reported no counter \"node_visited_mean\"");
    EXPECT_EQ(counters.count("node_visited_mean"), 0u);
}

} // namespace
} // namespace shadowlab
