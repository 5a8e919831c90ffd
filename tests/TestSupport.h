#pragma once
// Shared test helpers: a GL context with a debug callback that fails the test on any GL error,
// and paths to the real test data.
#include "framework/gl/GlContext.h"
#include "framework/gl/GlObjects.h"
#include "framework/gl/Shader.h"
#include "framework/render/LightUniforms.h"

#include <gtest/gtest.h>
#include <memory>
#include <string>
#include <vector>

namespace shadowlab::test {

/// Fixture for *GLTest: makes an OSMesa GL 4.5 context (skips the test with a message where none
/// can be made) and fails the test if the GL debug output reported any error.
class GLTest : public ::testing::Test {
protected:
    void SetUp() override;
    void TearDown() override;
    std::unique_ptr<GlContext> context_;
};

/// Compiles every program made while it lives with `faults` (SHADOWLAB_FAULT_* defines, see
/// setShaderFaultDefines): the algorithm must be created inside the scope.
class ScopedShaderFaults {
public:
    explicit ScopedShaderFaults(ShaderDefines faults) { setShaderFaultDefines(std::move(faults)); }
    ~ScopedShaderFaults() { setShaderFaultDefines({}); }
    ScopedShaderFaults(const ScopedShaderFaults&) = delete;
    ScopedShaderFaults& operator=(const ScopedShaderFaults&) = delete;
};

/// Runs the test-only compute probe `shader` (shaders/tests/, 64 invocations a group) on `count`
/// items: `in` at storage binding 0, `count` values of `fill` at binding 1, the light's uniforms and
/// `countUniform` set; returns binding 1 as the probe left it.
template <class In, class Out>
std::vector<Out> runComputeProbe(const std::string& shader, const Light& light, const char* countUniform, const std::vector<In>& in,
                                 uint32_t count, Out fill) {
    GlBuffer input = GlBuffer::fromVector(in);
    GlBuffer output = GlBuffer::fromVector(std::vector<Out>(count, fill));
    ShaderProgram probe = ShaderProgram::compute(shader);
    setLightUniforms(probe, light);
    probe.set(countUniform, count);
    input.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
    output.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
    probe.use();
    glDispatchCompute((count + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    return output.read<Out>(count);
}

/// Debian's assimp-testmodels glTF folder.
inline const std::string kAssimpGltf = "/usr/share/assimp/models/glTF2";
inline const std::string kEngineGlb = kAssimpGltf + "/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

/// Runs a shell command, returns its exit code; stdout+stderr go to `output`.
int runCommand(const std::string& command, std::string& output);
/// A fresh empty temporary directory for this test, removed when the process exits unless a test
/// failed or SHADOWLAB_KEEP_TEST_DIRS is set.
std::string makeTempDir(const std::string& tag);

} // namespace shadowlab::test
