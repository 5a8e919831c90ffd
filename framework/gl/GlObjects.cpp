#include "framework/gl/GlObjects.h"

#include "framework/core/Error.h"

#include <string>

#include <algorithm>

namespace shadowlab {

GlBuffer::GlBuffer(size_t bytes, const void* data, GLbitfield flags) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    name_ = GlBufferName(id);
    size_ = std::max<size_t>(bytes, 4);
    if (data && bytes < size_) {
        std::vector<unsigned char> padded(size_, 0);
        std::copy_n(static_cast<const unsigned char*>(data), bytes, padded.data());
        glNamedBufferStorage(id, GLsizeiptr(size_), padded.data(), flags);
    } else {
        glNamedBufferStorage(id, GLsizeiptr(size_), data, flags);
    }
}

void GlBuffer::clearUint(uint32_t value) const {
    glClearNamedBufferData(id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
}

void GlBuffer::upload(const void* data, size_t bytes, size_t offset) const {
    glNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), data);
}

void GlBuffer::download(void* data, size_t bytes, size_t offset) const {
    glGetNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), data);
}

GlTexture makeTexture2D(GLenum internalFormat, int width, int height, GLenum filter) {
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &id);
    glTextureStorage2D(id, 1, internalFormat, width, height);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, filter);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, filter);
    glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return GlTexture(id);
}

size_t maxTextureBufferTexels() {
    GLint maxTexels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &maxTexels);
    return size_t(std::max(maxTexels, 0));
}

GlTexture makeBufferTexture(const GlBuffer& buffer, GLenum internalFormat, size_t texelBytes, const char* what) {
    const size_t maxTexels = maxTextureBufferTexels();
    const size_t texels = buffer.size() / texelBytes;
    if (texels > maxTexels)
        throw RuntimeError(std::string(what) + ": " + std::to_string(texels) + " texels exceed this context's " +
                           "GL_MAX_TEXTURE_BUFFER_SIZE (" + std::to_string(maxTexels) + ")");
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &id);
    glTextureBuffer(id, internalFormat, buffer.id());
    return GlTexture(id);
}

std::vector<float> readTextureR32F(GLuint texture, int width, int height) {
    std::vector<float> out(size_t(width) * height);
    glGetTextureImage(texture, 0, GL_RED, GL_FLOAT, GLsizei(out.size() * sizeof(float)), out.data());
    return out;
}

std::vector<float> readTextureRGBA32F(GLuint texture, int width, int height) {
    std::vector<float> out(size_t(width) * height * 4);
    glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, GLsizei(out.size() * sizeof(float)), out.data());
    return out;
}

std::vector<unsigned char> readTextureRGBA8(GLuint texture, int width, int height) {
    std::vector<unsigned char> out(size_t(width) * height * 4);
    glGetTextureImage(texture, 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(out.size()), out.data());
    return out;
}

size_t maxShaderStorageBlockBytes() {
    GLint64 v = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &v);
    return size_t(v);
}

} // namespace shadowlab
