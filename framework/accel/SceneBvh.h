#pragma once
// A scene's BVH on the GPU (BvhGpu) that follows the scene's motion: for a moving scene the tree is
// kept on the host, and each frame the posed triangles are read back (the floats the G-buffer
// used), the tree refitted on the CPU and uploaded whole. bvh_raytrace traces through it, and so do
// shadow_volumes' close calls.
#include "framework/accel/BvhBuilder.h"
#include "framework/accel/BvhGpu.h"
#include "framework/gl/StageTimer.h"
#include "framework/render/SceneGpu.h"

#include <string>
#include <vector>

namespace shadowlab::bvh {

/// What a build made, for counters: the host tree itself is kept only where refits need it.
struct BvhStats {
    size_t nodes = 0, leaves = 0;
    int depth = 0;
    double sahCost = 0;
};

class SceneBvh {
public:
    /// Builds the tree of `scene` with `options` and uploads it (uploadBvh: `limit`, `owner`).
    BvhStats build(const SceneGpu& scene, const BuildOptions& options, size_t limit, const std::string& owner);
    /// The scene moved: the tree refitted to its posed triangles (stages read_scene, refit, upload).
    void refit(const SceneGpu& scene, StageTimer& timer);

    const BvhGpu& gpu() const { return gpu_; }

private:
    BvhGpu gpu_;
    Bvh tree_;                     ///< the last build, for refits (moving scenes only)
    std::vector<glm::vec3> posed_; ///< the posed scene positions the last refit used
};

} // namespace shadowlab::bvh
