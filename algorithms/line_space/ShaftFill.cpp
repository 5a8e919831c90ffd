#include "algorithms/line_space/ShaftFill.h"

#include "algorithms/line_space/NTree.h"

#include <algorithm>
#include <cmath>

namespace shadowlab::ls {
namespace {

/// Sub-faces of an end face a shaft from A reaches through a box, as cell ranges along the face's
/// two axes (u, v), and the shaft parameters s for which it crosses the box's extent on the face's
/// own axis.
struct Footprint {
    bool any = false;
    double s0 = 0, s1 = 1;
    int range[2][2] = {{0, -1}, {0, -1}};
};

/// A group of up to 2^k × 2^k × 2^k children (k = 0: one child).
struct Block {
    DBox box{};        ///< bounds of its non-empty children (widened)
    int count = 0;     ///< non-empty children
    bool full = false; ///< every child cell inside the node is non-empty: box is exactly their union
};

class NodeShafts {
public:
    NodeShafts(int n, glm::vec3 lo, glm::vec3 size, const std::vector<uint8_t>& occupied, double margin)
        : n_(n), n2_(n * n), lo_(lo), size_(size), cell_(glm::dvec3(size / float(n))) {
        invCell_ = 1.0 / cell_;
        all_ = n2_ == 64 ? ~0ull : (1ull << n2_) - 1;
        sub_.resize(size_t(6 * n2_));
        for (int f = 0; f < 6; ++f)
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) sub_[size_t(f * n2_ + j * n + i)] = subFaceBox(lo_, size_, n, f, i, j);
        for (int i0 = 0; i0 < n; ++i0)
            for (int i1 = i0; i1 < n; ++i1) {
                rowBits_[i0][i1] = ((1ull << (i1 + 1)) - 1) & ~((1ull << i0) - 1);
                uint64_t spread = 0;
                for (int j = i0; j <= i1; ++j) spread |= 1ull << (j * n);
                colSpread_[i0][i1] = spread;
            }
        buildBlocks(lo, size, occupied, margin);
    }

    void fill(uint32_t* words) const {
        if (levels_.empty() || levels_.back()[0].count == 0) return;
        const int top = int(levels_.size()) - 1;
        for (int fa = 0; fa < 5; ++fa)
            for (int sa = 0; sa < n2_; ++sa) {
                const DBox& A = sub_[size_t(fa * n2_ + sa)];
                glm::ivec3 flip(0);
                flip[fa >> 1] = fa & 1; // A on a max face: visit high blocks first along its axis
                for (int fb = fa + 1; fb < 6; ++fb) {
                    uint64_t known = 0;
                    visit(A, fb, top, glm::ivec3(0), known, flip);
                    for (uint64_t bits = known; bits; bits &= bits - 1) {
                        const uint32_t b = shaftBit(n_, fa, sa, fb, __builtin_ctzll(bits));
                        words[b >> 5] |= 1u << (b & 31);
                    }
                }
            }
    }

private:
    void buildBlocks(glm::vec3 lo, glm::vec3 size, const std::vector<uint8_t>& occupied, double margin) {
        const glm::vec3 cell = size / float(n_);
        // Level 0: the children, boxes as the shader's DDA computes them (float), widened.
        int grid = n_;
        std::vector<Block> level(size_t(grid * grid * grid));
        for (int z = 0; z < n_; ++z)
            for (int y = 0; y < n_; ++y)
                for (int x = 0; x < n_; ++x) {
                    const size_t c = size_t((z * n_ + y) * n_ + x);
                    if (!occupied[c]) continue;
                    const glm::vec3 clo = lo + glm::vec3(float(x), float(y), float(z)) * cell;
                    level[c] = {{glm::dvec3(clo) - margin, glm::dvec3(clo + cell) + margin}, 1, true};
                }
        grids_.push_back(grid);
        levels_.push_back(std::move(level));
        while (grid > 1) { // level k + 1 groups 2 × 2 × 2 blocks of level k
            const int fine = grid;
            grid = (grid + 1) / 2;
            std::vector<Block> up(size_t(grid * grid * grid));
            const std::vector<Block>& down = levels_.back();
            for (int z = 0; z < grid; ++z)
                for (int y = 0; y < grid; ++y)
                    for (int x = 0; x < grid; ++x) {
                        Block& b = up[size_t((z * grid + y) * grid + x)];
                        b.full = true;
                        b.box = {glm::dvec3(1e300), glm::dvec3(-1e300)};
                        for (int dz = 0; dz < 2; ++dz)
                            for (int dy = 0; dy < 2; ++dy)
                                for (int dx = 0; dx < 2; ++dx) {
                                    glm::ivec3 c(2 * x + dx, 2 * y + dy, 2 * z + dz);
                                    if (c.x >= fine || c.y >= fine || c.z >= fine) continue; // outside the node
                                    const Block& s = down[size_t((c.z * fine + c.y) * fine + c.x)];
                                    b.full = b.full && s.full;
                                    if (s.count == 0) continue;
                                    b.count += s.count;
                                    b.box.lo = glm::min(b.box.lo, s.box.lo), b.box.hi = glm::max(b.box.hi, s.box.hi);
                                }
                    }
            grids_.push_back(grid);
            levels_.push_back(std::move(up));
        }
    }

    uint64_t rectMask(const int r[2][2]) const { return rowBits_[r[0][0]][r[0][1]] * colSpread_[r[1][0]][r[1][1]]; }

    /// The cells of end face fb a shaft from A reaches through box C, bounded over s (conservative).
    Footprint footprint(const DBox& A, const DBox& C, int fb) const {
        Footprint f;
        const int axis = fb >> 1;
        const double cB = lo_[axis] + double(fb & 1) * size_[axis];
        auto clip = [&](double a, double b) { // a + b s <= 0
            if (b > 0.0) f.s1 = std::min(f.s1, -a / b);
            else if (b < 0.0) f.s0 = std::max(f.s0, -a / b);
            else if (a > 0.0) f.s1 = -1.0;
        };
        clip(A.lo[axis] - C.hi[axis], cB - A.lo[axis]);
        clip(C.lo[axis] - A.hi[axis], A.hi[axis] - cB);
        if (f.s0 > f.s1) return f;
        // The free coordinates' bounds L(s), U(s) are monotone in s: the ends of [s0, s1] bound them.
        f.any = cells(A, C, axis, std::max(f.s0, 1e-12), std::max(f.s1, 1e-12), f.range);
        return f;
    }

    /// Cells of the end face (axis `axis`) whose sub-face B satisfies B.hi >= min L and B.lo <= max U
    /// over s in {sa, sb}, per free axis. With sa == sb this is exactly the set hit at that s.
    bool cells(const DBox& A, const DBox& C, int axis, double sa, double sb, int range[2][2]) const {
        const double ia = 1.0 / sa, ib = 1.0 / sb; // L(s) = C.lo / s - (1/s - 1) A.hi, U alike
        for (int q = 0; q < 2; ++q) {
            const int j = (axis + 1 + q) % 3;
            const double need = std::min(C.lo[j] * ia - (ia - 1.0) * A.hi[j], C.lo[j] * ib - (ib - 1.0) * A.hi[j]);
            const double reach = std::max(C.hi[j] * ia - (ia - 1.0) * A.lo[j], C.hi[j] * ib - (ib - 1.0) * A.lo[j]);
            const double first = std::clamp((need - lo_[j]) * invCell_[j] - 1.0, -1.0, double(n_));
            const double last = std::clamp((reach - lo_[j]) * invCell_[j], -1.0, double(n_));
            range[q][0] = std::max(0, int(std::ceil(first - 1e-9)));
            range[q][1] = std::min(n_ - 1, int(std::floor(last + 1e-9)));
            if (range[q][0] > range[q][1]) return false;
        }
        return true;
    }

    /// `flip` reverses the sub-block order along A's axis so blocks nearest A come first: their
    /// footprints are the widest, and what they mark lets farther blocks be skipped.
    void visit(const DBox& A, int fb, int level, glm::ivec3 b, uint64_t& known, glm::ivec3 flip) const {
        const int grid = grids_[size_t(level)];
        const Block& blk = levels_[size_t(level)][size_t((b.z * grid + b.y) * grid + b.x)];
        if (blk.count == 0 || known == all_) return;
        const Footprint f = footprint(A, blk.box, fb);
        if (!f.any) return;
        const uint64_t candidates = rectMask(f.range) & ~known;
        if (candidates == 0) return; // nothing new through this block
        if (level == 0 || blk.full) {
            resolve(A, blk.box, fb, f, candidates, known);
            return;
        }
        const int fine = grids_[size_t(level - 1)];
        for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy)
                for (int dx = 0; dx < 2; ++dx) {
                    const glm::ivec3 c = 2 * b + (glm::ivec3(dx, dy, dz) ^ flip);
                    if (c.x < fine && c.y < fine && c.z < fine) visit(A, fb, level - 1, c, known, flip);
                }
    }

    /// Marks the candidates (sub-faces of fb) whose shaft from A touches box C.
    void resolve(const DBox& A, const DBox& C, int fb, const Footprint& f, uint64_t candidates, uint64_t& known) const {
        // Sub-faces reached at one fixed s are certainly hit: mark those without testing.
        for (double t : {0.0, 0.5, 1.0}) {
            const double s = std::max(f.s0 + t * (f.s1 - f.s0), 1e-12);
            int r[2][2];
            if (cells(A, C, fb >> 1, s, s, r)) known |= rectMask(r) & candidates;
        }
        const DBox* subB = sub_.data() + size_t((fb)*n2_);
        for (uint64_t rest = candidates & ~known; rest; rest &= rest - 1) {
            const int sb = __builtin_ctzll(rest);
            if (shaftOverlapsBox(A, subB[sb], C)) known |= 1ull << sb;
        }
    }

    int n_, n2_;
    glm::dvec3 lo_, size_, cell_, invCell_;
    uint64_t all_ = 0;
    std::vector<DBox> sub_;
    uint64_t rowBits_[kMaxN][kMaxN] = {}, colSpread_[kMaxN][kMaxN] = {};
    std::vector<std::vector<Block>> levels_; ///< levels_[0] = children, back() = one block
    std::vector<int> grids_;
};

} // namespace

void fillLineSpace(int n, glm::vec3 lo, glm::vec3 size, const std::vector<uint8_t>& occupied, double margin,
                   uint32_t* words) {
    NodeShafts(n, lo, size, occupied, margin).fill(words);
}

} // namespace shadowlab::ls
