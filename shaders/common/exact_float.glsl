// Exact-decision arithmetic, the twin of framework/core/ExactFloat.h: GLSL rounds +, - and *
// correctly (4.50 section 4.7.1) but may flush subnormals and may fuse a*b+c; `precise` forbids the
// fusing, and every operand and result below the smallest normal float is flushed here, on both
// sides alike, so that a GPU that flushes on its own and one that does not decide every tie the same.
float exactFlush(float x) { return abs(x) < 1.17549435e-38 ? 0.0 : x; }
vec3 exactFlush(vec3 v) { return vec3(exactFlush(v.x), exactFlush(v.y), exactFlush(v.z)); }
float exactSub(float a, float b) { precise float r = exactFlush(a) - exactFlush(b); return exactFlush(r); }
float exactAdd(float a, float b) { precise float r = exactFlush(a) + exactFlush(b); return exactFlush(r); }
float exactMul(float a, float b) { precise float r = exactFlush(a) * exactFlush(b); return exactFlush(r); }
vec3 exactSub(vec3 a, vec3 b) { return vec3(exactSub(a.x, b.x), exactSub(a.y, b.y), exactSub(a.z, b.z)); }
float exactDot(vec3 a, vec3 b) { return exactAdd(exactAdd(exactMul(a.x, b.x), exactMul(a.y, b.y)), exactMul(a.z, b.z)); }
