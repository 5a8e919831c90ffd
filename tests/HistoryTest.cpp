// `shadowlab history` on run folders written by hand (summary.json alone: what history reads), so
// that the noise, the steps and their runs are known: a step is named at the run it starts, noise
// of the size measured on a shared machine is no step, the newest run's regression is exit 3, and
// bad folders and options are exit 2.
#include "framework/core/Error.h"
#include "framework/experiment/History.h"
#include "tests/SweepTestData.h"
#include "tests/TestSupport.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

namespace shadowlab {
namespace {

namespace fs = std::filesystem;

/// Deterministic noise in [-1, 1) (a fixed LCG: the same folders every time).
struct Noise {
    uint32_t state;
    double next() {
        state = state * 1664525u + 1013904223u;
        return double(state >> 8) / double(1u << 23) - 1.0;
    }
};

/// One run's summary: 9 passes per id around `psvMs` and 10 ms (± `spread`), worst-frame mismatch
/// `psvMismatch` for psv and 0 for bvh_raytrace.
Json summaryOf(double psvMs, double psvMismatch, double spread, uint32_t seed, const std::string& commit, const std::string& started) {
    Noise noise{seed};
    auto passes = [&](double ms) {
        Json p = Json::array();
        for (int k = 0; k < 9; ++k) p.push_back(ms * (1 + spread * noise.next()));
        return p;
    };
    auto entry = [&](double ms, double mismatch) {
        return Json{{"repetitions", {{"count", 9}, {"time_ms", {{"total", passes(ms)}}}}},
                    {"time_ms", {{"total", {{"mean", ms}}}}},
                    {"accuracy", {{"mismatch_ratio_max", mismatch}}}};
    };
    return {{"complete", true},
            {"renderer", "llvmpipe"},
            {"started_utc", started},
            {"build", {{"commit", commit}, {"dirty", false}}},
            {"algorithms", {{"psv", entry(psvMs, psvMismatch)}, {"bvh_raytrace", entry(10.0, 0.0)}}}};
}

std::string commitOf(int k) { return std::string(39, 'a' + char(k % 6)) + char('0' + k % 10); }

/// Runs 0..n-1 in DIR, folder names in the reverse of their order (history orders by start time).
void writeRuns(const std::string& dir, const std::vector<double>& psvMs, const std::vector<double>& mismatch, double spread);

// ±8 % per pass is wider than the passes' spread measured on the smoke config (results/reference/compare_noise_llvmpipe.md).
constexpr double kSpread = 0.08;

void writeRuns(const std::string& dir, const std::vector<double>& psvMs, const std::vector<double>& mismatch, double spread) {
    for (size_t k = 0; k < psvMs.size(); ++k) {
        const std::string folder = dir + "/run-" + std::to_string(100 - k);
        fs::create_directories(folder);
        char started[32];
        std::snprintf(started, sizeof started, "2026-12-%02zuT10:00:00Z", k + 1);
        std::ofstream(folder + "/summary.json") << summaryOf(psvMs[k], mismatch[k], spread, uint32_t(7 + 31 * k), commitOf(int(k)), started).dump();
    }
}

std::vector<Json> stepsOf(const History& h, const std::string& id, const std::string& measure) {
    std::vector<Json> out;
    for (const Json& s : h.steps)
        if (s["id"] == id && s["measure"] == measure) out.push_back(s);
    return out;
}

TEST(HistoryTest, NoiseAloneIsNoStep) {
    const std::string dir = test::makeTempDir("history-flat");
    writeRuns(dir, std::vector<double>(10, 20.0), std::vector<double>(10, 0.0), kSpread);
    const History h = readHistory(dir, {});
    EXPECT_EQ(h.runs.size(), 10u);
    EXPECT_TRUE(h.steps.empty()) << h.steps.dump(2);
    EXPECT_EQ(h.newestRegressions, 0u);
}

// Runs of one build whose passes agree closely but whose medians differ from run to run by up to
// 8 % (a shared machine's state changes between runs): pooling the passes of neighbouring runs
// called that a step (first version, on 5 smoke runs of one build); the run is the unit.
TEST(HistoryTest, RunToRunNoiseIsNoStep) {
    const std::string dir = test::makeTempDir("history-runs");
    writeRuns(dir, {20.0, 21.2, 19.0, 21.6, 19.4, 20.8, 18.8, 21.4, 20.2, 19.6}, std::vector<double>(10, 0.0), 0.02);
    const History h = readHistory(dir, {});
    EXPECT_TRUE(h.steps.empty()) << h.steps.dump(2);
}

// A first run 20 % slower than the 5 of one build after it: alone it was named a step (0.80x at
// run 1 on same-build smoke runs, results/reference/compare_noise_llvmpipe.md); one run is no
// baseline. The newest run alone after a boundary still is judged (TheNewestRunsRegression...).
TEST(HistoryTest, AFirstRunAloneIsNoBaseline) {
    const std::string dir = test::makeTempDir("history-first");
    writeRuns(dir, {24.0, 20.0, 20.4, 19.8, 20.2, 19.9}, std::vector<double>(6, 0.0), 0.02);
    const History h = readHistory(dir, {});
    EXPECT_TRUE(h.steps.empty()) << h.steps.dump(2);
}

// The newest run's median 30 % up, but its own passes spread from the old level to 40 % up (half
// of them met a load spike): the reference did this on same-build smoke runs beside other work
// (results/reference/compare_noise_llvmpipe.md); its median alone was named a regression.
TEST(HistoryTest, ANewestRunThatMetLoadIsNoStep) {
    const std::string dir = test::makeTempDir("history-load");
    writeRuns(dir, {20.0, 20.4, 19.8, 20.2, 19.9, 20.1}, std::vector<double>(6, 0.0), 0.02);
    Json s = Json::parse(std::ifstream(dir + "/run-95/summary.json"));
    Json& passes = s["algorithms"]["psv"]["repetitions"]["time_ms"]["total"];
    passes = {20.1, 19.9, 27.6, 20.3, 26.8, 28.0, 26.0, 20.0, 27.2};
    std::ofstream(dir + "/run-95/summary.json") << s.dump();
    const History h = readHistory(dir, {});
    EXPECT_TRUE(h.steps.empty()) << h.steps.dump(2);
    EXPECT_EQ(h.newestRegressions, 0u);
}

TEST(HistoryTest, AStepIsNamedAtTheRunItStartsAndOnlyForTheIdThatChanged) {
    const std::string dir = test::makeTempDir("history-step");
    std::vector<double> ms(10, 20.0), mismatch(10, 0.0);
    for (size_t k = 5; k < 10; ++k) ms[k] = 26.0; // 30 % slower from run 5 on
    for (size_t k = 7; k < 10; ++k) mismatch[k] = 0.002; // wrong pixels from run 7 on
    writeRuns(dir, ms, mismatch, kSpread);
    const History h = readHistory(dir, {});
    const auto time = stepsOf(h, "psv", "time");
    ASSERT_EQ(time.size(), 1u) << h.steps.dump(2);
    EXPECT_EQ(time[0]["run"], 5u);
    EXPECT_EQ(time[0]["direction"], "slower");
    EXPECT_EQ(time[0]["label"], commitOf(5).substr(0, 10));
    EXPECT_NEAR(time[0]["ratio"].get<double>(), 1.3, 0.1);
    const auto accuracy = stepsOf(h, "psv", "accuracy");
    ASSERT_EQ(accuracy.size(), 1u);
    EXPECT_EQ(accuracy[0]["run"], 7u);
    EXPECT_EQ(accuracy[0]["direction"], "worse");
    EXPECT_TRUE(stepsOf(h, "bvh_raytrace", "time").empty()) << h.steps.dump(2);
    // Those steps are old news: the newest run starts none.
    EXPECT_EQ(h.newestRegressions, 0u);
    // Relative to the machine (the median of the ids' scaled totals), psv's step stays psv's.
    HistoryOptions relative;
    relative.relativeTo = "*";
    const History r = readHistory(dir, relative);
    ASSERT_EQ(stepsOf(r, "psv", "time").size(), 1u) << r.steps.dump(2);
    EXPECT_EQ(stepsOf(r, "psv", "time")[0]["run"], 5u);
}

TEST(HistoryTest, AFixIsAStepFasterAndBetter) {
    const std::string dir = test::makeTempDir("history-fix");
    std::vector<double> ms(8, 30.0), mismatch(8, 0.01);
    for (size_t k = 4; k < 8; ++k) ms[k] = 20.0, mismatch[k] = 0.0;
    writeRuns(dir, ms, mismatch, kSpread);
    const History h = readHistory(dir, {});
    ASSERT_EQ(stepsOf(h, "psv", "time").size(), 1u) << h.steps.dump(2);
    EXPECT_EQ(stepsOf(h, "psv", "time")[0]["direction"], "faster");
    EXPECT_EQ(stepsOf(h, "psv", "time")[0]["run"], 4u);
    EXPECT_EQ(stepsOf(h, "psv", "accuracy")[0]["direction"], "better");
}

TEST(HistoryTest, TheNewestRunsRegressionFailsTheCommand) {
    const std::string dir = test::makeTempDir("history-newest");
    std::vector<double> ms(6, 20.0), mismatch(6, 0.0);
    ms[5] = 28.0;
    writeRuns(dir, ms, mismatch, kSpread);
    const History h = readHistory(dir, {});
    EXPECT_EQ(h.newestRegressions, 1u) << h.steps.dump(2);

    const std::string out = test::makeTempDir("history-out") + "/report";
    const test::Ran ran = test::runArgs({SHADOWLAB_BINARY, "history", dir, "--out", out});
    EXPECT_EQ(ran.rc, 3) << ran.err;
    EXPECT_NE(ran.err.find("REGRESSION psv: slower from the newest run (" + commitOf(5).substr(0, 10) + ")"), std::string::npos) << ran.err;
    for (const char* f : {"history.md", "history.json", "history.junit.xml", "history.html", "history_time.png", "history_accuracy.png"})
        EXPECT_TRUE(fs::is_regular_file(out + "/" + f)) << f << "\n" << ran.err;
    std::ifstream junit(out + "/history.junit.xml");
    const std::string xml((std::istreambuf_iterator<char>(junit)), {});
    EXPECT_NE(xml.find("failures=\"1\""), std::string::npos) << xml;
    // The same folder without --out: the Markdown on standard output, the same verdict.
    const test::Ran md = test::runArgs({SHADOWLAB_BINARY, "history", dir});
    EXPECT_EQ(md.rc, 3);
    EXPECT_NE(md.out.find("**slower** from run 5"), std::string::npos) << md.out;
}

TEST(HistoryTest, RunsAreOrderedByStartTimeOrByName) {
    const std::string dir = test::makeTempDir("history-order");
    writeRuns(dir, {20, 20, 20, 20}, {0, 0, 0, 0}, kSpread);
    fs::create_directories(dir + "/not-a-run");
    const History byTime = readHistory(dir, {});
    ASSERT_EQ(byTime.runs.size(), 4u);
    EXPECT_EQ(byTime.runs[0]["folder"], "run-100");
    EXPECT_EQ(byTime.runs[3]["folder"], "run-97");
    ASSERT_EQ(byTime.notes.size(), 1u);
    EXPECT_NE(byTime.notes[0].find("not-a-run"), std::string::npos);
    HistoryOptions byName;
    byName.byName = true;
    EXPECT_EQ(readHistory(dir, byName).runs[0]["folder"], "run-100");
    EXPECT_EQ(readHistory(dir, byName).runs[3]["folder"], "run-99"); // "run-100" < "run-97" < ... as text
}

TEST(HistoryTest, AFolderNameIsShownAsTextWhenItNamesARun) {
    const std::string dir = test::makeTempDir("history-names");
    writeRuns(dir, {20, 20}, {0, 0}, kSpread);
    const std::string hostile = dir + "/[x](javascript:alert(1))";
    fs::create_directories(hostile);
    Json s = summaryOf(20, 0, kSpread, 3, "unknown", "2026-12-09T10:00:00Z");
    std::ofstream(hostile + "/summary.json") << s.dump();
    const History h = readHistory(dir, {});
    ASSERT_EQ(h.runs.size(), 3u);
    EXPECT_EQ(h.runs[2]["label"], "[x](javascript:alert(1))"); // no commit: the folder names it
    const std::string md = historyMarkdown(h, dir, {}, false);
    EXPECT_EQ(md.find("](javascript"), std::string::npos) << md;
    EXPECT_NE(md.find("\\[x\\]\\(javascript\\:alert\\(1\\)\\)"), std::string::npos) << md;
}

// Thirteenth probe: a tampered commit (100,000 characters and a bidi override) and renderer were
// written whole into history.json. A commit that is not hex is no build's; text is bounded.
TEST(HistoryTest, ACommitOrRendererNoRunWritesIsNotCopied) {
    const std::string dir = test::makeTempDir("history-commit");
    writeRuns(dir, {20, 20}, {0, 0}, kSpread);
    Json s = summaryOf(20, 0, kSpread, 3, std::string(100000, 'c') + "\u202E<script>", "2026-12-09T10:00:00Z");
    s["renderer"] = std::string(300000, 'R');
    fs::create_directories(dir + "/tampered");
    std::ofstream(dir + "/tampered/summary.json") << s.dump();
    // A 300,000-character renderer is no run's (twenty-second probe: sweep merge copied one whole
    // into its report): the summary is bad input, named (probe 26: it was left out, and a damaged
    // newest run could hide a regression).
    try {
        readHistory(dir, {});
        ADD_FAILURE() << "a damaged run was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("tampered/summary.json: at /renderer"), std::string::npos) << e.what();
    }
    // The commit alone is not copied: the run is kept, its commit "unknown".
    s["renderer"] = "llvmpipe";
    std::ofstream(dir + "/tampered/summary.json") << s.dump();
    const History h = readHistory(dir, {});
    ASSERT_EQ(h.runs.size(), 3u);
    EXPECT_EQ(h.runs[2]["commit"], "unknown");
    EXPECT_EQ(h.runs[2]["label"], "tampered");
}

// Fifteenth probe: a newest run at another resolution was called a regression with no word that
// its config changed (compare says so); history names where the config changed.
TEST(HistoryTest, AChangeOfConfigBetweenRunsIsNoted) {
    const std::string dir = test::makeTempDir("history-config");
    writeRuns(dir, {20, 20, 20}, {0, 0, 0}, kSpread);
    const std::vector<std::string> folders = {"run-98", "run-99", "run-100"};
    for (const std::string& f : folders)
        std::ofstream(dir + "/" + f + "/config.resolved.json") << Json{{"resolution", {64, f == "run-98" ? 128 : 64}}}.dump();
    const History h = readHistory(dir, {});
    ASSERT_EQ(h.notes.size(), 1u);
    // run-98 is the newest (writeRuns dates run-100 first).
    EXPECT_NE(h.notes[0].find("the config changed between run-99 and run-98 in: resolution"), std::string::npos) << h.notes[0];
}

TEST(HistoryTest, BadFoldersAndOptionsAreExit2) {
    const std::string dir = test::makeTempDir("history-bad");
    writeRuns(dir, {20}, {0}, kSpread);
    EXPECT_THROW(readHistory(dir, {}), InputError); // one run is no history
    EXPECT_THROW(readHistory(dir + "/missing", {}), InputError);
    writeRuns(dir, {20, 20}, {0, 0}, kSpread);
    HistoryOptions relative;
    relative.relativeTo = "nope";
    EXPECT_THROW(readHistory(dir, relative), InputError);
    const std::string out = dir + "-out";
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"history"}, {"history", dir, "--window", "0"}, {"history", dir, "--window", "x"},
          {"history", dir, "--threshold", "-1"}, {"history", dir, dir}, {"history", dir, "--bogus"},
          // Eleventh probe: 0x10 was read as 16 %, " 5" as 5 %.
          {"history", dir, "--threshold", "0x10"}, {"history", dir, "--threshold", " 5"}, {"history", dir, "--threshold", "inf"},
          // Fifteenth probe: a window of 1 could never find a step.
          {"history", dir, "--window", "1"},
          {"history", dir + "/missing", "--out", out}, {"history", dir, "--relative-to", "nope", "--out", out}}) {
        std::vector<std::string> argv{SHADOWLAB_BINARY};
        argv.insert(argv.end(), args.begin(), args.end());
        const test::Ran ran = test::runArgs(argv);
        EXPECT_EQ(ran.rc, 2) << args.back() << ": " << ran.err;
        EXPECT_EQ(std::count(ran.err.begin(), ran.err.end(), '\n'), 1) << ran.err;
        EXPECT_FALSE(fs::exists(out)) << "bad input left an output folder behind";
    }
}

// Seventh probe: a run whose started_utc was "not-a-date" sorted as the newest and decided the
// exit code; negative times were tabulated. Such a summary is not a run's: history and compare
// refuse it.
TEST(HistoryTest, ASummaryNoRunWritesIsBadInput) {
    const std::string dir = test::makeTempDir("history-tampered");
    writeRuns(dir, {20, 20, 20, 20}, {0, 0, 0, 0}, kSpread);
    auto edit = [&](const std::string& run, const std::function<void(Json&)>& change) {
        Json s = Json::parse(std::ifstream(dir + "/" + run + "/summary.json"));
        change(s);
        std::ofstream(dir + "/" + run + "/summary.json") << s.dump();
    };
    edit("run-100", [](Json& s) { s["started_utc"] = "not-a-date"; });
    edit("run-99", [](Json& s) { s["algorithms"]["psv"]["repetitions"]["time_ms"]["total"][0] = -5.0; });
    edit("run-98", [](Json& s) { s["algorithms"]["psv"]["repetitions"]["time_ms"]["total"][3] = "fast"; });
    writeRuns(dir + "/more", {20, 20}, {0, 0}, kSpread);
    for (const char* run : {"run-100", "run-99"}) fs::rename(dir + "/more/" + run, dir + "/ok-" + run);
    // Probe 26: left out with a note, a damaged newest run let the run before it stand for the
    // newest, and a regression pass (exit 0). A finished run's damaged summary is bad input, named
    // as compare names it; a folder that holds no run is still left out with a note.
    try {
        readHistory(dir, {});
        ADD_FAILURE() << "a damaged run was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("run-100/summary.json: at /started_utc"), std::string::npos) << e.what();
    }
    for (const char* run : {"run-100", "run-99", "run-98", "more"}) fs::remove_all(dir + "/" + run);
    fs::create_directories(dir + "/notes");
    const History h = readHistory(dir, {});
    EXPECT_EQ(h.runs.size(), 3u); // run-97 and the two good ones
    ASSERT_FALSE(h.notes.empty());
    EXPECT_NE(h.notes[0].find("left out: notes"), std::string::npos) << h.notes[0];
    const std::string bad = test::makeTempDir("history-tampered-compare");
    writeRuns(bad, {20, 20, 20, 20}, {0, 0, 0, 0}, kSpread);
    Json s = Json::parse(std::ifstream(bad + "/run-99/summary.json"));
    s["algorithms"]["psv"]["repetitions"]["time_ms"]["total"][0] = -5.0;
    std::ofstream(bad + "/run-99/summary.json") << s.dump();
    const test::Ran ran = test::runArgs({SHADOWLAB_BINARY, "compare", bad + "/run-97", bad + "/run-99"});
    EXPECT_EQ(ran.rc, 2) << ran.err;
    EXPECT_NE(ran.err.find("/algorithms/psv"), std::string::npos) << ran.err;
    const test::Ran history = test::runArgs({SHADOWLAB_BINARY, "history", bad});
    EXPECT_EQ(history.rc, 2) << history.err;
    EXPECT_NE(history.err.find("run-99/summary.json: at /algorithms/psv"), std::string::npos) << history.err;
}

// Eighth probe: a field of the wrong type (a time written as "NaN", an overflow as "many", a
// renderer as a number) stopped compare with a library's message and exit 1. It is bad input,
// named by its file and JSON path, by history too.
TEST(HistoryTest, AFieldOfTheWrongTypeIsBadInputNamingItsPath) {
    const std::vector<std::pair<std::function<void(Json&)>, std::string>> edits = {
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"]["total"]["mean"] = "NaN"; }, "/algorithms/psv/time_ms/total/mean"},
        {[](Json& s) { s["algorithms"]["psv"]["overflow"] = "many"; }, "/algorithms/psv/overflow"},
        {[](Json& s) { s["algorithms"]["psv"]["memory_bytes"] = Json::array({1, "x"}); }, "/algorithms/psv/memory_bytes/1"},
        {[](Json& s) { s["algorithms"]["psv"] = 7; }, "/algorithms/psv"},
        {[](Json& s) { s["renderer"] = 3; }, "/renderer"},
        {[](Json& s) { s["build"] = {{"commit", 5}}; }, "/build"},
        // Ninth probe: counts that no run counts were read as 0 or wrapped to 2^64 - 1.
        {[](Json& s) { s["algorithms"]["psv"]["overflow"] = 1e30; }, "/algorithms/psv/overflow"},
        {[](Json& s) { s["algorithms"]["psv"]["overflow"] = -1; }, "/algorithms/psv/overflow"},
        {[](Json& s) { s["algorithms"]["psv"]["overflow"] = 0.5; }, "/algorithms/psv/overflow"},
        {[](Json& s) { s["algorithms"]["psv"]["memory_bytes"] = -100; }, "/algorithms/psv/memory_bytes"},
        {[](Json& s) { s["algorithms"]["psv"]["accuracy"] = Json::array(); }, "/algorithms/psv/accuracy"},
        {[](Json& s) { s["algorithms"]["psv"]["accuracy"]["mismatch_ratio_max"] = -1; }, "/algorithms/psv/accuracy/mismatch_ratio_max"},
        {[](Json& s) { s["algorithms"]["psv"]["accuracy"]["per_frame_mismatch"] = Json::array({0.5, 2}); },
         "/algorithms/psv/accuracy/per_frame_mismatch/1"},
        // Eleventh probe: ids no run writes (control characters and U+FFFE made compare.junit.xml
        // unreadable), and a time that does not exist sorted as the newest run.
        {[](Json& s) { s["algorithms"]["ev\u0001\u001b[31m\uFFFEx"] = s["algorithms"]["psv"]; }, "/algorithms"},
        {[](Json& s) { s["algorithms"]["=HYPERLINK(\"x\")"] = s["algorithms"]["psv"]; }, "/algorithms"},
        {[](Json& s) { s["started_utc"] = "2026-13-45T99:99:99Z"; }, "/started_utc"},
        {[](Json& s) { s["started_utc"] = "2025-02-29T10:00:00Z"; }, "/started_utc"},
        // Twelfth probe: a 200,000-character stage name was written whole into compare.md.
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"][std::string(200000, 'A')] = {{"mean", 1.0}}; }, "/algorithms/psv/time_ms"},
        {[](Json& s) { s["algorithms"]["psv"]["counters"]["<img onerror=x>"] = {{"mean", 1.0}}; }, "/algorithms/psv/counters"},
        // Seventeenth probe: the right types in the wrong nesting (a stage time as a bare number,
        // repetitions without their times) stopped compare and history with the JSON library's
        // message and exit 1; an algorithm written as a formula was taken.
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"]["total"] = 3; }, "/algorithms/psv/time_ms/total"},
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"] = 3; }, "/algorithms/psv/time_ms"},
        {[](Json& s) { s["algorithms"]["psv"]["repetitions"] = {{"count", 9}}; }, "/algorithms/psv/repetitions"},
        {[](Json& s) { s["algorithms"]["psv"]["repetitions"] = Json::array({1, 2, 3}); }, "/algorithms/psv/repetitions"},
        {[](Json& s) { s["algorithms"]["psv"]["repetitions"]["time_ms"]["total"] = 4; }, "/algorithms/psv/repetitions/time_ms/total"},
        {[](Json& s) { s["algorithms"]["psv"]["repetitions"]["count"] = 2.5; }, "/algorithms/psv/repetitions/count"},
        {[](Json& s) { s["algorithms"]["psv"]["total_ms_per_frame"] = 4; }, "/algorithms/psv/total_ms_per_frame"},
        {[](Json& s) { s["algorithms"]["psv"]["algorithm"] = "=HYPERLINK(\"http://x\",\"y\")"; }, "/algorithms/psv/algorithm"},
    };
    for (const auto& [change, path] : edits) {
        SCOPED_TRACE(path);
        const std::string dir = test::makeTempDir("compare-types");
        writeRuns(dir, {20, 20, 20}, {0, 0, 0}, kSpread);
        Json s = Json::parse(std::ifstream(dir + "/run-99/summary.json"));
        change(s);
        std::ofstream(dir + "/run-99/summary.json") << s.dump();
        for (const auto& args : {std::vector<std::string>{dir + "/run-98", dir + "/run-99"}, {dir + "/run-99", dir + "/run-98"}}) {
            const test::Ran ran = test::runArgs({SHADOWLAB_BINARY, "compare", args[0], args[1], "--out", dir + "/cmp"});
            EXPECT_EQ(ran.rc, 2) << ran.err;
            EXPECT_EQ(std::count(ran.err.begin(), ran.err.end(), '\n'), 1) << ran.err;
            EXPECT_NE(ran.err.find("run-99/summary.json: at " + path), std::string::npos) << ran.err;
        }
        EXPECT_THROW(readHistory(dir, {}), InputError); // history names it as compare does (probe 26)
    }
}

// Seventh probe: `compare A B --out A --force` and `history H --out H/r1 --force` replaced a run
// they had just read with their report (exit 0). An output that is, holds or lies inside an input
// is refused before anything is read or written.
// Twentieth probe: a run and a compare went into a compare's output (and a history's), whose next
// --force was then refused for what it would delete. Outputs never nest.
TEST(HistoryTest, NothingIsWrittenInsideACompareOrHistoryOutput) {
    const std::string dir = test::makeTempDir("history-nesting");
    writeRuns(dir, {20, 20, 20}, {0, 0, 0}, kSpread);
    const std::string runs = dir + "/runs";
    fs::create_directories(runs);
    for (const char* r : {"run-100", "run-99", "run-98"}) fs::rename(dir + "/" + r, runs + "/" + r);
    ASSERT_EQ(test::runArgs({SHADOWLAB_BINARY, "compare", runs + "/run-100", runs + "/run-99", "--out", dir + "/cmp"}).rc, 0);
    ASSERT_EQ(test::runArgs({SHADOWLAB_BINARY, "history", runs, "--out", dir + "/hist"}).rc, 0);
    for (const std::string outer : {dir + "/cmp", dir + "/hist"}) {
        const test::Ran c = test::runArgs({SHADOWLAB_BINARY, "compare", runs + "/run-100", runs + "/run-99", "--out", outer + "/inner"});
        EXPECT_EQ(c.rc, 2) << c.err;
        EXPECT_NE(c.err.find("a shadowlab output"), std::string::npos) << c.err;
        const test::Ran r = test::runArgs({SHADOWLAB_BINARY, "validate", std::string(SHADOWLAB_SOURCE_DIR) + "/configs/smoke.json", "--set",
                                           "output.dir=\"" + outer + "/inner\""});
        EXPECT_EQ(r.rc, 2) << r.err;
        EXPECT_FALSE(fs::exists(outer + "/inner"));
    }
}

TEST(HistoryTest, NeitherHistoryNorCompareReplacesARunItReads) {
    const std::string dir = test::makeTempDir("history-inputs");
    writeRuns(dir, {20, 20, 20}, {0, 0, 0}, kSpread);
    const std::string a = dir + "/run-100", b = dir + "/run-99";
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"compare", a, b, "--out", a, "--force"}, {"compare", a, b, "--out", b, "--force"},
          {"compare", a, b, "--out", dir, "--force"}, {"compare", a, b, "--out", a + "/cmp"},
          {"history", dir, "--out", a, "--force"}, {"history", dir, "--out", dir, "--force"}, {"history", dir, "--out", dir + "/h"}}) {
        std::vector<std::string> argv{SHADOWLAB_BINARY};
        argv.insert(argv.end(), args.begin(), args.end());
        const test::Ran ran = test::runArgs(argv);
        EXPECT_EQ(ran.rc, 2) << ::testing::PrintToString(args) << ": " << ran.err;
        EXPECT_EQ(std::count(ran.err.begin(), ran.err.end(), '\n'), 1) << ran.err;
        for (const std::string& run : {a, b}) EXPECT_TRUE(fs::is_regular_file(run + "/summary.json")) << run;
    }
    EXPECT_FALSE(fs::exists(a + "/cmp"));
    EXPECT_FALSE(fs::exists(dir + "/h"));
    // Tenth probe: a run folder neither reads, given as --out with --force, was deleted and replaced
    // by the report. Only an earlier report of the same command is replaced.
    const std::string other = test::makeTempDir("history-other-run") + "/run";
    fs::copy(a, other, fs::copy_options::recursive);
    std::ofstream(other + "/.shadowlab-output");  // as a run marks its output
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"compare", a, b, "--out", other, "--force"}, {"history", dir, "--out", other, "--force"}}) {
        std::vector<std::string> argv{SHADOWLAB_BINARY};
        argv.insert(argv.end(), args.begin(), args.end());
        const test::Ran ran = test::runArgs(argv);
        EXPECT_EQ(ran.rc, 2) << ::testing::PrintToString(args) << ": " << ran.err;
        EXPECT_NE(ran.err.find("another command's output"), std::string::npos) << ran.err;
        EXPECT_TRUE(fs::is_regular_file(other + "/summary.json"));
    }
    const std::string report = test::makeTempDir("history-report") + "/cmp";
    for (int i = 0; i < 2; ++i) EXPECT_EQ(test::runArgs({SHADOWLAB_BINARY, "compare", a, b, "--out", report, "--force"}).rc, 0);
}

// Twenty-first probe: a full standard output was said twice (the command's error, then the
// program's check of the same stream); one line, exit 2, as every other command.
TEST(HistoryTest, AFullStandardOutputIsOneLine) {
    const std::string dir = test::makeTempDir("history-full");
    writeRuns(dir, std::vector<double>(3, 20.0), std::vector<double>(3, 0.0), kSpread);
    const std::string bin = SHADOWLAB_BINARY;
    for (const std::string& command : {bin + " history " + dir, bin + " compare " + dir + "/run-99 " + dir + "/run-100"}) {
        std::string out;
        EXPECT_EQ(test::runCommand("{ " + command + " > /dev/full; }", out), 2) << command << "\n" << out; // stderr kept
        const std::string trimmed = out.substr(0, out.find_last_not_of('\n') + 1);
        EXPECT_EQ(std::count(trimmed.begin(), trimmed.end(), '\n'), 0) << command << "\n" << out;
        EXPECT_NE(out.find("standard output"), std::string::npos) << out;
    }
}

// Twenty-first probe: sweep merge tabulated a negative and a 309-digit stage time, and
// multiplied a tampered resolution into a wrapped (or zero) pixel count. What compare, history and
// merge read is held to what a run writes.
TEST(HistoryTest, ATimeOrResolutionNoRunWritesIsBadInput) {
    const std::vector<std::pair<std::function<void(Json&)>, std::string>> edits = {
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"]["total"]["mean"] = -5.0; }, "/algorithms/psv/time_ms/total/mean"},
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"]["total"]["mean"] = 1e308; }, "/algorithms/psv/time_ms/total/mean"},
        {[](Json& s) { s["algorithms"]["psv"]["counters"] = {{"nodes", {{"mean", 1e300}}}}; }, "/algorithms/psv/counters/nodes/mean"},
        {[](Json& s) { s["resolution"] = Json::array({8589934593ull, 2147483648ull}); }, "/resolution"},
        {[](Json& s) { s["resolution"] = Json::array({0, 0}); }, "/resolution"},
        // Twenty-second probe: a null statistic stopped compare with the JSON library's message and
        // exit 1; a missing total, an empty repetition list and a 1 MB or bidi renderer were taken.
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"]["total"]["mean"] = nullptr; }, "/algorithms/psv/time_ms/total/mean"},
        {[](Json& s) { s["algorithms"]["psv"]["counters"] = {{"nodes", {{"mean", nullptr}}}}; }, "/algorithms/psv/counters/nodes/mean"},
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"].erase("total"); }, "/algorithms/psv/time_ms/total"},
        {[](Json& s) { s["algorithms"]["psv"]["repetitions"]["time_ms"]["total"] = Json::array(); }, "/algorithms/psv/repetitions/time_ms/total"},
        {[](Json& s) { s["renderer"] = std::string(1000000, 'R'); }, "/renderer"},
        {[](Json& s) { s["renderer"] = "a\u202eb\u200bc"; }, "/renderer"},
        // Twenty-second probe (left then): a statistic whose min lies above its max was compared.
        {[](Json& s) { s["algorithms"]["psv"]["time_ms"]["total"] = {{"mean", 5.0}, {"min", 9.0}, {"max", 1.0}}; }, "/algorithms/psv/time_ms/total/min"},
        {[](Json& s) { s["algorithms"]["psv"]["counters"] = {{"nodes", {{"mean", 50.0}, {"min", 1.0}, {"max", 2.0}}}}; }, "/algorithms/psv/counters/nodes/mean"},
        // Twenty-fourth probe: an object as a counter's mean stopped compare with the JSON library's
        // message (exit 1); -5e9 rays and frames of 50 % under a worst frame of 0 were compared.
        {[](Json& s) { s["algorithms"]["psv"]["counters"] = {{"nodes", {{"mean", Json::object()}}}}; }, "/algorithms/psv/counters/nodes/mean"},
        {[](Json& s) { s["algorithms"]["psv"]["counters"] = {{"nodes", {{"mean", -5e9}}}}; }, "/algorithms/psv/counters/nodes/mean"},
        {[](Json& s) { s["algorithms"]["psv"]["accuracy"]["per_frame_mismatch"] = {0.5, 0.5}; }, "/algorithms/psv/accuracy/per_frame_mismatch/0"},
        {[](Json& s) { s["algorithms"]["psv"]["accuracy"]["mismatch_ratio"] = 0.5; }, "/algorithms/psv/accuracy/mismatch_ratio"},
    };
    for (const auto& [change, path] : edits) {
        const std::string dir = test::makeTempDir("history-bad-number");
        writeRuns(dir, {20, 20}, {0, 0}, kSpread);
        Json s = Json::parse(std::ifstream(dir + "/run-99/summary.json"));
        change(s);
        std::ofstream(dir + "/run-99/summary.json") << s.dump();
        const test::Ran ran = test::runArgs({SHADOWLAB_BINARY, "compare", dir + "/run-100", dir + "/run-99"});
        EXPECT_EQ(ran.rc, 2) << path << ": " << ran.err;
        EXPECT_NE(ran.err.find(path), std::string::npos) << ran.err;
        EXPECT_EQ(std::count(ran.err.begin(), ran.err.end(), '\n'), 1) << ran.err;
    }
}

// Twenty-third probe: a summary with no results ("algorithms": {}) beside a config that runs sm
// compared as "No regression", exit 0, and history showed empty cells. Results must be those of
// exactly the ids the run's config.resolved.json gives, each of its algorithm (as sweep merge holds them).
// Twenty-fourth probe: "complete": "yes" stopped compare with the JSON library's message, exit 1.
TEST(HistoryTest, ACompleteThatIsNotTrueIsBadInput) {
    for (const Json& complete : {Json("yes"), Json(nullptr), Json(1), Json::object(), Json::array()}) {
        const std::string dir = test::makeTempDir("history-complete");
        writeRuns(dir, {20, 20}, {0, 0}, kSpread);
        Json s = Json::parse(std::ifstream(dir + "/run-99/summary.json"));
        s["complete"] = complete;
        std::ofstream(dir + "/run-99/summary.json") << s.dump();
        const test::Ran ran = test::runArgs({SHADOWLAB_BINARY, "compare", dir + "/run-100", dir + "/run-99"});
        EXPECT_EQ(ran.rc, 2) << complete.dump() << ": " << ran.err;
        EXPECT_NE(ran.err.find("not a complete run's summary"), std::string::npos) << ran.err;
    }
}

TEST(HistoryTest, ResultsOtherThanTheConfigsIdsAreBadInput) {
    const std::vector<std::pair<std::function<void(Json&)>, std::string>> edits = {
        {[](Json& s) { s["algorithms"] = Json::object(); }, "holds no results for \"bvh_raytrace\""},
        {[](Json& s) { s["algorithms"].erase("bvh_raytrace"); }, "holds no results for \"bvh_raytrace\""},
        {[](Json& s) { s["algorithms"]["extra"] = s["algorithms"]["psv"]; }, "an id its config.resolved.json does not give"},
        {[](Json& s) { s["algorithms"]["psv"]["algorithm"] = "izb"; }, "another algorithm than its config.resolved.json"},
    };
    for (const auto& [change, why] : edits) {
        const std::string dir = test::makeTempDir("history-ids");
        writeRuns(dir, {20, 20}, {0, 0}, kSpread);
        for (const char* run : {"/run-99", "/run-100"}) {
            Json s = Json::parse(std::ifstream(dir + run + "/summary.json"));
            s["algorithms"]["psv"]["algorithm"] = "psv";
            s["algorithms"]["bvh_raytrace"]["algorithm"] = "bvh_raytrace";
            if (std::string(run) == "/run-99") change(s);
            std::ofstream(dir + run + "/summary.json") << s.dump();
            std::ofstream(dir + run + "/config.resolved.json")
                << R"({"reference": false, "algorithms": [{"id": "psv", "algorithm": "psv"}, {"id": "bvh_raytrace", "algorithm": "bvh_raytrace"}]})";
        }
        const test::Ran ran = test::runArgs({SHADOWLAB_BINARY, "compare", dir + "/run-100", dir + "/run-99"});
        EXPECT_EQ(ran.rc, 2) << why << ": " << ran.err;
        EXPECT_NE(ran.err.find(why), std::string::npos) << ran.err;
        EXPECT_EQ(std::count(ran.err.begin(), ran.err.end(), '\n'), 1) << ran.err;
    }
}

// Twenty-second probe: compare followed a summary.json linked to another run's (merge refused it),
// and took a summary's resolution that its own config.resolved.json contradicts.
TEST(HistoryTest, ASummaryThatIsNotTheRunsOwnIsBadInput) {
    const std::string dir = test::makeTempDir("history-not-own");
    writeRuns(dir, {20, 20, 20}, {0, 0, 0}, kSpread);
    fs::remove(dir + "/run-99/summary.json");
    fs::create_symlink(dir + "/run-98/summary.json", dir + "/run-99/summary.json");
    test::Ran ran = test::runArgs({SHADOWLAB_BINARY, "compare", dir + "/run-100", dir + "/run-99"});
    EXPECT_EQ(ran.rc, 2) << ran.err;
    EXPECT_NE(ran.err.find("symbolic link"), std::string::npos) << ran.err;
    Json s = Json::parse(std::ifstream(dir + "/run-98/summary.json"));
    s["resolution"] = Json::array({64, 64});
    std::ofstream(dir + "/run-98/summary.json") << s.dump();
    std::ofstream(dir + "/run-98/config.resolved.json") << R"({"resolution": [32, 32]})";
    ran = test::runArgs({SHADOWLAB_BINARY, "compare", dir + "/run-100", dir + "/run-98"});
    EXPECT_EQ(ran.rc, 2) << ran.err;
    EXPECT_NE(ran.err.find("/resolution"), std::string::npos) << ran.err;
}

} // namespace
} // namespace shadowlab
