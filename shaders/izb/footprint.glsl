// A triangle's footprint on one face of the light's grid (izb): the box, in face coordinates
// [-1, 1], that holds every point where a ray from the light through the triangle lands, widened by
// a margin for rounding. With every vertex in front of the face (depth > 0), the footprint is the
// box of the projected vertices and the projected triangle itself (`exact`); with some vertex on or
// behind the face's plane the projection is unbounded, and the whole face is taken (conservative).
// A directional light projects orthographically. Returns false where nothing lands on the face.
struct Footprint {
    vec2 lo, hi;    // face coordinates
    vec2 p[3];      // the projected vertices (when exact)
    bool exact;
};
const float kIzbMargin = 1e-5; // face units: far above the projection's rounding

bool izbFootprint(vec3 a, vec3 b, vec3 c, int face, out Footprint fp) {
    vec3 v[3] = vec3[3](a, b, c);
    fp.exact = true;
    if (lightIsDirectional()) {
        for (int k = 0; k < 3; ++k) fp.p[k] = izbOrtho(v[k]);
    } else {
        bool allFront = true, anyFront = false;
        vec3 q[3];
        for (int k = 0; k < 3; ++k) {
            q[k] = izbOnFace(v[k] - uLightPosition, face);
            allFront = allFront && q[k].z > 0.0;
            anyFront = anyFront || q[k].z > 0.0;
        }
        if (!anyFront) return false;
        if (!allFront) {
            fp.exact = false;
            fp.lo = vec2(-1.0);
            fp.hi = vec2(1.0);
            return true;
        }
        for (int k = 0; k < 3; ++k) fp.p[k] = q[k].xy / q[k].z;
    }
    fp.lo = min(min(fp.p[0], fp.p[1]), fp.p[2]);
    fp.hi = max(max(fp.p[0], fp.p[1]), fp.p[2]);
    vec2 m = vec2(kIzbMargin) * (1.0 + max(abs(fp.lo), abs(fp.hi)));
    fp.lo -= m;
    fp.hi += m;
    return true; // whether it meets the face's grid is the caller's test (izbFaceBox)
}

// The cell's square (face coordinates) may hold a point of the projected triangle (conservative:
// false only when one edge has the whole square outside it by more than the margin).
bool izbCellTouches(Footprint fp, vec2 lo, vec2 hi) {
    if (any(greaterThan(lo, fp.hi)) || any(lessThan(hi, fp.lo))) return false;
    if (!fp.exact) return true;
    vec2 e0 = fp.p[1] - fp.p[0], e1 = fp.p[2] - fp.p[0];
    float area = e0.x * e1.y - e0.y * e1.x;
    if (!(abs(area) > 0.0)) return true; // edge-on from the light: its box decides
    float s = area > 0.0 ? 1.0 : -1.0;
    for (int k = 0; k < 3; ++k) {
        vec2 a = fp.p[k], d = fp.p[(k + 1) % 3] - a;
        // The square's corner farthest inside this edge.
        vec2 inward = s * vec2(-d.y, d.x);
        vec2 corner = vec2(inward.x >= 0.0 ? hi.x : lo.x, inward.y >= 0.0 ? hi.y : lo.y);
        float e = dot(inward, corner - a);
        if (e < -kIzbMargin * (1.0 + length(a) + length(d)) * length(d)) return false;
    }
    return true;
}
