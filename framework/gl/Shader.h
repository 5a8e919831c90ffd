#pragma once
// GLSL programs built from files under the shader folder. One source per stage; variants are
// `#define`s prepended after the #version line, and `#include "common/x.glsl"` is expanded here
// (relative to the shader folder), so shared GLSL lives once in shaders/common/.
#include "framework/gl/GlObjects.h"

#include <glm/glm.hpp>
#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

using ShaderDefines = std::vector<std::pair<std::string, std::string>>;

/// The shader folder: $SHADOWLAB_SHADER_DIR if set, else the source tree's shaders/ (compiled in).
std::string shaderDir();

/// Fault injection, for tests only (nothing else calls it): defines added to every program compiled
/// from now on. A software GL keeps denormals, runs a subgroup's lanes in lockstep and has a loop
/// cap, so the faults a GPU may show (a flushed denormal, a lane missing from a vote, a NaN step
/// that never ends a loop) are forced through SHADOWLAB_FAULT_* defines read at each fault site
/// (docs/architecture.md, "GPU portability"). Empty again with setShaderFaultDefines({}).
void setShaderFaultDefines(ShaderDefines defines);
const ShaderDefines& shaderFaultDefines();
/// Whether the fault `name` is set (for the few faults that act on the host, e.g. stale buffers).
bool shaderFaultActive(const std::string& name);
/// The value of fault define `name` as a count (0 when absent or not a small decimal number).
int shaderFaultCount(const std::string& name);

/// Loads a stage source with includes expanded and defines prepended.
std::string loadShaderSource(const std::string& relPath, const ShaderDefines& defines);

class ShaderProgram {
public:
    ShaderProgram() = default;
    /// Compute program from one .comp file.
    static ShaderProgram compute(const std::string& comp, const ShaderDefines& defines = {});
    /// Vertex + fragment program.
    static ShaderProgram graphics(const std::string& vert, const std::string& frag, const ShaderDefines& defines = {});

    GLuint id() const { return program_.id(); }
    explicit operator bool() const { return bool(program_); }
    void use() const { glUseProgram(id()); }

    GLint location(const char* name) const { return glGetUniformLocation(id(), name); }
    void set(const char* name, int v) const { glProgramUniform1i(id(), location(name), v); }
    void set(const char* name, unsigned v) const { glProgramUniform1ui(id(), location(name), v); }
    void set(const char* name, float v) const { glProgramUniform1f(id(), location(name), v); }
    void set(const char* name, glm::vec2 v) const { glProgramUniform2f(id(), location(name), v.x, v.y); }
    void set(const char* name, glm::vec3 v) const { glProgramUniform3f(id(), location(name), v.x, v.y, v.z); }
    void set(const char* name, glm::vec4 v) const { glProgramUniform4f(id(), location(name), v.x, v.y, v.z, v.w); }
    void set(const char* name, glm::ivec2 v) const { glProgramUniform2i(id(), location(name), v.x, v.y); }
    void set(const char* name, const glm::mat4& m) const { glProgramUniformMatrix4fv(id(), location(name), 1, GL_FALSE, &m[0][0]); }

    /// Dispatches enough work groups of (localX × localY) to cover width × height.
    void dispatch2D(int width, int height, int localX, int localY) const;
    /// One invocation per item (triangle, cluster, ...) in groups of `localSize`, laid out as a 2D
    /// grid when the count needs more than 65535 groups (GL's minimum limit per dimension); the
    /// shader's `uniform uint uInvocationsPerRow` turns gl_GlobalInvocationID back into the item.
    void dispatchLinear(size_t count, unsigned localSize) const;

private:
    GlProgramName program_;
};

/// The subgroup (warp) width of the current context, read at run time: the lanes a ballot holds
/// in a tiny compute shader (not gl_SubGroupSizeARB, only an upper bound; see Shader.cpp); 0 when
/// ARB_shader_ballot or ARB_gpu_shader_int64 is absent. A hint for `auto` choices: a driver may
/// pick another width for another shader, so each shader that depends on it checks it again.
int querySubgroupSize();
bool hasExtension(const char* name);

} // namespace shadowlab
