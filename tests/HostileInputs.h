#pragma once
// Small, valid inputs to break on purpose: a config and a one-triangle glTF whose top-level fields
// a test replaces with raw JSON text (so the text can be what no JSON library would write:
// duplicate keys, 1e999, nesting 20,000 deep).
#include <string>
#include <utility>
#include <vector>

namespace shadowlab::test {

using Fields = std::vector<std::pair<std::string, std::string>>;  ///< key → raw JSON text, in order

/// A valid 16², 2-frame config (plane + sphere, point light, shadow_map and the reference, no
/// plots); `fields` replace its top-level keys of the same name, or are added (a key given twice
/// appears twice).
std::string configWith(const Fields& fields);
/// A valid glTF 2.0 document of one triangle (buffer embedded as a data URI); `fields` replace or
/// add top-level keys as above; `positionCount` > 0 overrides the POSITION accessor's count.
std::string triangleGltf(const Fields& fields = {}, long long positionCount = 0);
/// One animation channel of animatedTriangleGltf(): `values` are 3 (translation, scale) or 4
/// (rotation) floats per key, three times that for CUBICSPLINE (in-tangent, value, out-tangent).
struct ChannelSpec {
    std::string path;                        ///< "translation", "rotation" or "scale"
    std::string interpolation = "LINEAR";
    std::vector<float> times, values;
    int node = 0;
};
/// triangleGltf() whose node 0 is animated by animation 0 ("a"), one sampler per channel, every
/// float in the embedded buffer (so any float, 3e38 included, can be written).
std::string animatedTriangleGltf(const std::vector<ChannelSpec>& channels);
/// `json` wrapped in a GLB container (header and one JSON chunk).
std::string glbOf(const std::string& json);

} // namespace shadowlab::test
