#include "framework/scene/GltfLoader.h"

#include "framework/scene/GltfAnimation.h"
#include "framework/scene/GltfChecks.h"

#include "framework/core/FileIO.h"

#include "framework/core/JsonNode.h"
#include "framework/core/JsonParse.h"
#include "framework/core/Text.h"

#include <tiny_gltf.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <sys/stat.h>
#include <tuple>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

// Loading runs in three stages, each making the next one safe:
//  1. (GltfChecks.cpp) a JSON type check of the glTF document (tinygltf 2.7 silently ignores most wrongly typed
//     properties, e.g. "primitives": {} or "index": -1, and would hand us a quietly different model);
//  2. (GltfChecks.cpp, then here) what the reader would refuse without a path is refused with one;
//     tinygltf parses the document and fetches buffers; its errors become InputErrors;
//  3. every index, range and type we are about to use is validated before any buffer byte is read,
//     so a malformed file can throw but never crash or read out of bounds (here; an animation's
//     tracks become the model of GltfAnimation.h).

namespace shadowlab {
namespace {

using gltf::escapeKey;
using gltf::NodeAnimation;
using gltf::rotationMatrix;
using gltf::slerp;
using gltf::Track;

/// A node's rotation as a unit quaternion: scaled by its largest component first, so that neither
/// tiny components (1e-300, whose squares underflow: twenty-fourth probe, a 180-degree turn reported
/// as vertices at -nan) nor huge ones overflow the length. Zero is refused by validateNodes().
glm::vec4 unitQuaternion(const std::vector<double>& q) {
    const double m = std::max(std::max(std::abs(q[0]), std::abs(q[1])), std::max(std::abs(q[2]), std::abs(q[3])));
    return glm::vec4(glm::normalize(glm::dvec4(q[0] / m, q[1] / m, q[2] / m, q[3] / m)));
}

// Images are never used (only geometry and base colour factors), so skip decoding them.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
    return true;
}

// ---------------------------------------------------------------------------------------------
// Stage 3: validation and geometry extraction.

// Accessors without a bufferView are zero-filled (a base for sparse values): they cost memory that no
// byte of the file backs, so they are capped in bytes (16 M vec4 floats), not left to a declared count.
constexpr size_t kMaxUnbackedBytes = size_t(256) << 20;

// Extensions that may be required without changing what shadowlab reads (geometry, base colour
// factor, alpha mode): texture and shading extensions. Any other required extension is rejected, as
// the glTF spec asks of a loader that does not implement it.
const char* const kHarmlessExtensions[] = {
    "KHR_materials_unlit",    "KHR_texture_transform",  "KHR_texture_basisu",     "EXT_texture_webp",
    "KHR_materials_emissive_strength", "KHR_materials_clearcoat", "KHR_materials_sheen",
    "KHR_materials_specular", "KHR_materials_ior",      "KHR_materials_variants", "KHR_materials_iridescence",
    "KHR_materials_anisotropy", "KHR_lights_punctual"};

class Loader {
public:
    Loader(const std::string& file, const tinygltf::Model& model, size_t maxTriangles, const GltfMotion& motion = {})
        : file_(file), m_(model), maxTriangles_(maxTriangles), animation_(motion.animation), nodeMotions_(motion.nodes) {}

    Scene run(GltfStats* stats);

private:
    [[noreturn]] void fail(const std::string& path, const std::string& cause) const { throw InputError(file_, path, cause); }
    static std::string at(const char* array, size_t i) { return std::string("/") + array + "/" + std::to_string(i); }
    template <class Vec> void checkIndex(int index, const Vec& v, const std::string& path, const char* what) const {
        if (index < 0 || size_t(index) >= v.size())
            fail(path, std::string(what) + " index " + std::to_string(index) + " is out of range (the file has " +
                           std::to_string(v.size()) + ")");
    }
    /// offset + stride*(count-1) + elem <= limit, in 128 bits so that huge declared values cannot wrap.
    static bool fits(uint64_t offset, uint64_t stride, uint64_t count, uint64_t elem, uint64_t limit) {
        if (count == 0) return offset <= limit;
        return static_cast<unsigned __int128>(offset) + static_cast<unsigned __int128>(stride) * (count - 1) + elem <= limit;
    }
    size_t elementSize(const tinygltf::Accessor& a) const {
        return size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType))) *
               size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
    }

    void validateStructure();
    void validateAccessor(size_t i);
    void validateNodes();
    std::vector<unsigned char> gather(int accessor) const;
    const std::vector<glm::vec3>& positions(int accessor);
    Material material(int index) const;
    glm::mat4 localMatrix(const tinygltf::Node& n) const;
    size_t emitPrimitive(Scene& scene, size_t meshIndex, size_t primIndex, const glm::mat4& world);
    /// The chosen animation's tracks (nullptr when none is chosen); fills the time range.
    std::shared_ptr<const NodeAnimation> readAnimation();
    Track readTrack(const tinygltf::AnimationSampler& sampler, const std::string& path, bool rotation);
    std::vector<float> floats(int accessor, int type, const std::string& path);
    /// Centre of the bounding box of every mesh vertex at or below `node`, in the node's own frame.
    glm::vec3 subtreeCentre(size_t node);
    /// Whether a mesh hangs at or below `node` (the file's node graph is a forest, checked before).
    bool subtreeHasMesh(size_t node) const;

    const std::string& file_;
    const tinygltf::Model& m_;
    size_t maxTriangles_;
    size_t instanced_ = 0;  // triangle instances emitted so far, against maxTriangles_
    std::vector<int> parent_;
    std::map<int, std::vector<glm::vec3>> positionCache_;
    size_t skipped_ = 0;  // primitive instances without triangles (points, lines, no POSITION)
    std::string animation_;  // "" = none; else a name or a decimal index
    std::vector<GltfNodeMotion> nodeMotions_;
    double animStart_ = 0, animEnd_ = 0;
};

glm::vec3 Loader::subtreeCentre(size_t node) {
    Bounds b;
    std::vector<std::pair<size_t, glm::mat4>> stack{{node, glm::mat4(1.0f)}};
    while (!stack.empty()) {
        auto [n, m] = stack.back();
        stack.pop_back();
        const auto& nd = m_.nodes[n];
        if (nd.mesh != -1)
            for (const auto& prim : m_.meshes[size_t(nd.mesh)].primitives)
                if (auto it = prim.attributes.find("POSITION"); it != prim.attributes.end())
                    for (const glm::vec3& p : positions(it->second)) b.extend(glm::vec3(m * glm::vec4(p, 1.0f)));
        for (int c : nd.children) stack.emplace_back(size_t(c), m * localMatrix(m_.nodes[size_t(c)]));
    }
    return b.empty() ? glm::vec3(0.0f) : b.center();
}

bool Loader::subtreeHasMesh(size_t node) const {
    std::vector<size_t> stack{node};
    while (!stack.empty()) {
        const auto& nd = m_.nodes[stack.back()];
        stack.pop_back();
        if (nd.mesh != -1) return true;
        for (int c : nd.children) stack.push_back(size_t(c));
    }
    return false;
}

std::vector<float> Loader::floats(int accessor, int type, const std::string& path) {
    checkIndex(accessor, m_.accessors, path, "accessor");
    const auto& a = m_.accessors[size_t(accessor)];
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || a.type != type)
        fail(path, "accessor " + std::to_string(accessor) + " must be FLOAT " +
                       (type == TINYGLTF_TYPE_SCALAR ? "SCALAR" : type == TINYGLTF_TYPE_VEC3 ? "VEC3" : "VEC4") +
                       " (quantized animation data needs KHR_mesh_quantization, not supported)");
    std::vector<unsigned char> bytes = gather(accessor);
    std::vector<float> out(bytes.size() / sizeof(float));
    std::memcpy(out.data(), bytes.data(), out.size() * sizeof(float));
    for (float v : out)
        if (!std::isfinite(v)) fail(path, "accessor " + std::to_string(accessor) + " holds a non-finite value");
    return out;
}

Track Loader::readTrack(const tinygltf::AnimationSampler& sampler, const std::string& path, bool rotation) {
    Track tr;
    tr.rotation = rotation;
    if (sampler.interpolation == "STEP") tr.mode = Track::Step;
    else if (sampler.interpolation == "CUBICSPLINE") tr.mode = Track::Cubic;
    else if (!sampler.interpolation.empty() && sampler.interpolation != "LINEAR")
        fail(path + "/interpolation", "unknown interpolation \"" + sampler.interpolation.substr(0, 40) + "\"");
    tr.times = floats(sampler.input, TINYGLTF_TYPE_SCALAR, path + "/input");
    if (tr.times.empty()) fail(path + "/input", "an animation sampler needs at least one key");
    for (size_t k = 1; k < tr.times.size(); ++k)
        if (!(tr.times[k] > tr.times[k - 1])) fail(path + "/input", "key times must increase strictly (key " + std::to_string(k) + ")");
    const int width = rotation ? 4 : 3;
    std::vector<float> v = floats(sampler.output, rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, path + "/output");
    const size_t perKey = tr.mode == Track::Cubic ? 3 : 1;
    if (v.size() != tr.times.size() * perKey * size_t(width))
        fail(path + "/output", "has " + std::to_string(v.size() / size_t(width)) + " values for " + std::to_string(tr.times.size()) +
                                   " keys (" + std::to_string(perKey) + " per key expected)");
    for (size_t i = 0; i < v.size(); i += size_t(width)) {
        glm::vec4 x(v[i], v[i + 1], v[i + 2], width == 4 ? v[i + 3] : 0.0f);
        const bool keyValue = perKey == 1 || i / 4 % 3 == 1;  // not a CUBICSPLINE tangent
        if (rotation && keyValue) {
            // The length in double: a float one overflows for components above ~1.8e19 and the key
            // would turn into NaN. A quaternion means the rotation of its direction, so keys are
            // made unit length, as slerp needs (glTF asks for unit keys; the tangents scale with them).
            const double len = glm::length(glm::dvec4(x));
            if (!(len > 0.0)) fail(path + "/output", "a rotation key is the zero quaternion (key " + std::to_string(i / 4 / perKey) + ")");
            if (perKey == 1) x = glm::vec4(glm::dvec4(x) / len);
        }
        tr.values.push_back(x);
    }
    return tr;
}

std::shared_ptr<const NodeAnimation> Loader::readAnimation() {
    if (animation_.empty() && nodeMotions_.empty()) return nullptr;
    size_t chosen = m_.animations.size();
    for (size_t i = 0; i < m_.animations.size(); ++i)
        if (m_.animations[i].name == animation_) chosen = i;
    const bool digits = !animation_.empty() &&
                        std::all_of(animation_.begin(), animation_.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
    if (chosen == m_.animations.size() && digits && animation_.size() < 10 && std::stoul(animation_) < m_.animations.size())
        chosen = std::stoul(animation_);
    if (chosen == m_.animations.size() && !animation_.empty()) {
        // An index past the end is said to be one (probe 25: `"animation": 5` read as a name "5").
        const std::string what = digits ? "no animation of index or name " + animation_.substr(0, 20)
                                        : "no animation \"" + animation_.substr(0, 40) + "\"";
        std::string names;
        for (size_t i = 0; i < m_.animations.size() && i < 8; ++i)
            names += (i ? ", " : "") + std::to_string(i) + (m_.animations[i].name.empty() ? "" : " \"" + m_.animations[i].name.substr(0, 30) + "\"");
        fail("/animations", what + " (the file has " +
                                (m_.animations.empty() ? std::string("none") : std::to_string(m_.animations.size()) + ": " + names) + ")");
    }
    auto anim = std::make_shared<NodeAnimation>();
    anim->file = file_;
    anim->extra.resize(m_.nodes.size());
    animStart_ = 1e300, animEnd_ = -1e300;
    for (const GltfNodeMotion& nm : nodeMotions_) {
        if (nm.node >= m_.nodes.size())
            fail("/nodes", "a node path names node " + std::to_string(nm.node) + ", but the file has " +
                               std::to_string(m_.nodes.size()) + " nodes");
        if (anim->extra[nm.node])
            fail("/nodes/" + std::to_string(nm.node), "two node paths move this node; give each node one path");
        // A path that moves nothing is a mistake, not a motion (probe 26: accepted, it did nothing).
        if (!subtreeHasMesh(nm.node))
            fail("/nodes/" + std::to_string(nm.node), "a node path moves this node, which carries no mesh and has none below it: "
                                                      "it would move nothing");
        if (nm.aboutCentre) {
            // Spin about the middle of what the node carries, not its frame's origin (which in
            // many files sits far from the part and would swing it round the scene).
            const glm::vec3 c = subtreeCentre(nm.node);
            MotionFn motion = nm.motion;
            anim->extra[nm.node] = [c, motion](double time) {
                return glm::translate(glm::mat4(1.0f), c) * motion(time) * glm::translate(glm::mat4(1.0f), -c);
            };
        } else {
            anim->extra[nm.node] = nm.motion;
        }
        animStart_ = std::min(animStart_, nm.startTime);
        animEnd_ = std::max(animEnd_, nm.endTime);
    }
    const size_t n = m_.nodes.size();
    anim->parent = parent_;
    anim->fixed.resize(n);
    anim->t.resize(n), anim->r.resize(n), anim->s.resize(n);
    for (auto& slot : anim->track) slot.assign(n, -1);
    for (size_t i = 0; i < n; ++i) {
        const auto& node = m_.nodes[i];
        anim->fixed[i] = localMatrix(node);
        anim->t[i] = node.translation.size() == 3 ? glm::vec3(float(node.translation[0]), float(node.translation[1]), float(node.translation[2])) : glm::vec3(0.0f);
        anim->r[i] = node.rotation.size() == 4 ? unitQuaternion(node.rotation) : glm::vec4(0, 0, 0, 1);
        anim->s[i] = node.scale.size() == 3 ? glm::vec3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2])) : glm::vec3(1.0f);
    }
    if (chosen == m_.animations.size()) return anim;  // node paths only
    const auto& a = m_.animations[chosen];
    const std::string base = at("animations", chosen);
    for (size_t c = 0; c < a.channels.size(); ++c) {
        const auto& ch = a.channels[c];
        const std::string path = base + "/channels/" + std::to_string(c);
        checkIndex(ch.target_node, m_.nodes, path + "/target/node", "node");
        checkIndex(ch.sampler, a.samplers, path + "/sampler", "sampler");
        const std::string& what = ch.target_path;
        if (what == "weights") fail(path + "/target/path", "morph target animation (weights) is not supported: only node (rigid) animation is played");
        const int slot = what == "translation" ? 0 : what == "rotation" ? 1 : what == "scale" ? 2 : -1;
        if (slot < 0) fail(path + "/target/path", "unknown animated property \"" + what.substr(0, 40) + "\"");
        if (m_.nodes[size_t(ch.target_node)].matrix.size() == 16)
            fail(path + "/target/node", "node " + std::to_string(ch.target_node) + " has a matrix; glTF animates only nodes given by TRS");
        // Two channels on one node's property (the spec forbids it) would leave one of them unplayed.
        if (const int earlier = anim->track[slot][size_t(ch.target_node)]; earlier >= 0)
            fail(path + "/target", "node " + std::to_string(ch.target_node) + "'s " + what + " is animated by " +
                                       anim->tracks[size_t(earlier)].where + " already (glTF allows one channel per node and property)");
        Track tr = readTrack(a.samplers[size_t(ch.sampler)], base + "/samplers/" + std::to_string(ch.sampler), slot == 1);
        tr.where = path;
        animStart_ = std::min(animStart_, double(tr.times.front()));
        animEnd_ = std::max(animEnd_, double(tr.times.back()));
        anim->track[slot][size_t(ch.target_node)] = int(anim->tracks.size());
        anim->tracks.push_back(std::move(tr));
    }
    if (animStart_ > animEnd_) animStart_ = animEnd_ = 0;
    return anim;
}

void Loader::validateStructure() {
    // These extensions replace or add geometry; loading without them would silently give wrong shapes.
    for (const auto& ext : m_.extensionsRequired)
        if (ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression" || ext == "KHR_mesh_quantization" ||
            ext == "EXT_mesh_gpu_instancing")
            fail("/extensionsRequired", "requires extension " + ext + ", which changes geometry and is not supported");
    for (size_t i = 0; i < m_.extensionsRequired.size(); ++i) {
        const std::string& ext = m_.extensionsRequired[i];
        if (std::find(std::begin(kHarmlessExtensions), std::end(kHarmlessExtensions), ext) == std::end(kHarmlessExtensions))
            fail("/extensionsRequired/" + std::to_string(i),
                 "requires extension \"" + (ext.size() > 60 ? ext.substr(0, 57) + "..." : ext) +
                     "\", which shadowlab does not implement (a loader must reject what it cannot read)");
    }
    for (size_t i = 0; i < m_.bufferViews.size(); ++i) {
        const auto& bv = m_.bufferViews[i];
        checkIndex(bv.buffer, m_.buffers, at("bufferViews", i) + "/buffer", "buffer");
        size_t size = m_.buffers[size_t(bv.buffer)].data.size();
        if (!fits(bv.byteOffset, 0, 1, bv.byteLength, size))
            fail(at("bufferViews", i), "byte range [" + std::to_string(bv.byteOffset) + ", +" + std::to_string(bv.byteLength) +
                                           ") exceeds buffer " + std::to_string(bv.buffer) + " (" + std::to_string(size) +
                                           " bytes)");
        if (bv.byteStride != 0 && (bv.byteStride < 4 || bv.byteStride > 252))
            fail(at("bufferViews", i) + "/byteStride", "byteStride " + std::to_string(bv.byteStride) + " is outside [4, 252]");
    }
    for (size_t i = 0; i < m_.accessors.size(); ++i) validateAccessor(i);
    for (size_t i = 0; i < m_.materials.size(); ++i) {
        // The spec's enumeration (fourteenth probe: "blend" was read as opaque, its translucency lost).
        const std::string& mode = m_.materials[i].alphaMode;
        if (mode != "OPAQUE" && mode != "MASK" && mode != "BLEND")
            fail(at("materials", i) + "/alphaMode", "\"" + shortText(mode, 40) + "\" is not OPAQUE, MASK or BLEND");
        const auto& f = m_.materials[i].pbrMetallicRoughness.baseColorFactor;
        bool ok = f.size() == 4;
        for (double c : f) ok = ok && std::isfinite(c) && c >= 0.0 && c <= 1.0;
        if (!ok) fail(at("materials", i) + "/pbrMetallicRoughness/baseColorFactor", "expected 4 numbers in [0, 1]");
    }
    for (size_t mi = 0; mi < m_.meshes.size(); ++mi) {
        for (size_t pi = 0; pi < m_.meshes[mi].primitives.size(); ++pi) {
            const auto& p = m_.meshes[mi].primitives[pi];
            std::string path = at("meshes", mi) + "/primitives/" + std::to_string(pi);
            for (const auto& [name, acc] : p.attributes)
                checkIndex(acc, m_.accessors, path + "/attributes/" + escapeKey(name), "accessor");
            if (p.material != -1) checkIndex(p.material, m_.materials, path + "/material", "material");
            if (p.mode < -1 || p.mode > TINYGLTF_MODE_TRIANGLE_FAN)
                fail(path + "/mode", "unknown primitive mode " + std::to_string(p.mode));
            if (auto it = p.attributes.find("POSITION"); it != p.attributes.end()) {
                const auto& a = m_.accessors[size_t(it->second)];
                if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || a.type != TINYGLTF_TYPE_VEC3)
                    fail(path + "/attributes/POSITION",
                         "POSITION accessor " + std::to_string(it->second) + " must be FLOAT VEC3");
            }
            if (p.indices != -1) {
                checkIndex(p.indices, m_.accessors, path + "/indices", "accessor");
                const auto& a = m_.accessors[size_t(p.indices)];
                bool intType = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                               a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                               a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
                if (!intType || a.type != TINYGLTF_TYPE_SCALAR)
                    fail(path + "/indices",
                         "index accessor " + std::to_string(p.indices) + " must be UNSIGNED_BYTE/SHORT/INT SCALAR");
            }
        }
    }
}

void Loader::validateAccessor(size_t i) {
    const auto& a = m_.accessors[i];
    std::string path = at("accessors", i);
    if (tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)) <= 0 ||
        tinygltf::GetNumComponentsInType(uint32_t(a.type)) <= 0)
        fail(path, "unknown componentType " + std::to_string(a.componentType) + " or type " + std::to_string(a.type));
    size_t elem = elementSize(a);
    if (a.bufferView == -1) {
        if (a.count > kMaxUnbackedBytes / elem)
            fail(path + "/count", "count " + std::to_string(a.count) + " is too large for an accessor without bufferView (at most " +
                                      std::to_string(kMaxUnbackedBytes >> 20) + " MiB of zeros)");
    } else {
        checkIndex(a.bufferView, m_.bufferViews, path + "/bufferView", "bufferView");
        const auto& bv = m_.bufferViews[size_t(a.bufferView)];
        size_t stride = bv.byteStride ? bv.byteStride : elem;
        if (stride < elem)
            fail(path,
                 "bufferView byteStride " + std::to_string(stride) + " is smaller than the element size " + std::to_string(elem));
        if (!fits(a.byteOffset, stride, a.count, elem, bv.byteLength))
            fail(path, std::to_string(a.count) + " elements of " + std::to_string(elem) + " bytes (stride " +
                           std::to_string(stride) + ", offset " + std::to_string(a.byteOffset) + ") exceed bufferView " +
                           std::to_string(a.bufferView) + " (" + std::to_string(bv.byteLength) + " bytes)");
    }
    if (!a.sparse.isSparse) return;
    const auto& s = a.sparse;
    if (s.count < 1 || size_t(s.count) > a.count)  // tinygltf's int: a count past 2^31 reads negative, so not echoed
        fail(path + "/sparse/count", "the sparse count is outside [1, " + std::to_string(a.count) + "] (the accessor's count)");
    checkIndex(s.indices.bufferView, m_.bufferViews, path + "/sparse/indices/bufferView", "bufferView");
    checkIndex(s.values.bufferView, m_.bufferViews, path + "/sparse/values/bufferView", "bufferView");
    int isz = tinygltf::GetComponentSizeInBytes(uint32_t(s.indices.componentType));
    if (s.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        s.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        s.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail(path + "/sparse/indices/componentType", "sparse indices must be UNSIGNED_BYTE/SHORT/INT");
    if (s.indices.byteOffset < 0 || !fits(uint64_t(s.indices.byteOffset), uint64_t(isz), uint64_t(s.count), uint64_t(isz),
                                          m_.bufferViews[size_t(s.indices.bufferView)].byteLength))
        fail(path + "/sparse/indices", "sparse indices exceed their bufferView");
    if (s.values.byteOffset < 0 || !fits(uint64_t(s.values.byteOffset), elem, uint64_t(s.count), elem,
                                         m_.bufferViews[size_t(s.values.bufferView)].byteLength))
        fail(path + "/sparse/values", "sparse values exceed their bufferView");
}

void Loader::validateNodes() {
    parent_.assign(m_.nodes.size(), -1);
    for (size_t i = 0; i < m_.nodes.size(); ++i) {
        const auto& n = m_.nodes[i];
        std::string path = at("nodes", i);
        if (n.mesh != -1) checkIndex(n.mesh, m_.meshes, path + "/mesh", "mesh");
        for (size_t c = 0; c < n.children.size(); ++c)
            checkIndex(n.children[c], m_.nodes, path + "/children/" + std::to_string(c), "node");
        auto checkVec = [&](const std::vector<double>& v, size_t n, const char* key) {
            bool ok = v.empty() || v.size() == n;
            for (double d : v) ok = ok && std::isfinite(d);
            if (!ok) fail(path + "/" + key, "expected " + std::to_string(n) + " finite numbers");
            // Placed in float (twenty-fourth probe: a translation of 1e300 became inf, and its
            // vertices were reported at -nan, with no word of the node).
            for (double d : v)
                if (!(std::abs(d) <= double(std::numeric_limits<float>::max())))
                    fail(path + "/" + key, "holds " + shortText(std::to_string(d), 30) + ", which does not fit a float");
        };
        checkVec(n.matrix, 16, "matrix");
        checkVec(n.translation, 3, "translation");
        checkVec(n.rotation, 4, "rotation");
        checkVec(n.scale, 3, "scale");
        if (n.rotation.size() == 4 && n.rotation[0] == 0 && n.rotation[1] == 0 && n.rotation[2] == 0 && n.rotation[3] == 0)
            fail(path + "/rotation", "rotation quaternion is zero");
    }
    // Cycles first (the clearer message for a RecursiveNodes-style file): depth-first over children
    // with an explicit stack, so that deep hierarchies cannot overflow the call stack.
    enum : char { Unvisited, Visiting, Done };
    std::vector<char> state(m_.nodes.size(), Unvisited);
    for (size_t start = 0; start < m_.nodes.size(); ++start) {
        if (state[start] != Unvisited) continue;
        std::vector<std::pair<size_t, size_t>> stack{{start, 0}};  // node, next child position
        state[start] = Visiting;
        while (!stack.empty()) {
            auto& [node, next] = stack.back();
            const auto& children = m_.nodes[node].children;
            if (next == children.size()) {
                state[node] = Done;
                stack.pop_back();
                continue;
            }
            size_t child = size_t(children[next++]);
            if (state[child] == Visiting)
                fail(at("nodes", node) + "/children", "node hierarchy has a cycle (node " + std::to_string(node) + " -> node " +
                                                          std::to_string(child) + ", which is its own ancestor)");
            if (state[child] == Unvisited) {
                state[child] = Visiting;
                stack.emplace_back(child, 0);
            }
        }
    }
    // glTF requires disjoint strict trees; a shared child would also make traversal cost explode.
    for (size_t i = 0; i < m_.nodes.size(); ++i)
        for (int c : m_.nodes[i].children) {
            if (parent_[size_t(c)] != -1)
                fail(at("nodes", i) + "/children", "node " + std::to_string(c) + " has two parents (nodes " +
                                                       std::to_string(parent_[size_t(c)]) + " and " + std::to_string(i) + ")");
            parent_[size_t(c)] = int(i);
        }
}

/// The accessor's elements, tightly packed, with sparse substitutions applied. Ranges were validated.
std::vector<unsigned char> Loader::gather(int index) const {
    const auto& a = m_.accessors[size_t(index)];
    size_t elem = elementSize(a);
    std::vector<unsigned char> out(a.count * elem, 0);
    if (a.bufferView != -1) {
        const auto& bv = m_.bufferViews[size_t(a.bufferView)];
        size_t stride = bv.byteStride ? bv.byteStride : elem;
        const unsigned char* base = m_.buffers[size_t(bv.buffer)].data.data() + bv.byteOffset + a.byteOffset;
        for (size_t k = 0; k < a.count; ++k) std::memcpy(out.data() + k * elem, base + k * stride, elem);
    }
    if (a.sparse.isSparse) {
        const auto& s = a.sparse;
        const auto& ibv = m_.bufferViews[size_t(s.indices.bufferView)];
        const auto& vbv = m_.bufferViews[size_t(s.values.bufferView)];
        const unsigned char* ib = m_.buffers[size_t(ibv.buffer)].data.data() + ibv.byteOffset + size_t(s.indices.byteOffset);
        const unsigned char* vb = m_.buffers[size_t(vbv.buffer)].data.data() + vbv.byteOffset + size_t(s.values.byteOffset);
        size_t isz = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(s.indices.componentType)));
        for (size_t k = 0, previous = 0; k < size_t(s.count); ++k) {
            uint32_t target = 0;
            std::memcpy(&target, ib + k * isz, isz);  // little-endian: low bytes first
            if (target >= a.count)
                fail(at("accessors", size_t(index)) + "/sparse/indices",
                     "sparse index " + std::to_string(target) + " is out of range");
            // Strictly increasing, as the spec requires (thirteenth probe: a repeated index let a later
            // value replace an infinite one, which was never reported).
            if (k > 0 && target <= previous)
                fail(at("accessors", size_t(index)) + "/sparse/indices",
                     "sparse index " + std::to_string(target) + " at element " + std::to_string(k) + " does not follow " +
                         std::to_string(previous) + " (sparse indices strictly increase)");
            previous = target;
            std::memcpy(out.data() + target * elem, vb + k * elem, elem);
        }
    }
    return out;
}

const std::vector<glm::vec3>& Loader::positions(int accessor) {
    auto it = positionCache_.find(accessor);
    if (it != positionCache_.end()) return it->second;
    std::vector<unsigned char> bytes = gather(accessor);
    std::vector<glm::vec3> pos(bytes.size() / sizeof(glm::vec3));
    std::memcpy(pos.data(), bytes.data(), pos.size() * sizeof(glm::vec3));
    for (size_t k = 0; k < pos.size(); ++k)
        if (!std::isfinite(pos[k].x) || !std::isfinite(pos[k].y) || !std::isfinite(pos[k].z))
            fail(at("accessors", size_t(accessor)), "POSITION element " + std::to_string(k) + " is not finite");
    return positionCache_.emplace(accessor, std::move(pos)).first->second;
}

Material Loader::material(int index) const {
    Material out;  // no material: the project default (0.8 grey, opaque)
    if (index < 0) return out;
    const auto& mat = m_.materials[size_t(index)];
    const auto& f = mat.pbrMetallicRoughness.baseColorFactor;
    out.albedo = glm::vec3(float(f[0]), float(f[1]), float(f[2]));
    // Only BLEND makes alpha a transmittance; MASK and OPAQUE surfaces block all light they cover.
    out.opacity = mat.alphaMode == "BLEND" ? float(f[3]) : 1.0f;
    return out;
}

glm::mat4 Loader::localMatrix(const tinygltf::Node& n) const {
    if (n.matrix.size() == 16) {
        glm::mat4 m;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[c][r] = float(n.matrix[size_t(c * 4 + r)]);  // glTF is column-major too
        return m;
    }
    glm::mat4 t(1.0f), r(1.0f), s(1.0f);
    if (n.translation.size() == 3)
        t[3] = glm::vec4(float(n.translation[0]), float(n.translation[1]), float(n.translation[2]), 1.0f);
    if (n.rotation.size() == 4) {
        r = rotationMatrix(unitQuaternion(n.rotation));
    }
    if (n.scale.size() == 3)
        s = glm::mat4(glm::vec4(float(n.scale[0]), 0, 0, 0), glm::vec4(0, float(n.scale[1]), 0, 0),
                      glm::vec4(0, 0, float(n.scale[2]), 0), glm::vec4(0, 0, 0, 1));
    return t * r * s;
}

/// Appends one primitive instance; returns its triangle count before degenerate ones are dropped.
size_t Loader::emitPrimitive(Scene& scene, size_t mi, size_t pi, const glm::mat4& world) {
    const auto& p = m_.meshes[mi].primitives[pi];
    std::string path = at("meshes", mi) + "/primitives/" + std::to_string(pi);
    int mode = p.mode == -1 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    auto posIt = p.attributes.find("POSITION");
    if (mode < TINYGLTF_MODE_TRIANGLES || posIt == p.attributes.end()) {  // points, lines, or nothing to place
        ++skipped_;
        return 0;
    }
    const std::vector<glm::vec3>& pos = positions(posIt->second);

    std::vector<uint32_t> seq;
    if (p.indices != -1) {
        std::vector<unsigned char> bytes = gather(p.indices);
        size_t isz = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(m_.accessors[size_t(p.indices)].componentType)));
        seq.resize(bytes.size() / isz);
        for (size_t k = 0; k < seq.size(); ++k) {
            uint32_t v = 0;
            std::memcpy(&v, bytes.data() + k * isz, isz);
            if (v >= pos.size())
                fail(path + "/indices", "index " + std::to_string(v) + " at element " + std::to_string(k) +
                                            " is out of range (POSITION has " + std::to_string(pos.size()) + " vertices)");
            seq[k] = v;
        }
    } else {
        seq.resize(pos.size());
        for (size_t k = 0; k < seq.size(); ++k) seq[k] = uint32_t(k);
    }
    if (mode == TINYGLTF_MODE_TRIANGLES && seq.size() % 3 != 0)
        fail(path, "TRIANGLES primitive has " + std::to_string(seq.size()) + " vertices, not a multiple of 3");

    // Triangle k as three positions in seq; strips alternate winding and fans pivot on vertex 0 (glTF 2.0 spec, 3.7.2.1).
    size_t triCount = mode == TINYGLTF_MODE_TRIANGLES ? seq.size() / 3 : seq.size() >= 3 ? seq.size() - 2 : 0;
    instanced_ += triCount;
    if (instanced_ > maxTriangles_)
        fail(path, "the file's node instances reach " + std::to_string(instanced_) + " triangles, more than the scene's limit (" +
                       std::to_string(maxTriangles_) + ", max_triangles)");
    auto corner = [&](size_t k, int c) -> uint32_t {
        if (mode == TINYGLTF_MODE_TRIANGLES) return seq[3 * k + size_t(c)];
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) return seq[k + (c == 0 ? 0 : c == 1 ? 1 + k % 2 : 2 - k % 2)];
        return c == 0 ? seq[k + 1] : c == 1 ? seq[k + 2] : seq[0];
    };
    // A mirroring node transform flips the winding; glTF says to flip it back so fronts stay fronts.
    bool mirrored = glm::determinant(glm::mat3(world)) < 0.0f;
    std::vector<glm::vec3> tri;
    tri.reserve(triCount * 3);
    for (size_t k = 0; k < triCount; ++k) {
        glm::vec3 v[3];
        // A triangle with an area in the file keeps it where its nodes place it (fourteenth probe: a
        // node's scale of 1e-30 dropped it silently); one without is the file's own, dropped as documented.
        glm::vec3 local[3], n;
        for (int c = 0; c < 3; ++c) local[c] = pos[corner(k, c)];
        const bool hasArea = unitNormal(local[0], local[1], local[2], n);
        for (int c = 0; c < 3; ++c) {
            v[c] = glm::vec3(world * glm::vec4(local[c], 1.0f));
            // Beyond the coordinates every input is held to, a triangle's cross product overflows and
            // it was dropped as degenerate, silently (thirteenth probe: a vertex at 1e20).
            for (int a = 0; a < 3; ++a)
                if (!(std::abs(double(v[c][a])) <= kMaxCoordinate))
                    fail(path, "triangle " + std::to_string(k) + " has a vertex at " + shortNumber(double(v[c][a])) +
                                   " once placed by its nodes, beyond ±1e15 scene units");
        }
        if (mirrored) std::swap(v[1], v[2]);
        if (hasArea && !unitNormal(v[0], v[1], v[2], n))
            fail(path, "triangle " + std::to_string(k) + " has an area in the file but none in float once placed by its nodes "
                                                          "(a scale too small, or coordinates too large for its size)");
        tri.insert(tri.end(), {v[0], v[1], v[2]});
    }
    scene.addTriangles(tri, material(p.material));
    return triCount;
}

Scene Loader::run(GltfStats* stats) {
    validateStructure();
    validateNodes();
    std::vector<int> roots;
    if (m_.defaultScene != -1) checkIndex(m_.defaultScene, m_.scenes, "/scene", "scene");
    if (!m_.scenes.empty()) {
        size_t si = m_.defaultScene >= 0 ? size_t(m_.defaultScene) : 0;
        const auto& nodes = m_.scenes[si].nodes;
        for (size_t k = 0; k < nodes.size(); ++k) {
            std::string path = at("scenes", si) + "/nodes/" + std::to_string(k);
            checkIndex(nodes[k], m_.nodes, path, "node");
            // glTF makes a scene's nodes unique (fourteenth probe: a root listed twice was built twice).
            if (std::find(nodes.begin(), nodes.begin() + long(k), nodes[k]) != nodes.begin() + long(k))
                fail(path, "node " + std::to_string(nodes[k]) + " is listed twice (a scene's nodes are unique)");
            // Keeps traversal a forest walk: each node is visited (and instanced) once per root.
            if (parent_[size_t(nodes[k])] != -1)
                fail(path, "node " + std::to_string(nodes[k]) + " is not a root node (its parent is node " +
                               std::to_string(parent_[size_t(nodes[k])]) + ")");
            roots.push_back(nodes[k]);
        }
    } else {
        for (size_t i = 0; i < m_.nodes.size(); ++i)
            if (parent_[i] == -1) roots.push_back(int(i));
    }
    Scene scene;
    GltfStats counts;
    std::vector<bool> meshCounted(m_.meshes.size(), false);
    std::shared_ptr<const NodeAnimation> anim = readAnimation();
    for (int root : roots) {
        // (node, parent's world matrix, whether the node or an ancestor is animated)
        std::vector<std::tuple<int, glm::mat4, bool>> stack{{root, glm::mat4(1.0f), false}};
        while (!stack.empty()) {
            auto [node, parentMatrix, moving] = stack.back();
            stack.pop_back();
            const auto& n = m_.nodes[size_t(node)];
            glm::mat4 world = parentMatrix * localMatrix(n);
            moving = moving || (anim && anim->animated(size_t(node)));
            if (n.mesh != -1) {
                // A moving node's triangles stay in mesh space; its part is posed by the animation.
                const size_t first = scene.triangleCount();
                size_t meshTris = 0;
                for (size_t pi = 0; pi < m_.meshes[size_t(n.mesh)].primitives.size(); ++pi)
                    meshTris += emitPrimitive(scene, size_t(n.mesh), pi, moving ? glm::mat4(1.0f) : world);
                if (moving && scene.triangleCount() > first) {
                    MovingPart part;
                    part.firstTriangle = first;
                    part.triangleCount = scene.triangleCount() - first;
                    part.setLocal({scene.positions.begin() + ptrdiff_t(3 * first), scene.positions.end()});
                    part.worldFromLocal = [anim, node = size_t(node)](double time) { return anim->world(node, time); };
                    part.sourceFile = file_;
                    part.sourcePath = at("nodes", size_t(node));
                    part.startTime = animStart_;
                    part.endTime = animEnd_;
                    scene.moving.push_back(std::move(part));
                }
                counts.instanceTriangles += meshTris;
                if (!meshCounted[size_t(n.mesh)]) counts.meshTriangles += meshTris;
                meshCounted[size_t(n.mesh)] = true;
            }
            for (int c : n.children) stack.emplace_back(c, world, moving);
        }
    }
    if (scene.dynamic()) scene.applyPose(scene.poseAt(0.0));
    if (stats) *stats = counts;
    if (scene.triangleCount() == 0) {
        std::string why = counts.instanceTriangles ? " (all " + std::to_string(counts.instanceTriangles) + " are degenerate)"
                          : skipped_ ? " (" + std::to_string(skipped_) + " point, line or POSITION-less primitives skipped)"
                                     : std::string();
        fail("", "no triangles" + why);
    }
    return scene;
}

} // namespace

/// A uri's percent-encoded characters decoded, as the reader decodes a buffer file's name (tinygltf's
/// urldecode: "%XX" is a byte, "+" a space).
std::string percentDecoded(const std::string& uri) {
    auto hex = [](char c) { // a non-hex digit counts 0, as there
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        return c >= 'A' && c <= 'F' ? c - 'A' + 10 : 0;
    };
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '+') out += ' ';
        else if (uri[i] == '%' && i + 2 < uri.size()) out += char((hex(uri[i + 1]) << 4) | hex(uri[i + 2])), i += 2;
        else out += uri[i];
    }
    return out;
}

Scene loadGltf(const std::string& file) { return loadGltf(file, nullptr); }

Scene loadGltf(const std::string& file, GltfStats* stats, size_t maxTriangles, const GltfMotion& motion) {
    const std::vector<unsigned char> bytes = readInputFileBytes(file, 0xFFFFFFF0u);

    bool magic = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    std::string ext = file.size() >= 4 ? file.substr(file.size() - 4) : "";
    ext = asciiLowerCase(ext);
    if (ext == ".glb" && !magic) throw InputError(file, "", "not a GLB file (it does not start with \"glTF\")");
    bool binary = magic;  // a .gltf that is really binary loads too

    std::string jsonText = binary ? gltf::glbJson(file, bytes) : std::string(bytes.begin(), bytes.end());
    // The GLB spec pads the JSON chunk with spaces; some exporters pad it with NULs, which parseJson
    // refuses anywhere else (it would end the text there): trailing ones are padding.
    if (binary)
        while (!jsonText.empty() && jsonText.back() == '\0') jsonText.pop_back();
    // Depth and size are checked before tinygltf sees the text: its reader recurses into "extras"
    // and would overflow the stack on a document nested tens of thousands deep.
    JsonLimits limits;
    limits.maxValues = 50'000'000;      // big scenes have many nodes and accessors; still bounded
    limits.rejectDuplicateKeys = false;  // tolerated in glTF files in the wild (the last one wins)
    Json doc = parseJson(jsonText, file, limits);
    if (!doc.is_object()) throw InputError(file, "", "not a glTF file (the JSON document is not an object)");
    gltf::checkDocument(doc, file, binary, binary ? gltf::glbBinLength(bytes) : 0);

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(skipImage, nullptr);
    // External buffers are read like every other input: regular files only, size-capped (a FIFO
    // or /dev/zero named as a buffer's uri is bad input, not a hang or an out-of-memory abort).
    tinygltf::FsCallbacks fs{};
    // tinygltf's own FileExists fopen()s the file, which blocks on a FIFO until a writer comes:
    // whether something is there is a stat(); what it is, readInputFileBytes() says.
    fs.FileExists = [](const std::string& path, void*) {
        struct stat st {};
        return ::stat(path.c_str(), &st) == 0;
    };
    fs.ExpandFilePath = tinygltf::ExpandFilePath;
    fs.WriteWholeFile = tinygltf::WriteWholeFile;
    fs.ReadWholeFile = [](std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
        try {
            *out = readInputFileBytes(path, gltf::kMaxBufferFileBytes);
            return true;
        } catch (const InputError& e) {
            if (err) *err += e.cause() + "\n";
            return false;
        }
    };
    loader.SetFsCallbacks(fs);
    tinygltf::Model model;
    std::string err, warn, baseDir = parentDir(file);
    bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), baseDir)
                     : loader.LoadASCIIFromString(&model, &err, &warn, jsonText.data(), unsigned(jsonText.size()), baseDir);
    // tinygltf sometimes returns true with a non-empty err (a property it could not use): treat as malformed.
    if (!ok || !err.empty()) {
        std::string cause = gltf::oneLine(err + "\n" + warn);
        throw InputError(file, "", cause.empty() ? std::string("tinygltf could not load the file") : cause);
    }
    return Loader(file, model, maxTriangles, motion).run(stats);
}

} // namespace shadowlab
