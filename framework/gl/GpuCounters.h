#pragma once
// A block of 32-bit per-frame statistics gathered by shaders (atomics into an SSBO), read back to
// the CPU at most once per frame, and only when someone asks (counters(), overflowCount()), so an
// algorithm's timed stages never wait for a download.
#include "framework/gl/GlObjects.h"

#include <array>
#include <cstdint>

namespace shadowlab {

template <size_t Words>
class GpuCounters {
public:
    static constexpr size_t kBytes = Words * sizeof(uint32_t);

    /// (Re)creates the buffer, zeroed.
    void allocate() {
        buffer_ = GlBuffer(kBytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
        clear();
        values_.fill(0);
    }
    /// Zeroes every word on the GPU (start of a frame).
    void clear() {
        buffer_.clearUint(0);
        stale_ = true;
    }
    /// The shaders of this frame have written: the next read() downloads.
    void markStale() { stale_ = true; }
    /// The values after the last frame (downloaded on the first call after markStale()).
    const std::array<uint32_t, Words>& read() const {
        if (stale_ && buffer_) {
            buffer_.download(values_.data(), kBytes);
            stale_ = false;
        }
        return values_;
    }
    uint32_t operator[](size_t word) const { return read()[word]; }
    /// A 64-bit count kept in two words, low word at `lo` (the shaders carry into `lo + 1`).
    uint64_t wide(size_t lo) const { return (uint64_t(read()[lo + 1]) << 32) | read()[lo]; }

    const GlBuffer& buffer() const { return buffer_; }
    GLuint id() const { return buffer_.id(); }
    size_t size() const { return buffer_.size(); }
    explicit operator bool() const { return bool(buffer_); }
    void bindBase(GLenum target, GLuint index) const { buffer_.bindBase(target, index); }
    void upload(const void* data, size_t bytes, size_t offset = 0) {
        buffer_.upload(data, bytes, offset);
        stale_ = true;
    }

private:
    GlBuffer buffer_;
    mutable std::array<uint32_t, Words> values_{};
    mutable bool stale_ = true;
};

} // namespace shadowlab
