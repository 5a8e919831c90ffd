#pragma once
// Perspective camera state for one frame.
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace shadowlab {

struct Camera {
    glm::vec3 position{0, 1, 5};
    glm::vec3 target{0, 0, 0};
    glm::vec3 up{0, 1, 0};
    float fovYDeg = 60.0f; ///< vertical field of view, degrees
    float nearPlane = 0.05f; ///< world units
    float farPlane = 100.0f; ///< world units

    bool operator==(const Camera&) const = default;

    glm::mat4 view() const {
        glm::vec3 dir = glm::normalize(target - position);
        // Looking straight up or down makes `up` degenerate; pick another reference axis.
        glm::vec3 u = std::abs(glm::dot(dir, up)) > 0.999f ? glm::vec3(0, 0, 1) : up;
        return glm::lookAt(position, target, u);
    }
    glm::mat4 projection(float aspect) const {
        return glm::perspective(glm::radians(fovYDeg), aspect, nearPlane, farPlane);
    }
};

} // namespace shadowlab
