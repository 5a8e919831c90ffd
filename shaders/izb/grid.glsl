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
ivec2 izbCellOf(vec2 uv) { // uv in [-1, 1]
    return clamp(ivec2(floor((uv * 0.5 + 0.5) * float(uGrid))), ivec2(0), ivec2(uGrid - 1));
}
// Directional: (u, v) in [-1, 1] over the covered square.
vec2 izbOrtho(vec3 p) { return vec2(dot(p - uGridCenter, uGridU), dot(p - uGridCenter, uGridV)) / uGridRadius; }
uint izbCellIndex(int face, ivec2 c) { return (uint(face) * uint(uGrid) + uint(c.y)) * uint(uGrid) + uint(c.x); }
