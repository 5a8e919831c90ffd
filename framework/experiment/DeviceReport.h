#pragma once
// `shadowlab info`: the device record (framework/gl/DeviceInfo.h) and, per registered algorithm,
// what its device-dependent parameters resolve to with the defaults.
#include "framework/core/JsonNode.h"

#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

/// One registered algorithm created with its default values.
struct ResolvedDefaults {
    std::string algorithm;
    std::vector<std::pair<std::string, std::string>> params; ///< ShadowAlgorithm::resolvedParams()
    std::string error; ///< why it could not be created on this device ("" when it was)
};

/// Every registered algorithm, created as the runner creates it (statistics compiled out) with its
/// defaults, sized and given a tiny procedural scene, then asked resolvedParams(). Nothing is
/// written: a `cache` parameter is turned off. Needs a current context.
std::vector<ResolvedDefaults> resolveDefaults();

/// `shadowlab info --json`: {"device": deviceRecord(), "algorithms": {name: {"resolved_params": {...}}
/// or {"error": "..."}}}.
Json deviceInfoJson(const Json& device, const std::vector<ResolvedDefaults>& algorithms);
/// The same for people: the implementation, the subgroup width, the limits, the extensions and
/// which shaders use them, and the algorithms' resolved parameters.
std::string deviceInfoText(const Json& device, const std::vector<ResolvedDefaults>& algorithms);

} // namespace shadowlab
