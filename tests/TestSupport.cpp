#include "tests/TestSupport.h"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace shadowlab::test {

void GLTest::SetUp() {
    try {
        context_ = createHeadlessContext(true);
    } catch (const std::exception& e) {
        // OSMesa (libosmesa6-dev, installed by scripts/setup.sh) always gives one: no context is a failure.
        FAIL() << "no OpenGL 4.5 context can be made here: " << e.what();
    }
    installGlDebugCallback(true);
    resetGlErrors();
}

void GLTest::TearDown() {
    if (context_) EXPECT_EQ(glErrorCount(), 0) << "GL errors:\n" << glLastErrors();
    context_.reset();
}

int runCommand(const std::string& command, std::string& output) {
    output.clear();
    FILE* p = popen((command + " 2>&1").c_str(), "r");
    if (!p) return -1;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) output.append(buf.data(), n);
    int status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

namespace {

/// The folders makeTempDir made in this process, removed when it exits: repeated test runs used to
/// leave every one of them behind (thousands, gigabytes, in /tmp). A run with a failed test keeps
/// them for a look, and so does SHADOWLAB_KEEP_TEST_DIRS=1.
class TempDirs {
public:
    void add(const std::filesystem::path& dir) {
        for (const auto& d : dirs_)
            if (d == dir) return;
        dirs_.push_back(dir);
    }
    ~TempDirs() {
        const char* keep = std::getenv("SHADOWLAB_KEEP_TEST_DIRS");
        if (::getpid() != owner_) return; // a forked child that exits normally leaves its parent's folders
        if ((keep && *keep && std::string(keep) != "0") || ::testing::UnitTest::GetInstance()->Failed()) return;
        std::error_code ignored;
        for (const auto& d : dirs_) std::filesystem::remove_all(d, ignored);
    }

private:
    std::vector<std::filesystem::path> dirs_;
    pid_t owner_ = ::getpid();
};

TempDirs& tempDirs() {
    static TempDirs dirs;
    return dirs;
}

} // namespace

std::string makeTempDir(const std::string& tag) {
    namespace fs = std::filesystem;
    fs::path base = fs::temp_directory_path() / ("shadowlab-test-" + tag + "-" + std::to_string(::getpid()));
    fs::remove_all(base);
    fs::create_directories(base);
    tempDirs().add(base);
    return base.string();
}

} // namespace shadowlab::test
