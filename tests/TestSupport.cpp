#include "tests/TestSupport.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <sys/wait.h>
#include <unistd.h>

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

std::string makeTempDir(const std::string& tag) {
    namespace fs = std::filesystem;
    fs::path base = fs::temp_directory_path() / ("shadowlab-test-" + tag + "-" + std::to_string(::getpid()));
    fs::remove_all(base);
    fs::create_directories(base);
    return base.string();
}

} // namespace shadowlab::test
