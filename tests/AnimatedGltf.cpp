#include "tests/AnimatedGltf.h"

#include "framework/core/JsonNode.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

namespace shadowlab::test {
namespace {

std::string base64(const std::vector<uint8_t>& data) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < data.size(); i += 3) {
        uint32_t v = uint32_t(data[i]) << 16;
        if (i + 1 < data.size()) v |= uint32_t(data[i + 1]) << 8;
        if (i + 2 < data.size()) v |= data[i + 2];
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < data.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < data.size() ? table[v & 63] : '=';
    }
    return out;
}

/// Appends floats to the buffer and declares a FLOAT accessor (and its bufferView) over them.
struct Builder {
    std::vector<uint8_t> bytes;
    Json views = Json::array(), accessors = Json::array();

    int add(const std::vector<float>& values, const char* type, int components) {
        const size_t offset = bytes.size();
        bytes.resize(offset + values.size() * 4);
        std::memcpy(bytes.data() + offset, values.data(), values.size() * 4);
        views.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * 4}});
        Json a = {{"bufferView", views.size() - 1}, {"componentType", 5126}, {"count", values.size() / size_t(components)},
                  {"type", type}};
        if (std::string(type) == "VEC3") {
            std::vector<float> lo(3, 1e30f), hi(3, -1e30f);
            for (size_t i = 0; i < values.size(); ++i) lo[i % 3] = std::min(lo[i % 3], values[i]), hi[i % 3] = std::max(hi[i % 3], values[i]);
            a["min"] = lo;
            a["max"] = hi;
        }
        accessors.push_back(a);
        return int(accessors.size() - 1);
    }
};

} // namespace

void writeAnimatedGltf(const std::string& path, const AnimatedGltfOptions& o) {
    Builder b;
    // The blade: two triangles in the hub's XZ plane (horizontal, so it casts a real shadow).
    const int positions = b.add({0.3f, 0, -0.25f, 1.9f, 0, -0.25f, 1.9f, 0, 0.25f,  //
                                 0.3f, 0, -0.25f, 1.9f, 0, 0.25f, 0.3f, 0, 0.25f},
                                "VEC3", 3);
    const float s45 = std::sin(0.25f * 3.14159265f), c45 = std::cos(0.25f * 3.14159265f);
    const int rotTimes = b.add({0, 1, 2}, "SCALAR", 1);
    std::vector<float> rot = {0, 0, 0, 1, 0, s45, 0, c45, 0, 1, 0, 0};  // 0°, 90°, 180° about Y (x, y, z, w)
    if (o.rotationInterpolation == "CUBICSPLINE") {
        std::vector<float> cubic;
        for (int k = 0; k < 3; ++k) {
            cubic.insert(cubic.end(), {0, 0, 0, 0});                                // in-tangent
            cubic.insert(cubic.end(), rot.begin() + 4 * k, rot.begin() + 4 * k + 4); // value
            cubic.insert(cubic.end(), {0, 0, 0, 0});                                // out-tangent
        }
        rot = cubic;
    }
    const int rotValues = b.add(rot, "VEC4", 4);
    const int slideTimes = b.add({0, 2}, "SCALAR", 1);
    const int slideValues = b.add({0, 0, 0, 0.4f, 0, 0}, "VEC3", 3);
    Json samplers = Json::array({{{"input", rotTimes}, {"output", rotValues}, {"interpolation", o.rotationInterpolation}},
                                 {{"input", slideTimes}, {"output", slideValues}, {"interpolation", o.translationInterpolation}}});
    Json channels = Json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "rotation"}}}},
                                 {{"sampler", 1}, {"target", {{"node", 1}, {"path", "translation"}}}}});
    if (o.morphChannel) channels.push_back({{"sampler", 0}, {"target", {{"node", 1}, {"path", "weights"}}}});
    Json doc = {{"asset", {{"version", "2.0"}}},
                {"scene", 0},
                {"scenes", Json::array({{{"nodes", {0}}}})},
                {"nodes", Json::array({{{"name", "hub"}, {"translation", {0, 2, 0}}, {"children", {1}}},
                                       {{"name", "blade"}, {"mesh", 0}}})},
                {"meshes", Json::array({{{"primitives", Json::array({{{"attributes", {{"POSITION", positions}}}}})}}})},
                {"animations", Json::array({{{"name", "spin"}, {"channels", channels}, {"samplers", samplers}}})},
                {"buffers", Json::array({{{"byteLength", b.bytes.size()},
                                          {"uri", "data:application/octet-stream;base64," + base64(b.bytes)}}})},
                {"bufferViews", b.views},
                {"accessors", b.accessors}};
    std::ofstream(path) << doc.dump(1);
}

} // namespace shadowlab::test
