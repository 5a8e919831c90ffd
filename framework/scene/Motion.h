#pragma once
// Rigid motion of scene objects. An object that moves keeps its triangles in its own ("local")
// space and a function of time giving its world matrix; the experiment samples that function at
// each frame's time, so every algorithm sees the same poses (docs/scene.md, "Moving objects").
//
// Two sources produce such functions: a config object's "path" (keyframes of translate, rotate,
// scale) and a glTF file's node animation (GltfLoader). Grids and nested transforms compose them.
#include "framework/core/JsonNode.h"

#include <glm/glm.hpp>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace shadowlab {

/// Every element is finite. A NaN or infinite pose moves its triangles out of every view (they
/// vanish without an error), so each pose is checked before anything uses it.
bool isFinite(const glm::mat4& m);
bool isFinite(glm::vec3 v);
/// "at time 1.25 s", for errors about a pose.
std::string atTimeText(double time);

/// translate · rotate · scale, the rotation as Euler degrees applied X first, then Y, then Z
/// (the convention of a config's "transform").
glm::mat4 composeTransform(glm::vec3 translate, glm::vec3 rotateDeg, glm::vec3 scale);

/// The "scale" key of a transform or keyframe: a number (uniform) or [sx, sy, sz]; 1 when absent.
glm::vec3 readScale(JsonNode& node);

/// One keyframe of a rigid path.
struct RigidKey {
    double time = 0;
    glm::vec3 translate{0.0f};
    glm::vec3 rotateDeg{0.0f};
    glm::vec3 scale{1.0f};
};

enum class Interpolation { Linear, Step, CatmullRom };

/// Keyframed translate / rotate (Euler degrees, interpolated per angle so a turn of 360° is a full
/// spin) / scale, clamped outside its keys.
class RigidPath {
public:
    RigidPath() = default;
    RigidPath(std::vector<RigidKey> keys, Interpolation interpolation);

    /// The pose at `time`; InputError (naming the path's file and JSON path, and the time) when an
    /// interpolated value or the matrix is not finite or does not fit a float.
    glm::mat4 at(double time) const;
    /// The path as a motion function (a copy: it outlives this object).
    std::function<glm::mat4(double)> motion() const;
    double startTime() const { return keys_.empty() ? 0 : keys_.front().time; }
    double endTime() const { return keys_.empty() ? 0 : keys_.back().time; }

    /// Reads {"keyframes": [{"time", "translate", "rotate_deg", "scale"}, ...],
    ///        "interpolation": "catmull_rom" | "linear" | "step"}; at least one keyframe, times
    /// strictly increasing, scales positive (a mirror belongs in the static "transform").
    static RigidPath parse(JsonNode node);

    /// Where the path was read from, for its errors (parse() sets it).
    std::string file, jsonPath;

private:
    std::vector<RigidKey> keys_;
    Interpolation interpolation_ = Interpolation::CatmullRom;
};

/// A world matrix as a function of time (seconds on the experiment's clock).
using MotionFn = std::function<glm::mat4(double)>;

/// Triangles [firstTriangle, firstTriangle + triangleCount) of a scene that move rigidly together.
struct MovingPart {
    size_t firstTriangle = 0;
    size_t triangleCount = 0;
    std::vector<glm::vec3> local; ///< 3 per triangle, in the part's own space
    MotionFn worldFromLocal;
    double startTime = 0, endTime = 0; ///< when its motion starts and ends (the default clock)
    glm::vec3 localMin{0.0f}, localMax{0.0f}; ///< box of `local` (setLocal() keeps it)
    /// Where its motion was given (a config's path, a glTF node), named by errors about its pose.
    std::string sourceFile, sourcePath;
    /// Its triangles are a mesh's: each keeps its shape within 1 % at every pose, not just an area.
    bool heldEachTriangle = false;
    /// When the part is a grid's copies of one object: each copy's local box (min, max), so each is
    /// held to the float spacing rule at every pose as a static grid's copies are; empty otherwise.
    std::vector<std::pair<glm::vec3, glm::vec3>> copyBoxes;

    /// Sets the local copy and its box.
    void setLocal(std::vector<glm::vec3> vertices);
    /// Marks the part as copies of `trianglesPerCopy` triangles each (a grid's innermost object)
    /// when it holds two or more whole copies; does nothing otherwise.
    void setCopies(size_t trianglesPerCopy);
};

/// `outer` composed onto `inner` (world = outer(t) · inner(t)), checked: a product of two finite
/// poses can still overflow a float, which is blamed on the outer motion (file, JSON path, time).
MotionFn composeMotion(MotionFn outer, MotionFn inner, std::string file, std::string jsonPath);

/// Places one triangle of a moving part with matrix `m`: the three vertices, the winding flipped
/// back under a mirroring matrix, and the unit normal ((0, 1, 0) should the triangle collapse).
/// shaders/common/scene_update.comp does the same on the GPU.
void poseTriangle(const glm::mat4& m, const glm::vec3* local, glm::vec3* out, glm::vec3& normal);

} // namespace shadowlab
