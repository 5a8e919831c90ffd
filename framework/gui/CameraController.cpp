#include "framework/gui/CameraController.h"

#define GLFW_INCLUDE_NONE // key codes only; GL headers would clash with framework/gl/Gl.h
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>

namespace shadowlab {

bool CameraController::updateCamera(Camera& camera, float sceneRadius, float dt) {
    ImGuiIO& io = ImGui::GetIO();
    bool moved = false;
    glm::vec3 dir = camera.target - camera.position;
    float distance = std::max(glm::length(dir), 1e-4f);
    dir /= distance;

    if (!io.WantCaptureMouse && ImGui::IsMouseDown(ImGuiMouseButton_Right) &&
        (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f)) {
        // Yaw about world up, pitch clamped short of the poles so view() keeps a stable up vector.
        float yaw = std::atan2(dir.x, -dir.z) + io.MouseDelta.x * sensitivity;
        float pitch = std::asin(std::clamp(dir.y, -1.0f, 1.0f)) - io.MouseDelta.y * sensitivity;
        pitch = std::clamp(pitch, -1.55f, 1.55f);
        dir = {std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw)};
        moved = true;
    }

    glm::vec3 move(0.0f);
    if (!io.WantCaptureKeyboard && !io.KeyCtrl) {
        glm::vec3 right = glm::normalize(glm::cross(dir, glm::vec3(0, 1, 0)) + glm::vec3(1e-6f, 0, 0));
        if (ImGui::IsKeyDown(GLFW_KEY_W)) move += dir;
        if (ImGui::IsKeyDown(GLFW_KEY_S)) move -= dir;
        if (ImGui::IsKeyDown(GLFW_KEY_D)) move += right;
        if (ImGui::IsKeyDown(GLFW_KEY_A)) move -= right;
        if (ImGui::IsKeyDown(GLFW_KEY_E)) move += glm::vec3(0, 1, 0);
        if (ImGui::IsKeyDown(GLFW_KEY_Q)) move -= glm::vec3(0, 1, 0);
    }
    if (move != glm::vec3(0.0f)) {
        float boost = io.KeyShift ? 4.0f : 1.0f;
        camera.position += glm::normalize(move) * speed * boost * sceneRadius * dt;
        moved = true;
    }
    // The target stays at the same distance ahead, so the far plane and path targets stay sensible.
    if (moved) camera.target = camera.position + dir * distance;
    return moved;
}

bool CameraController::updateLight(Light& light, const Camera& camera, float viewportHeight) {
    ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureMouse || !io.KeyCtrl || !ImGui::IsMouseDown(ImGuiMouseButton_Left) || viewportHeight <= 0) return false;
    if (io.MouseDelta.x == 0.0f && io.MouseDelta.y == 0.0f) return false;
    glm::vec3 forward = glm::normalize(camera.target - camera.position);
    glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 1, 0)) + glm::vec3(1e-6f, 0, 0));
    glm::vec3 up = glm::cross(right, forward);
    // World units per pixel at the light's depth, so the light follows the cursor.
    float depth = std::max(glm::dot(light.position - camera.position, forward), camera.nearPlane);
    float perPixel = 2.0f * depth * std::tan(glm::radians(camera.fovYDeg) * 0.5f) / viewportHeight;
    glm::vec3 delta = (right * io.MouseDelta.x - up * io.MouseDelta.y) * perPixel;
    light.position += delta;
    return true;
}

} // namespace shadowlab
