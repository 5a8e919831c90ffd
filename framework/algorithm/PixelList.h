#pragma once
// Pixels one per-pixel pass hands to a second, slower pass (close calls decided by a ray): the
// first lists them (pixelListAppend, shaders/common/pixel_list.glsl), the second runs one
// invocation per listed pixel through an indirect dispatch sized on the GPU (no readback). The list
// holds every pixel once, so a first pass that lists each pixel at most once cannot overflow it.
#include "framework/gl/Shader.h"

#include <glm/glm.hpp>
#include <string>

namespace shadowlab {

class PixelList {
public:
    /// The list is the storage block at `listBinding`, the second pass's grid is written to
    /// `argsBinding` (both the algorithm's own binding points).
    void compile(GLuint listBinding, GLuint argsBinding) {
        listBinding_ = listBinding;
        argsBinding_ = argsBinding;
        argsPass_ = ShaderProgram::compute("common/pixel_list_args.comp",
                                           {{"PIXEL_LIST_BINDING", std::to_string(listBinding)},
                                            {"PIXEL_LIST_ARGS_BINDING", std::to_string(argsBinding)}});
    }
    /// Room for every pixel of `resolution` once (x and y below 65,536, which GL_MAX_TEXTURE_SIZE
    /// keeps them).
    void resize(glm::ivec2 resolution) {
        list_ = GlBuffer((size_t(resolution.x) * size_t(resolution.y) + 1) * sizeof(uint32_t));
        if (!args_) args_ = GlBuffer(3 * sizeof(uint32_t), nullptr, 0);
    }
    /// Empties the list and binds it for the pass that fills it.
    void begin() const {
        const uint32_t noEntries = 0;
        glNamedBufferSubData(list_.id(), 0, sizeof(noEntries), &noEntries);
        list_.bindBase(GL_SHADER_STORAGE_BUFFER, listBinding_);
    }
    /// Runs `pass` (local size PIXEL_LIST_GROUP; it reads its pixel with pixelListEntry) once per
    /// listed pixel, after the filling pass's writes.
    void dispatch(const ShaderProgram& pass) const {
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        list_.bindBase(GL_SHADER_STORAGE_BUFFER, listBinding_);
        args_.bindBase(GL_SHADER_STORAGE_BUFFER, argsBinding_);
        argsPass_.use();
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
        pass.use();
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, args_.id());
        glDispatchComputeIndirect(0);
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
    }
    size_t bytes() const { return list_.size() + args_.size(); }

private:
    GlBuffer list_, args_;
    ShaderProgram argsPass_;
    GLuint listBinding_ = 0, argsBinding_ = 0;
};

} // namespace shadowlab
