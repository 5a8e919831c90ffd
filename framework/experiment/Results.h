#pragma once
// Per-frame measurements of an experiment and the files made from them: frames.csv,
// summary.json and report.md.
#include "framework/core/JsonNode.h"
#include "framework/gl/StageTimer.h"
#include "framework/metrics/Accuracy.h"

#include <map>
#include <string>
#include <vector>

namespace shadowlab {

struct FrameRecord {
    int frame = 0;
    std::vector<StageTime> stages; ///< the algorithm's stages, then "total"
    std::map<std::string, double> counters;
    bool hasAccuracy = false;
    Accuracy accuracy;
    uint64_t overflow = 0;
};

struct AlgorithmResults {
    std::string id, algorithm;
    Json params;
    double preprocessMs = 0;
    size_t memoryBytes = 0;
    std::vector<FrameRecord> frames;
};

struct Stats {
    double mean = 0, min = 0, max = 0, median = 0;
    Json toJson() const { return {{"mean", mean}, {"min", min}, {"max", max}, {"median", median}}; }
};
Stats computeStats(std::vector<double> values);

struct ExperimentResults {
    Json meta; ///< name, renderer, resolution, triangles, ... (copied into summary.json)
    std::vector<AlgorithmResults> algorithms;

    void writeFramesCsv(const std::string& path) const;
    Json summary() const;
    void writeReport(const std::string& path, const Json& summary) const;
};

/// Writes `text` to `path` through a temporary file and a rename, so a reader never sees half a file.
void writeFileAtomic(const std::string& path, const std::string& text);

} // namespace shadowlab
