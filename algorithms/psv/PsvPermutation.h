#pragma once
// The insertion order of the PSV build: a keyed bijection on [0, n) (4-round Feistel network with
// cycle walking), evaluated on the GPU by psvPermute() in shaders/psv/tree.glsl and mirrored here
// for tests. It replaces the paper's permutation list, so the order costs no memory.
#include <cstdint>

namespace shadowlab::psv {

struct Permutation {
    uint32_t n = 0;         ///< domain size (triangles)
    uint32_t halfBits = 1;  ///< the network works on 2 * halfBits bits, 2^(2 halfBits) >= n
    uint32_t keys[4] = {};  ///< round keys, from the seed
};

inline uint32_t permutationHash(uint32_t x) { // "lowbias32" (C. Wellons), as in tree.glsl
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

inline Permutation makePermutation(uint32_t n, uint32_t seed) {
    Permutation p;
    p.n = n;
    while (p.halfBits < 16 && (uint64_t(1) << (2 * p.halfBits)) < n) ++p.halfBits;
    uint64_t s = seed;
    for (auto& k : p.keys) { // splitmix64: distinct, well-mixed keys even for seeds 0, 1, 2...
        s += 0x9e3779b97f4a7c15ull;
        uint64_t z = s;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        k = uint32_t(z ^ (z >> 31));
    }
    return p;
}

inline uint32_t feistel(const Permutation& p, uint32_t x) {
    uint32_t mask = (1u << p.halfBits) - 1u;
    uint32_t l = x >> p.halfBits, r = x & mask;
    for (uint32_t key : p.keys) {
        uint32_t f = permutationHash(r ^ key) & mask;
        uint32_t nl = r;
        r = l ^ f;
        l = nl;
    }
    return (l << p.halfBits) | r;
}

/// Position k of the insertion order → triangle index; a bijection on [0, n).
inline uint32_t permute(const Permutation& p, uint32_t k) {
    uint32_t x = feistel(p, k);
    while (x >= p.n) x = feistel(p, x); // k < n is on x's cycle, so this ends
    return x;
}

} // namespace shadowlab::psv
