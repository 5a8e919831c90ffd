#pragma once
// The Catmull-Rom segment every keyframed path uses (camera and light paths, object paths): it
// passes through p1 at u = 0 and p2 at u = 1, shaped by the neighbours p0 and p3.
#include <glm/glm.hpp>

namespace shadowlab {

inline glm::vec3 catmullRom(glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, float u) {
    const float u2 = u * u, u3 = u2 * u;
    return 0.5f * ((2.0f * p1) + (-p0 + p2) * u + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * u2 +
                   (-p0 + 3.0f * p1 - 3.0f * p2 + p3) * u3);
}

} // namespace shadowlab
