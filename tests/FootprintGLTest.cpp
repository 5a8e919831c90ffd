// The memory plan's estimate of each algorithm against what the algorithm then held: every
// registered algorithm with a footprint, run on a small scene at a resolution that is no multiple
// of any tile, and ptsv at every tile size whose padding changes its per-sample buffers (third
// probe: tile_size 2 at 64² held 6.4 MB more than planned). An estimate may be larger, never smaller.
#include "framework/experiment/Config.h"
#include "framework/experiment/MemoryPlan.h"
#include "framework/experiment/Runner.h"
#include "tests/TestSupport.h"

#include <string>
#include <vector>

namespace shadowlab {
namespace {

using test::GLTest;

class FootprintGLTest : public GLTest {};

Json footprintConfig(const Json& algorithms, int resolution) {
    return {{"name", "footprint"},
            {"resolution", {resolution, resolution}},
            {"frames", 1},
            {"warmup_frames", 0},
            {"reference", false},
            {"scene", {{"objects", Json::array({{{"procedural", "plane"}, {"size", {6, 6}}, {"subdivisions", 4}},
                                                {{"procedural", "sphere"}, {"radius", 0.6}, {"triangles", 2000},
                                                 {"transform", {{"translate", {0, 1, 0}}}}}})}}},
            {"camera", {{"position", {0, 3, 5}}, {"target", {0, 0.5, 0}}}},
            {"light", {{"type", "point"}, {"position", {1, 4, 1}}}},
            {"algorithms", algorithms},
            {"output", {{"plots", false}}}};
}

TEST_F(FootprintGLTest, EveryEstimateBoundsWhatTheAlgorithmHeld) {
    Json algorithms = Json::array();
    for (const AlgorithmInfo& a : algorithmRegistry())
        // The template too: a plugin copied from it starts from its footprint (a newcomer's copy
        // was 12 bytes short: the template's had never counted its counter block).
        if (a.footprint && a.name != "reference") algorithms.push_back({{"algorithm", a.name}});
    for (int tile : {2, 3, 5, 16})
        algorithms.push_back({{"id", "ptsv_tile_" + std::to_string(tile)}, {"algorithm", "ptsv"}, {"params", {{"tile_size", tile}}}});
    algorithms.push_back({{"id", "ptsv_heat"}, {"algorithm", "ptsv"}, {"params", {{"heat_map", true}, {"job_iterations", true}}}});
    for (int resolution : {64, 100}) {
        const std::string dir = test::makeTempDir("footprint");
        Json config = footprintConfig(algorithms, resolution);
        Json scene = config["scene"];
        Json resolved = Json::object();
        const ScenePrediction predicted = predictScene(JsonNode(dir + "/cfg.json", &scene, "/scene", &resolved));
        const ExperimentConfig cfg = parseConfig(config, dir + "/cfg.json");
        const MemoryPlan plan = checkMemoryPlan(cfg, predicted, currentDeviceLimits(predicted.triangles));
        RunOptions opt;
        opt.writeOutputs = false;
        opt.progress = false;
        const ExperimentResults r = runExperiment(cfg, opt, "osmesa");
        for (const AlgorithmResults& a : r.algorithms) {
            size_t planned = 0;
            for (const auto& [id, bytes] : plan.held)
                if (id == a.id) planned = bytes;
            EXPECT_GT(a.residentBytes, 0u) << a.id;
            EXPECT_GE(planned, a.residentBytes) << a.id << " at " << resolution << "²";
        }
    }
}

} // namespace
} // namespace shadowlab
