#include "framework/experiment/CompareCli.h"

#include "framework/core/Error.h"
#include "framework/core/StandardStreams.h"
#include "framework/core/FileIO.h"
#include "framework/core/Interrupt.h"
#include "framework/core/Text.h"
#include "framework/experiment/Compare.h"
#include "framework/experiment/History.h"
#include "framework/experiment/JUnit.h"
#include "framework/experiment/OutputPlace.h"

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace shadowlab {

const char* kCompareUsage = R"(  shadowlab compare BASE NEW [--threshold PCT] [--relative-to ID] [--out DIR] [--force]
      What changed from run folder BASE to run folder NEW, per algorithm id: each stage's time
      (ratio, 95 % interval, faster / slower / within noise), accuracy, overflow, memory, counters
      and the saved images' changed pixels. A regression: total time slower past PCT (default 10) %
      with its whole interval above 1, accuracy worse past PCT %, or more overflow. Markdown on
      standard output, or with --out: DIR/compare.md, compare.html, compare.junit.xml and images/
      (--force replaces an earlier compare output there, never a run's or another command's).
      --relative-to ID divides every time by ID's total of the same pass first ("*": by the
      median over the ids of each one's total over its median in BASE): on a shared machine
      whose load changed between the runs, only what changed relative to it remains.
      Exit code 0 without regression, 3 with one.
)";

const char* kHistoryUsage = R"(  shadowlab history DIR [--threshold PCT] [--relative-to ID] [--window N] [--by-name] [--out OUT] [--force]
      The runs of one experiment kept across commits, one run folder each directly in DIR, oldest
      first (by summary.json's started_utc; --by-name: by folder name): each id's total time and
      worst-frame mismatch run by run, and the runs where a step happened, named by commit. A time
      step: the median of the N (default 3) runs after a boundary over that of the N before, past
      PCT (default 10) % and past 4x the id's run-to-run noise, with 2 runs or more before it (a
      single run after it: with its whole interval; with fewer than 4 runs: compare's rule on the
      pooled passes); --relative-to as compare's.
      Markdown on standard output, or with --out: OUT/history.md, history.html, history.json,
      history.junit.xml and the plots history_time.png, history_accuracy.png (--force replaces an
      earlier history output there, never a run's or another command's).
      Exit code 0, or 3 when the newest run starts a step for the worse (slower, less accurate).
)";

namespace {

double parseThreshold(const std::string& text) {
    std::string t = text;
    if (!t.empty() && t.back() == '%') t.pop_back();
    char* end = nullptr;
    const double v = t.empty() ? NAN : std::strtod(t.c_str(), &end);
    // Plain decimals only (eleventh probe: "0x10" was read as 16 %, " 5" as 5 %).
    if (!plainDecimal(t) || !(v >= 0 && v <= 1000) || end != t.c_str() + t.size())
        throw InputError("--threshold", "", "expected a percentage from 0 to 1000, e.g. 5 or 5%, got \"" + shortText(text, 40) + "\"");
    return v / 100.0;
}

/// One of scripts/ with `args` (argv only), its output in DIR/LOG, removed when it succeeded; a
/// warning naming what was not written otherwise.
void runScript(const std::string& command, const std::string& script, std::vector<std::string> args, const std::string& dir,
               const std::string& log, const std::string& what) {
    const char* python = std::getenv("SHADOWLAB_PYTHON");
    args.insert(args.begin(), {python && *python ? python : SHADOWLAB_PLOT_PYTHON, std::string(SHADOWLAB_SOURCE_DIR) + "/scripts/" + script});
    if (runChildProcess(args, dir + "/" + log) == 0) {
        std::error_code ec;
        std::filesystem::remove(dir + "/" + log, ec);
    } else {
        std::fprintf(stderr, "shadowlab %s: %s not written (see %s)\n", command.c_str(), what.c_str(), log.c_str());
    }
}

/// An option's value: the next argument, which must be there and not be another option.
std::string optionValue(const std::vector<std::string>& args, size_t& i, const char* what) {
    const std::string& a = args[i];
    if (++i >= args.size()) throw InputError(a, "", std::string("needs ") + what);
    if (args[i].empty() || args[i].starts_with("--")) throw InputError(a, "", std::string("needs ") + what + ", not \"" + shortText(args[i], 40) + "\"");
    return args[i];
}

/// The options compare and history share; false when `args[i]` is none of them.
bool sharedOption(const std::vector<std::string>& args, size_t& i, double& threshold, bool& thresholdGiven, std::string& relativeTo,
                  std::string& out, bool& force) {
    const std::string& a = args[i];
    if (a == "--threshold") {
        if (thresholdGiven) throw InputError(a, "", "is given twice");
        threshold = parseThreshold(optionValue(args, i, "a percentage"));
        thresholdGiven = true;
    } else if (a == "--relative-to") {
        if (!relativeTo.empty()) throw InputError(a, "", "is given twice");
        relativeTo = optionValue(args, i, "an algorithm id");
    } else if (a == "--out") {
        if (!out.empty()) throw InputError(a, "", "is given twice");
        out = optionValue(args, i, "a folder");
        if (const std::string why = pathTextProblem(out); !why.empty()) throw InputError("--out", "", "the folder's name " + why);
    } else if (a == "--force") {
        if (force) throw InputError(a, "", "is given twice");
        force = true;
    } else {
        return false;
    }
    return true;
}

} // namespace

int compareCommand(const std::vector<std::string>& args) {
    std::vector<std::string> runs;
    std::string out;
    bool force = false, thresholdGiven = false;
    CompareOptions opt;
    for (size_t i = 1; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--help" || a == "-h") {
            std::fputs((std::string("Usage:\n") + kCompareUsage).c_str(), stdout);
            return 0;
        }
        if (sharedOption(args, i, opt.threshold, thresholdGiven, opt.relativeTo, out, force)) {
        } else if (!a.empty() && a[0] == '-') {
            throw InputError(shortText(a, 60), "", "unknown option of `compare` (see shadowlab compare --help)");
        } else {
            runs.push_back(a);
        }
    }
    if (runs.size() != 2) throw InputError("compare", "", "expects two run folders, BASE and NEW (see shadowlab compare --help)");
    if (out.empty()) {
        const Comparison c = compareRuns(runs[0], runs[1], opt);
        writeStandardOutput(comparisonMarkdown(c, runs[0], runs[1], opt));
        std::fprintf(stderr, "shadowlab compare: %zu regressions\n", c.regressions);
        return c.regressions ? kRegressionExit : 0;
    }
    OutputPlace::refuseInputsInside(out, runs, "compare"); // --force would delete a run it compares
    OutputPlace::refuseOtherKind(out, "compare.md", "compare");
    installInterruptHandlers();
    OutputPlace place = OutputPlace::open(out, force);
    const std::string dir = place.partialDir();
    std::filesystem::create_directories(dir + "/images");
    opt.imagesDir = dir + "/images";
    const Comparison c = compareRuns(runs[0], runs[1], opt);
    writeFileAtomic(dir + "/compare.md", comparisonMarkdown(c, runs[0], runs[1], opt));
    writeFileAtomic(dir + "/compare.junit.xml", comparisonJUnit(c));
    writeFileAtomic(dir + "/compare.json", Json{{"regressions", c.regressions}, {"notes", c.notes}, {"ids", c.records}}.dump(2) + "\n");
    runScript("compare", "report_html.py", {dir + "/compare.md", dir + "/compare.html"}, dir, "compare_html.log", "compare.html");
    throwIfInterrupted();
    place.commit();
    std::fprintf(stderr, "shadowlab compare: %zu regressions; wrote %s (compare.md, compare.html, compare.junit.xml)\n", c.regressions,
                 shortText(place.finalDir(), 300).c_str());
    for (const Json& r : c.records)
        for (const Json& g : r["regressions"])
            std::fprintf(stderr, "shadowlab compare: REGRESSION %s: %s\n", r["id"].get<std::string>().c_str(), g.get<std::string>().c_str());
    return c.regressions ? kRegressionExit : 0;
}

namespace {

/// history.junit.xml: per id, whether the newest run starts a step for the worse.
std::string historyJUnit(const History& h) {
    std::vector<JUnitCase> cases;
    for (const auto& [id, v] : h.ids.items()) {
        std::string slower, worse;
        for (const Json& s : h.steps) {
            if (s["id"] != id || !isNewestRegression(h, s)) continue;
            if (s["direction"] == "slower") slower = "slower from the newest run: " + shortNumber(s["ratio"].get<double>(), 4) + "×";
            if (s["direction"] == "worse")
                worse = "worst-frame mismatch " + shortNumber(100 * s["before"].get<double>(), 4) + " % → " + shortNumber(100 * s["after"].get<double>(), 4) + " %";
        }
        cases.push_back({id, "newest run not slower", slower});
        cases.push_back({id, "newest run not less accurate", worse});
    }
    return junitXml("shadowlab history", cases, 0.0);
}

} // namespace

int historyCommand(const std::vector<std::string>& args) {
    std::string dir, out;
    bool force = false, thresholdGiven = false, windowGiven = false;
    HistoryOptions opt;
    for (size_t i = 1; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--help" || a == "-h") {
            std::fputs((std::string("Usage:\n") + kHistoryUsage).c_str(), stdout);
            return 0;
        }
        if (sharedOption(args, i, opt.threshold, thresholdGiven, opt.relativeTo, out, force)) {
        } else if (a == "--window") {
            if (windowGiven) throw InputError(a, "", "is given twice");
            const std::string v = optionValue(args, i, "a number of runs");
            // At least 2: a step needs 2 runs before it inside the window (fifteenth probe: 1 was
            // accepted and no step could ever be found).
            if (v.empty() || v.size() > 3 || v.find_first_not_of("0123456789") != std::string::npos || std::stoi(v) < 2 || std::stoi(v) > 100)
                throw InputError("--window", "", "expected a number of runs from 2 to 100 (a step needs 2 runs before it), got \"" +
                                                      shortText(v, 40) + "\"");
            opt.window = size_t(std::stoi(v));
            windowGiven = true;
        } else if (a == "--by-name") {
            if (opt.byName) throw InputError(a, "", "is given twice");
            opt.byName = true;
        } else if (!a.empty() && a[0] == '-') {
            throw InputError(shortText(a, 60), "", "unknown option of `history` (see shadowlab history --help)");
        } else if (dir.empty()) {
            dir = a;
        } else {
            throw InputError("history", "", "expects one folder of run folders (see shadowlab history --help)");
        }
    }
    if (dir.empty()) throw InputError("history", "", "expects one folder of run folders (see shadowlab history --help)");
    auto report = [&](const History& h) {
        for (const Json& s : h.steps)
            if (isNewestRegression(h, s))
                std::fprintf(stderr, "shadowlab history: REGRESSION %s: %s from the newest run (%s)\n", shortText(s["id"].get<std::string>(), 60).c_str(),
                             s["direction"].get<std::string>().c_str(), shortText(s["label"].get<std::string>(), 60).c_str());
        std::fprintf(stderr, "shadowlab history: %zu runs, %zu steps, %zu from the newest run for the worse\n", h.runs.size(), h.steps.size(),
                     h.newestRegressions);
        return h.newestRegressions ? kRegressionExit : 0;
    };
    if (out.empty()) {
        const History h = readHistory(dir, opt);
        writeStandardOutput(historyMarkdown(h, dir, opt, false));
        return report(h);
    }
    const History h = readHistory(dir, opt); // before the output folder: bad input leaves nothing behind
    OutputPlace::refuseInputsInside(out, {dir}, "history"); // --force would delete runs it reads
    OutputPlace::refuseOtherKind(out, "history.md", "history");
    installInterruptHandlers();
    OutputPlace place = OutputPlace::open(out, force);
    const std::string outDir = place.partialDir();
    writeFileAtomic(outDir + "/history.md", historyMarkdown(h, dir, opt, true));
    writeFileAtomic(outDir + "/history.json", historyJson(h, opt).dump(2) + "\n");
    writeFileAtomic(outDir + "/history.junit.xml", historyJUnit(h));
    runScript("history", "history_plot.py", {outDir + "/history.json", outDir}, outDir, "history_plot.log", "the plots were");
    runScript("history", "report_html.py", {outDir + "/history.md", outDir + "/history.html"}, outDir, "history_html.log", "history.html");
    throwIfInterrupted();
    place.commit();
    std::fprintf(stderr, "shadowlab history: wrote %s (history.md, history.html, history.json, history.junit.xml)\n", shortText(place.finalDir(), 300).c_str());
    return report(h);
}

} // namespace shadowlab
