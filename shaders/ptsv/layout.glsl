// PTSV GPU layout constants, shared by GLSL (#include "ptsv/layout.glsl") and C++
// (algorithms/ptsv/PtsvLayout.h includes this very file). #defines and comments only, so it is
// valid in both languages and every number exists once.

// SSBO binding points (0..2 are the scene buffers of shaders/common/scene.glsl).
#define PTSV_MASK_BINDING 3    // child masks of every tree level, one 32-bit word per node
#define PTSV_AABB_BINDING 4    // explicit bounds: 6 floats (min xyz, max xyz) per node below the root
#define PTSV_SAMPLE_BINDING 5  // per view sample (tile-major): shadow-ray origin q (float bits, xyz) and
                               // cluster key or PTSV_KEY_* (w)
#define PTSV_SHADOW_BINDING 7  // per view sample (tile-major): 1 once a test-and-set found it shadowed
#define PTSV_PLANE_BINDING 8   // per triangle: PTSV_PLANES_PER_TRIANGLE vec4
#define PTSV_JOB_BINDING 9     // two-pass job list: (triangle, node) pairs
#define PTSV_COUNTER_BINDING 10
#define PTSV_HEAT_BINDING 11   // per view sample (tile-major): test-and-set operations (heat map)
#define PTSV_JOB_ITER_BINDING 12 // per job: traversal iterations (pass one: triangle t at t; pass two: n + job)

// Texture units of the buffer-texture views through which a pass reads what it does not write: the
// explicit bounds (RGB32F, 2 texels per node), sample slots (RGBA32UI: q's bits and key) and planes
// (RGBA32F).
#define PTSV_BOUNDS_UNIT 2
#define PTSV_SAMPLE_UNIT 3
#define PTSV_PLANE_UNIT 5
#define PTSV_MASK_UNIT 6   // child masks (R32UI)
#define PTSV_SHADOW_UNIT 7 // shadow marks (R32UI), read by the resolve pass

// Traversal workgroup size with traversal = invocation (one job per invocation).
#define PTSV_INVOCATION_GROUP 64

// A tree has at most this many levels of child masks (32-bit keys, 5 bits per level).
#define PTSV_MAX_LEVELS 7
#define PTSV_MAX_KEY_BITS 30

// Keys of samples that are not in the hierarchy.
#define PTSV_KEY_BACKGROUND 0xFFFFFFFFu // no geometry: lit, like the reference's background
#define PTSV_KEY_AWAY 0xFFFFFFFEu       // facing away from the light: shadowed without a test

// Per triangle: 3 shadow (edge) planes, the triangle plane, 3 additional culling planes, and an
// info vec4 whose x holds the PTSV_CASTER_* status as a float value (0.0, 1.0 or 2.0). Inside the
// volume is negative; a culled triangle's seven planes are PTSV_REJECT_ALL (+1 everywhere).
#define PTSV_PLANES_PER_TRIANGLE 8
#define PTSV_CASTER_OK 0u
#define PTSV_CASTER_EDGE_ON 1u
#define PTSV_CASTER_FACING 2u
#define PTSV_REJECT_ALL vec4(0.0, 0.0, 0.0, 1.0)

// Per-frame counters, one 32-bit word each.
#define PTSV_COUNTER_WORDS 32
#define PTSV_C_TESTS_LO 0        // test-and-set operations (sample x volume tests): low 32 bits ...
#define PTSV_C_TESTS_HI 1        // ... high 32 bits
#define PTSV_C_NODE_TESTS_LO 2   // existing child nodes tested against a volume: low ...
#define PTSV_C_NODE_TESTS_HI 3   // ... high
#define PTSV_C_ITER_MAX_1 4      // most traversal iterations of one pass-one (or one-pass) job
#define PTSV_C_ITER_SUM_1 5      // iterations of all pass-one jobs
#define PTSV_C_JOBS_1 6          // triangles traversed (not culled)
#define PTSV_C_ITER_MAX_2 7      // most iterations of one pass-two job
#define PTSV_C_ITER_SUM_2 8      // iterations of all pass-two jobs
#define PTSV_C_JOBS_PUSHED 9     // push attempts onto the job list (may exceed its capacity)
#define PTSV_C_JOB_OVERFLOW 10   // pushes that found the list full: finished in pass one instead
#define PTSV_C_ACCEPTED 11       // nodes trivially accepted (bits cleared)
#define PTSV_C_CLUSTERS 12       // leaf clusters in the hierarchy
#define PTSV_C_RECEIVERS 13      // samples in the hierarchy (covered and facing the light)
#define PTSV_C_CULLED_FACING 14  // triangles dropped by front-face culling
#define PTSV_C_CULLED_EDGE_ON 15 // triangles whose plane contains the light (empty volume)
#define PTSV_C_TRUNCATED 16      // jobs cut short by the driver's loop cap (llvmpipe: 65535): must stay 0
#define PTSV_C_DISPATCH 17       // words 17..19: pass two's indirect dispatch (groups x, y, z)
#define PTSV_C_LEAF_VISITS 21    // leaf clusters whose samples were tested
#define PTSV_C_SHADOWED 20       // receivers written shadowed by the resolve pass
#define PTSV_C_SUBGROUP_MISMATCH 22 // ballot workgroups on subgroups of another width than compiled: jobs not run (overflow)
#define PTSV_C_VOTE_RECOVERED 23 // votes or broadcasts that missed a lane (no reconvergence): decided alone, exact
#define PTSV_C_CLOSE_CALLS 24    // sample tests too close to call by the planes: decided by the reference's ray test
