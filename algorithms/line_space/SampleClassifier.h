#pragma once
// Where line_space's binary answer per shadow sample differs from the scene's: each sample the GPU
// traced is traced again exactly on the CPU (Embree, the reference's rays) and classified.
//   over-occluded:  the line space said blocked, the segment is free (a non-empty shaft it passed);
//   under-occluded: the line space said free, the segment is blocked. The method is conservative
//                   everywhere except in the node the ray starts in (skipped, paper 4.1), so each
//                   under-occluded sample is traced once more from where it leaves that node: a hit
//                   there would be a miss outside the start node, which must never happen.
// Used by the `classify` parameter (counters, untimed) and the tests.
#include "algorithms/line_space/NTree.h"
#include "framework/reference/EmbreeTracer.h"
#include "framework/render/GBuffer.h"
#include "framework/view/Light.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace shadowlab::ls {

/// start_region, in the values of the shader's LS_START_MODE.
/// Bvh: the distance region's walk with its start region traced exactly through a BVH (nothing ignored).
enum class StartMode { Node = 0, Distance = 1, Exact = 2, Bvh = 3 };

/// The start region of line_space's rays (twin of startRegionEnd in shaders/line_space/trace.comp).
/// Node: the paper's, the last-level node holding the origin (the shader reports it per pixel).
/// Distance: the first end(n, d) of the ray, geometry beyond it answered conservatively. Exact: the
/// same nodes tested against their triangles, so no sample may be under-occluded at all.
struct StartRegion {
    StartMode mode = StartMode::Node;
    float cells = 0, maxCells = 0; ///< schema: start_cells, start_max_cells
    glm::vec3 leafCell{0.0f};      ///< world size of a leaf cell
    /// End of the region for unit normal `nu` and unit direction `d`, float for float the shader's.
    float end(glm::vec3 nu, glm::vec3 d) const {
        const float sinAngle = glm::dot(nu, d), longest = maxCells * glm::dot(glm::abs(d), leafCell);
        if (!(sinAngle > 0.0f)) return mode == StartMode::Exact || mode == StartMode::Bvh ? longest : 0.0f;
        return std::min(cells * glm::dot(glm::abs(nu), leafCell) / sinAngle, longest);
    }
};

struct SampleClasses {
    uint64_t samples = 0;        ///< rays classified: lit pixels × light samples
    uint64_t exactOccluded = 0;  ///< blocked in the scene
    uint64_t lineSpaceOccluded = 0;
    uint64_t over = 0;           ///< line space blocked, scene free
    uint64_t under = 0;          ///< line space free, scene blocked ...
    uint64_t underInStart = 0;   ///< ... by geometry inside the start region (node or distance)
    uint64_t underElsewhere = 0; ///< ... by geometry outside it (0 for a conservative line space)
};

/// Words per pixel of the shader's classify buffer: the start node (LS_EMPTY = none), then one
/// occlusion bit per sample.
inline size_t classifyStride(size_t samples) { return 1 + (samples + 31) / 32; }

/// Classifies every sample of every lit pixel of `g`; `perPixel` is the shader's classify buffer,
/// `nodes` the node pool (for the start nodes' boxes), `start` the start region the shader used.
/// `threads` = 0 uses every hardware thread.
SampleClasses classifySamples(const EmbreeTracer& tracer, const CpuGBuffer& g, const Light& light, float rayOffset,
                              const std::vector<NodeGpu>& nodes, const std::vector<uint32_t>& perPixel,
                              const StartRegion& start = {}, int threads = 0);

} // namespace shadowlab::ls
