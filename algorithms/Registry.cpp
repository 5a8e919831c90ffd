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

#include <algorithm>

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

bool AlgorithmInfo::supports(LightType t) const { return std::find(lights.begin(), lights.end(), t) != lights.end(); }

std::string AlgorithmInfo::motionRefusal(const ParamValues& params) const {
    if (motion != MotionHandling::StaticOnly) return "";
    if (!rebuildParam.empty() && std::get<bool>(params.get(rebuildParam))) return "";
    return name + " precomputes its structure for static geometry and the scene moves" +
           (rebuildParam.empty() ? std::string() : "; set params." + rebuildParam + " = true to rebuild it every frame (timed)");
}

const char* toString(MotionHandling m) {
    switch (m) {
    case MotionHandling::PerFrame: return "per_frame";
    case MotionHandling::Rigid: return "rigid";
    case MotionHandling::Refit: return "refit";
    case MotionHandling::StaticOnly: return "static_only";
    }
    return "?";
}

} // namespace shadowlab
