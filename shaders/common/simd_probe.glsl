// The SIMD probe: how well a kernel's loops keep a subgroup's lanes busy, measured in instrumented
// (statistics) passes where ARB_shader_ballot is present (SHADOWLAB_SIMD_PROBE, set by the host:
// simdProbeDefine() in framework/algorithm/AlgorithmSupport.h). Include it before any code: it
// enables the extensions. A kernel defines SIMD_PROBE_SECTIONS, calls SIMD_TICK(k) once per pass
// of section k, SIMD_PROBE_ENTER() at entry before its first barrier and SIMD_PROBE_FLUSH(add) with
// one invocation after its last; `add(i, value)` adds to its 64-bit counter words i (LO, HI).
// Per section: passes (a subgroup ran it once, counted by its lowest active lane) and the lanes
// active in them; utilisation = lanes / (passes × width), width = the lanes of a ballot at entry.
// Nothing is assumed of the width or of lanes reconverging: every pass asks the ballot.
#ifndef SHADOWLAB_SIMD_PROBE
#define SHADOWLAB_SIMD_PROBE 0
#endif
#if SHADOWLAB_SIMD_PROBE
#extension GL_ARB_shader_ballot : require
#extension GL_ARB_gpu_shader_int64 : require
shared uint sSimdProbe[2 * SIMD_PROBE_SECTIONS];
shared uint sSimdWidth;
uint simdActiveLanes(uvec2 b) { return uint(bitCount(b.x) + bitCount(b.y)); }
void simdTick(int k) {
    uvec2 b = unpackUint2x32(ballotARB(true));
    uint lowest = b.x != 0u ? uint(findLSB(b.x)) : 32u + uint(findLSB(b.y));
    if (gl_SubGroupInvocationARB == lowest) {
        atomicAdd(sSimdProbe[2 * k], 1u);
        atomicAdd(sSimdProbe[2 * k + 1], simdActiveLanes(b));
    }
}
#define SIMD_TICK(k) simdTick(k)
// Before the kernel's first barrier: zero the shared sums, then (after it) every lane's ballot.
#define SIMD_PROBE_ENTER()                                                                   \
    if (gl_LocalInvocationIndex < uint(2 * SIMD_PROBE_SECTIONS)) sSimdProbe[gl_LocalInvocationIndex] = 0u; \
    if (gl_LocalInvocationIndex == 0u) sSimdWidth = 0u;                                       \
    barrier();                                                                               \
    atomicMax(sSimdWidth, simdActiveLanes(unpackUint2x32(ballotARB(true))))
// Words: section k's passes at base + 4k (LO, HI), lanes at base + 4k + 2; the width at widthWord.
#define SIMD_PROBE_FLUSH(add, counters, base, widthWord)                    \
    for (int k_ = 0; k_ < SIMD_PROBE_SECTIONS; ++k_) {                      \
        add((base) + 4 * k_, sSimdProbe[2 * k_]);                           \
        add((base) + 4 * k_ + 2, sSimdProbe[2 * k_ + 1]);                   \
    }                                                                       \
    atomicMax(counters[widthWord], sSimdWidth)
#else
#define SIMD_TICK(k)
#define SIMD_PROBE_ENTER()
#define SIMD_PROBE_FLUSH(add, counters, base, widthWord)
#endif
