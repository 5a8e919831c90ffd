#include "tests/HostileInputs.h"

#include <algorithm>
#include <cstdint>
#include <set>
#include <cstring>

namespace shadowlab::test {
namespace {

std::string assemble(Fields defaults, const Fields& fields) {
    std::set<std::string> replaced;
    for (const auto& [key, text] : fields) {
        auto it = std::find_if(defaults.begin(), defaults.end(), [&](const auto& d) { return d.first == key; });
        // The first mention of a key replaces the default; a second one is added (the duplicate-key case).
        if (it != defaults.end() && replaced.insert(key).second) it->second = text;
        else defaults.emplace_back(key, text);
    }
    std::string out = "{";
    for (size_t i = 0; i < defaults.size(); ++i)
        out += (i ? ",\n\"" : "\"") + defaults[i].first + "\": " + defaults[i].second;
    return out + "}\n";
}

std::string base64(const unsigned char* data, size_t n) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = uint32_t(data[i]) << 16 | (i + 1 < n ? uint32_t(data[i + 1]) << 8 : 0) | (i + 2 < n ? data[i + 2] : 0);
        out += k[v >> 18 & 63];
        out += k[v >> 12 & 63];
        out += i + 1 < n ? k[v >> 6 & 63] : '=';
        out += i + 2 < n ? k[v & 63] : '=';
    }
    return out;
}

} // namespace

std::string configWith(const Fields& fields) {
    return assemble({{"name", R"("hostile")"},
                     {"resolution", "[16, 16]"},
                     {"frames", "2"},
                     {"warmup_frames", "0"},
                     {"scene", R"({"objects": [{"procedural": "plane", "size": [6, 6]},
                                   {"procedural": "sphere", "radius": 0.5, "triangles": 200, "transform": {"translate": [0, 1, 0]}}]})"},
                     {"camera", R"({"position": [0, 3, 5], "target": [0, 0.5, 0]})"},
                     {"light", R"({"type": "point", "position": [1, 4, 1]})"},
                     {"algorithms", R"([{"algorithm": "shadow_map"}])"},
                     {"output", R"({"dir": "out", "plots": false})"}},
                    fields);
}

std::string triangleGltf(const Fields& fields, long long positionCount) {
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    unsigned char bytes[sizeof pos];
    std::memcpy(bytes, pos, sizeof pos);
    std::string count = std::to_string(positionCount > 0 ? positionCount : 3);
    return assemble(
        {{"asset", R"({"version": "2.0"})"},
         {"scene", "0"},
         {"scenes", R"([{"nodes": [0]}])"},
         {"nodes", R"([{"mesh": 0}])"},
         {"meshes", R"([{"primitives": [{"attributes": {"POSITION": 0}}]}])"},
         {"accessors", R"([{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": )" + count +
                           R"(, "min": [0, 0, 0], "max": [1, 1, 0]}])"},
         {"bufferViews", R"([{"buffer": 0, "byteLength": 36}])"},
         {"buffers", R"([{"byteLength": 36, "uri": "data:application/octet-stream;base64,)" + base64(bytes, sizeof bytes) + "\"}]"}},
        fields);
}

std::string animatedTriangleGltf(const std::vector<ChannelSpec>& channels) {
    std::vector<float> floats = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::string views = R"({"buffer": 0, "byteLength": 36})";
    std::string accessors = R"({"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3, "min": [0, 0, 0], "max": [1, 1, 0]})";
    std::string samplers, targets;
    int next = 1;  // accessor and view index
    auto add = [&](const std::vector<float>& v, const char* type, size_t count) {
        views += R"(, {"buffer": 0, "byteOffset": )" + std::to_string(floats.size() * 4) + R"(, "byteLength": )" +
                 std::to_string(v.size() * 4) + "}";
        accessors += R"(, {"bufferView": )" + std::to_string(next) + R"(, "componentType": 5126, "type": ")" + type +
                     R"(", "count": )" + std::to_string(count) + "}";
        floats.insert(floats.end(), v.begin(), v.end());
        return next++;
    };
    for (size_t c = 0; c < channels.size(); ++c) {
        const ChannelSpec& ch = channels[c];
        const int width = ch.path == "rotation" ? 4 : 3;
        const int input = add(ch.times, "SCALAR", ch.times.size());
        const int output = add(ch.values, width == 4 ? "VEC4" : "VEC3", ch.values.size() / size_t(width));
        samplers += std::string(c ? ", " : "") + R"({"input": )" + std::to_string(input) + R"(, "output": )" +
                    std::to_string(output) + R"(, "interpolation": ")" + ch.interpolation + "\"}";
        targets += std::string(c ? ", " : "") + R"({"sampler": )" + std::to_string(c) + R"(, "target": {"node": )" +
                   std::to_string(ch.node) + R"(, "path": ")" + ch.path + "\"}}";
    }
    std::vector<unsigned char> bytes(floats.size() * 4);
    std::memcpy(bytes.data(), floats.data(), bytes.size());
    return triangleGltf({{"accessors", "[" + accessors + "]"},
                         {"bufferViews", "[" + views + "]"},
                         {"buffers", R"([{"byteLength": )" + std::to_string(bytes.size()) +
                                         R"(, "uri": "data:application/octet-stream;base64,)" + base64(bytes.data(), bytes.size()) + "\"}]"},
                         {"animations", R"([{"name": "a", "samplers": [)" + samplers + "], \"channels\": [" + targets + "]}]"}});
}

std::string glbOf(const std::string& json) {
    std::string chunk = json;
    while (chunk.size() % 4) chunk += ' ';
    auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    std::string out = "glTF" + u32(2) + u32(uint32_t(12 + 8 + chunk.size()));
    return out + u32(uint32_t(chunk.size())) + u32(0x4E4F534Au) + chunk;
}

} // namespace shadowlab::test
