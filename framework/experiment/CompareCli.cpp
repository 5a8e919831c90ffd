#include "framework/experiment/CompareCli.h"

#include "framework/core/Error.h"
#include "framework/core/FileIO.h"
#include "framework/core/Interrupt.h"
#include "framework/core/Text.h"
#include "framework/experiment/Compare.h"
#include "framework/experiment/OutputPlace.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace shadowlab {

const char* kCompareUsage = R"(  shadowlab compare BASE NEW [--threshold PCT] [--relative-to ID] [--out DIR] [--force]
      What changed from run folder BASE to run folder NEW, per algorithm id: each stage's time
      (ratio, 95 % interval, faster / slower / within noise), accuracy, overflow, memory, counters
      and the saved images' changed pixels. A regression: total time slower past PCT (default 10) %
      with its whole interval above 1, accuracy worse past PCT %, or more overflow. Markdown on
      standard output, or with --out: DIR/compare.md, compare.html, compare.junit.xml and images/.
      --relative-to ID divides every time by ID's total of the same pass first ("*": by the
      geometric mean of every id's): on a shared machine whose load changed between the runs,
      only what changed relative to it remains.
      Exit code 0 without regression, 3 with one.
)";

namespace {

double parseThreshold(const std::string& text) {
    std::string t = text;
    if (!t.empty() && t.back() == '%') t.pop_back();
    char* end = nullptr;
    const double v = t.empty() ? NAN : std::strtod(t.c_str(), &end);
    if (!(v >= 0 && v <= 1000) || end != t.c_str() + t.size())
        throw InputError("--threshold", "", "expected a percentage from 0 to 1000, e.g. 5 or 5%, got \"" + shortText(text, 40) + "\"");
    return v / 100.0;
}

/// compare.html from compare.md, as the run's report (scripts/report_html.py, argv only).
void writeHtml(const std::string& dir) {
    const std::string script = std::string(SHADOWLAB_SOURCE_DIR) + "/scripts/report_html.py";
    if (runChildProcess({SHADOWLAB_PLOT_PYTHON, script, dir + "/compare.md", dir + "/compare.html"}, dir + "/compare_html.log") == 0) {
        std::error_code ec;
        std::filesystem::remove(dir + "/compare_html.log", ec);
    } else {
        std::fprintf(stderr, "shadowlab compare: compare.html was not written (see compare_html.log)\n");
    }
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
        auto value = [&](const char* what) {
            if (++i >= args.size()) throw InputError(a, "", std::string("needs ") + what);
            if (args[i].empty() || args[i].starts_with("--")) throw InputError(a, "", std::string("needs ") + what + ", not \"" + shortText(args[i], 40) + "\"");
            return args[i];
        };
        if (a == "--threshold") {
            if (thresholdGiven) throw InputError(a, "", "is given twice");
            opt.threshold = parseThreshold(value("a percentage"));
            thresholdGiven = true;
        } else if (a == "--relative-to") {
            if (!opt.relativeTo.empty()) throw InputError(a, "", "is given twice");
            opt.relativeTo = value("an algorithm id");
        } else if (a == "--out") {
            if (!out.empty()) throw InputError(a, "", "is given twice");
            out = value("a folder");
            if (const std::string why = pathTextProblem(out); !why.empty()) throw InputError("--out", "", "the folder's name " + why);
        } else if (a == "--force") {
            force = true;
        } else if (!a.empty() && a[0] == '-') {
            throw InputError(shortText(a, 60), "", "unknown option of `compare` (see shadowlab compare --help)");
        } else {
            runs.push_back(a);
        }
    }
    if (runs.size() != 2) throw InputError("compare", "", "expects two run folders, BASE and NEW (see shadowlab compare --help)");
    if (out.empty()) {
        const Comparison c = compareRuns(runs[0], runs[1], opt);
        std::cout << comparisonMarkdown(c, runs[0], runs[1], opt);
        std::cout.flush();
        if (!std::cout) throw InputError("standard output", "", "cannot be written (a full disk or a closed stream)");
        std::fprintf(stderr, "shadowlab compare: %zu regressions\n", c.regressions);
        return c.regressions ? kRegressionExit : 0;
    }
    installInterruptHandlers();
    OutputPlace place = OutputPlace::open(out, force);
    const std::string dir = place.partialDir();
    std::filesystem::create_directories(dir + "/images");
    opt.imagesDir = dir + "/images";
    const Comparison c = compareRuns(runs[0], runs[1], opt);
    writeFileAtomic(dir + "/compare.md", comparisonMarkdown(c, runs[0], runs[1], opt));
    writeFileAtomic(dir + "/compare.junit.xml", comparisonJUnit(c));
    writeFileAtomic(dir + "/compare.json", Json{{"regressions", c.regressions}, {"notes", c.notes}, {"ids", c.records}}.dump(2) + "\n");
    writeHtml(dir);
    throwIfInterrupted();
    place.commit();
    std::fprintf(stderr, "shadowlab compare: %zu regressions; wrote %s (compare.md, compare.html, compare.junit.xml)\n", c.regressions,
                 shortText(place.finalDir(), 300).c_str());
    for (const Json& r : c.records)
        for (const Json& g : r["regressions"])
            std::fprintf(stderr, "shadowlab compare: REGRESSION %s: %s\n", r["id"].get<std::string>().c_str(), g.get<std::string>().c_str());
    return c.regressions ? kRegressionExit : 0;
}

} // namespace shadowlab
