// bvh_raytrace GPU layout constants, shared by GLSL (#include "bvh_raytrace/layout.glsl") and C++
// (framework/accel/BvhGpuLayout.h includes this very file). #defines and comments only,
// so it is valid in both languages and the numbers exist once.

// SSBO binding points (after the scene buffers 0..2 of shaders/common/scene.glsl, which the BVH
// does not read: it holds its own copy of the triangles, in leaf order).
#define BVH_SAMPLE_BINDING 5
#define BVH_COUNTER_BINDING 6
// Texture units of the trace's buffer-texture views of the nodes (RGBA32UI, 4 texels per node) and
// the leaf-ordered triangles (RGBA32F, 3 texels per triangle); units 0 and 1 are the G-buffer.
#define BVH_NODE_UNIT 2
#define BVH_TRI_UNIT 3

// Per-frame counters, one 32-bit word each; 64-bit sums are split into LO/HI words (the shader
// carries into HI when LO wraps).
#define BVH_COUNTER_WORDS 21
#define BVH_C_RAYS_LO 0           // shadow rays traced (lit pixels × samples)
#define BVH_C_RAYS_HI 1
#define BVH_C_VISITED_LO 2        // inner nodes fetched, summed over rays
#define BVH_C_VISITED_HI 3
#define BVH_C_VISITED_MAX 4       // most nodes one ray fetched
#define BVH_C_TRIS_LO 5           // ray–triangle tests, summed over rays
#define BVH_C_TRIS_HI 6
#define BVH_C_OVERFLOW_RAYS 7     // rays whose traversal stack overflowed (counted as blocked)
#define BVH_C_OVERFLOW_PIXELS 8   // pixels with at least one such ray (written shadowed)
#define BVH_C_PIXELS 9            // pixels that traced rays (covered, facing and reached by the light)
#define BVH_C_TRUNCATED_PIXELS 10 // pixels whose sample loop the driver cut short (written shadowed)
#define BVH_C_CAPPED_PIXELS 11    // pixels with a ray whose traversal reached its step cap (written shadowed)
// Instrumented, with ARB_shader_ballot: the SIMD probe (common/simd_probe.glsl) of the two loops.
#define BVH_SIMD_NODE 0           // an inner node fetched and both children's boxes tested
#define BVH_SIMD_TRI 1            // a triangle tested
#define BVH_SIMD_SECTIONS 2
#define BVH_C_SIMD_BASE 12        // section k: passes at 12 + 4k (LO, HI), lanes at 14 + 4k (LO, HI)
#define BVH_C_SIMD_WIDTH 20       // the widest ballot at entry (0: no probe)

// A frame whose light has more samples than samples_per_dispatch runs several dispatches; between
// them each traced pixel keeps its state in the accumulation image (image unit BVH_ACCUM_UNIT,
// R32UI, RG32UI when instrumented: y = nodes visited so far): the unblocked samples so far in the
// low bits, and a flag per way a ray can fail, any of which writes the pixel shadowed.
#define BVH_ACCUM_UNIT 3
#define BVH_ACC_COUNT_MASK 0x0FFFFFFFu // unblocked samples (at most 1,024 per light: far below the mask)
#define BVH_ACC_OVERFLOW 0x10000000u   // a ray's stack overflowed
#define BVH_ACC_CAPPED 0x20000000u     // a ray's traversal reached its step cap
#define BVH_ACC_TRUNCATED 0x40000000u  // the driver cut a dispatch's sample loop short
