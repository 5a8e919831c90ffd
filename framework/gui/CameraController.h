#pragma once
// Fly camera and light dragging from the mouse and keyboard (read from ImGui's IO, which the GLFW
// back end feeds): right-drag looks around, WASD moves, Q/E go down/up, Shift is faster;
// Ctrl + left-drag moves the light in the camera's image plane.
#include "framework/view/Camera.h"
#include "framework/view/Light.h"

#include <glm/glm.hpp>

namespace shadowlab {

class CameraController {
public:
    float speed = 0.25f;        ///< movement, in scene radii per second
    float sensitivity = 0.005f; ///< look, radians per pixel of mouse movement

    /// Moves `camera` from this frame's input; `sceneRadius` scales the speed, `dt` in seconds.
    /// Returns true when the user moved it (so a followed path lets go of it).
    bool updateCamera(Camera& camera, float sceneRadius, float dt);
    /// Ctrl + left-drag over the viewport (`viewportHeight` in pixels) moves the light; true when it moved.
    bool updateLight(Light& light, const Camera& camera, float viewportHeight);
};

} // namespace shadowlab
