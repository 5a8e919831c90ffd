#pragma once
// A sweep file (docs/sweep.md): a base experiment config plus axes. Each axis sets one or more
// dotted JSON paths of the config (the syntax of `--set`); the paths of one axis move together
// (zip) and the axes combine as a product. Every generated run is validated like a config before
// anything runs, and gets an id derived from its resolved config.
#include "framework/core/JsonNode.h"

#include <set>
#include <string>
#include <vector>

namespace shadowlab {

/// How plots and fits treat an axis.
enum class AxisScale {
    Category,  ///< plotted in order, linear axes (parameter values, light types, ...)
    Value,     ///< a size: the axis value itself (a number) is x; log-log plots and power-law fits
    Triangles, ///< a size: the run's triangle count (summary.json `triangles`) is x
    Pixels,    ///< a size: the run's width × height is x
};

struct SweepAxis {
    std::string name;                     ///< column name in sweep.csv, plan and tables
    std::vector<std::string> paths;       ///< dotted config paths, in file order
    std::vector<std::vector<Json>> values; ///< values[path][k]: the k-th value of each path
    std::vector<std::string> labels;      ///< labels[k]: how the k-th value is shown
    AxisScale scale = AxisScale::Category;
    size_t size() const { return labels.size(); }
};

/// A run is its point on the axes; its config is made from the base when needed (Sweep::runConfig),
/// so a sweep of many runs over a large base holds the base once, not once per run.
struct SweepRun {
    size_t index = 0;          ///< position in the product (the last axis varies fastest)
    std::string id;            ///< runId() of the resolved config: the run's folder name
    std::vector<size_t> point; ///< point[a]: the value index on axis a
};

struct Sweep {
    std::string file;        ///< the sweep file
    std::string name;        ///< `name`, default: the file name without .sweep.json / .json
    Json base;               ///< the base config, glTF paths made absolute
    std::vector<SweepAxis> axes; ///< values with their glTF paths made absolute
    Json axesJson;           ///< `axes` as written, glTF paths in values made absolute (for the snapshot)
    Json merge;              ///< the `merge` object: stages, counters, ratios for sweep.md
    std::string outputDir;   ///< `output.dir`, resolved against the sweep file's folder
    std::vector<SweepRun> runs;

    /// The experiment config of runs[k]: the base with the axis values of its point (glTF paths
    /// absolute). Built anew on each call; callers keep one at a time.
    Json runConfig(size_t k) const;

    /// The sweep as one self-contained file: base inlined, paths absolute, output.dir = `dir`
    /// (made absolute). Written as DIR/sweep.json; expanding it again gives the same runs and ids.
    Json snapshot(const std::string& dir) const;
};

/// `dir` absolute and lexically normal, without a trailing '/': the one spelling of an output
/// folder in snapshots, job scripts and messages, so the same folder always compares equal.
std::string absoluteFolder(const std::string& dir);

/// Reads, expands and validates a sweep file, one run at a time; any problem is an InputError
/// naming the file, the axis and the JSON path. Names, labels and paths are refused unless they are
/// UTF-8 without control characters; names and labels are at most kMaxLabelChars long.
Sweep loadSweep(const std::string& file);
Sweep parseSweep(const Json& json, const std::string& file);

/// A stable id of a run: a hash of its resolved config with output.dir left out, so the same run
/// keeps its id when axes are added or the sweep is written to another folder.
std::string runId(const Json& resolvedConfig);

/// The runs as JSON: {name, axes: [{name, scale, labels, paths}], merge, runs: [{index, id, axes: {name: label}}]}
/// (`sweep plan --json`, and DIR/plan.json for the merge's report).
Json planJson(const Sweep& sweep);

/// "size=10k res=[64,64]": the run's axis labels, for progress lines and errors (cut to a few
/// hundred characters).
std::string runLabel(const Sweep& sweep, const SweepRun& run);

std::string toString(AxisScale scale);

} // namespace shadowlab
