// line_space GPU layout constants, shared by GLSL (#include "line_space/layout.glsl") and C++
// (algorithms/line_space/LineSpaceLayout.h includes this very file). #defines and comments only,
// so it is valid in both languages and the numbers exist once.

// SSBO binding points (0..2 are the scene buffers; only start_region exact reads the scene, its
// positions, through their buffer texture, unit 15).
#define LS_SAMPLE_BINDING 6     // light sample points (vec4)
#define LS_COUNTER_BINDING 7    // per-frame counters
#define LS_CLASSIFY_BINDING 8   // with classify: per pixel, start node + one occlusion bit per sample

// The pools, read-only in the trace, are read through buffer textures over their buffers (texture
// units; 0 and 1 are the G-buffer): nodes as RGBA32UI (2 texels per node), the others as R32UI
// (one texel per word).
#define LS_NODE_UNIT 2          // node pool: one LsNode per subdivided node, breadth-first, root = 0
#define LS_TREE_UNIT 3          // tree pool: children groups of N³ entries, one per node above the last level
#define LS_OCC_UNIT 4           // occupancy pool: LS_OCC_WORDS_PER_NODE(N) words per node, node order
// start_region exact: the leaf lists (ls::LeafLists); the triangles' vertices are the scene's.
#define LS_LEAF_RANK_UNIT 5
#define LS_LEAF_PREFIX_UNIT 6
#define LS_LEAF_TRIS_UNIT 7
// Line-space pool: LS_WORDS_PER_NODE(N) words per node, node order. It is the one that outgrows a
// shader storage block (128 MiB here): (8, 3) on a 2 M-triangle scene needs ~220 MB. It is split at
// node boundaries into up to LS_BIT_CHUNKS buffers of uNodesPerChunk nodes each; chunk c is read
// at unit LS_BITS_UNIT + c.
#define LS_BIT_CHUNKS 4
#define LS_BITS_UNIT 8
// start_region exact, start_triangles culled: per scene triangle its plane (RGBA32F: unit normal,
// offset), read by the plane test before the watertight one.
#define LS_TRI_PLANE_UNIT 12
// leaf_split > 1: per occupied leaf (numbered by its rank) the occupancy of its sub-cells (RG32UI).
#define LS_LEAF_SUB_UNIT 13
// start_region bvh: the near field's BVH (bvh_raytrace's layout: nodes RGBA32UI, triangles RGBA32F).
#define LS_BVH_NODE_UNIT 16
#define LS_BVH_TRI_UNIT 17

// Node pool entry: vec3 lo; uint children; vec3 size; uint level (32 bytes, std430).
#define LS_NODE_BYTES 32
// `children` of a node on the last subdivided level (its children are leaves, never stored).
#define LS_NO_CHILDREN 0xFFFFFFFFu
// Tree pool entry of an empty child (every non-empty child above the last level is subdivided).
#define LS_EMPTY 0xFFFFFFFFu

// Sub-faces: face f = 2 × axis + side (side 0 = the min plane); the face's sub-face (i, j) along
// axes u = (axis + 1) % 3, v = (axis + 2) % 3 has index j × N + i. A shaft joins sub-faces on two
// different faces fa < fb; its bit is
//   LS_PAIR_INDEX(fa, fb) × N⁴ + subA × N² + subB
// so a node holds exactly the 15 N⁴ bits of the paper (the symmetric half, no same-face pairs).
#define LS_PAIR_INDEX(fa, fb) ((fa) * (11 - (fa)) / 2 + (fb) - (fa) - 1)
#define LS_BITS_PER_NODE(n) (15 * (n) * (n) * (n) * (n))
#define LS_WORDS_PER_NODE(n) ((LS_BITS_PER_NODE(n) + 31) / 32)
// Occupancy of a node's N³ children, one bit each in child order (z × N + y) × N + x.
#define LS_OCC_WORDS_PER_NODE(n) (((n) * (n) * (n) + 31) / 32)

// Per-frame counters, one 32-bit word each; 64-bit sums are split into LO/HI words.
#define LS_COUNTER_WORDS 54
#define LS_C_RAYS_LO 0          // shadow rays (lit pixels × samples)
#define LS_C_RAYS_HI 1
#define LS_C_VISITED_LO 2       // nodes entered, summed over rays
#define LS_C_VISITED_HI 3
#define LS_C_VISITED_MAX 4      // most nodes one ray entered
#define LS_C_SHAFTS_LO 5        // line-space bits read, summed over rays
#define LS_C_SHAFTS_HI 6
#define LS_C_OCCLUDED_LO 7      // rays the line space declared occluded
#define LS_C_OCCLUDED_HI 8
#define LS_C_PIXELS 9           // pixels that traced rays
#define LS_C_OVERFLOW 10        // traversal stack overflows (cannot happen: one frame per level)
#define LS_C_CELLS_LO 11        // child cells the DDA stepped through (empty ones included), summed over rays
#define LS_C_CELLS_HI 12
#define LS_C_LEAVES_LO 13       // leaf cells read by the start region's leaf walks, summed over rays
#define LS_C_LEAVES_HI 14
#define LS_C_TRIS_LO 15         // triangles tested by the exact start region, summed over rays
#define LS_C_TRIS_HI 16
#define LS_C_TRUNCATED 17       // pixels whose sample loop the driver cut short (written shadowed)
#define LS_C_CAPPED 18          // pixels with a ray whose walk reached its loop cap (written shadowed)
#define LS_C_NEAR_NODES_LO 19   // start_region bvh: BVH nodes the near fields fetched, summed over rays
#define LS_C_NEAR_NODES_HI 20
// Instrumented, with ARB_shader_ballot: the SIMD probe. Per section of the trace (LS_SIMD_*), how
// often a subgroup ran it (passes) and with how many lanes active in all (lanes), each 64 bits
// (LO, HI); utilisation = lanes / (passes × width), the width being the lanes of a ballot at entry.
#define LS_SIMD_WALK 0   // a pass of the DDA over a node's children (empty cells included)
#define LS_SIMD_NODE 1   // a node entered: slab test and shaft bit
#define LS_SIMD_LEAF 2   // a leaf visited by a leaf walk (start region, last level)
#define LS_SIMD_PLANE 3  // a plane test of a start-region triangle (start_triangles culled)
#define LS_SIMD_TRI 4    // a watertight triangle test (exact start region)
#define LS_SIMD_SUB 5    // a sub-cell visited (leaf_split > 1)
#define LS_SIMD_NEAR_NODE 6 // a BVH node of the near field (start_region bvh)
#define LS_SIMD_NEAR_TRI 7  // a triangle test of the near field
#define LS_SIMD_SECTIONS 8
#define LS_C_SIMD_BASE 21       // section k: passes at 21 + 4k (LO, HI), lanes at 23 + 4k (LO, HI)
#define LS_C_SIMD_WIDTH 53      // the widest ballot at entry (0: no probe)

// A frame whose light has more samples than samples_per_dispatch runs several dispatches; between
// them each traced pixel keeps its state in the accumulation image (image unit LS_ACCUM_UNIT, R32UI,
// RG32UI when instrumented: y = nodes visited so far): the unblocked samples so far in the low bits,
// and a flag per way a pixel can fail, either of which writes it shadowed.
#define LS_ACCUM_UNIT 3
#define LS_ACC_COUNT_MASK 0x0FFFFFFFu // unblocked samples (at most 1,024 per light: far below the mask)
#define LS_ACC_CAPPED 0x20000000u     // a ray's walk reached its loop cap
#define LS_ACC_TRUNCATED 0x40000000u  // the driver cut a dispatch's sample loop short
