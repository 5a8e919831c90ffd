// PSV GPU layout constants, shared by GLSL (#include "psv/layout.glsl") and C++
// (algorithms/psv/PsvGpuLayout.h includes this very file). It holds #defines and comments only,
// so it is valid in both languages and the numbers exist once.

// SSBO binding points (0..2 are the scene buffers of shaders/common/scene.glsl).
#define PSV_NODE_BINDING 3
#define PSV_COUNTER_BINDING 4
#define PSV_DEFER_LIST_BINDING 5  // the pixels the plane walk leaves to the exact walk (PixelList)
#define PSV_DEFER_ARGS_BINDING 6  // the exact walk's grid over them
// Texture unit of the nodes' buffer-texture view (RGBA32UI, two texels per node; units 0 and 1
// are the query's G-buffer).
#define PSV_NODE_UNIT 2

// TOP tree: node 0 is a sentinel whose `pos` field is the root pointer (its plane's w carries the
// frame's tolerance: psvReadMargins in psv/tree.glsl); triangle t owns the four
// nodes 4t+1 .. 4t+4 (three shadow planes, then its capping plane), so `index % 4 == 0` marks a
// capping node and the negative child of a shadow-plane node is simply index + 1 (never stored).
// Index 0 in a child field is an empty leaf. 4n + 1 nodes of 32 bytes in all.
#define PSV_NODE_BYTES 32
#define PSV_NODES_PER_TRIANGLE 4

// Per-frame counters, one 32-bit word each. The block is 96 bytes so that the tree plus the
// counters take exactly 32 (4n + 1) + 96 = 128 (n + 1) bytes: the paper's memory figure.
#define PSV_COUNTER_WORDS 24
#define PSV_C_INSERTED 0          // triangles merged into the tree
#define PSV_C_CULLED_FACING 1     // front faces dropped by front_face_culling
#define PSV_C_CULLED_EDGE_ON 2    // triangles whose plane contains the light (empty frustum)
#define PSV_C_CULLED_OCCLUDED 3   // opaque mode: triangles strictly inside another frustum
#define PSV_C_BUILD_ERRORS 4      // corrupt child index or runaway descent (must stay 0)
#define PSV_C_INSERT_DEPTH_MAX 5  // most nodes tested by one insertion
#define PSV_C_TRAVERSED 6         // pixels that ran the query (covered, facing the light)
#define PSV_C_VISITED_LO 7        // nodes visited by all queries: low 32 bits ...
#define PSV_C_VISITED_HI 8        // ... and high 32 bits (carry added by whoever wraps LO)
#define PSV_C_VISITED_MAX 9       // most nodes visited by one pixel
#define PSV_C_STACK_OVERFLOW 10   // pixels whose traversal stack overflowed (written as shadowed)
#define PSV_C_CLOSE_CALLS 11      // triangles decided by the reference's ray test (plane too close to call)
#define PSV_C_STACKLESS_WALKS 12  // stackless walks: 1 per pixel (stackless), 1 per full stack (hybrid)
#define PSV_C_CULLED_CONE 13      // spot light: triangles wholly outside its cone
#define PSV_C_LOOP_CAPPED 14      // pixels whose stackless walk hit its escape cap (written shadowed)
#define PSV_C_DEFERRED 15         // pixels the plane walk left to the exact walk (a close call met)
// Words 16..23 are reserved (kept so the block size, hence memory_bytes, stays fixed).

// Below this light transmission a transparent query stops: the same cut-off as the reference
// (EmbreeTracer::kOpaqueTransmission).
#define PSV_OPAQUE_TRANSMISSION 1e-6
