#pragma once
// Size arithmetic that cannot wrap. Counts and byte totals computed from input (a grid's copies, a
// requested triangle count, a memory estimate) must never be taken modulo 2^64: a wrapped product
// reads as a small number and would let a run that cannot fit pass as one that needs nothing.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>

namespace shadowlab {

/// a × b, or nothing when the product does not fit a size_t.
constexpr std::optional<size_t> checkedMul(size_t a, size_t b) {
    size_t r = 0;
    if (__builtin_mul_overflow(a, b, &r)) return std::nullopt;
    return r;
}

/// a + b, or nothing when the sum does not fit a size_t.
constexpr std::optional<size_t> checkedAdd(size_t a, size_t b) {
    size_t r = 0;
    if (__builtin_add_overflow(a, b, &r)) return std::nullopt;
    return r;
}

/// What a saturating result is pinned to when the exact one does not fit: callers that must not go
/// on with it (the memory plan) refuse it as too large.
constexpr size_t kSaturated = SIZE_MAX;

/// a × b, or kSaturated past size_t (estimates stay readable as sums of products this way).
constexpr size_t saturatingMul(size_t a, size_t b) { return checkedMul(a, b).value_or(kSaturated); }

/// The sum of `terms`, or kSaturated past size_t.
constexpr size_t saturatingSum(std::initializer_list<size_t> terms) {
    size_t sum = 0;
    for (size_t t : terms) sum = checkedAdd(sum, t).value_or(kSaturated);
    return sum;
}

} // namespace shadowlab
