// The output place: checked before any work, locked against a second run, swapped in one step,
// cleaned of what killed runs left, never replacing what is not a shadowlab output.
#include "framework/core/Error.h"
#include "framework/experiment/Compare.h"
#include "framework/experiment/OutputPlace.h"
#include "tests/TestSupport.h"

#include <filesystem>
#include <fstream>
#include <sys/stat.h>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// A finished output holding `tag` in its summary.json, with the mark every run's output carries.
void makeOutput(const std::string& dir, const std::string& tag) {
    fs::create_directories(dir);
    std::ofstream(dir + "/summary.json") << tag;
    std::ofstream(dir + "/.shadowlab-output");
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
    // A killed run's temporary directories carry the mark the run left in them.
    makeOutput(base + "/out.partial-999999", "half");
    std::ofstream(base + "/out.partial-999999/.shadowlab-partial");
    makeOutput(base + "/out.old-999998", "previous");  // killed between the two renames: no out/
    std::ofstream(base + "/out.old-999998/.shadowlab-old");
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
    std::ofstream(base + "/other.old-1/.shadowlab-old");
    EXPECT_NE(errorOf(base + "/other", false).find("already exists"), std::string::npos);
    EXPECT_EQ(slurp(base + "/other/summary.json"), "kept");
    EXPECT_FALSE(fs::exists(base + "/other/.shadowlab-old")) << "the mark goes with the recovery";
}

// What lies beside DIR and only looks like a leftover by its name is the user's, never removed,
// moved or locked: folders and files named DIR.partial-..., DIR.old-..., a finished run made with
// --out DIR.partial-9, a file or FIFO at DIR.lock.
TEST(OutputPlaceTest, LookalikesOfLeftoversAreNeverTouched) {
    std::string base = test::makeTempDir("place-lookalike"), out = base + "/notes";
    fs::create_directories(base + "/notes.partial-draft");
    fs::create_directories(base + "/notes.old-2023");
    std::ofstream(base + "/notes.old-2023/chapter.tex") << "years of work";
    std::ofstream(base + "/notes.partial-file.txt") << "x";
    makeOutput(base + "/notes.partial-9", "a finished run");
    {
        OutputPlace p = OutputPlace::open(out, false);
        p.commit();
    }
    EXPECT_TRUE(fs::is_directory(base + "/notes.partial-draft"));
    EXPECT_EQ(slurp(base + "/notes.old-2023/chapter.tex"), "years of work");
    EXPECT_TRUE(fs::exists(base + "/notes.partial-file.txt"));
    EXPECT_EQ(slurp(base + "/notes.partial-9/summary.json"), "a finished run");
    EXPECT_FALSE(fs::exists(out + "/.shadowlab-partial")) << "the committed output keeps no mark";

    std::ofstream(base + "/mine.lock") << "my shopping list";
    EXPECT_NE(errorOf(base + "/mine", false).find("not a shadowlab lock file"), std::string::npos);
    EXPECT_EQ(slurp(base + "/mine.lock"), "my shopping list");
    ASSERT_EQ(::mkfifo((base + "/pipe.lock").c_str(), 0644), 0);
    EXPECT_NE(errorOf(base + "/pipe", false).find("not a shadowlab lock file"), std::string::npos);
    EXPECT_TRUE(fs::is_fifo(base + "/pipe.lock"));
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

std::string commitError(OutputPlace& p) {
    try {
        p.commit();
    } catch (const RuntimeError& e) {
        return e.what();
    }
    return "";
}

TEST(OutputPlaceTest, AnOutputInsideARunInProgressOrInsideAnotherOutputIsRefused) {
    std::string base = test::makeTempDir("place-nest"), outer = base + "/X/L", inner = outer + "/sub";
    {
        // The longer run into X/L started first; the shorter one into X/L/sub would have created
        // X/L and committed there, then been replaced by the first one's commit.
        OutputPlace first = OutputPlace::open(outer, false);
        std::string err = errorOf(inner, false);
        EXPECT_NE(err.find("inside " + fs::absolute(outer).string() + ", the output of a shadowlab run in progress (pid " +
                           std::to_string(::getpid()) + ")"),
                  std::string::npos)
            << err;
        EXPECT_FALSE(fs::exists(outer)) << "nothing may be created for a refused run";
        std::ofstream(first.partialDir() + "/summary.json") << "outer";
        first.commit();
    }
    // Once committed, X/L is an output: a run inside it would be deleted by the next --force there.
    EXPECT_NE(errorOf(inner, true).find("a shadowlab run's output (it holds summary.json)"), std::string::npos);
    EXPECT_NE(errorOf(outer + "/images/deeper", true).find("a shadowlab run's output"), std::string::npos);
    EXPECT_NE(errorOf(outer + ".partial-12/sub", true).find("temporary directory"), std::string::npos);
    EXPECT_EQ(slurp(outer + "/summary.json"), "outer");
}

TEST(OutputPlaceTest, ForceDoesNotReplaceADirectoryHoldingARunInProgress) {
    std::string base = test::makeTempDir("place-nest-live"), outer = base + "/X/L";
    // The shorter run into X/L/sub started first (and created X/L); the longer one aims at X/L.
    OutputPlace inner = OutputPlace::open(outer + "/sub", false);
    std::string err = errorOf(outer, true);
    EXPECT_NE(err.find("sub.lock, the lock of a shadowlab run in progress"), std::string::npos) << err;
    EXPECT_NE(errorOf(outer, false).find("already exists"), std::string::npos);
    std::ofstream(inner.partialDir() + "/summary.json") << "inner";
    inner.commit();
    EXPECT_EQ(slurp(outer + "/sub/summary.json"), "inner");
    // Done, X/L holds an output in a subdirectory: still not a single run's output to replace.
    EXPECT_NE(errorOf(outer, true).find("not a shadowlab output"), std::string::npos);
    EXPECT_EQ(slurp(outer + "/sub/summary.json"), "inner");
}

TEST(OutputPlaceTest, ForceReplacesOnlyASingleRunsOutputNeverOneHoldingOthers) {
    std::string base = test::makeTempDir("place-force-nested");
    makeOutput(base + "/A", "a");
    makeOutput(base + "/A/B", "nested run");
    std::string err = errorOf(base + "/A", true);
    EXPECT_NE(err.find("/A/B, another shadowlab output (it holds summary.json)"), std::string::npos) << err;
    makeOutput(base + "/S", "s");
    fs::create_directories(base + "/S/sweep/runs");
    std::ofstream(base + "/S/sweep/sweep.json") << "{}";
    EXPECT_NE(errorOf(base + "/S", true).find("another shadowlab sweep (it holds sweep.json)"), std::string::npos);
    // A sweep's own directory is not a run's output either.
    fs::create_directories(base + "/T/runs");
    std::ofstream(base + "/T/sweep.json") << "{}";
    EXPECT_NE(errorOf(base + "/T", true).find("is a sweep (it holds sweep.json)"), std::string::npos);
    EXPECT_TRUE(fs::exists(base + "/T/sweep.json"));
    EXPECT_EQ(slurp(base + "/A/B/summary.json"), "nested run");
    EXPECT_TRUE(fs::exists(base + "/S/sweep/sweep.json"));
}

TEST(OutputPlaceTest, ASweepsRunSlotsAreTheOnlyOutputsInsideIt) {
    std::string base = test::makeTempDir("place-sweep"), sweep = base + "/sweep";
    fs::create_directories(sweep + "/runs");
    std::ofstream(sweep + "/sweep.json") << "{}";
    // Only a slot the sweep planned: it writes runs/ID.config.json before it starts the run there.
    EXPECT_NE(errorOf(sweep + "/runs/abc123", false).find("inside the sweep directory"), std::string::npos);
    std::ofstream(sweep + "/runs/abc123.config.json") << "{}";
    // Only a run of that config (third probe: `run other.json --out SWEEP/runs/ID --force` was
    // taken, its results then read as the sweep's), and not one changed by --set (no config given).
    std::ofstream(base + "/other.json") << "{}";
    for (const std::string& config : {base + "/other.json", std::string()})
        try {
            OutputPlace::open(sweep + "/runs/abc123", true, nullptr, config);
            ADD_FAILURE() << "a run of '" << config << "' took the sweep's slot";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("takes only a run of its own config"), std::string::npos) << e.what();
        }
    EXPECT_FALSE(fs::exists(sweep + "/runs/abc123"));
    {
        // As `sweep run` starts its runs: `run runs/ID.config.json --out runs/ID --force`.
        OutputPlace run = OutputPlace::open(sweep + "/runs/abc123", true, nullptr, sweep + "/runs/./abc123.config.json");
        std::ofstream(run.partialDir() + "/summary.json") << "run";
        run.commit();
    }
    EXPECT_EQ(slurp(sweep + "/runs/abc123/summary.json"), "run");
    EXPECT_NE(errorOf(sweep + "/mine", false).find("inside the sweep directory"), std::string::npos);
    EXPECT_NE(errorOf(sweep + "/runs/abc123/x", false).find("a shadowlab run's output"), std::string::npos);
}

// Fourth probe: `run --out A.partial-PID --force` took over the temporary folder of the run in
// progress into A, which then committed the other run's images as its own.
TEST(OutputPlaceTest, ARunsTemporaryFolderIsNeverAnOutput) {
    const std::string base = test::makeTempDir("place-temporary");
    for (const char* name : {"/A.partial-123", "/A.old-7", "/A.kept-42"}) {
        makeOutput(base + name, "a run's");
        EXPECT_NE(errorOf(base + name, true).find("a shadowlab run's temporary directory"), std::string::npos) << name;
        EXPECT_EQ(slurp(base + name + "/summary.json"), "a run's") << name;
    }
}

// Third probe: --out X/n/. made n (the parent of ".") and was then refused, leaving n behind empty.
TEST(OutputPlaceTest, APathEndingInDotOrDotDotIsRefusedBeforeAnythingIsMade) {
    const std::string base = test::makeTempDir("place-dot");
    for (const char* tail : {"/n/.", "/n/..", "/n/./", "/n/../"}) {
        EXPECT_NE(errorOf(base + tail, false).find("the output path ends in"), std::string::npos) << tail;
        EXPECT_NE(errorOf(base + tail, true).find("the output path ends in"), std::string::npos) << tail;
        EXPECT_FALSE(fs::exists(base + "/n")) << tail;
    }
}

// Fourth probe: a run refused after its place was opened (by the memory plan, or an algorithm
// refusing the scene) left the folders made for --out new/deeper/out behind, empty.
TEST(OutputPlaceTest, APlaceNeverCommittedRemovesTheFoldersItMadeWhenEmpty) {
    const std::string base = test::makeTempDir("place-parents");
    { OutputPlace p = OutputPlace::open(base + "/new/deeper/out", false); }
    EXPECT_FALSE(fs::exists(base + "/new"));
    // A folder that is not empty by then (the user put a file there meanwhile) is left as it is.
    {
        OutputPlace p = OutputPlace::open(base + "/new/deeper/out", false);
        std::ofstream(base + "/new/mine.txt") << "keep";
    }
    EXPECT_TRUE(fs::exists(base + "/new/mine.txt"));
    EXPECT_FALSE(fs::exists(base + "/new/deeper"));
    // A committed place keeps them, of course.
    {
        OutputPlace p = OutputPlace::open(base + "/made/out", false);
        std::ofstream(p.partialDir() + "/summary.json") << "run";
        p.commit();
    }
    EXPECT_TRUE(fs::exists(base + "/made/out/summary.json"));
}

TEST(OutputPlaceTest, ACommitKeepsWhatAppearedAtThePlaceAfterOpenAndKeepsItsOwnResultsBeside) {
    std::string base = test::makeTempDir("place-appeared"), out = base + "/X/L";
    std::string kept = out + ".kept-" + std::to_string(::getpid());
    {
        OutputPlace p = OutputPlace::open(out, false);
        std::ofstream(p.partialDir() + "/summary.json") << "mine";
        // Meanwhile another run (one that passed its checks just before this one took its lock)
        // committed X/L/sub, creating X/L.
        makeOutput(out + "/sub", "theirs");
        std::string err = commitError(p);
        EXPECT_NE(err.find("not replacing " + out + ": it appeared while this run was working"), std::string::npos) << err;
        EXPECT_NE(err.find(kept), std::string::npos) << err;
    }  // the destructor keeps the moved results
    EXPECT_EQ(slurp(out + "/sub/summary.json"), "theirs");
    EXPECT_EQ(slurp(kept + "/summary.json"), "mine");
    EXPECT_FALSE(fs::exists(out + ".lock"));
    // The kept results are no leftover: a later run into the place leaves them alone.
    fs::remove_all(out);
    {
        OutputPlace again = OutputPlace::open(out, false);
        again.commit();
    }
    EXPECT_EQ(slurp(kept + "/summary.json"), "mine");

    // --force: the checked output was given an output inside it meanwhile.
    std::string forced = base + "/F";
    makeOutput(forced, "old");
    OutputPlace p = OutputPlace::open(forced, true);
    makeOutput(forced + "/late", "late");
    std::string err = commitError(p);
    EXPECT_NE(err.find("it now holds " + forced + "/late, another shadowlab output"), std::string::npos) << err;
    EXPECT_EQ(slurp(forced + "/late/summary.json"), "late");
    EXPECT_EQ(slurp(forced + "/summary.json"), "old");
}

// Eleventh probe: a user's notes.txt and folder put into a run's output were deleted with it by the
// next run --force. A committed output lists what it wrote in its mark; --force replaces only an
// output that holds nothing else, and a file that appears in it during the run keeps it.
TEST(OutputPlaceTest, ForceReplacesOnlyWhatTheOutputWroteNeverAFileAddedToIt) {
    std::string base = test::makeTempDir("place-foreign"), out = base + "/out";
    {
        OutputPlace p = OutputPlace::open(out, false);
        std::ofstream(p.partialDir() + "/summary.json") << "first";
        p.commit();
    }
    {
        OutputPlace p = OutputPlace::open(out, true);  // only its own entries: replaced
        std::ofstream(p.partialDir() + "/summary.json") << "second";
        p.commit();
    }
    EXPECT_EQ(slurp(out + "/summary.json"), "second");
    std::ofstream(out + "/notes.txt") << "mine";
    const std::string err = errorOf(out, true);
    EXPECT_NE(err.find("holds \"notes.txt\", which it did not write"), std::string::npos) << err;
    fs::remove(out + "/notes.txt");
    fs::create_directories(out + "/mydata");
    EXPECT_NE(errorOf(out, true).find("\"mydata\""), std::string::npos);
    fs::remove(out + "/mydata");
    // Twelfth probe: inside the output's own folders too.
    std::ofstream(out + "/images/mine.txt") << "mine";
    EXPECT_NE(errorOf(out, true).find("\"images/mine.txt\""), std::string::npos);
    EXPECT_EQ(slurp(out + "/images/mine.txt"), "mine");
    fs::remove(out + "/images/mine.txt");

    OutputPlace p = OutputPlace::open(out, true);
    std::ofstream(p.partialDir() + "/summary.json") << "third";
    std::ofstream(out + "/late.txt") << "mine too";
    const std::string late = commitError(p);
    EXPECT_NE(late.find("it now holds \"late.txt\", which the output there did not write"), std::string::npos) << late;
    EXPECT_EQ(slurp(out + "/late.txt"), "mine too");
    EXPECT_EQ(slurp(out + "/summary.json"), "second");
}

TEST(OutputPlaceTest, AnAbsurdlyLongPathIsEchoedShort) {
    std::string base = test::makeTempDir("place-long");
    std::string deep = base;
    for (int i = 0; i < 30; ++i) deep += "/" + std::string(100, 'd');  // 3,000 characters
    std::ofstream(base + "/file") << "x";
    std::string err = errorOf(base + "/file/" + std::string(3000, 'x'), true);
    EXPECT_FALSE(err.empty());
    EXPECT_LT(err.size(), 600u) << err;
    fs::create_directories(deep);
    makeOutput(deep, "x");
    err = errorOf(deep, false);
    EXPECT_NE(err.find("already exists"), std::string::npos) << err;
    EXPECT_NE(err.find("..."), std::string::npos) << err;
    EXPECT_LT(err.size(), 600u) << err;
}

// Twenty-third probe: a run killed while it deleted the results it had just replaced left them,
// unmarked, at DIR.partial-PID; no later run removed them and history counted them as a run. They
// carry the leftover mark before the exchange now, the next run into DIR removes them, and no
// reader of results takes a run's temporary folder for a run.
TEST(OutputPlaceTest, PreviousResultsCaughtMidDeletionAreALeftoverTheNextRunRemoves) {
    std::string base = test::makeTempDir("place-mid-delete"), out = base + "/out";
    makeOutput(out, "old");
    static std::string leftover;
    static bool marked = false;
    OutputPlace::afterExchangeForTests = [](const std::string& previous) {
        leftover = previous;
        marked = fs::exists(previous + "/.shadowlab-partial");
        throw std::runtime_error("killed");  // the deletion never happens
    };
    {
        OutputPlace p = OutputPlace::open(out, true);
        std::ofstream(p.partialDir() + "/summary.json") << "new";
        EXPECT_THROW(p.commit(), std::runtime_error);
    }
    OutputPlace::afterExchangeForTests = nullptr;
    EXPECT_EQ(slurp(out + "/summary.json"), "new");
    ASSERT_TRUE(fs::exists(leftover + "/summary.json")) << "the previous results, where the kill left them";
    EXPECT_TRUE(marked) << "the previous results carried no leftover mark at the exchange";
    try {
        readRunSummary(leftover);
        ADD_FAILURE() << "a run's temporary folder was read as a run";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("temporary folder"), std::string::npos) << e.what();
    }
    std::vector<std::string> notes;
    { OutputPlace next = OutputPlace::open(out, true, &notes); }
    EXPECT_FALSE(fs::exists(leftover)) << "the next run into the output left the leftover";
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("left by an interrupted run"), std::string::npos) << notes[0];
}

// Twenty-fourth probe: validate accepted an output beside a folder (or a user's file) named
// DIR.lock, which run then could not lock; --out fo.lock made an output that blocked every later
// run into fo. Both are refused before anything is made.
TEST(OutputPlaceTest, ALockNameThatCannotBeTakenOrAnOutputNamedLikeALockIsRefused) {
    const std::string base = test::makeTempDir("place-lock-name");
    fs::create_directories(base + "/fresh.lock");
    std::string err = errorOf(base + "/fresh", false);
    EXPECT_NE(err.find("not a shadowlab lock file"), std::string::npos) << err;
    std::ofstream(base + "/mine.lock") << "my notes";
    err = errorOf(base + "/mine", false);
    EXPECT_NE(err.find("not a shadowlab lock file"), std::string::npos) << err;
    EXPECT_EQ(slurp(base + "/mine.lock"), "my notes");
    err = errorOf(base + "/fo.lock", false);
    EXPECT_NE(err.find("ends in .lock"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(base + "/fo.lock"));
    EXPECT_EQ(errorOf(base + "/fine", false), "");
}

} // namespace
} // namespace shadowlab
