#include "framework/view/Path.h"

#include <gtest/gtest.h>

namespace shadowlab {
namespace {

Path threeKeys() {
    return Path({{0.0, {0, 0, 0}, {0, 0, -1}}, {1.0, {1, 2, 0}, {1, 0, -1}}, {3.0, {4, 0, 2}, {0, 0, 0}}});
}

TEST(PathTest, PassesThroughEveryKeyframe) {
    Path p = threeKeys();
    for (const auto& k : p.keyframes()) {
        PathSample s = p.at(k.time);
        EXPECT_NEAR(glm::distance(s.position, k.position), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::distance(s.target, k.target), 0.0f, 1e-5f);
    }
}

TEST(PathTest, ClampsOutsideTheKeyframes) {
    Path p = threeKeys();
    EXPECT_EQ(p.at(-5).position, glm::vec3(0, 0, 0));
    EXPECT_EQ(p.at(10).position, glm::vec3(4, 0, 2));
}

TEST(PathTest, IsContinuousAndSmooth) {
    Path p = threeKeys();
    // Catmull-Rom is C1: the finite-difference velocity on either side of a keyframe agrees.
    const double h = 1e-3;
    glm::vec3 before = (p.at(1.0).position - p.at(1.0 - h).position) / float(h);
    glm::vec3 after = (p.at(1.0 + h).position - p.at(1.0).position) / float(h);
    // Segments differ in duration (1 s vs 2 s), so compare directions, not magnitudes.
    EXPECT_GT(glm::dot(glm::normalize(before), glm::normalize(after)), 0.99f);
}

TEST(PathTest, LinearKeyframesGiveUniformMotion) {
    // Evenly spaced collinear keys: Catmull-Rom reproduces the straight line at constant speed.
    Path p({{0, {0, 0, 0}, {}}, {1, {1, 0, 0}, {}}, {2, {2, 0, 0}, {}}, {3, {3, 0, 0}, {}}});
    for (double t = 1.0; t <= 2.0; t += 0.125) EXPECT_NEAR(p.at(t).position.x, float(t), 1e-5f);
}

TEST(PathTest, FramesSampleUniformlyFromFirstToLastKey) {
    Path p = threeKeys();
    EXPECT_DOUBLE_EQ(p.frameTime(0, 7), 0.0);
    EXPECT_DOUBLE_EQ(p.frameTime(6, 7), 3.0);
    EXPECT_DOUBLE_EQ(p.frameTime(3, 7), 1.5);
    EXPECT_DOUBLE_EQ(p.frameTime(0, 1), 0.0);
}

} // namespace
} // namespace shadowlab
