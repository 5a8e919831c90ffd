#pragma once
// Move-only owners of GL object names, and small helpers for buffers and textures.
#include "framework/gl/Gl.h"

#include <cstddef>
#include <utility>
#include <vector>

namespace shadowlab {

template <void (*Delete)(GLuint)>
class GlName {
public:
    GlName() = default;
    explicit GlName(GLuint id) : id_(id) {}
    ~GlName() { reset(); }
    GlName(GlName&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
    GlName& operator=(GlName&& o) noexcept {
        if (this != &o) { reset(); id_ = std::exchange(o.id_, 0); }
        return *this;
    }
    GlName(const GlName&) = delete;
    GlName& operator=(const GlName&) = delete;
    GLuint id() const { return id_; }
    explicit operator bool() const { return id_ != 0; }
    void reset() { if (id_) Delete(id_); id_ = 0; }

private:
    GLuint id_ = 0;
};

namespace gldelete {
inline void buffer(GLuint id) { glDeleteBuffers(1, &id); }
inline void texture(GLuint id) { glDeleteTextures(1, &id); }
inline void framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
inline void vertexArray(GLuint id) { glDeleteVertexArrays(1, &id); }
inline void program(GLuint id) { glDeleteProgram(id); }
inline void query(GLuint id) { glDeleteQueries(1, &id); }
} // namespace gldelete

using GlBufferName = GlName<gldelete::buffer>;
using GlTexture = GlName<gldelete::texture>;
using GlFramebuffer = GlName<gldelete::framebuffer>;
using GlVertexArray = GlName<gldelete::vertexArray>;
using GlProgramName = GlName<gldelete::program>;
using GlQuery = GlName<gldelete::query>;

/// An immutable-storage buffer (glNamedBufferStorage) that knows its size, for memory accounting.
class GlBuffer {
public:
    GlBuffer() = default;
    /// Allocates `bytes` (at least 4, since zero-sized storage is an error) and uploads `data` if given.
    GlBuffer(size_t bytes, const void* data = nullptr, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT);
    template <class T>
    static GlBuffer fromVector(const std::vector<T>& v, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT) {
        return GlBuffer(v.size() * sizeof(T), v.empty() ? nullptr : v.data(), flags);
    }
    GLuint id() const { return name_.id(); }
    size_t size() const { return size_; }
    explicit operator bool() const { return bool(name_); }

    void bindBase(GLenum target, GLuint index) const { glBindBufferBase(target, index, id()); }
    /// Clears to zero with a 32-bit unsigned pattern (GL_RED_INTEGER, as strict drivers require).
    void clearUint(uint32_t value = 0) const;
    void upload(const void* data, size_t bytes, size_t offset = 0) const;
    void download(void* data, size_t bytes, size_t offset = 0) const;
    template <class T>
    std::vector<T> read(size_t count, size_t offset = 0) const {
        std::vector<T> v(count);
        if (count) download(v.data(), count * sizeof(T), offset);
        return v;
    }

private:
    GlBufferName name_;
    size_t size_ = 0;
};

/// GL_MAX_SHADER_STORAGE_BLOCK_SIZE of the current context, in bytes.
size_t maxShaderStorageBlockBytes();

/// A 2D texture with immutable storage.
GlTexture makeTexture2D(GLenum internalFormat, int width, int height, GLenum filter = GL_NEAREST);

/// A buffer texture (GL_TEXTURE_BUFFER) over all of `buffer`, read as texels of `internalFormat`
/// (GL_RGBA32UI, GL_RGBA32F, GL_RGB32F, ...) of `texelBytes` bytes. Kernels read their read-only
/// structures through it: texel fetches take the sampler's gather path, which on a CPU SIMD back end
/// (llvmpipe) is far cheaper than per-lane storage-buffer loads. Throws RuntimeError when the buffer
/// holds more texels than GL_MAX_TEXTURE_BUFFER_SIZE.
GlTexture makeBufferTexture(const GlBuffer& buffer, GLenum internalFormat, size_t texelBytes, const char* what);
/// GL_MAX_TEXTURE_BUFFER_SIZE of the current context: texels one buffer-texture view can address.
size_t maxTextureBufferTexels();

/// Reads a whole single-channel float texture (level 0) into a vector of width*height floats.
std::vector<float> readTextureR32F(GLuint texture, int width, int height);
/// Reads an RGBA float texture into 4*width*height floats.
std::vector<float> readTextureRGBA32F(GLuint texture, int width, int height);
/// Reads an RGBA8 texture into 4*width*height bytes.
std::vector<unsigned char> readTextureRGBA8(GLuint texture, int width, int height);

} // namespace shadowlab
