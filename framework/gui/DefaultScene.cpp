#include "framework/gui/DefaultScene.h"

#include "framework/algorithm/ShadowAlgorithm.h"

namespace shadowlab {

Json defaultGuiConfig() {
    // Scene keys as in docs/scene.md; the algorithm is the first registered one, with its defaults.
    Json config = Json::parse(R"({
      "name": "gui-default",
      "resolution": [256, 256],
      "frames": 60,
      "scene": {"objects": [
        {"procedural": "plane", "size": [8, 8], "subdivisions": 4, "material": {"albedo": [0.75, 0.75, 0.7]}},
        {"procedural": "sphere", "radius": 0.6, "triangles": 2000, "transform": {"translate": [-0.8, 0.8, 0]},
         "material": {"albedo": [0.8, 0.3, 0.25]}},
        {"procedural": "torus", "major_radius": 0.5, "minor_radius": 0.15, "triangles": 1500,
         "transform": {"translate": [0.9, 0.6, 0.3], "rotate_deg": [60, 0, 0]}, "material": {"albedo": [0.3, 0.5, 0.8]}}
      ]},
      "camera": {"fov_y_deg": 55, "near": 0.05, "far": 50, "position": [0, 3.0, 5.0], "target": [0, 0.4, 0]},
      "light": {"type": "point", "position": [2.0, 4.0, 1.5]},
      "reference": true
    })");
    Json entry = Json::object();
    entry["algorithm"] = algorithmRegistry().front().name;
    config["algorithms"] = Json::array({entry});
    return config;
}

} // namespace shadowlab
