#pragma once
// Procedural scene generators. Triangle counts are requests: each generator picks tessellation
// parameters whose count is as close as it can get (see each function), and returns the real count.
#include "framework/scene/Scene.h"

#include <cstddef>
#include <cstdint>

namespace shadowlab {

// How each generator tessellates a request. The generator and the scene's prediction
// (predictScene) both take their counts from these, so the memory plan counts exactly the
// triangles a generator makes, minimums and rounding included. (Triangles that come out
// degenerate, from a zero or overflowing size, are dropped when made: the count is then a bound.)

/// 2·subdivisions² triangles.
size_t planeTriangles(int subdivisions);

/// `stacks` latitude bands and `slices` longitude segments: 2·slices·(stacks − 1) triangles.
struct SphereTessellation {
    int stacks = 3, slices = 4;
    size_t triangles() const { return 2 * size_t(slices) * size_t(stacks - 1); }
};
SphereTessellation sphereTessellation(int triangles);

/// `major` segments around the axis and `minor` around the tube: 2·major·minor triangles.
struct TorusTessellation {
    int major = 3, minor = 3;
    size_t triangles() const { return 2 * size_t(major) * size_t(minor); }
};
TorusTessellation torusTessellation(float majorRadius, float minorRadius, int triangles);

/// `slices` around, `stacks` bands up the side and a fan on each cap: 2·slices·(stacks + 1) triangles.
struct CylinderTessellation {
    int slices = 3, stacks = 1;
    size_t triangles() const { return 2 * size_t(slices) * size_t(stacks + 1); }
};
CylinderTessellation cylinderTessellation(float radius, float height, int triangles);

/// A fence's parts: `posts` posts and `rails` rails (none for a single post: nothing to join), each
/// a cylinder tessellated for its own length.
struct FenceLayout {
    int posts = 1, rails = 0;
    float firstX = 0.0f, length = 0.0f; ///< the first post's x and the rails' length
    CylinderTessellation post, rail;
    size_t triangles() const { return size_t(posts) * post.triangles() + size_t(rails) * rail.triangles(); }
};
FenceLayout fenceLayout(int posts, float spacing, float height, float radius, int rails, int trianglesPerCylinder);

/// A soup makes exactly its request (none for a negative one).
size_t soupTriangles(int triangles);

/// A grid's copies: count.x · count.y · count.z (each at least 1).
size_t gridCopies(glm::ivec3 count);

/// A rectangle in the XZ plane at y = 0 centred on the origin, facing +Y; 2·subdivisions² triangles.
Scene makePlane(glm::vec2 size, int subdivisions, const Material& m);
/// A UV sphere of `radius` at the origin with about `triangles` triangles.
Scene makeSphere(float radius, int triangles, const Material& m);
/// A torus around the Y axis with about `triangles` triangles (a ring torus: minorRadius < majorRadius).
Scene makeTorus(float majorRadius, float minorRadius, int triangles, const Material& m);
/// A closed cylinder along Y from y = 0 to `height` with about `triangles` triangles (caps included).
Scene makeCylinder(float radius, float height, int triangles, const Material& m);
/// A fence: `posts` vertical thin cylinders along X spaced by `spacing`, joined by `rails` horizontal ones.
Scene makeFence(int posts, float spacing, float height, float radius, int rails, int trianglesPerCylinder, const Material& m);
/// `triangles` random triangles of edge length about `triangleSize` inside a box of `extent` centred at the origin.
Scene makeTriangleSoup(int triangles, glm::vec3 extent, float triangleSize, uint32_t seed, const Material& m);
/// The triangles `triangles` (indices into `vertices`, counter-clockwise seen from the front), as
/// given; a degenerate one (no unit normal) is left out, so callers refuse those first.
Scene makeMesh(const std::vector<glm::vec3>& vertices, const std::vector<glm::ivec3>& triangles, const Material& m);
/// Where makeGrid() places copy `copy` (x fastest, then z, then y): its offset and rotation step.
glm::mat4 gridCopyTransform(glm::ivec3 count, glm::vec3 spacing, glm::vec3 rotateStepDeg, size_t copy);
/// `count.x × count.y × count.z` copies of `object`, spaced by `spacing`, grid centred on the origin in X and Z.
Scene makeGrid(const Scene& object, glm::ivec3 count, glm::vec3 spacing, glm::vec3 rotateStepDeg = glm::vec3(0.0f));

} // namespace shadowlab
