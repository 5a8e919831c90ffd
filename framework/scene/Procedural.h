#pragma once
// Procedural scene generators. Triangle counts are requests: each generator picks tessellation
// parameters whose count is as close as it can get (see each function), and returns the real count.
#include "framework/scene/Scene.h"

#include <cstdint>

namespace shadowlab {

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
/// `count.x × count.y × count.z` copies of `object`, spaced by `spacing`, grid centred on the origin in X and Z.
Scene makeGrid(const Scene& object, glm::ivec3 count, glm::vec3 spacing, glm::vec3 rotateStepDeg = glm::vec3(0.0f));

} // namespace shadowlab
