// The point whose shadow the stencil count decides, for a pixel's G-buffer point p with its
// camera-facing normal n: on p's view ray (the only points a depth test can compare with), at the
// depth of the reference's ray origin x = p + n * offset, so offset * |n . v| nearer the eye than p.
// The depth pass writes its depth; the volume pass measures the faces' planes against it, p and x.
uniform vec3 uEye;
vec3 svTestPoint(vec3 p, vec3 n, float offset) {
    vec3 v = normalize(p - uEye);
    return p + v * (dot(n, v) * offset);
}
