#pragma once
// The images an experiment writes for a frame listed in `images_at_frames` (images/ID_fNNNN_*.png).
#include "framework/algorithm/ShadowAlgorithm.h"
#include "framework/render/ShadingPass.h"

#include <glm/glm.hpp>

#include <array>
#include <string>
#include <vector>

namespace shadowlab {

/// ID_fNNNN_: the prefix of every image of one algorithm on one frame.
std::string frameImagePrefix(const std::string& id, int frame);

/// The images a frame may have, ID_fNNNN_KIND.png: writeFrameImages' kinds, and writeHeatMaps'
/// kHeatMapPrefix + NAME (what `compare` reads back).
inline constexpr std::array<const char*, 3> kFrameImageKinds = {"shaded", "visibility", "diff"};
inline constexpr const char* kHeatMapPrefix = "heat_";

/// From the timed pass: shaded.png, visibility.png and, against the reference, diff.png.
void writeFrameImages(const std::string& dir, const std::string& id, int frame, glm::ivec2 res, ShadingPass& shading,
                      const std::vector<float>& vis, const std::vector<float>* ref, const std::vector<uint8_t>& lit,
                      const std::vector<uint8_t>& covered);

/// From the statistics pass, for each of the algorithm's debug views: heat_NAME.png, coloured over
/// [0, maxValue] where the view fixes one, else over [0, 99th percentile of its non-zero pixels], and
/// heat_NAME.json beside it (name, unit, scale "fixed" | "p99", min, max, data_max, the ramp's colours).
void writeHeatMaps(const std::string& dir, const std::string& id, int frame, glm::ivec2 res, const std::vector<DebugView>& views);

} // namespace shadowlab
