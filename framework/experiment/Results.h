#pragma once
// Per-frame measurements of an experiment and the files made from them: frames.csv,
// summary.json and report.md.
#include "framework/core/FileIO.h"
#include "framework/core/JsonNode.h"
#include "framework/gl/StageTimer.h"
#include "framework/metrics/Accuracy.h"

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

/// A 64-bit hash as the 16 hex digits summary.json writes.
std::string hexHash(uint64_t h);

struct FrameRecord {
    int frame = 0;
    std::vector<StageTime> stages; ///< the algorithm's stages, then "total"
    std::map<std::string, double> counters;
    bool hasAccuracy = false;
    Accuracy accuracy;
    uint64_t overflow = 0;
    uint64_t visibilityHash = 0; ///< of the frame's visibility image: runs that must agree compare it
};

struct AlgorithmResults {
    std::string id, algorithm;
    Json params;
    double preprocessMs = 0;
    size_t memoryBytes = 0;
    size_t residentBytes = 0; ///< everything it held (ShadowAlgorithm::residentBytes), largest over frames
    std::vector<FrameRecord> frames;      ///< the timed pass: statistics compiled out, every frame
    /// The timed pass's repetitions after the first (ExperimentConfig::repeats): times and overflow
    /// only; the first's images and accuracy stand for all (a repetition whose image differs is warned of).
    std::vector<std::vector<FrameRecord>> repetitions;
    std::vector<int> repetitionDiffers;   ///< frames whose image differed in some repetition
    /// The untimed statistics pass (instrumented shaders) over ExperimentConfig::statisticsFrames():
    /// its counters are the ones reported; its times only show what the statistics cost.
    std::vector<FrameRecord> statistics;
    /// Frames of the statistics pass whose visibility differed from the timed pass's (it must not:
    /// statistics only count), for the summary's warning.
    std::vector<int> visibilityDiffers;
    /// ShadowAlgorithm::resolvedParams() after the timed pass: what its device-dependent choices were.
    std::vector<std::pair<std::string, std::string>> resolvedParams;
};

struct Stats {
    double mean = 0, min = 0, max = 0, median = 0;
    Json toJson() const { return {{"mean", mean}, {"min", min}, {"max", max}, {"median", median}}; }
};
Stats computeStats(std::vector<double> values);

struct ExperimentResults {
    Json meta; ///< name, renderer, device, resolution, triangles, ... (copied into summary.json)
    /// The frames' width in pixels, from meta's resolution (1 without one).
    int imageWidth() const;
    std::vector<AlgorithmResults> algorithms;

    /// frames.csv (the timed pass) or, with `statisticsPass`, statistics.csv (the statistics pass).
    void writeFramesCsv(const std::string& path, bool statisticsPass = false) const;
    Json summary() const;
    void writeReport(const std::string& path, const Json& summary) const;
};

/// The few lines `shadowlab run` prints at the end: per algorithm its timed mean frame time (the
/// timed pass: statistics compiled out), preprocessing, worst-frame mismatch and overflow.
std::string summaryTable(const Json& summary);


} // namespace shadowlab
