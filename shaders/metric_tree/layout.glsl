// metric_tree GPU layout constants, shared by GLSL (#include "metric_tree/layout.glsl") and C++
// (algorithms/metric_tree/MetricTreeGpuLayout.h includes this very file). #defines and comments
// only, so it is valid in both languages and the numbers exist once.

// SSBO binding points (0..2 are the scene buffers of shaders/common/scene.glsl, which metric_tree
// does not read: it keeps the triangles in cluster order, see MT_GEOMETRY_BINDING_0).
#define MT_CLUSTER_BINDING 3
#define MT_NODE_BINDING 4
#define MT_COUNTER_BINDING 5
// The triangles in cluster order, 9 floats each, split over MT_GEOMETRY_CHUNKS blocks of at most
// MT_TRIANGLES_PER_CHUNK triangles. The query reads them through buffer-texture views, of at most
// GL_MAX_TEXTURE_BUFFER_SIZE texels (134 M on llvmpipe: 44.7 M triangles); rigid motion writes them
// as storage blocks, of at most 128 MiB on llvmpipe (3.5 M triangles are 126 MB). The host picks
// the block size per scene (the parameter geometry_block) and passes it as a define; the default
// here is the storage-block one.
#define MT_GEOMETRY_BINDING_0 6
// Texture units of the query's buffer-texture views of the nodes, clusters and geometry blocks
// (units 0 and 1 are the G-buffer).
#define MT_NODE_UNIT 2
#define MT_CLUSTER_UNIT 3
#define MT_GEOMETRY_UNIT_0 4
#define MT_GEOMETRY_CHUNKS 6
#ifndef MT_TRIANGLES_PER_CHUNK
#define MT_TRIANGLES_PER_CHUNK 3500000
#endif

// Both arrays are 64 bytes per element: cluster i owns node i, so the pool can never overflow
// and clusters + nodes take exactly 128 bytes per cluster (the paper's figure).
#define MT_CLUSTER_BYTES 64
#define MT_NODE_BYTES 64
#define MT_NO_CHILD 0u // child fields hold node index + 1; 0 is an empty leaf
#define MT_CHILD_NEAR 0 // slots of MtNode.child
#define MT_CHILD_FAR 1
#define MT_CHILD_OVERLAP 2

// MtNode.b.w (the partitioning distance) before its node is linked: the bits of -1.0, which no
// distance has (every delta is uDelta0 / 2^k > 0). insert.comp writes the real value once, after
// the CAS that links the node, so a concurrent reader sees either this or the final value (see
// insert.comp), and compares the raw word, before any float conversion. Not a NaN's bits: what
// uintBitsToFloat gives for a NaN encoding is undefined, and a store may change a NaN's payload;
// -1.0 is a normal number, stored and converted exactly everywhere.
#define MT_DELTA_PENDING 0xBF800000u

// Cluster flags (MtCluster.flags).
#define MT_FLAG_CAPSULE 1u

// Node flags (MtNode.flags), written by prepare.comp.
#define MT_NODE_CULLED 1u // back-facing by its normal cone: not inserted

// Per-frame counters, one 32-bit word each (128 bytes).
#define MT_COUNTER_WORDS 32
#define MT_C_ROOT 0                // root pointer: node index + 1, 0 = empty tree
#define MT_C_INSERTED 1            // clusters linked into the tree
#define MT_C_CULLED 2              // clusters dropped by the normal-cone test
#define MT_C_BUILD_ERRORS 3        // corrupt child index or runaway descent (must stay 0)
#define MT_C_INSERT_DEPTH_MAX 4    // most nodes crossed by one insertion
#define MT_C_TRAVERSED 5           // pixels that ran the query (covered, facing the light)
#define MT_C_VISITED_LO 6          // nodes visited by all queries, low 32 bits ...
#define MT_C_VISITED_HI 7          // ... and high 32 bits
#define MT_C_VISITED_MAX 8         // most nodes visited by one pixel
#define MT_C_TRIANGLES_LO 9        // ray-triangle tests by all queries, low / high 32 bits
#define MT_C_TRIANGLES_HI 10
#define MT_C_TRIANGLES_MAX 11      // most ray-triangle tests by one pixel
#define MT_C_FRUITLESS_LO 12       // clusters whose triangles were all tested without a hit
#define MT_C_FRUITLESS_HI 13
#define MT_C_FRUITLESS_MAX 14
#define MT_C_CONE_HITS_LO 15       // points found inside a cluster's cone / capsule-cone
#define MT_C_CONE_HITS_HI 16
#define MT_C_SLAB_REJECTS_LO 17    // ... of which the slabs rejected the shadow ray
#define MT_C_SLAB_REJECTS_HI 18
#define MT_C_STACK_OVERFLOW 19     // pixels whose traversal stack overflowed (written shadowed)
#define MT_C_DEPTH_SKIPS_LO 20     // subtrees skipped by the light-distance test
#define MT_C_DEPTH_SKIPS_HI 21
#define MT_C_TILE_NODES_LO 22      // nodes the tile query's caps visited (query: tile), low / high
#define MT_C_TILE_NODES_HI 23
#define MT_C_TILE_FALLBACKS 24     // tiles whose candidate list or stack was full: per-pixel query
#define MT_C_LOOP_CAPPED 25        // pixels whose query loop was ended from outside (written shadowed)
// Words 26..31 are reserved (the block size stays fixed).
