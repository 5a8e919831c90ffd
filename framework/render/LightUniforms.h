#pragma once
// Sets the uniforms of shaders/common/light.glsl from a Light.
#include "framework/gl/Shader.h"
#include "framework/view/Light.h"

#include <cmath>

namespace shadowlab {

inline void setLightUniforms(const ShaderProgram& p, const Light& light) {
    p.set("uLightType", int(light.type));
    p.set("uLightPosition", light.position);
    p.set("uLightDirection", light.direction());
    p.set("uLightCosCone", float(std::cos(glm::radians(light.coneDeg))));
    p.set("uLightCosConeSq", light.cosConeSquared());
}

} // namespace shadowlab
