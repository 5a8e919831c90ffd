// What every plugin's AlgorithmInfo can answer, and the footprint helpers the plugins' memory
// estimates share (framework/algorithm/ShadowAlgorithm.h).
#include "framework/algorithm/ShadowAlgorithm.h"

#include <algorithm>

namespace shadowlab {

std::string storageRefusal(const FootprintQuery& q, const char* what, size_t bytes, bool reportedLimit) {
    const size_t limit = reportedLimit ? q.reportedStorageBlockBytes : q.storageBlockBytes;
    if (limit == 0 || bytes <= limit) return "";
    return std::string(what) + " (" + std::to_string(bytes >> 20) + " MiB) exceed one storage block (" +
           std::to_string(limit >> 20) + " MiB" + (reportedLimit ? ", GL_MAX_SHADER_STORAGE_BLOCK_SIZE" : "") + ")";
}

std::string texelRefusal(const FootprintQuery& q, const char* what, size_t texels) {
    if (q.textureBufferTexels == 0 || texels <= q.textureBufferTexels) return "";
    return std::string(what) + " (" + std::to_string(texels) + " texels) exceed one buffer-texture view (" +
           std::to_string(q.textureBufferTexels) + ", GL_MAX_TEXTURE_BUFFER_SIZE)";
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
