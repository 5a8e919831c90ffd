#include "algorithms/metric_tree/Clustering.h"

#include "framework/core/Parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <span>
#include <thread>

namespace shadowlab::mt {
namespace {

// ---- Smallest enclosing sphere and circle (Welzl: random order, support set of at most 4 / 3) ----

Sphere sphereOf2(glm::dvec3 a, glm::dvec3 b) { return {0.5 * (a + b), 0.5 * glm::length(b - a)}; }

Sphere sphereOf3(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const glm::dvec3 ab = b - a, ac = c - a, n = glm::cross(ab, ac);
    const double n2 = glm::dot(n, n);
    if (n2 <= 1e-30 * glm::dot(ab, ab) * glm::dot(ac, ac)) { // collinear: the farthest pair
        Sphere s = sphereOf2(a, b);
        for (Sphere t : {sphereOf2(a, c), sphereOf2(b, c)})
            if (t.radius > s.radius) s = t;
        return s;
    }
    const glm::dvec3 off = (glm::dot(ac, ac) * glm::cross(n, ab) + glm::dot(ab, ab) * glm::cross(ac, n)) / (2.0 * n2);
    return {a + off, glm::length(off)};
}

bool contains(const Sphere& s, glm::dvec3 p) { return glm::length(p - s.centre) <= s.radius * (1.0 + 1e-9) + 1e-12; }

Sphere sphereOf4(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
    const glm::dmat3 m(b - a, c - a, d - a); // columns; the centre solves (p_i - a) . x = |p_i - a|^2 / 2
    const double det = glm::determinant(m);
    const glm::dvec3 rhs(0.5 * glm::dot(b - a, b - a), 0.5 * glm::dot(c - a, c - a), 0.5 * glm::dot(d - a, d - a));
    if (std::abs(det) > 1e-30) {
        const glm::dvec3 x = glm::inverse(glm::transpose(m)) * rhs;
        return {a + x, glm::length(x)};
    }
    // Coplanar: the smallest three-point sphere holding the fourth point.
    Sphere best{a, 1e300};
    const glm::dvec3 p[4] = {a, b, c, d};
    for (int skip = 0; skip < 4; ++skip) {
        glm::dvec3 q[3];
        for (int i = 0, k = 0; i < 4; ++i)
            if (i != skip) q[k++] = p[i];
        Sphere s = sphereOf3(q[0], q[1], q[2]);
        if (contains(s, p[skip]) && s.radius < best.radius) best = s;
    }
    return best;
}

Sphere trivialBall(const glm::dvec3* r, int nr) {
    switch (nr) {
    case 0: return {glm::dvec3(0.0), -1.0};
    case 1: return {r[0], 0.0};
    case 2: return sphereOf2(r[0], r[1]);
    case 3: return sphereOf3(r[0], r[1], r[2]);
    default: return sphereOf4(r[0], r[1], r[2], r[3]);
    }
}

Circle circleOf2(glm::dvec2 a, glm::dvec2 b) { return {0.5 * (a + b), 0.5 * glm::length(b - a)}; }

Circle circleOf3(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    const glm::dvec2 ab = b - a, ac = c - a;
    const double d = 2.0 * (ab.x * ac.y - ab.y * ac.x);
    if (std::abs(d) <= 1e-30) { // collinear
        Circle s = circleOf2(a, b);
        for (Circle t : {circleOf2(a, c), circleOf2(b, c)})
            if (t.radius > s.radius) s = t;
        return s;
    }
    const double ab2 = glm::dot(ab, ab), ac2 = glm::dot(ac, ac);
    const glm::dvec2 off((ac.y * ab2 - ab.y * ac2) / d, (ab.x * ac2 - ac.x * ab2) / d);
    return {a + off, glm::length(off)};
}

bool contains(const Circle& s, glm::dvec2 p) { return glm::length(p - s.centre) <= s.radius * (1.0 + 1e-9) + 1e-12; }

Circle trivialBall(const glm::dvec2* r, int nr) {
    switch (nr) {
    case 0: return {glm::dvec2(0.0), -1.0};
    case 1: return {r[0], 0.0};
    case 2: return circleOf2(r[0], r[1]);
    default: return circleOf3(r[0], r[1], r[2]);
    }
}

/// Welzl's recursion in any dimension: `K` support points at most (4 in 3D, 3 in 2D).
template <class Ball, class Vec, size_t K>
Ball welzl(const std::vector<Vec>& p, size_t n, std::array<Vec, K>& r, int nr) {
    if (n == 0 || nr == int(K)) return trivialBall(r.data(), nr);
    Ball s = welzl<Ball>(p, n - 1, r, nr);
    if (s.radius >= 0 && contains(s, p[n - 1])) return s;
    r[size_t(nr)] = p[n - 1];
    return welzl<Ball>(p, n - 1, r, nr + 1);
}

/// Smallest ball around `points`; the radius is then raised to the largest distance measured.
template <class Ball, class Vec, size_t K>
Ball smallestEnclosingBall(std::vector<Vec> points) {
    if (points.empty()) return {};
    std::mt19937 rng(12345);
    std::shuffle(points.begin(), points.end(), rng); // Welzl's expected linear time needs a random order
    std::array<Vec, K> support{};
    Ball s = welzl<Ball>(points, points.size(), support, 0);
    double r = 0;
    for (const Vec& p : points) r = std::max(r, glm::length(p - s.centre));
    s.radius = r;
    return s;
}

// ---- Covariance OBB axes: Jacobi eigenvectors of a symmetric 3x3 matrix ----

void eigenSymmetric(double a[3][3], glm::dvec3 vectors[3], double values[3]) {
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 50; ++sweep) {
        const double off = std::abs(a[0][1]) + std::abs(a[0][2]) + std::abs(a[1][2]);
        if (off < 1e-30) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (std::abs(a[p][q]) < 1e-300) continue;
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) { // A <- A J
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) { // A <- J^T A
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    for (int i = 0; i < 3; ++i) {
        values[i] = a[i][i];
        vectors[i] = glm::normalize(glm::dvec3(v[0][i], v[1][i], v[2][i]));
    }
}

// ---- k-means ----

struct Element {
    glm::vec3 centroid, lo, hi; ///< the triangle's centroid and bounding box
};

/// Distance of an element to a centre, after Meister and Bittner's idea of measuring how much a
/// cluster would grow: the squared diagonal of the box enclosing the element's box and the centre.
/// A big triangle is thereby drawn to the centre it enlarges least, not merely to the nearest one.
float kmeansDistance(const Element& e, glm::vec3 centre) {
    const glm::vec3 d = glm::max(e.hi, centre) - glm::min(e.lo, centre);
    return glm::dot(d, d);
}

constexpr int kMaxK = 4;           ///< children per k-means level (the hierarchy's branching)
constexpr int kSeedCandidates = 4; ///< k-means++ draws this many candidates and keeps the farthest

/// Splits `ids` (indices into `elems`) recursively until each part has at most `maxSize`
/// elements; appends the parts to `out`.
void splitRecursive(const std::vector<Element>& elems, std::vector<uint32_t> ids, size_t maxSize, int iterations, std::mt19937& rng,
                    std::vector<std::vector<uint32_t>>& out) {
    if (ids.size() <= maxSize) {
        out.push_back(std::move(ids));
        return;
    }
    const int k = int(std::min<size_t>(kMaxK, (ids.size() + maxSize - 1) / maxSize));
    // k-means++ seeding: the first centre at random, each next one drawn with probability
    // proportional to the squared distance to the nearest centre, best of a few candidates.
    std::vector<glm::vec3> centres;
    centres.push_back(elems[ids[rng() % ids.size()]].centroid);
    std::vector<float> nearest(ids.size());
    while (int(centres.size()) < k) {
        double total = 0;
        for (size_t i = 0; i < ids.size(); ++i) {
            float d = 1e30f;
            for (glm::vec3 c : centres) {
                glm::vec3 v = elems[ids[i]].centroid - c;
                d = std::min(d, glm::dot(v, v));
            }
            nearest[i] = d;
            total += d;
        }
        if (total <= 0) break; // all centroids coincide
        size_t best = 0;
        float bestD = -1;
        for (int c = 0; c < kSeedCandidates; ++c) {
            double x = std::uniform_real_distribution<double>(0.0, total)(rng);
            size_t i = 0;
            for (; i + 1 < ids.size() && x >= nearest[i]; ++i) x -= nearest[i];
            if (nearest[i] > bestD) bestD = nearest[i], best = i;
        }
        centres.push_back(elems[ids[best]].centroid);
    }
    std::vector<int> assign(ids.size(), 0);
    for (int it = 0; it < iterations; ++it) {
        bool changed = false;
        for (size_t i = 0; i < ids.size(); ++i) {
            int best = 0;
            float bestD = 1e30f;
            for (int c = 0; c < int(centres.size()); ++c) {
                float d = kmeansDistance(elems[ids[i]], centres[c]);
                if (d < bestD) bestD = d, best = c;
            }
            changed |= assign[i] != best || it == 0;
            assign[i] = best;
        }
        if (!changed) break;
        std::vector<glm::dvec3> sum(centres.size(), glm::dvec3(0.0));
        std::vector<size_t> count(centres.size(), 0);
        for (size_t i = 0; i < ids.size(); ++i) sum[assign[i]] += glm::dvec3(elems[ids[i]].centroid), ++count[assign[i]];
        for (size_t c = 0; c < centres.size(); ++c)
            if (count[c]) centres[c] = glm::vec3(sum[c] / double(count[c]));
    }
    std::vector<std::vector<uint32_t>> parts(centres.size());
    for (size_t i = 0; i < ids.size(); ++i) parts[assign[i]].push_back(ids[i]);
    size_t nonEmpty = 0;
    for (const auto& p : parts) nonEmpty += !p.empty();
    if (nonEmpty < 2) {
        // No split (coincident centroids): halve in the given (Morton) order so the recursion ends.
        parts.assign(2, {});
        parts[0].assign(ids.begin(), ids.begin() + ids.size() / 2);
        parts[1].assign(ids.begin() + ids.size() / 2, ids.end());
    }
    for (auto& p : parts)
        if (!p.empty()) splitRecursive(elems, std::move(p), maxSize, iterations, rng, out);
}

uint32_t spreadBits(uint32_t x) { // 10 bits -> every third bit
    x &= 0x3FF;
    x = (x | (x << 16)) & 0x030000FF;
    x = (x | (x << 8)) & 0x0300F00F;
    x = (x | (x << 4)) & 0x030C30C3;
    x = (x | (x << 2)) & 0x09249249;
    return x;
}

/// The cluster record of triangles `tris` (scene indices).
ClusterGpu makeCluster(const Scene& scene, std::span<const uint32_t> tris, bool capsules) {
    std::vector<glm::dvec3> vertices;
    vertices.reserve(3 * tris.size());
    glm::dvec3 normalSum(0.0);
    for (uint32_t t : tris) {
        for (int k = 0; k < 3; ++k) vertices.push_back(glm::dvec3(scene.positions[3 * t + k]));
        normalSum += glm::dvec3(scene.normals[t]);
    }
    BoundingVolume bv = boundingVolume(vertices, capsules);
    ClusterGpu c{};
    const glm::vec3 a(bv.a), b(bv.capsule ? glm::vec3(bv.b) : glm::vec3(bv.a));
    // The radius is re-measured from the float ends and widened by a few float ulps of the
    // coordinates: the GPU sees the rounded centre, and must still enclose every vertex.
    double radius = 0, magnitude = 0;
    for (const glm::dvec3& v : vertices) {
        const glm::dvec3 ab = glm::dvec3(b) - glm::dvec3(a);
        const double l2 = glm::dot(ab, ab);
        const double t = l2 > 0 ? std::clamp(glm::dot(v - glm::dvec3(a), ab) / l2, 0.0, 1.0) : 0.0;
        radius = std::max(radius, glm::length(v - (glm::dvec3(a) + t * ab)));
        magnitude = std::max(magnitude, glm::length(v));
    }
    radius = radius * (1.0 + 1e-6) + 1e-6 * magnitude;
    c.a[0] = a.x, c.a[1] = a.y, c.a[2] = a.z, c.a[3] = float(radius);
    c.b[0] = b.x, c.b[1] = b.y, c.b[2] = b.z;
    // Normal cone: axis = mean normal, half-angle = largest deviation from it.
    const double nl = glm::length(normalSum);
    glm::vec3 axis(0, 0, 1);
    float cosHalf = -1.0f; // any direction: never culled
    if (nl > 1e-6 * double(tris.size())) {
        axis = glm::vec3(normalSum / nl);
        cosHalf = 1.0f;
        for (uint32_t t : tris) cosHalf = std::min(cosHalf, glm::dot(axis, scene.normals[t]));
        cosHalf -= 1e-5f; // rounding of the normals: widen the cone slightly
    }
    c.b[3] = std::max(cosHalf, -1.0f);
    float lo = 1e30f, hi = -1e30f;
    for (const glm::dvec3& v : vertices) {
        const float s = glm::dot(axis, glm::vec3(v));
        lo = std::min(lo, s), hi = std::max(hi, s);
    }
    c.axis[0] = axis.x, c.axis[1] = axis.y, c.axis[2] = axis.z, c.axis[3] = lo;
    c.slabMax = hi;
    c.count = uint32_t(tris.size());
    c.flags = bv.capsule ? MT_FLAG_CAPSULE : 0u;
    return c;
}

} // namespace

Sphere smallestEnclosingSphere(std::vector<glm::dvec3> points) {
    return smallestEnclosingBall<Sphere, glm::dvec3, 4>(std::move(points));
}

Circle smallestEnclosingCircle(std::vector<glm::dvec2> points) {
    return smallestEnclosingBall<Circle, glm::dvec2, 3>(std::move(points));
}

BoundingVolume boundingVolume(const std::vector<glm::dvec3>& vertices, bool capsules) {
    BoundingVolume bv;
    if (capsules && vertices.size() >= 2) {
        // Covariance OBB (Gottschalk et al.): eigenvectors of the vertices' covariance.
        glm::dvec3 mean(0.0);
        for (const glm::dvec3& v : vertices) mean += v;
        mean /= double(vertices.size());
        double cov[3][3] = {};
        for (const glm::dvec3& v : vertices) {
            const glm::dvec3 d = v - mean;
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k) cov[j][k] += d[j] * d[k];
        }
        glm::dvec3 axes[3];
        double values[3];
        eigenSymmetric(cov, axes, values);
        double lo[3], hi[3], ext[3];
        for (int i = 0; i < 3; ++i) {
            lo[i] = 1e300, hi[i] = -1e300;
            for (const glm::dvec3& v : vertices) {
                const double s = glm::dot(v, axes[i]);
                lo[i] = std::min(lo[i], s), hi[i] = std::max(hi[i], s);
            }
            ext[i] = hi[i] - lo[i];
        }
        const int l = int(std::max_element(ext, ext + 3) - ext), u = (l + 1) % 3, w = (l + 2) % 3;
        if (ext[l] > 0 && ext[l] >= 2.0 * ext[u] && ext[l] >= 2.0 * ext[w]) {
            // Capsule: its axis through the centre of the smallest circle enclosing the vertices
            // projected orthogonally to the long axis, as long as the OBB.
            std::vector<glm::dvec2> projected;
            projected.reserve(vertices.size());
            for (const glm::dvec3& v : vertices) projected.emplace_back(glm::dot(v, axes[u]), glm::dot(v, axes[w]));
            const Circle circle = smallestEnclosingCircle(std::move(projected));
            const glm::dvec3 side = circle.centre.x * axes[u] + circle.centre.y * axes[w];
            // The paper's segment spans the whole OBB extent, so the caps overhang it by a radius.
            // A vertex at axial position s and distance rho from the axis only needs the segment to
            // reach s -+ sqrt(r^2 - rho^2): the tightest segment with the same radius, still
            // enclosing every vertex (and then re-measured like every bounding volume).
            const double r = circle.radius;
            double segLo = hi[l], segHi = lo[l];
            for (const glm::dvec3& v : vertices) {
                const double s = glm::dot(v, axes[l]);
                const double rho = glm::length(glm::dvec2(glm::dot(v, axes[u]), glm::dot(v, axes[w])) - circle.centre);
                const double reach = std::sqrt(std::max(0.0, r * r - rho * rho));
                segLo = std::min(segLo, s + reach), segHi = std::max(segHi, s - reach);
            }
            if (segLo > segHi) segLo = segHi = 0.5 * (segLo + segHi);
            bv.a = side + segLo * axes[l];
            bv.b = side + segHi * axes[l];
            bv.radius = r;
            bv.capsule = true;
            return bv;
        }
    }
    const Sphere s = smallestEnclosingSphere(vertices);
    bv.a = bv.b = s.centre;
    bv.radius = s.radius;
    return bv;
}

Clustering clusterScene(const Scene& scene, const ClusteringOptions& options) {
    const size_t n = scene.triangleCount();
    Clustering result;
    if (n == 0) return result;
    auto element = [&](size_t t) {
        const glm::vec3 a = scene.positions[3 * t], b = scene.positions[3 * t + 1], c = scene.positions[3 * t + 2];
        return Element{(a + b + c) / 3.0f, glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))};
    };
    // Morton order of the centroids over the scene box.
    const glm::vec3 lo = scene.bounds.min, ext = glm::max(scene.bounds.extent(), glm::vec3(1e-20f));
    std::vector<std::pair<uint32_t, uint32_t>> keyed(n);
    for (size_t t = 0; t < n; ++t) {
        const glm::vec3 u = glm::clamp((element(t).centroid - lo) / ext, 0.0f, 1.0f) * 1023.0f;
        keyed[t] = {(spreadBits(uint32_t(u.x)) << 2) | (spreadBits(uint32_t(u.y)) << 1) | spreadBits(uint32_t(u.z)), uint32_t(t)};
    }
    std::sort(keyed.begin(), keyed.end());

    // Chunks are independent: k-means runs on a few threads, each chunk with its own seeded RNG
    // so the result does not depend on the thread count. A chunk's elements exist only while it is
    // split, and its clusters are kept flat (triangles in cluster order, and their counts): the
    // working set stays ~20 bytes a triangle at 74 M triangles instead of one element and one
    // vector per cluster for the whole scene.
    const size_t chunk = size_t(std::max(1, options.chunkTriangles));
    const size_t chunks = (n + chunk - 1) / chunk;
    struct ChunkParts {
        std::vector<uint32_t> triangles, counts;
    };
    std::vector<ChunkParts> parts(chunks);
    const int threads = int(std::max(1u, std::min(4u, std::thread::hardware_concurrency())));
    parallelFor(chunks, threads, [&](size_t c) {
        const size_t begin = c * chunk, end = std::min(n, (c + 1) * chunk);
        std::vector<Element> elems;
        std::vector<uint32_t> ids;
        for (size_t i = begin; i < end; ++i) {
            ids.push_back(uint32_t(i - begin));
            elems.push_back(element(keyed[i].second));
        }
        std::mt19937 rng(uint32_t(c * 2654435761u) ^ options.seed);
        std::vector<std::vector<uint32_t>> local;
        splitRecursive(elems, std::move(ids), size_t(options.clusterSize), options.kmeansIterations, rng, local);
        for (const auto& p : local) {
            parts[c].counts.push_back(uint32_t(p.size()));
            for (uint32_t i : p) parts[c].triangles.push_back(keyed[begin + i].second);
        }
    });
    keyed = {};

    size_t clusterCount = 0;
    for (const ChunkParts& p : parts) clusterCount += p.counts.size();
    result.clusters.resize(clusterCount);
    result.order.reserve(n);
    std::vector<uint32_t> first(clusterCount), count(clusterCount);
    for (size_t c = 0, i = 0; c < chunks; ++c) {
        size_t at = result.order.size(); // where this chunk's triangles start
        for (uint32_t k : parts[c].counts) first[i] = uint32_t(at), count[i++] = k, at += k;
        result.order.insert(result.order.end(), parts[c].triangles.begin(), parts[c].triangles.end());
        parts[c] = {};
    }
    parallelFor(clusterCount, threads, [&](size_t i) {
        result.clusters[i] = makeCluster(scene, std::span<const uint32_t>(result.order.data() + first[i], count[i]), options.capsules);
        result.clusters[i].first = first[i];
    });
    for (const ClusterGpu& c : result.clusters) result.capsules += (c.flags & MT_FLAG_CAPSULE) != 0;
    // The cluster order is the insertion order, hence the order pivots are taken in. Morton order
    // would make neighbours pivots of one another all the way down; shuffled, the first pivots are
    // spread over the scene (the paper leaves this to the GPU scheduler, which llvmpipe does not shuffle).
    if (options.randomOrder) {
        std::mt19937 rng(options.seed);
        std::shuffle(result.clusters.begin(), result.clusters.end(), rng);
    }
    return result;
}

} // namespace shadowlab::mt
