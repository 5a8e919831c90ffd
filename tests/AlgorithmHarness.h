#pragma once
// Runs one shadow algorithm for one frame on a test shot and compares it with the Embree reference,
// as the algorithms' GL tests all do: render the G-buffer, run the algorithm, read back what it
// reports (visibility, counters, overflow, memory, debug views), trace the reference with the
// algorithm's own ray offset, and compare over the lit pixels.
#include "framework/algorithm/ShadowAlgorithm.h"
#include "framework/gl/StageTimer.h"
#include "framework/metrics/Accuracy.h"
#include "tests/ShadowTestScenes.h"

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <map>
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace shadowlab::test {

/// The tests' resolution: small, since GLSL runs on the CPU (llvmpipe) here.
inline constexpr int kRes = 96;

/// The counters an algorithm reported for a frame, by name. Reading one it did not report is a
/// test failure naming it: with a plain map a misspelt, renamed or statistics-only counter read as
/// 0, and a test expecting 0 passed whatever the algorithm did. count() asks whether it is there.
class ReportedCounters {
public:
    using Map = std::map<std::string, double>;
    double operator[](const std::string& name) const { return at(name); }
    double at(const std::string& name) const {
        const auto it = values_.find(name);
        if (it != values_.end()) return it->second;
        ADD_FAILURE() << "the algorithm reported no counter \"" << name << "\" (it reported: " << names() << ")";
        return 0.0;
    }
    size_t count(const std::string& name) const { return values_.count(name); }
    void set(const std::string& name, double value) { values_[name] = value; }
    Map::const_iterator begin() const { return values_.begin(); }
    Map::const_iterator end() const { return values_.end(); }
    operator const Map&() const { return values_; }
    std::string names() const {
        std::string out;
        for (const auto& [name, value] : values_) out += (out.empty() ? "" : ", ") + name;
        return out;
    }

private:
    Map values_;
};

/// What one frame of an algorithm produced, next to the reference.
struct AlgorithmRun {
    std::vector<float> visibility, reference;
    std::vector<uint8_t> lit;
    ReportedCounters counters;
    uint64_t overflow = 0;
    size_t memory = 0;
    std::vector<float> overflowMask;                 ///< the "stack_overflow" debug view, where there is one
    std::map<std::string, std::vector<float>> views; ///< the other debug views asked for, by name
    std::vector<StageTime> stages;                   ///< of the measured frame
    Accuracy accuracy;                               ///< only with the reference
    CpuGBuffer gbuffer;                              ///< the frame's G-buffer, as the reference saw it
};

struct RunOptions {
    /// Run an untimed frame first: llvmpipe compiles shaders at their first dispatch and rasterises
    /// the G-buffer lazily, so neither belongs in the measured frame's stage times.
    bool warmUp = false;
    bool withReference = true;
    /// The frame's side in pixels: kRes unless a test needs a smaller, cheaper frame.
    int resolution = kRes;
    /// Off: the host's timed pass (AlgorithmOptions::statistics off), statistics compiled out.
    bool statistics = true;
    /// Each stage waits for the GL (StageTimer::setSynchronous), so its CPU time is its wall time, as
    /// the runner times a CPU rasteriser: an implementation that defers work to a later submission
    /// (zink) would otherwise show only the time to issue it.
    bool synchronousStages = false;
    /// Debug views read back into AlgorithmRun::views where the algorithm offers them.
    std::vector<std::string> debugViews;
    /// Called after the frame, before the reference, while the algorithm still exists and its
    /// buffers are still bound: where a test reads the algorithm's own structures back.
    std::function<void(const AlgorithmRun&)> inspect;
};

/// Runs the algorithm `info` with `overrides` on its schema's defaults for one frame of
/// options.resolution² pixels (kRes² by default).
AlgorithmRun runAlgorithm(const AlgorithmInfo& info, const Shot& shot, const std::map<std::string, ParamValue>& overrides,
                          const RunOptions& options = {});

/// `shot` lit by a light of `type` placed where the shot's light is, aimed at its scene's centre (a
/// 40° spot, an area light a fifth of the scene's radius wide with 4 samples): how the registry-driven
/// tables (ConformanceGLTest, PortabilityGLTest) run every light an algorithm supports on one shot.
Shot withLight(Shot shot, LightType type);

/// The SIMD probe's counters of an instrumented run (shaders/common/simd_probe.glsl), where the
/// context has a ballot: its width is the context's, every section's utilisation lies in (0, 1],
/// and the lanes it counted per ray (slots × utilisation) are exactly the work the kernel's own
/// per-ray counter `work` counted at the same place. Pairs: section name, counter. Without a
/// ballot the probe's counters must be absent.
void expectSimdProbe(const AlgorithmRun& o, const std::vector<std::pair<std::string, std::string>>& sectionWork);

/// Prints `name` and its parameter overrides, for gtest's names of parameterised cases.
void printCase(std::ostream& os, const char* name, const std::map<std::string, ParamValue>& params);

/// One row of an algorithm's accuracy table: a shot, overrides of the algorithm's defaults, and the
/// bound on the mismatch.
struct AccuracyCase {
    const char* name;
    Shot (*make)();
    std::map<std::string, ParamValue> params;
    double maxMismatch; ///< share of lit pixels whose binary visibility differs from the reference
};

/// Readable in ctest's listing (gtest would otherwise print the row's bytes).
void PrintTo(const AccuracyCase& c, std::ostream* os);

/// The hard scenes every exact baseline's table starts with, with its defaults and `maxMismatch`:
/// the shared shots (intersecting triangles to a wall in a plane through the light) and the hard
/// ones (a light amid clutter, grazing light over thin geometry, open meshes, soups and fins, the
/// engine). `rows` follow them (the algorithm's own parameters).
std::vector<AccuracyCase> hardSceneTable(double maxMismatch, std::vector<AccuracyCase> rows);

/// One accuracy row's checks: the view shows lit surfaces and shadows on them (or the row tests
/// nothing), the mismatch is within `maxMismatch`, and nothing overflowed.
void expectAccurateRow(const AlgorithmRun& o, double maxMismatch);

/// The stack-overflow contract of the traversing algorithms: every pixel their "stack_overflow"
/// view marks is written fully shadowed (never lit by mistake), and the view marks exactly the
/// `pixels` their counter reports.
void expectOverflowedPixelsShadowed(const AlgorithmRun& o, double pixels);

/// A run under a fault that cuts loops short (`o`) against the same run without it (`clean`): some
/// pixels were capped, exactly those are counted as overflow and written shadowed, and no pixel
/// came out lighter than without the fault.
void expectCutLoopsCappedAndShadowed(const AlgorithmRun& o, const AlgorithmRun& clean);

} // namespace shadowlab::test
