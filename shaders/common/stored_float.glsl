// What a GPU may do to a float a kernel stores and reads back (GLSL 4.50 section 4.7.1): flush a
// denormal to 0, and give back some NaN for a NaN encoding (what uintBitsToFloat makes of one is
// undefined). Software GL keeps every bit, so the fault SHADOWLAB_FAULT_FLOAT_STORAGE (tests only)
// makes it happen at each site where a kernel stores a float: data that must survive bit for bit
// (indices, flags, sentinels) travels as integers instead (docs/architecture.md, rules 4 and 5).
#ifndef SHADOWLAB_FAULT_FLOAT_STORAGE
#define SHADOWLAB_FAULT_FLOAT_STORAGE 0
#endif

float storedFloat(float f) {
#if SHADOWLAB_FAULT_FLOAT_STORAGE
    uint u = floatBitsToUint(f);
    if ((u & 0x7F800000u) == 0x7F800000u && (u & 0x007FFFFFu) != 0u) return uintBitsToFloat(0x7FC00000u);
    if ((u & 0x7F800000u) == 0u) return 0.0;
#endif
    return f;
}
vec3 storedFloat(vec3 v) { return vec3(storedFloat(v.x), storedFloat(v.y), storedFloat(v.z)); }
