#version 450
// PSV build, pass 1 of 2: every triangle writes its shadow frustum (4 nodes, children empty) into
// the slots it owns, 4t+1 .. 4t+4. Writing all nodes before any insertion (pass 2, build.comp)
// means a thread that loses a compare-and-swap and descends into another triangle's subtree never
// reads half-written planes, without relying on memory ordering between the node writes and the
// atomic that publishes them (GLSL atomics carry no acquire/release semantics).
#include "common/light.glsl"
#define SCENE_POSITION_TEXELS 1
#include "common/scene.glsl"
#define PSV_STATUS_WRITER 1 // the one shader that decides a triangle's status (see main)
#include "psv/tree.glsl"
layout(local_size_x = 64) in;

uniform uint uInvocationsPerRow; // gl_NumWorkGroups.x * 64: 2D dispatch past 65535 groups

void main() {
    psvReadMargins();
    uint t = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (t >= uTriangleCount) return;
    vec3 v0 = sceneVertex(t, 0u), v1 = sceneVertex(t, 1u), v2 = sceneVertex(t, 2u);
    PsvFrustum f = psvFrustum(v0, v1, v2);
    uint base = PSV_NODES_PER_TRIANGLE * t + 1u;
    // The status is decided here only, and stored for build.comp: two shaders computing it would
    // not be bound to agree (GLSL 4.50 section 4.7.1 lets each fuse or round differently), and a
    // triangle build.comp took for a caster that frusta.comp culled would link four nodes nobody
    // wrote. It lives in the first node's minDepth field, which a shadow plane does not use.
    if (f.status != PSV_CASTER_OK) { // never linked into the tree: only the status is read
        psvNodes[base] = PsvNode(PSV_REJECT_ALL, 0u, 0u, 0u, uint(f.status));
        return;
    }
    for (uint i = 0u; i < 3u; ++i) psvNodes[base + i] = PsvNode(f.planes[i], 0u, 0u, 0u, uint(PSV_CASTER_OK));
#if PSV_DEPTH_SKIP
    // The capping node's depth starts at its own triangle's: the subtree it roots includes it.
    uint minDepth = floatBitsToUint(psvTriangleMinDepth(v0, v1, v2));
#else
    uint minDepth = 0u; // never read
#endif
    psvNodes[base + 3u] = PsvNode(f.planes[3], 0u, 0u, 0u, minDepth);
}
