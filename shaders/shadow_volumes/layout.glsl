// Bindings, units and counter slots of shadow_volumes: #defines only, included by C++ and GLSL.
#define SV_SIDES_BINDING 3    // uint[3 n]: packed edge sides (EdgeAdjacency.h), grouped by edge
#define SV_FIRST_BINDING 4    // uint[edges + 1]: edge e's sides are [first[e], first[e + 1])
#define SV_FACING_BINDING 5   // int[n]: +1 the triangle's volume as wound, -1 flipped, 0 no volume
#define SV_RECORDS_BINDING 6  // uint[capacity]: one per silhouette quad drawn: first side << 1 | reversed
#define SV_DRAW_BINDING 7     // the quads' DrawArraysIndirectCommands: faces {6, quads, 0, 0}, then the border
                              // pass's lines {8, quads, 0, 0} and corners {2, quads, 0, 0}
#define SV_DRAW_WORDS 12
#define SV_COUNTER_BINDING 8
#define SV_CLOSE_LIST_BINDING 9    // {count, uint[pixels]}: close-call pixels, x | y << 16
#define SV_CLOSE_ARGS_BINDING 11    // the close-ray dispatch's {x, y, z} groups
// Texture units of the volume pass (its vertex shader reads buffers as buffer textures: every GL
// has those in vertex shaders, while vertex-stage storage blocks may be 0).
#define SV_FACING_UNIT 3
#define SV_RECORDS_UNIT 4
#define SV_SIDES_UNIT 5
#define SV_POSITION_UNIT 15   // the scene's positions (kScenePositionUnit)
// Units of the fragment and resolve passes: 0 position, 1 normal (bindPixelPassInputs), then these;
// image units: 0 visibility, 1 and 2 the resolve pass's debug views (instrumented), then the close calls.
#define SV_TRIANGLE_ID_UNIT 2
#define SV_STENCIL_UNIT 3
#define SV_COUNT_UNIT 4
#define SV_CLOSE_IMAGE 3      // r32ui: 1 where a volume face passed too close to the pixel's point to call
#define SV_OTHER_IMAGE 4      // r32i: analytic ZFAIL, the faces before the test point (the check)
// Counters (words).
#define SV_C_SILHOUETTES 0    // edges of nonzero multiplicity
#define SV_C_QUADS 1          // silhouette quads (the sum of |multiplicity|)
#define SV_C_RECORD_OVERFLOW 2 // quads that found the record list full (impossible by its size: checked)
#define SV_C_CLOSE_PIXELS 3   // lit pixels decided by the reference's ray test
#define SV_C_WRAPPED 4        // lit pixels whose 8-bit stencil count wrapped (the exact count decided)
#define SV_C_LIT 5            // lit pixels resolved
#define SV_C_FRAGMENTS_LO 6   // volume fragments rasterised (instrumented), 64-bit
#define SV_C_CLOSE_TESTS_LO 8 // triangle tests of the close calls, 64-bit
#define SV_C_CUT_LOOPS 10     // close-ray walks that reached their step cap or were ended from outside (written shadowed)
#define SV_C_EYE 11           // volumes holding the eye (eye_count.comp): every pixel's two counts differ by it
#define SV_C_INCONSISTENT 12  // lit pixels whose counts broke that rule (decided by the ray as close calls)
#define SV_C_STACK_OVERFLOW 13 // close-ray walks whose stack overflowed (the pixel is written shadowed)
#define SV_COUNTER_WORDS 14
#define SV_DEPTH_UNIT 5       // the G-buffer's depth (the depth pass)
// The depth pass moves the G-buffer's depth at least this many float steps nearer (depth.frag);
// the close calls allow for this many steps of depth-buffer rounding (volume.frag). The second is
// the larger: a face the depth test orders wrongly lies within it, and is a close call.
#define SV_NUDGE_ULPS 8
#define SV_DEPTH_ULPS 16
#define SV_BVH_NODE_UNIT 6    // the BVH's nodes and leaf-ordered triangles (buffer textures)
#define SV_BVH_TRI_UNIT 7
// The eye's count (eye_count.comp): SV_EYE_LANES invocations, SV_EYE_RANGE triangles a dispatch (so
// 8,192 loop iterations at most per invocation, far from llvmpipe's 65,535 and from a watchdog).
#define SV_EYE_LANES 64
#define SV_EYE_RANGE 524288
// The kinds of volume face (volume.vert to volume.frag).
#define SV_FACE_SIDE 0
#define SV_FACE_NEAR_CAP 1
#define SV_FACE_FAR_CAP 2
// How volume.frag decides a face's side of the test point.
#define SV_SIDE_PLANE 0   // where the view ray meets the face's plane
#define SV_SIDE_BORDER 1  // near the face's border: a close call if the test point is near it too
#define SV_SIDE_CLOSE 2   // not to be decided here: a close call
// The border pass finds the faces that separate a pixel's q and x within this many pixels of its
// centre (the screen length of [q, x]); the resolve pass makes a pixel where it is longer a close call.
#define SV_BORDER_REACH 0.25
