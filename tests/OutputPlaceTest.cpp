// The output place: checked before any work, locked against a second run, swapped in one step,
// cleaned of what killed runs left, never replacing what is not a shadowlab output.
#include "framework/core/Error.h"
#include "framework/experiment/OutputPlace.h"
#include "tests/TestSupport.h"

#include <filesystem>
#include <fstream>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// A finished output holding `tag` in its summary.json.
void makeOutput(const std::string& dir, const std::string& tag) {
    fs::create_directories(dir);
    std::ofstream(dir + "/summary.json") << tag;
}

std::string errorOf(const std::string& dir, bool force) {
    try {
        OutputPlace::open(dir, force);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(OutputPlaceTest, CommitReplacesTheOldOutputInOneStep) {
    std::string base = test::makeTempDir("place-commit"), out = base + "/out";
    makeOutput(out, "old");
    {
        OutputPlace p = OutputPlace::open(out, true);
        std::ofstream(p.partialDir() + "/summary.json") << "new";
        EXPECT_EQ(slurp(out + "/summary.json"), "old");  // untouched until the commit
        p.commit();
    }
    EXPECT_EQ(slurp(out + "/summary.json"), "new");
    // Nothing left beside it: no partial, no old copy, no lock.
    for (const auto& e : fs::directory_iterator(base)) EXPECT_EQ(e.path().filename(), "out");
}

TEST(OutputPlaceTest, WithoutCommitThePreviousOutputStaysAndThePartialGoes) {
    std::string base = test::makeTempDir("place-abort"), out = base + "/out";
    makeOutput(out, "old");
    {
        OutputPlace p = OutputPlace::open(out, true);
        std::ofstream(p.partialDir() + "/summary.json") << "half";
    }  // an exception or an interrupt unwinds here
    EXPECT_EQ(slurp(out + "/summary.json"), "old");
    for (const auto& e : fs::directory_iterator(base)) EXPECT_EQ(e.path().filename(), "out");
}

TEST(OutputPlaceTest, ASecondRunOnTheSamePlaceIsRefusedWhileTheFirstHoldsIt) {
    std::string base = test::makeTempDir("place-lock"), out = base + "/out";
    OutputPlace first = OutputPlace::open(out, false);
    std::string err = errorOf(out, false);
    EXPECT_NE(err.find("in use by another shadowlab run (pid " + std::to_string(::getpid()) + ")"), std::string::npos) << err;
    EXPECT_NE(errorOf(base + "/out/", true).find("in use"), std::string::npos);  // same place, spelled differently
    std::ofstream(first.partialDir() + "/summary.json") << "done";
    first.commit();
    // Done: the place is free again, and now holds an output.
    EXPECT_NE(errorOf(out, false).find("already exists"), std::string::npos);
    EXPECT_EQ(errorOf(out, true), "");
}

TEST(OutputPlaceTest, LeftoversOfKilledRunsAreCleanedAndAnInterruptedCommitRecovered) {
    std::string base = test::makeTempDir("place-stale"), out = base + "/out";
    makeOutput(base + "/out.partial-999999", "half");
    makeOutput(base + "/out.old-999998", "previous");  // killed between the two renames: no out/
    std::vector<std::string> notes;
    {
        OutputPlace p = OutputPlace::open(out, true, &notes);
        EXPECT_EQ(slurp(out + "/summary.json"), "previous");  // recovered before anything else
    }
    EXPECT_EQ(notes.size(), 2u);
    EXPECT_FALSE(fs::exists(base + "/out.partial-999999"));
    EXPECT_FALSE(fs::exists(base + "/out.old-999998"));
    // Recovered without --force: the previous results are not replaced.
    makeOutput(base + "/other.old-1", "kept");
    EXPECT_NE(errorOf(base + "/other", false).find("already exists"), std::string::npos);
    EXPECT_EQ(slurp(base + "/other/summary.json"), "kept");
}

TEST(OutputPlaceTest, PlacesThatCannotHoldAnOutputAreBadInput) {
    std::string base = test::makeTempDir("place-bad");
    fs::create_directories(base + "/notes");
    std::ofstream(base + "/notes/thesis.tex") << "years of work";
    EXPECT_NE(errorOf(base + "/notes", true).find("not a shadowlab output"), std::string::npos);
    EXPECT_TRUE(fs::exists(base + "/notes/thesis.tex"));
    std::ofstream(base + "/file") << "x";
    EXPECT_NE(errorOf(base + "/file", true).find("not a directory"), std::string::npos);
    fs::create_symlink(base + "/nowhere", base + "/dangling");
    EXPECT_NE(errorOf(base + "/dangling", true).find("symbolic link"), std::string::npos);
    EXPECT_NE(errorOf("", true).find("must not be empty"), std::string::npos);
    fs::path cwd = fs::current_path();
    fs::current_path(base);
    EXPECT_NE(errorOf(".", true).find("working directory"), std::string::npos);
    EXPECT_NE(errorOf(base, true).find("working directory"), std::string::npos);
    fs::current_path(cwd);
    EXPECT_NE(errorOf("/", true).find("working directory"), std::string::npos);
    // A trailing slash names the same place and works.
    OutputPlace p = OutputPlace::open(base + "/fresh/", false);
    p.commit();
    EXPECT_TRUE(fs::is_directory(base + "/fresh"));
}

} // namespace
} // namespace shadowlab
