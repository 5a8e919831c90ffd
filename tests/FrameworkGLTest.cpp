// GL unit tests of the shared framework pieces: tiny dispatches and renders read back and checked.
#include "framework/gl/Shader.h"
#include "framework/render/GBuffer.h"
#include "framework/render/SceneGpu.h"
#include "framework/scene/Procedural.h"
#include "tests/TestSupport.h"

namespace shadowlab {
namespace {

class FrameworkGLTest : public test::GLTest {};

TEST_F(FrameworkGLTest, SubgroupSizeIsReadAtRunTime) {
    int size = querySubgroupSize();
    // llvmpipe reports 8 lanes on this machine's AVX2; GPUs 32 or 64. Only a power of two is assumed.
    ASSERT_GT(size, 0) << "ARB_shader_ballot is expected on Mesa 22";
    EXPECT_EQ(size & (size - 1), 0);
}

TEST_F(FrameworkGLTest, IntegerBufferClearUsesRedInteger) {
    GlBuffer b(64 * sizeof(uint32_t));
    b.clearUint(0xdeadbeefu);
    for (uint32_t v : b.read<uint32_t>(64)) EXPECT_EQ(v, 0xdeadbeefu);
}

TEST_F(FrameworkGLTest, GBufferStoresPositionsAndCameraFacingNormals) {
    Scene scene = makePlane({4, 4}, 2, Material{});
    SceneGpu gpu(scene);
    GBuffer g({32, 32});
    Camera cam;
    cam.position = {0, -3, 0.01f}; // below the plane: its +Y normal must be flipped to face the camera
    cam.target = {0, 0, 0};
    g.render(gpu, cam);
    CpuGBuffer c = g.readBack();
    size_t covered = 0;
    for (size_t i = 0; i < size_t(c.width) * c.height; ++i) {
        if (!c.covered(i)) continue;
        ++covered;
        EXPECT_NEAR(c.positionAt(i).y, 0.0f, 1e-5f);
        EXPECT_NEAR(c.normalAt(i).y, -1.0f, 1e-3f);
    }
    EXPECT_GT(covered, size_t(32 * 32 / 2));
}

} // namespace
} // namespace shadowlab
