#pragma once
// The reference tree of the paper's Table 2: a ternary metric tree built on the CPU with the
// classic strategy (Yianilos's pivot choice, median partitioning distance), over the same nodes the
// GPU build links, so the two trees' traversal costs can be compared on the same query shader.
#include "algorithms/metric_tree/MetricTreeGpuLayout.h"

#include <vector>

namespace shadowlab::mt {

struct CpuTreeOptions {
    bool directional = false; ///< light-space distances are Euclidean (else angular)
    float lsEps = 0;          ///< the margin the GPU build adds to its bounds (uLsEps)
    bool overlapInterval = true;
    bool depthSkip = true;
};

/// Links `nodes` (light-space elements as prepare.comp writes them; culled ones are left out) into
/// a ternary metric tree: fills children, delta, the subtree light distances and the overlap
/// intervals. Returns the root as node index + 1 (0: empty tree).
uint32_t buildCpuTree(std::vector<NodeGpu>& nodes, const CpuTreeOptions& options);

} // namespace shadowlab::mt
