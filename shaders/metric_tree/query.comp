#version 450
// metric_tree query (paper section 5.4), one invocation per pixel: the G-buffer point walks the
// ternary metric tree with an explicit stack. Inside a pivot's cone or capsule-cone, the shadow ray
// is tested against the cluster's slabs and then its triangles (exact; early exit on a hit). Steps
// 1-3 of the paper: skip a subtree whose geometry is all farther from the light than the point
// (MT_DEPTH_SKIP), slabs (MT_SLABS), visit an overlap child only inside its interval
// (MT_OVERLAP_INTERVAL). Writes 1 lit, 0 shadowed.
#define MT_NODE_ACCESS readonly restrict // the tree is complete: built by the previous dispatches
#include "common/light.glsl"
#include "common/counters.glsl"
#include "common/shadow_ray.glsl"
#include "metric_tree/tree.glsl"
#include "common/pixel_order.glsl"
#include "common/loop_fault.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

// The tree, clusters and cluster-ordered triangles as buffer textures (views of the SSBOs the build
// writes): texel fetches are gathered per SIMD group, storage loads per lane on llvmpipe.
layout(binding = MT_CLUSTER_UNIT) uniform usamplerBuffer uClusterTexels; // 4 texels per cluster
layout(binding = MT_GEOMETRY_UNIT_0) uniform samplerBuffer uGeometry0;   // 3 texels per triangle
layout(binding = MT_GEOMETRY_UNIT_0 + 1) uniform samplerBuffer uGeometry1;
layout(binding = MT_GEOMETRY_UNIT_0 + 2) uniform samplerBuffer uGeometry2;
layout(binding = MT_GEOMETRY_UNIT_0 + 3) uniform samplerBuffer uGeometry3;
layout(binding = MT_GEOMETRY_UNIT_0 + 4) uniform samplerBuffer uGeometry4;
layout(binding = MT_GEOMETRY_UNIT_0 + 5) uniform samplerBuffer uGeometry5;
#if MT_GEOMETRY_CHUNKS != 6
#error "query.comp declares six geometry blocks"
#endif

MtCluster mtCluster(uint i) {
    int t = int(4u * i);
    uvec4 t0 = texelFetch(uClusterTexels, t), t1 = texelFetch(uClusterTexels, t + 1);
    uvec4 t2 = texelFetch(uClusterTexels, t + 2), t3 = texelFetch(uClusterTexels, t + 3);
    return MtCluster(uintBitsToFloat(t0), uintBitsToFloat(t1), uintBitsToFloat(t2), uintBitsToFloat(t3.x), t3.y, t3.z, t3.w);
}

layout(binding = 0) uniform sampler2D uPosition; // world xyz, w = 1 on geometry
layout(binding = 1) uniform sampler2D uNormal;   // camera-facing normal
layout(r32f, binding = 0) writeonly uniform image2D uVisibility;
#if SHADOWLAB_STATISTICS
layout(r32f, binding = 1) writeonly uniform image2D uNodesVisited; // debug heat maps
layout(r32f, binding = 2) writeonly uniform image2D uTriangleTests;
layout(r32f, binding = 3) writeonly uniform image2D uFruitless;    // paper Figure 9
layout(r32f, binding = 4) writeonly uniform image2D uOverflow;     // 1 where the stack overflowed
#endif
uniform uint uClusterCount; // nodes of the tree: no walk visits more (each node at most once)
uniform float uRayOffset;     // world units: the reference's shadow-ray origin offset along the normal
uniform float uSlabTolerance; // world units added on both sides of a cluster's slabs

// Triangle t of the cluster-ordered geometry. Vertices come out as vec3s: an array return value
// would live in scratch memory on llvmpipe.
#define MT_LOAD(tex, base, v0, v1, v2) { v0 = texelFetch(tex, int(base)).xyz; \
    v1 = texelFetch(tex, int(base) + 1).xyz; v2 = texelFetch(tex, int(base) + 2).xyz; }
// MT_GEOMETRY_USED (1..MT_GEOMETRY_CHUNKS, set from the scene at compile time) is how many blocks
// hold triangles: one below 3.5 M triangles, where the load is a single unconditional read. A
// CPU SIMD back end (llvmpipe) runs every arm of a divergent if/else chain, so only the blocks
// that exist get an arm.
#ifndef MT_GEOMETRY_USED
#define MT_GEOMETRY_USED MT_GEOMETRY_CHUNKS
#endif
void mtTriangle(uint t, out vec3 v0, out vec3 v1, out vec3 v2) {
#if MT_GEOMETRY_USED == 1
    MT_LOAD(uGeometry0, 3u * t, v0, v1, v2)
#else
    uint chunk = t / uint(MT_TRIANGLES_PER_CHUNK);
    uint base = 3u * (t - chunk * uint(MT_TRIANGLES_PER_CHUNK));
    if (chunk == 0u) MT_LOAD(uGeometry0, base, v0, v1, v2)
#if MT_GEOMETRY_USED > 2
    else if (chunk == 1u) MT_LOAD(uGeometry1, base, v0, v1, v2)
#endif
#if MT_GEOMETRY_USED > 3
    else if (chunk == 2u) MT_LOAD(uGeometry2, base, v0, v1, v2)
#endif
#if MT_GEOMETRY_USED > 4
    else if (chunk == 3u) MT_LOAD(uGeometry3, base, v0, v1, v2)
#endif
#if MT_GEOMETRY_USED > 5
    else if (chunk == 4u) MT_LOAD(uGeometry4, base, v0, v1, v2)
#endif
#if MT_GEOMETRY_USED == 2
    else MT_LOAD(uGeometry1, base, v0, v1, v2)
#elif MT_GEOMETRY_USED == 3
    else MT_LOAD(uGeometry2, base, v0, v1, v2)
#elif MT_GEOMETRY_USED == 4
    else MT_LOAD(uGeometry3, base, v0, v1, v2)
#elif MT_GEOMETRY_USED == 5
    else MT_LOAD(uGeometry4, base, v0, v1, v2)
#else
    else MT_LOAD(uGeometry5, base, v0, v1, v2)
#endif
#endif
}

// Whether the shadow ray (q + t dir, t in (0, tMax)) crosses the slab between the cluster's two
// planes (paper step 2); always with slabs off.
bool mtCrossesSlabs(MtCluster c, vec3 q, vec3 dir, float tMax) {
#if MT_SLABS
    float s0 = dot(c.axis.xyz, q), ds = dot(c.axis.xyz, dir);
    float lo = c.axis.w - uSlabTolerance, hi = c.slabMax + uSlabTolerance;
    float sNear = ds >= 0.0 ? s0 : (tMax == kMtInf ? -kMtInf : s0 + ds);
    float sFar = ds >= 0.0 ? (tMax == kMtInf ? (ds > 0.0 ? kMtInf : s0) : s0 + ds) : s0;
    return sFar >= lo && sNear <= hi;
#else
    return true;
#endif
}

struct Result {
    float visibility;
    uint visited, triangles, fruitless, coneHits, slabRejects, depthSkips;
    bool overflow;
    bool capped; // a loop ended before its work did (a driver's loop limit, or the walk's cap)
};

Result query(vec3 q) {
    Result r = Result(1.0, 0u, 0u, 0u, 0u, 0u, 0u, false, false);
    // The shadow ray: to the light (t in (0, 1)), or towards it forever for a directional light.
    vec3 dir = lightIsDirectional() ? -uLightDirection : uLightPosition - q;
    float tMax = lightIsDirectional() ? kMtInf : 1.0;
    // Triangles are decided by the reference's own ray and test: the same decision, pixel for pixel.
    WatertightRay ray = shadowRayToLight(q, uRayOffset);
    vec3 p = mtToLightSpace(q);
#if MT_DEPTH_SKIP
    float depth = mtLightDepth(q);
#endif
    uint stack[MT_STACK_SIZE];
    int sp = 0;
    // Pushing onto a full stack would drop a subtree that may hold the occluder: stop and report.
#define MT_PUSH(x) { if (sp == MT_STACK_SIZE) { r.overflow = true; done = true; break; } stack[sp++] = (x); }
    uint next = mtCounters[MT_C_ROOT];
    // Two phases, each a loop of its own: walk the tree until this pixel has a cluster to test (or
    // nothing left), then test that cluster's triangles. In a SIMD group (8 to 64 pixels in
    // lockstep) a pixel that found its cluster waits for the others to find theirs, and the group
    // tests all its pixels' clusters in one triangle loop instead of one loop per pixel's cluster.
    // `finished` is set only where the work really ends (the walk done, a hit, an overflow): a loop
    // that a driver ends from outside leaves it false, and the pixel is written shadowed (rule 13).
    bool done = false, finished = false;
    uint triangle = 0u, trianglesEnd = 0u; // the cluster to test: [triangle, trianglesEnd)
    while (!done) {
        FAULT_LOOP_STEP()
        while (true) {
            FAULT_LOOP_STEP()
            if (next == MT_NO_CHILD) {
                if (sp == 0) { done = true; finished = true; break; }
                next = stack[--sp];
            }
            // A tree's walk visits each node at most once: more is a corrupt tree, stopped here.
            if (r.visited >= uClusterCount) { done = true; break; }
            uint node = next - 1u;
            ++r.visited;
            MtNode n = mtNode(node);
#if MT_DEPTH_SKIP
            // Mora et al. 2016: nothing in this subtree is nearer the light than q, so nothing in it
            // can lie between q and the light.
            if (depth <= uintBitsToFloat(n.minDist)) { ++r.depthSkips; next = MT_NO_CHILD; continue; }
#endif
            float dq = mtPointDist(p, n.a.xyz, n.b.xyz);
            if (dq <= n.a.w + uLsEps) { // inside the cone or capsule-cone: the cluster may occlude q
                ++r.coneHits;
                MtCluster c = mtCluster(node);
                bool test = mtCrossesSlabs(c, q, dir, tMax);
                if (!test) ++r.slabRejects;
                if (test) { triangle = c.first; trianglesEnd = c.first + c.count; }
            }
            uint follow = dq <= n.b.w ? n.child[MT_CHILD_NEAR] : n.child[MT_CHILD_FAR];
            uint overlap = n.child[MT_CHILD_OVERLAP];
#if MT_OVERLAP_INTERVAL
            if (overlap != MT_NO_CHILD && (dq < uintBitsToFloat(n.overlapMin) || dq > uintBitsToFloat(n.overlapMax)))
                overlap = MT_NO_CHILD;
#endif
            if (overlap != MT_NO_CHILD) {
                if (follow == MT_NO_CHILD) follow = overlap;
                else MT_PUSH(overlap);
            }
            next = follow;
            if (triangle < trianglesEnd) break;
        }
        if (r.overflow) { finished = true; break; }
        bool hit = false;
        for (; triangle < trianglesEnd && !hit; ++triangle) {
            FAULT_LOOP_STEP()
            ++r.triangles;
            vec3 v0, v1, v2;
            mtTriangle(triangle, v0, v1, v2);
            hit = watertightHit(ray, v0, v1, v2);
        }
        if (hit) { r.visibility = 0.0; finished = true; break; }
        if (triangle < trianglesEnd) break; // the triangle loop was ended from outside
        if (trianglesEnd != 0u) ++r.fruitless;
        triangle = trianglesEnd = 0u;
    }
#undef MT_PUSH
    // An overflowed or cut pixel is never reported lit: it is written shadowed and counted.
    r.capped = !finished;
    if (r.overflow || r.capped) r.visibility = 0.0;
    return r;
}

#if SHADOWLAB_STATISTICS
shared uint sTraversed, sOverflow, sVisitedMax, sTrianglesMax, sFruitlessMax;
shared uint sVisited, sTriangles, sFruitless, sConeHits, sSlabRejects, sDepthSkips;

void addWide(uint lo, uint value) {
    if (value == 0u) return;
    COUNTER_ADD_WIDE(mtCounters, lo, value)
}
#endif

#if MT_QUERY_TILE
// A cluster the tile's walk reached, for one pixel: the per-pixel query's cone test, then slabs
// and triangles; true on a hit.
bool testCluster(uint node, vec3 q, vec3 p, vec3 dir, float tMax, WatertightRay ray, inout Result r) {
    ++r.visited;
    int t = int(4u * node);
    vec4 a = uintBitsToFloat(texelFetch(uNodeTexels, t)), b = uintBitsToFloat(texelFetch(uNodeTexels, t + 1));
    if (mtPointDist(p, a.xyz, b.xyz) > a.w + uLsEps) return false; // outside this pixel's cone
    ++r.coneHits;
    MtCluster c = mtCluster(node);
    if (!mtCrossesSlabs(c, q, dir, tMax)) { ++r.slabRejects; return false; }
    bool hit = false;
    uint tri = c.first;
    for (; tri < c.first + c.count && !hit; ++tri) {
        FAULT_LOOP_STEP()
        ++r.triangles;
        vec3 v0, v1, v2;
        mtTriangle(tri, v0, v1, v2);
        hit = watertightHit(ray, v0, v1, v2);
    }
    if (!hit && tri < c.first + c.count) r.capped = true; // ended from outside
    if (!hit) ++r.fruitless;
    return hit;
}
#endif

#if MT_QUERY_TILE
// The tile query: a tile of MT_TILE_PIXELS pixels (consecutive invocations: 4 × 2, 8 × 2, 8 × 4 or
// 8 × 8, see pixel_order.glsl) walks the tree once, as a cap (light
// space: the centre c of their points and the radius rho enclosing them all), and each pixel then
// tests only the clusters the cap reached. A pixel's distance to any element lies within rho of
// c's (triangle inequality), so the cap visits every node any of its pixels would visit, and each
// pixel applies the very cone test of the per-pixel query to those clusters: the same clusters
// reach the triangle tests, hence the same image. Every lane of a SIMD group runs the same list,
// so nothing diverges but the triangle tests. A tile whose list or stack would overflow falls back
// to the per-pixel query (counted in tile_fallbacks): exact either way.
shared vec3 sPoint[64]; // light-space point of each invocation's query
shared float sDepth[64];
shared bool sValid[64];
#define MT_TILES (64 / MT_TILE_PIXELS)
shared uint sCandidates[MT_TILES][MT_TILE_CANDIDATES];
shared uint sCandidateCount[MT_TILES];
shared bool sTileFallback[MT_TILES];

// Invocation `tile`: the clusters whose cones the cap of the tile's pixels reaches, into its list.
void collectCandidates(uint tile) {
    sCandidateCount[tile] = 0u;
    sTileFallback[tile] = false;
    vec3 c = vec3(0.0);
    float maxDepth = 0.0;
    uint valid = 0u, first = tile * uint(MT_TILE_PIXELS), end = first + uint(MT_TILE_PIXELS);
    uint i = first;
    for (; i < end; ++i) {
        FAULT_LOOP_STEP()
        if (sValid[i]) { c += sPoint[i]; maxDepth = max(maxDepth, sDepth[i]); ++valid; }
    }
    // A loop ended from outside leaves the cap too small: the tile's pixels query alone instead.
    if (i < end) { sTileFallback[tile] = true; atomicAdd(mtCounters[MT_C_TILE_FALLBACKS], 1u); return; }
    if (valid == 0u) return;
    c = lightIsDirectional() ? c / float(valid) : normalize(c);
    float rho = 0.0;
    for (i = first; i < end; ++i) {
        FAULT_LOOP_STEP()
        if (sValid[i]) rho = max(rho, lightIsDirectional() ? length(sPoint[i] - c) : mtAngle(c, sPoint[i]));
    }
    if (i < end) { sTileFallback[tile] = true; atomicAdd(mtCounters[MT_C_TILE_FALLBACKS], 1u); return; }
    rho += uLsEps; // far above the rounding of rho, of c's distances and of each pixel's
    uint stack[MT_STACK_SIZE];
    int sp = 0;
    uint next = mtCounters[MT_C_ROOT], count = 0u, visited = 0u;
#define MT_TILE_PUSH(x) { if (sp == MT_STACK_SIZE) { sTileFallback[tile] = true; break; } stack[sp++] = (x); }
    bool finished = false; // set only where the walk really ends (see query())
    while (true) {
        FAULT_LOOP_STEP()
        if (next == MT_NO_CHILD) {
            if (sp == 0) { finished = true; break; }
            next = stack[--sp];
        }
        if (visited >= uClusterCount) break; // more than the tree's nodes: corrupt, stopped
        uint node = next - 1u;
        ++visited;
        MtNode n = mtNode(node);
        next = MT_NO_CHILD;
#if MT_DEPTH_SKIP
        if (maxDepth <= uintBitsToFloat(n.minDist)) continue; // every point of the tile skips it
#endif
        float dc = mtPointDist(c, n.a.xyz, n.b.xyz), lo = dc - rho, hi = dc + rho;
        if (lo <= n.a.w + uLsEps) {
            if (count == uint(MT_TILE_CANDIDATES)) { sTileFallback[tile] = true; break; }
            sCandidates[tile][count++] = node;
        }
        // A pixel goes near when its distance is <= delta, far otherwise: the tile, to each side
        // some pixel may take.
        uint nearChild = lo <= n.b.w ? n.child[MT_CHILD_NEAR] : MT_NO_CHILD;
        uint farChild = hi > n.b.w ? n.child[MT_CHILD_FAR] : MT_NO_CHILD;
        uint overlap = n.child[MT_CHILD_OVERLAP];
#if MT_OVERLAP_INTERVAL
        if (hi < uintBitsToFloat(n.overlapMin) || lo > uintBitsToFloat(n.overlapMax)) overlap = MT_NO_CHILD;
#endif
        if (overlap != MT_NO_CHILD) MT_TILE_PUSH(overlap);
        if (farChild != MT_NO_CHILD) {
            if (nearChild == MT_NO_CHILD) nearChild = farChild;
            else MT_TILE_PUSH(farChild);
        }
        next = nearChild;
    }
#undef MT_TILE_PUSH
    if (!finished) sTileFallback[tile] = true; // ended from outside, or full: the per-pixel query
    sCandidateCount[tile] = count;
#if SHADOWLAB_STATISTICS
    addWide(MT_C_TILE_NODES_LO, visited);
#endif
    if (sTileFallback[tile]) atomicAdd(mtCounters[MT_C_TILE_FALLBACKS], 1u);
}

// Every invocation of the group calls it (it holds barriers); `needs`: this one has a query at q.
Result tileQuery(bool needs, vec3 q) {
    uint i = gl_LocalInvocationIndex;
    sValid[i] = needs;
    sPoint[i] = needs ? mtToLightSpace(q) : vec3(0.0);
    sDepth[i] = needs ? mtLightDepth(q) : 0.0;
    barrier();
    if (i < uint(MT_TILES)) collectCandidates(i);
    barrier();
    Result r = Result(1.0, 0u, 0u, 0u, 0u, 0u, 0u, false, false);
    if (!needs) return r;
    uint tile = i / uint(MT_TILE_PIXELS);
    if (sTileFallback[tile]) return query(q);
    vec3 dir = lightIsDirectional() ? -uLightDirection : uLightPosition - q;
    float tMax = lightIsDirectional() ? kMtInf : 1.0;
    WatertightRay ray = shadowRayToLight(q, uRayOffset);
    vec3 p = sPoint[i];
    uint count = sCandidateCount[tile];
    bool hit = false;
    uint k = 0u;
    for (; k < count && !hit; ++k) {
        FAULT_LOOP_STEP()
        hit = testCluster(sCandidates[tile][k], q, p, dir, tMax, ray, r);
    }
    if (!hit && k < count) r.capped = true; // ended from outside
    if (hit) r.capped = false;              // a hit is a hit, whatever was left
    if (hit || r.capped) r.visibility = 0.0;
    return r;
}
#endif

void main() {
#if SHADOWLAB_STATISTICS
    if (gl_LocalInvocationIndex == 0u) {
        sTraversed = sOverflow = sVisitedMax = sTrianglesMax = sFruitlessMax = 0u;
        sVisited = sTriangles = sFruitless = sConeHits = sSlabRejects = sDepthSkips = 0u;
    }
    barrier();
#endif
    ivec2 px = pixelOfInvocation();
    bool inside = all(lessThan(px, imageSize(uVisibility)));
    float visibility = 1.0; // background: nothing to shadow (the reference's convention)
    bool needs = false;     // covered and facing the light: a query at q
    vec3 q = vec3(0.0);
    if (inside) {
        vec4 pos = texelFetch(uPosition, px, 0);
        if (pos.w >= 0.5) {
            vec3 x = pos.xyz, nrm = texelFetch(uNormal, px, 0).xyz;
            visibility = 0.0; // facing away from the light
            // The reference's ray origin: the same offset along the same (unnormalised) normal.
            // Facing the light and inside a spot's cone, decided as the reference decides it (Light::reaches).
            if (lightReaches(x, nrm)) { needs = true; q = watertightOrigin(x, nrm, uRayOffset); }
        }
    }
    Result r = Result(1.0, 0u, 0u, 0u, 0u, 0u, 0u, false, false);
#if MT_QUERY_TILE
    r = tileQuery(needs, q);
#else
    if (needs) r = query(q);
#endif
    if (needs) {
        visibility = r.visibility;
        // Pixels a cut loop wrote shadowed: counted in both modes (never a silent wrong image).
        if (r.capped) atomicAdd(mtCounters[MT_C_LOOP_CAPPED], 1u);
#if SHADOWLAB_STATISTICS
        atomicAdd(sTraversed, 1u);
        atomicAdd(sVisited, r.visited);
        atomicAdd(sTriangles, r.triangles);
        atomicAdd(sFruitless, r.fruitless);
        atomicAdd(sConeHits, r.coneHits);
        atomicAdd(sSlabRejects, r.slabRejects);
        atomicAdd(sDepthSkips, r.depthSkips);
        atomicMax(sVisitedMax, r.visited);
        atomicMax(sTrianglesMax, r.triangles);
        atomicMax(sFruitlessMax, r.fruitless);
        if (r.overflow) atomicAdd(sOverflow, 1u);
#else
        // The timed pass still counts every overflowed pixel (never a silent wrong image).
        if (r.overflow) atomicAdd(mtCounters[MT_C_STACK_OVERFLOW], 1u);
#endif
    }
    if (inside) {
        imageStore(uVisibility, px, vec4(visibility));
#if SHADOWLAB_STATISTICS
        imageStore(uNodesVisited, px, vec4(float(r.visited)));
        imageStore(uTriangleTests, px, vec4(float(r.triangles)));
        imageStore(uFruitless, px, vec4(float(r.fruitless)));
        imageStore(uOverflow, px, vec4(r.overflow || r.capped ? 1.0 : 0.0));
#endif
    }
#if SHADOWLAB_STATISTICS
    barrier();
    if (gl_LocalInvocationIndex == 0u && sTraversed != 0u) {
        atomicAdd(mtCounters[MT_C_TRAVERSED], sTraversed);
        addWide(MT_C_VISITED_LO, sVisited);
        addWide(MT_C_TRIANGLES_LO, sTriangles);
        addWide(MT_C_FRUITLESS_LO, sFruitless);
        addWide(MT_C_CONE_HITS_LO, sConeHits);
        addWide(MT_C_SLAB_REJECTS_LO, sSlabRejects);
        addWide(MT_C_DEPTH_SKIPS_LO, sDepthSkips);
        atomicMax(mtCounters[MT_C_VISITED_MAX], sVisitedMax);
        atomicMax(mtCounters[MT_C_TRIANGLES_MAX], sTrianglesMax);
        atomicMax(mtCounters[MT_C_FRUITLESS_MAX], sFruitlessMax);
        if (sOverflow != 0u) atomicAdd(mtCounters[MT_C_STACK_OVERFLOW], sOverflow);
    }
#endif
}
