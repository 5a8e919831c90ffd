#pragma once
// Float arithmetic that a GLSL shader can repeat bit for bit: every sum, difference and product
// rounded to IEEE single once (no fused multiply-add: include this only in files compiled with
// -ffp-contract=off, see CMakeLists.txt) and every subnormal flushed to zero, operands and result,
// as a GPU may do on its own (GLSL 4.50 section 4.7.1); flushing on both sides makes that choice
// moot. The shaders' twin: shaders/common/exact_float.glsl (exactFlush, exactSub, exactAdd,
// exactMul, exactDot), used by common/light.glsl and common/watertight.glsl.
#include <cmath>
#include <limits>

#include <glm/glm.hpp>

namespace shadowlab::exact {

inline float flushed(float x) { return std::fabs(x) < std::numeric_limits<float>::min() ? 0.0f : x; }
inline glm::vec3 flushed(glm::vec3 v) { return {flushed(v.x), flushed(v.y), flushed(v.z)}; }
inline float sub(float a, float b) { return flushed(flushed(a) - flushed(b)); }
inline float add(float a, float b) { return flushed(flushed(a) + flushed(b)); }
inline float mul(float a, float b) { return flushed(flushed(a) * flushed(b)); }
inline glm::vec3 sub(glm::vec3 a, glm::vec3 b) { return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z)}; }
inline float dot(glm::vec3 a, glm::vec3 b) { return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z)); }

} // namespace shadowlab::exact
