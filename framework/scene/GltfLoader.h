#pragma once
// glTF 2.0 (.gltf and .glb) through tinygltf.
#include "framework/scene/Scene.h"

#include <vector>

#include <cstddef>
#include <string>

namespace shadowlab {

/// Loads every triangle primitive reachable from the default scene (the first scene when "scene" is
/// absent; all root nodes when the file has no scenes), applying node hierarchy transforms; a mesh
/// used by several nodes appears once per node. Indexed and non-indexed triangles (strips and fans
/// converted); points and lines are skipped.
/// Albedo comes from the material's baseColorFactor and opacity from its alpha (BLEND mode).
/// Malformed content (bad JSON, missing buffers, indices or accessors out of range, wrong types,
/// non-finite positions, node cycles) throws InputError(file, JSON path inside the glTF, cause);
/// it never crashes.
Scene loadGltf(const std::string& file);
/// Triangle counts of one load, for reports and tests: the file's own count can differ a lot from
/// Scene::triangleCount() (2CylinderEngine: 75,730 mesh triangles, 121,496 instanced, 110,336 kept).
struct GltfStats {
    size_t meshTriangles = 0;      ///< in the meshes the scene uses, each mesh counted once (what viewers report)
    size_t instanceTriangles = 0;  ///< over every node instance, before degenerate (zero-area) ones are dropped
};
/// A motion a config gives one node, in the node's own frame (after its local transform): the
/// meshes at and below the node move with it.
struct GltfNodeMotion {
    size_t node = 0;
    MotionFn motion;
    double startTime = 0, endTime = 0;
    bool aboutCentre = true; ///< about the centre of the node's meshes (else its frame's origin)
};
/// What moves in a file: `animation` (its name, else its index; "" = none) plays that animation:
/// the meshes of animated nodes (or of nodes below one) become moving parts posed by its
/// translation, rotation and scale channels (LINEAR, STEP, CUBICSPLINE) on the file's own clock,
/// in seconds. Skinned meshes and morph-target (weights) channels are an InputError, as is an
/// unknown name. `nodes` are composed after the animation's channels of each node.
struct GltfMotion {
    std::string animation;
    std::vector<GltfNodeMotion> nodes;
};

/// As above, also filling `stats` when it is not null, with `motion`. More than `maxTriangles`
/// triangle instances is an InputError raised before they are allocated (a few nodes instancing a
/// big mesh can ask for billions).
Scene loadGltf(const std::string& file, GltfStats* stats, size_t maxTriangles = 200'000'000, const GltfMotion& motion = {});

/// A buffer or image uri's percent-encoded characters decoded, as the reader decodes a file's name
/// (tinygltf's urldecode: "%XX" is a byte, "+" a space): the file it names, relative to the glTF's folder.
std::string percentDecoded(const std::string& uri);

} // namespace shadowlab
