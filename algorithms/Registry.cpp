// The list of algorithms. Adding one is a folder under algorithms/ and one line here.
#include "framework/algorithm/ShadowAlgorithm.h"
#include "algorithms/bvh_raytrace/BvhRaytrace.h"
#include "algorithms/izb/Izb.h"
#include "algorithms/line_space/LineSpace.h"
#include "algorithms/metric_tree/MetricTree.h"
#include "algorithms/psv/Psv.h"
#include "algorithms/ptsv/Ptsv.h"
#include "algorithms/reference/Reference.h"
#include "algorithms/shadow_map/ShadowMap.h"
#include "algorithms/shadow_volumes/ShadowVolumes.h"

namespace shadowlab {

const std::vector<AlgorithmInfo>& algorithmRegistry() {
    static const std::vector<AlgorithmInfo> registry = {
        shadowMapInfo(),
        referenceInfo(),
        psvInfo(),
        bvhRaytraceInfo(),
        lineSpaceInfo(),
        ptsvInfo(),
        metricTreeInfo(),
        shadowVolumesInfo(),
        izbInfo(),
    };
    return registry;
}

const AlgorithmInfo* findAlgorithm(const std::string& name) {
    for (const auto& a : algorithmRegistry())
        if (a.name == name) return &a;
    return nullptr;
}

} // namespace shadowlab
