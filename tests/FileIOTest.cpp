// The one way inputs are read and small outputs written (framework/core/FileIO.h): only regular
// files are read, never blocking on a FIFO or reading a device forever; a write replaces only a
// regular file, and on any failure leaves the target as it was and no temporary behind.
#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "tests/HostileInputs.h"
#include "tests/TestSupport.h"

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string readError(const std::string& path, size_t cap = kMaxTextInputBytes) {
    try {
        readInputFile(path, cap);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

std::string writeError(const std::string& path, const std::string& text) {
    try {
        writeFileAtomic(path, text);
    } catch (const InputError& e) {
        return std::string("input: ") + e.what();
    } catch (const RuntimeError& e) {
        return std::string("runtime: ") + e.what();
    }
    return "";
}

/// Names in `dir` other than `keep`: temporaries a write should not have left.
std::vector<std::string> strays(const std::string& dir, const std::set<std::string>& keep) {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir))
        if (!keep.count(e.path().filename().string())) out.push_back(e.path().filename().string());
    return out;
}

TEST(FileIOTest, ReadsOnlyRegularFilesAndNeverBlocksOnAFifo) {
    const std::string dir = test::makeTempDir("fileio-read");
    std::ofstream(dir + "/ok.json") << "{\"a\": 1}";
    EXPECT_EQ(readInputFile(dir + "/ok.json"), "{\"a\": 1}");
    EXPECT_EQ(readInputFileBytes(dir + "/ok.json").size(), 8u);

    // A FIFO without a writer: opening it blocking would wait forever.
    ASSERT_EQ(::mkfifo((dir + "/fifo").c_str(), 0644), 0);
    EXPECT_NE(readError(dir + "/fifo").find("is a FIFO, not a regular file"), std::string::npos) << readError(dir + "/fifo");
    // A device that never ends, and one that is not there.
    EXPECT_NE(readError("/dev/zero").find("/dev/zero: is a character device, not a regular file"), std::string::npos);
    EXPECT_NE(readError(dir).find("is a directory"), std::string::npos);
    EXPECT_NE(readError(dir + "/none.json").find("cannot open file: No such file or directory"), std::string::npos);
    // A symbolic link to a regular file is that file.
    fs::create_symlink(dir + "/ok.json", dir + "/link.json");
    EXPECT_EQ(readInputFile(dir + "/link.json"), "{\"a\": 1}");
}

TEST(FileIOTest, ASizeCapRefusesLargerFilesAndAcceptsOneExactlyAtIt) {
    const std::string dir = test::makeTempDir("fileio-cap");
    std::ofstream(dir + "/f") << std::string(100, 'x');
    EXPECT_EQ(readInputFile(dir + "/f", 100).size(), 100u);
    const std::string err = readError(dir + "/f", 99);
    EXPECT_NE(err.find("is larger than 99 bytes (100 bytes)"), std::string::npos) << err;
    EXPECT_THROW(readInputFileBytes(dir + "/f", 10), InputError);
}

TEST(FileIOTest, AFifoOrDeviceGivenAsAConfigIsBadInputNotAHang) {
    const std::string dir = test::makeTempDir("fileio-cli");
    ASSERT_EQ(::mkfifo((dir + "/c.json").c_str(), 0644), 0);
    std::string out;
    // `timeout`: a regression would hang here instead of failing.
    int rc = test::runCommand("timeout 60 " + std::string(SHADOWLAB_BINARY) + " validate " + dir + "/c.json", out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("c.json: is a FIFO, not a regular file"), std::string::npos) << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
    rc = test::runCommand("timeout 60 " + std::string(SHADOWLAB_BINARY) + " validate /dev/zero", out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("/dev/zero: is a character device"), std::string::npos) << out;
    rc = test::runCommand("timeout 60 " + std::string(SHADOWLAB_BINARY) + " validate " + dir, out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("is a directory"), std::string::npos) << out;
    // A glTF buffer whose uri names a FIFO (read through tinygltf's callbacks, by the same function).
    ASSERT_EQ(::mkfifo((dir + "/buf.bin").c_str(), 0644), 0);
    std::ofstream(dir + "/m.gltf") << test::triangleGltf({{"buffers", R"([{"byteLength": 36, "uri": "buf.bin"}])"}});
    std::ofstream(dir + "/g.json") << test::configWith({{"scene", R"({"objects": [{"gltf": "m.gltf"}]})"}});
    rc = test::runCommand("timeout 60 " + std::string(SHADOWLAB_BINARY) + " validate " + dir + "/g.json", out);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("m.gltf: at /buffers/0/uri: the buffer file"), std::string::npos) << out;
    EXPECT_NE(out.find("is a FIFO, not a regular file"), std::string::npos) << out;
}

TEST(FileIOTest, WritesReplaceARegularFileWholeAndLeaveNoTemporary) {
    const std::string dir = test::makeTempDir("fileio-write");
    writeFileAtomic(dir + "/a.json", "first\n");
    EXPECT_EQ(slurp(dir + "/a.json"), "first\n");
    writeFileAtomic(dir + "/a.json", "second\n");
    EXPECT_EQ(slurp(dir + "/a.json"), "second\n");
    writeFileAtomic(dir + "/empty", "");
    EXPECT_TRUE(fs::is_regular_file(dir + "/empty"));
    EXPECT_EQ(fs::file_size(dir + "/empty"), 0u);
    EXPECT_EQ(strays(dir, {"a.json", "empty"}), std::vector<std::string>{});
    // No parent directory: an I/O failure naming the target.
    EXPECT_NE(writeError(dir + "/no/such/x.json", "x").find("runtime: cannot write " + dir + "/no/such/x.json"), std::string::npos);
}

TEST(FileIOTest, ASymlinkADeviceOrADirectoryAtTheTargetIsRefusedAndLeftAsItWas) {
    const std::string dir = test::makeTempDir("fileio-refuse");
    std::ofstream(dir + "/real") << "precious";
    fs::create_symlink(dir + "/real", dir + "/link");
    std::string err = writeError(dir + "/link", "x");
    EXPECT_NE(err.find("input: " + dir + "/link: is a symbolic link: refusing to replace it with a file"), std::string::npos) << err;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir + "/link")));
    EXPECT_EQ(slurp(dir + "/real"), "precious");

    err = writeError("/dev/full", "x");
    EXPECT_NE(err.find("input: /dev/full: is a character device"), std::string::npos) << err;
    EXPECT_TRUE(fs::is_character_file("/dev/full"));

    fs::create_directories(dir + "/sub");
    err = writeError(dir + "/sub", "x");
    EXPECT_NE(err.find("is a directory"), std::string::npos) << err;
    EXPECT_TRUE(fs::is_directory(dir + "/sub"));
    ASSERT_EQ(::mkfifo((dir + "/fifo").c_str(), 0644), 0);
    EXPECT_NE(writeError(dir + "/fifo", "x").find("is a FIFO"), std::string::npos);
    // Nothing beside them: no dir/sub.tmp-PID, no link.tmp-PID.
    EXPECT_EQ(strays(dir, {"real", "link", "sub", "fifo"}), std::vector<std::string>{});
}

TEST(FileIOTest, AFailedWriteKeepsTheOldFileAndRemovesItsTemporary) {
    // A full disk, simulated without root: a file size limit makes write() fail (EFBIG) part way.
    const std::string dir = test::makeTempDir("fileio-full"), target = dir + "/summary.json";
    std::ofstream(target) << "old results";
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        std::signal(SIGXFSZ, SIG_IGN);  // the limit then gives EFBIG instead of killing the process
        struct rlimit lim = {4096, 4096};
        ::setrlimit(RLIMIT_FSIZE, &lim);
        int code = 0;
        try {
            writeFileAtomic(target, std::string(100000, 'n'));
            code = 3;  // accepted: wrong
        } catch (const RuntimeError& e) {
            code = std::string(e.what()).find("cannot write " + target) != std::string::npos ? 0 : 4;
        } catch (...) {
            code = 5;
        }
        ::_exit(code);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "3: the write succeeded, 4: another message, 5: another exception";
    EXPECT_EQ(slurp(target), "old results");
    EXPECT_EQ(strays(dir, {"summary.json"}), std::vector<std::string>{});
}

/// Runs this test binary on one test in a child process; returns the child's pid after it exited 0.
pid_t runSelfOn(const std::string& filter, bool keepDirs) {
    const pid_t child = ::fork();
    if (child == 0) {
        if (keepDirs) ::setenv("SHADOWLAB_KEEP_TEST_DIRS", "1", 1);
        else ::unsetenv("SHADOWLAB_KEEP_TEST_DIRS");
        const std::string arg = "--gtest_filter=" + filter;
        ::execl("/proc/self/exe", "shadowlab_tests", arg.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    int status = 0;
    if (child < 0 || ::waitpid(child, &status, 0) != child || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
    return child;
}

TEST(TestSupportTest, TempDirsAreRemovedWhenTheTestsPass) {
    // Each test run used to leave every folder it made in /tmp behind (thousands, gigabytes).
    const std::string probe = "FileIOTest.AFailedWriteKeepsTheOldFileAndRemovesItsTemporary";
    const auto dirOf = [](pid_t pid) { return fs::temp_directory_path() / ("shadowlab-test-fileio-full-" + std::to_string(pid)); };
    const pid_t removed = runSelfOn(probe, false);
    ASSERT_GT(removed, 0);
    EXPECT_FALSE(fs::exists(dirOf(removed)));
    const pid_t kept = runSelfOn(probe, true);
    ASSERT_GT(kept, 0);
    EXPECT_TRUE(fs::exists(dirOf(kept) / "summary.json")) << "SHADOWLAB_KEEP_TEST_DIRS=1 keeps them for a look";
    fs::remove_all(dirOf(kept));
}

} // namespace
} // namespace shadowlab
