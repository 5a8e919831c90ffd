#pragma once
// The Catmull-Rom segment every keyframed path uses (camera and light paths, object paths): it
// passes through p1 at u = 0 and p2 at u = 1, shaped by the neighbours p0 and p3.
#include <glm/glm.hpp>

namespace shadowlab {

/// For any glm vector type: object paths evaluate it in double, where keys near the float limit
/// (a scale of 3e38) cannot overflow in the weighted sums; the caller checks the result fits a float.
template <class V>
V catmullRom(V p0, V p1, V p2, V p3, typename V::value_type u) {
    using S = typename V::value_type;
    const S u2 = u * u, u3 = u2 * u;
    return S(0.5) * ((S(2) * p1) + (-p0 + p2) * u + (S(2) * p0 - S(5) * p1 + S(4) * p2 - p3) * u2 +
                     (-p0 + S(3) * p1 - S(3) * p2 + p3) * u3);
}

} // namespace shadowlab
