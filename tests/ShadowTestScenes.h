#pragma once
// Scenes shared by the algorithms' GL tests. Each algorithm is checked against the reference on the
// same shots, so a scene is defined once here and a difference between the algorithms' results
// cannot come from two copies of it drifting apart.
#include "framework/scene/Scene.h"
#include "framework/view/Camera.h"
#include "framework/view/Light.h"

#include <glm/glm.hpp>

namespace shadowlab::test {

glm::mat4 translate(glm::vec3 t);
glm::mat4 rotate(float deg, glm::vec3 axis);
glm::mat4 scale(glm::vec3 s);

/// A grey, opaque, square plane of side `size` at y = 0.
Scene ground(float size = 10.0f);

/// What one test frame needs: the geometry, the view and the light.
struct Shot {
    Scene scene;
    Camera camera;
    Light light;
};

/// A camera at `from` looking at `to`, with the near and far planes every test scene fits in.
Camera lookAt(glm::vec3 from, glm::vec3 to, float fovYDeg = 60.0f);
Light pointLight(glm::vec3 position);
/// A directional light shining from `from` towards the origin.
Light directionalLight(glm::vec3 from);

/// Three big triangles crossing one another, one of them also piercing the ground they shadow
/// (a cluster of them is all overlap: their bounding volumes intersect).
Shot intersectingTriangles();
/// A point light inside a sphere shell with six holes, inside a closed room: light escapes in every
/// direction (floor, ceiling, four walls), so shadow volumes point every way, every side of the
/// omni light is exercised, and some bounding volumes (the walls' big triangles) contain the light.
/// The camera looks across several of them with a 100° field of view.
Shot omniInsideShell();
/// Closed objects on a plane under an oblique directional light.
Shot directionalObjects();
/// The camera sits under a roof, inside the roof's shadow volume, looking out at the lit ground.
Shot cameraInsideShadow();
/// A few thousand triangles of closed meshes (a sphere and a tilted torus) under a point light.
Shot thousandsOfTriangles();

/// A point light amid 600 random triangles (a soup: no two share an edge, many pierce one another)
/// over a ground: shadow volumes start all around the light, and the eye is inside some.
Shot lightAmidClutter();
/// A fence of 1.5 cm posts and rails under a directional light 4° above the horizon: long, thin
/// shadows on ground lit at a grazing angle (n . l = 0.07).
Shot grazingOverThin();
/// Open meshes: a bowl (the lower half of a sphere), a tube (a cylinder without its ends) and a box
/// without a lid, under a point light that shines into all three.
Shot openMeshes();
/// Non-manifold fins (five quads around one edge), a soup of 300 triangles and a sphere, under a
/// 40° spot light.
Shot finsAndSoup();

/// The 2CylinderEngine (a real CAD model, 110k triangles with many open edges), scaled to a radius
/// of 3 over a 12 × 12 ground, under a point light.
Shot engineOnGround();

/// `s` with a 2 × 2 wall added in a plane that holds its point light, beside the scene's centre:
/// a triangle whose shadow volume is empty (status "edge-on"), which shadow-volume algorithms cull.
Shot withEdgeOnWall(Shot s);

/// The smoke scene's objects (≈ 3,800 triangles): a sphere, a tilted torus and a thin fence on an
/// 8 × 8 plane; with the camera the ray-tracing algorithms' tests look at it from (55°, a little
/// narrower than the other shots) and a point light.
Shot smokePointShot();
/// smokePointShot() under a 35° spot light aimed at the origin.
Shot smokeSpotShot();
/// smokeSpotShot() with a 22° cone: the cone's border crosses the casters and their shadows.
Shot narrowSpot();
/// smokePointShot() under a directional light shining towards the origin.
Shot smokeDirectionalShot();
/// smokePointShot() under a square area light of side `side` facing the origin, with `samples`
/// samples in `pattern`.
Shot smokeAreaShot(int samples, float side, const char* pattern = "stratified");

} // namespace shadowlab::test
