#pragma once
// The machine's memory and this process's use of it, from /proc (Linux): what a run checks its
// memory plan against (framework/experiment/MemoryPlan.h) and what it reports as measured.
#include <cstddef>

namespace shadowlab {

struct SystemMemory {
    size_t total = 0;     ///< MemTotal, bytes (0: unknown)
    /// What this process can still allocate, bytes: MemAvailable (without swapping), or less where
    /// an address-space limit (ulimit -v: its headroom over VmSize and what the libraries map later,
    /// SystemMemory.cpp) or the cgroup's memory.max
    /// (a container's limit: its headroom over memory.current) leaves less.
    size_t available = 0;
    const char* limitedBy = "";  ///< "" (MemAvailable), "ulimit -v" or "cgroup memory.max"
};
SystemMemory systemMemory();
/// The address space a new thread's stack takes (RLIMIT_STACK, as glibc sizes thread stacks).
size_t threadStackBytes();

/// This process's peak resident set (VmHWM), bytes; 0 when unknown.
size_t peakResidentBytes();
/// This process's resident set now (VmRSS), bytes; 0 when unknown.
size_t residentBytes();

} // namespace shadowlab
