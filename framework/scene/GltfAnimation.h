#pragma once
// The animation model of a glTF file (glTF 2.0 spec 3.11): channel tracks and the node hierarchy
// they pose, evaluated at any time with every value checked. GltfLoader.cpp reads it from the file.
#include "framework/core/Error.h"
#include "framework/scene/Motion.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace shadowlab::gltf {

/// Quaternion (x, y, z, w) to matrix, written out to avoid any doubt about glm's quat argument order.
inline glm::mat4 rotationMatrix(glm::vec4 q) {
    float len = glm::length(q);
    float x = q.x / len, y = q.y / len, z = q.z / len, w = q.w / len;
    glm::mat4 r(1.0f);
    r[0] = glm::vec4(1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y), 0);
    r[1] = glm::vec4(2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x), 0);
    r[2] = glm::vec4(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y), 0);
    return r;
}

inline glm::mat4 trsMatrix(glm::vec3 t, glm::vec4 q, glm::vec3 s) {
    glm::mat4 m = rotationMatrix(q);
    for (int c = 0; c < 3; ++c) m[c] *= s[c];
    m[3] = glm::vec4(t, 1.0f);
    return m;
}

inline glm::dvec4 slerp(glm::dvec4 a, glm::dvec4 b, double u) {
    double d = glm::dot(a, b);
    if (d < 0.0) b = -b, d = -d;  // the shorter way round
    if (d > 0.9995) return glm::normalize(glm::mix(a, b, u));
    double theta = std::acos(std::min(d, 1.0));
    return (std::sin((1.0 - u) * theta) * a + std::sin(u * theta) * b) / std::sin(theta);
}

/// One animation channel's keys (glTF 2.0 spec 3.11): values are vec3 (translation, scale) or
/// quaternions; CUBICSPLINE stores (in-tangent, value, out-tangent) per key.
struct Track {
    enum Mode { Linear, Step, Cubic } mode = Linear;
    std::vector<float> times;
    std::vector<glm::vec4> values;
    bool rotation = false;
    std::string where;  ///< the channel's JSON path, for errors about its values

    glm::dvec4 key(size_t k) const { return glm::dvec4(mode == Cubic ? values[3 * k + 1] : values[k]); }
    /// Evaluated in double: keys and tangents near the float limit cannot overflow the weighted sums
    /// (the caller checks that the value fits a float). A rotation comes out normalised, or zero
    /// when a spline's tangents cancel it out.
    glm::dvec4 at(double time) const {
        if (times.size() == 1 || !(time > times.front())) return key(0);
        if (time >= times.back()) return key(times.size() - 1);
        size_t k = size_t(std::upper_bound(times.begin(), times.end(), float(time)) - times.begin()) - 1;
        if (k + 1 >= times.size()) return key(times.size() - 1);
        if (mode == Step) return key(k);
        const double dt = double(times[k + 1]) - double(times[k]), u = std::clamp((time - double(times[k])) / dt, 0.0, 1.0);
        if (mode == Linear) return rotation ? slerp(key(k), key(k + 1), u) : glm::mix(key(k), key(k + 1), u);
        const double u2 = u * u, u3 = u2 * u;
        glm::dvec4 v = (2 * u3 - 3 * u2 + 1) * key(k) + (u3 - 2 * u2 + u) * dt * glm::dvec4(values[3 * k + 2]) +
                       (-2 * u3 + 3 * u2) * key(k + 1) + (u3 - u2) * dt * glm::dvec4(values[3 * (k + 1)]);
        if (!rotation) return v;
        const double len = glm::length(v);
        return len > 0.0 && std::isfinite(len) ? v / len : glm::dvec4(0.0);
    }
};

/// The node hierarchy with one animation's tracks: every node's world matrix at any time. Shared
/// (immutable) by the motion functions of the file's moving parts. Every value it computes is
/// checked: a NaN or infinite pose would make the node's meshes vanish from every image.
struct NodeAnimation {
    std::string file;
    std::vector<int> parent;
    std::vector<glm::mat4> fixed;             ///< local matrix of nodes without tracks
    std::vector<glm::vec3> t, s;              ///< rest TRS of animated nodes
    std::vector<glm::vec4> r;
    std::vector<int> track[3];                ///< translation, rotation, scale: index into tracks, -1 = none
    std::vector<Track> tracks;
    std::vector<MotionFn> extra;              ///< a config's node path, in the node's own frame (empty = none)

    bool animated(size_t n) const { return track[0][n] >= 0 || track[1][n] >= 0 || track[2][n] >= 0 || extra[n]; }
    glm::mat4 local(size_t n, double time) const {
        if (extra[n]) return channels(n, time) * extra[n](time);
        return channels(n, time);
    }
    glm::mat4 channels(size_t n, double time) const {
        if (track[0][n] < 0 && track[1][n] < 0 && track[2][n] < 0) return fixed[n];
        auto value = [&](int slot, glm::vec4 rest) {
            if (track[slot][n] < 0) return rest;
            const Track& tr = tracks[size_t(track[slot][n])];
            const glm::dvec4 v = tr.at(time);
            for (int c = 0; c < 4; ++c)
                if (!(std::abs(v[c]) <= double(std::numeric_limits<float>::max())))
                    throw InputError(file, tr.where, "the channel's interpolated value does not fit a float " + atTimeText(time) +
                                                         (tr.mode == Track::Cubic ? " (check the CUBICSPLINE tangents)" : ""));
            if (tr.rotation && v == glm::dvec4(0.0))
                throw InputError(file, tr.where, "the channel's interpolated rotation is the zero quaternion " + atTimeText(time) +
                                                     " (its CUBICSPLINE tangents cancel the keys out)");
            return glm::vec4(v);
        };
        const glm::mat4 m = trsMatrix(glm::vec3(value(0, glm::vec4(t[n], 0))), value(1, r[n]), glm::vec3(value(2, glm::vec4(s[n], 0))));
        if (!isFinite(m)) throw InputError(file, "/nodes/" + std::to_string(n), "the node's animated matrix is not finite " + atTimeText(time));
        return m;
    }
    glm::mat4 world(size_t n, double time) const {
        glm::mat4 m = local(n, time);
        for (int p = parent[n]; p != -1; p = parent[size_t(p)]) m = local(size_t(p), time) * m;
        if (!isFinite(m))
            throw InputError(file, "/nodes/" + std::to_string(n),
                             "the node's world matrix (its animation composed with its parents') overflows a float " + atTimeText(time));
        return m;
    }
};

} // namespace shadowlab::gltf
