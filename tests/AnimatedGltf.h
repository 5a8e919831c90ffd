#pragma once
// A small animated glTF 2.0 file written by the tests (no rigidly animated glTF 2.0 file ships with
// Debian's test models: theirs are skinned or morphed). A hub node at (0, 2, 0) turns about Y and
// carries a child "blade", a 1.6 × 0.5 quad at x = 0.3..1.9, so the blade sweeps a circle above
// the ground; the blade also slides along its own x axis by a second channel.
#include <string>

namespace shadowlab::test {

struct AnimatedGltfOptions {
    std::string rotationInterpolation = "LINEAR";    ///< the hub's turn: keys at 0, 1, 2 s (0°, 90°, 180°)
    std::string translationInterpolation = "STEP";   ///< the blade's slide: keys at 0, 2 s (x + 0, x + 0.4)
    bool morphChannel = false;                       ///< add a "weights" channel (must be refused)
};

/// Writes the file (buffer embedded as a base64 data URI) to `path`; animation 0 is named "spin".
void writeAnimatedGltf(const std::string& path, const AnimatedGltfOptions& options = {});

} // namespace shadowlab::test
