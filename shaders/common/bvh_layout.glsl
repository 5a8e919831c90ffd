// The scene BVH's GPU layout (framework/accel: built on the CPU, traversed by common/bvh_traverse.glsl),
// shared by GLSL (#include "common/bvh_layout.glsl") and C++ (framework/accel/BvhGpuLayout.h includes
// this very file). #defines and comments only, so it is valid in both languages.

// A node stores the bounds of both children (Aila & Laine 2009), so one 64-byte fetch decides
// which children a ray enters. countK > 0: child K is a leaf of countK triangles starting at
// triangle childK of the leaf-ordered triangle buffer; countK == 0: child K is inner node childK. An absent child
// (a tree of fewer than two leaves) has an inverted box that no ray enters.
#define BVH_NODE_BYTES 64
// Leaf triangles: 3 vec4 vertices (w unused) in leaf order.
#define BVH_TRI_BYTES 48
// Leaves hold at most this many triangles (the shader packs count - 1 in 4 bits of a stack entry).
#define BVH_MAX_LEAF 16

// Child reference of an absent child (only the root of a tree of fewer than two leaves has one).
#define BVH_ABSENT 0xFFFFFFFFu
