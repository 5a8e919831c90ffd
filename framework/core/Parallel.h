#pragma once
// A minimal parallel loop for the CPU preprocessing passes (N-tree build, clustering).
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace shadowlab {

/// Runs job(i) for every i in [0, count) on `threads` threads, the caller's included. Dynamic
/// scheduling (items are taken one at a time): item costs vary a lot. Jobs must not depend on
/// which thread runs them, so results are the same for any thread count.
template <class Job>
void parallelFor(size_t count, int threads, Job job) {
    std::atomic<size_t> next{0};
    auto worker = [&] {
        for (size_t i = next.fetch_add(1); i < count; i = next.fetch_add(1)) job(i);
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads && size_t(t) < count; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
}

} // namespace shadowlab
