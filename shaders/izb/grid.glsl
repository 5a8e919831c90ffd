// The light's grid (izb): where a point's shadow ray falls. A point light (and a spot, whose cone
// the lit test applies) has six faces, the cube around the light: a direction w from the light lands
// on the face of its largest axis, at (u, v) = (w_b, w_c) / |w_a| in [-1, 1]. A directional light has
// one face, an orthographic grid across its direction over the scene's bounding square. Every point
// of a shadow ray lands where the ray's origin does, so a triangle can block the ray only if its
// own footprint on that face covers that cell.
uniform int uGrid;          // cells per face side
uniform vec3 uGridCenter;   // directional: the scene's centre
uniform float uGridRadius;  // directional: half the side of the square covered
uniform vec3 uGridU, uGridV; // directional: unit axes across the light

// Face and axes of direction w (the largest axis first, ties to the lower axis).
int izbFace(vec3 w) {
    vec3 a = abs(w);
    int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    return 2 * axis + (w[axis] < 0.0 ? 1 : 0);
}
// (u, v, depth) of w on face f: depth along the face's axis, positive in front of it.
vec3 izbOnFace(vec3 w, int f) {
    int axis = f >> 1;
    float s = (f & 1) != 0 ? -1.0 : 1.0;
    vec3 p = axis == 0 ? w.yzx : (axis == 1 ? w.zxy : w.xyz);
    // p.z is the face's axis; p.xy the two others, in a fixed order per axis.
    return vec3(p.x, p.y, s * p.z);
}
// Where each face's grid lies, in face coordinates. grid_fit `scene`: the whole face, [-1, 1]^2.
// grid_fit `samples` (IZB_FIT_SAMPLES): the box of the face's own samples this frame (bounds.comp),
// so that the cells go where the samples are (the paper's reprojection of crowded regions, in its
// simplest form: one fitted grid per face). Points outside fall into the border cells, which reach
// to infinity outward (test.comp), so nothing is missed either way.
#if IZB_FIT_SAMPLES
layout(std430, binding = IZB_BOUNDS_BINDING) readonly buffer FaceBounds { uint faceBounds[]; }; // 4 ordered words per face
// Ordered uint <-> float: the uint order of the words is the float order of the values.
float izbUnorder(uint u) { return uintBitsToFloat((u & 0x80000000u) != 0u ? u ^ 0x80000000u : ~u); }
#endif
vec4 izbFaceBox(int face) { // (lo.x, lo.y, hi.x, hi.y)
#if IZB_FIT_SAMPLES
    uint b = 4u * uint(face);
    vec4 box = vec4(izbUnorder(faceBounds[b]), izbUnorder(faceBounds[b + 1u]), izbUnorder(faceBounds[b + 2u]),
                    izbUnorder(faceBounds[b + 3u]));
    if (!(box.x <= box.z && box.y <= box.w)) return vec4(-1.0, -1.0, 1.0, 1.0); // no sample on the face
    vec2 pad = max(vec2(1e-6), 1e-5 * max(abs(box.xy), abs(box.zw))); // a single sample still has a box
    return vec4(box.xy - pad, box.zw + pad);
#else
    return vec4(-1.0, -1.0, 1.0, 1.0);
#endif
}
ivec2 izbCellOf(int face, vec2 uv) {
    vec4 box = izbFaceBox(face);
    vec2 t = (uv - box.xy) / (box.zw - box.xy);
    return clamp(ivec2(floor(t * float(uGrid))), ivec2(0), ivec2(uGrid - 1));
}
// The cell's square in face coordinates, the border cells reaching to infinity outward.
void izbCellBox(int face, ivec2 cell, out vec2 lo, out vec2 hi) {
    vec4 box = izbFaceBox(face);
    vec2 size = (box.zw - box.xy) / float(uGrid);
    lo = box.xy + vec2(cell) * size;
    hi = lo + size;
    if (cell.x == 0) lo.x = -1e30;
    if (cell.y == 0) lo.y = -1e30;
    if (cell.x == uGrid - 1) hi.x = 1e30;
    if (cell.y == uGrid - 1) hi.y = 1e30;
}
// Directional: (u, v) in [-1, 1] over the covered square.
vec2 izbOrtho(vec3 p) { return vec2(dot(p - uGridCenter, uGridU), dot(p - uGridCenter, uGridV)) / uGridRadius; }
uint izbCellIndex(int face, ivec2 c) { return (uint(face) * uint(uGrid) + uint(c.y)) * uint(uGrid) + uint(c.x); }
