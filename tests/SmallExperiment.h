#pragma once
// The small experiment the in-process experiment tests run: a sphere over a plane under a point
// light, 64², 3 frames, psv and bvh_raytrace, no plots. Each test changes what it is about.
#include "framework/core/JsonNode.h"

#include <string>

namespace shadowlab::test {

inline Json sphereOverPlane(const std::string& name) {
    return {{"name", name},
            {"resolution", {64, 64}},
            {"frames", 3},
            {"warmup_frames", 1},
            {"scene", {{"objects", Json::array({{{"procedural", "plane"}, {"size", {8, 8}}},
                                                {{"procedural", "sphere"}, {"radius", 0.8}, {"transform", {{"translate", {0, 1.0, 0}}}}}})}}},
            {"camera", {{"position", {0.5, 5, 4}}, {"target", {0, 0, 0}}}},
            {"light", {{"type", "point"}, {"position", {0.7, 5, 0.4}}}},
            {"algorithms", Json::array({{{"algorithm", "psv"}}, {{"algorithm", "bvh_raytrace"}}})},
            {"statistics", "none"},
            {"output", {{"plots", false}}}};
}

} // namespace shadowlab::test
