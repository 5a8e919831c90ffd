#version 450
// metric_tree under rigid motion: poses what was precomputed per moving part.
//   MT_POSE_CLUSTERS 1: each moving cluster's bounding volume, normal cone and slabs go from the
//     part's own space (rest, as clustered) to the world through the part's matrix.
//   MT_POSE_CLUSTERS 0: each moving triangle of the cluster-ordered geometry is copied from the
//     posed scene (the floats the G-buffer rasterised), so the triangle tests stay exact.
#include "metric_tree/layout.glsl"

layout(local_size_x = 64) in;

uniform uint uInvocationsPerRow;
uniform uint uFirst; // first moving cluster / cluster-ordered triangle
uniform uint uCount;

#if MT_POSE_CLUSTERS
struct Cluster { vec4 a; vec4 b; vec4 axis; float slabMax; uint first; uint count; uint flags; };
layout(std430, binding = 1) readonly buffer RestClusters { Cluster restClusters[]; };
layout(std430, binding = 2) readonly buffer ClusterPart { uint clusterPart[]; };
layout(std430, binding = MT_CLUSTER_BINDING) writeonly buffer Clusters { Cluster clusters[]; };
layout(std430, binding = 4) readonly buffer Transforms { mat4 transforms[]; };

void main() {
    uint i = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (i >= uCount) return;
    i += uFirst;
    Cluster c = restClusters[i];
    mat4 m = transforms[clusterPart[i]];
    mat3 l = mat3(m);
    vec3 scales = vec3(length(l[0]), length(l[1]), length(l[2]));
    float maxScale = max(scales.x, max(scales.y, scales.z));
    // A similarity (rotation, uniform scale, mirror) keeps cones and slabs; any other scale shears
    // normals, so the cone and the slabs are dropped (always pass) rather than risk a wrong cull.
    bool similar = maxScale - min(scales.x, min(scales.y, scales.z)) <= 1e-5 * maxScale;
    vec3 a = (m * vec4(c.a.xyz, 1.0)).xyz, b = (m * vec4(c.b.xyz, 1.0)).xyz;
    // Rounding of the transform is ~1e-7 of the coordinates; 2e-6 of them keeps every vertex inside.
    float pad = 2e-6 * (max(length(a), length(b)) + c.a.w * maxScale);
    c.a = vec4(a, c.a.w * maxScale + pad);
    c.b = vec4(b, c.b.w);
    if (similar) {
        vec3 axis = normalize(l * c.axis.xyz);
        // dot(axis', M x) = s dot(axis, x) + dot(axis', t) for M = t + s R (and for mirrors too).
        float offset = dot(axis, m[3].xyz);
        float slabPad = 2e-6 * (abs(offset) + maxScale * max(abs(c.axis.w), abs(c.slabMax)) + length(a)) + pad;
        c.axis = vec4(axis, maxScale * c.axis.w + offset - slabPad);
        c.slabMax = maxScale * c.slabMax + offset + slabPad;
    } else {
        c.b.w = -1.0;
        c.axis.w = -3.0e38;
        c.slabMax = 3.0e38;
    }
    clusters[i] = c;
}
#else
layout(std430, binding = 0) readonly buffer ScenePositions { float scenePositions[]; };
layout(std430, binding = 1) readonly buffer Order { uint order[]; };
layout(std430, binding = MT_GEOMETRY_BINDING_0) writeonly buffer G0 { float g0[]; };
layout(std430, binding = MT_GEOMETRY_BINDING_0 + 1) writeonly buffer G1 { float g1[]; };
layout(std430, binding = MT_GEOMETRY_BINDING_0 + 2) writeonly buffer G2 { float g2[]; };
layout(std430, binding = MT_GEOMETRY_BINDING_0 + 3) writeonly buffer G3 { float g3[]; };
layout(std430, binding = MT_GEOMETRY_BINDING_0 + 4) writeonly buffer G4 { float g4[]; };
layout(std430, binding = MT_GEOMETRY_BINDING_0 + 5) writeonly buffer G5 { float g5[]; };
#if MT_GEOMETRY_CHUNKS != 6
#error "pose.comp declares six geometry blocks"
#endif

void main() {
    uint i = gl_GlobalInvocationID.y * uInvocationsPerRow + gl_GlobalInvocationID.x;
    if (i >= uCount) return;
    i += uFirst;
    uint src = 9u * order[i];
    uint chunk = i / uint(MT_TRIANGLES_PER_CHUNK), dst = 9u * (i % uint(MT_TRIANGLES_PER_CHUNK));
    for (uint k = 0u; k < 9u; ++k) {
        float v = scenePositions[src + k];
        if (chunk == 0u) g0[dst + k] = v;
        else if (chunk == 1u) g1[dst + k] = v;
        else if (chunk == 2u) g2[dst + k] = v;
        else if (chunk == 3u) g3[dst + k] = v;
        else if (chunk == 4u) g4[dst + k] = v;
        else g5[dst + k] = v;
    }
}
#endif
