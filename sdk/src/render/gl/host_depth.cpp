#include "host_depth.hpp"

#include <epoxy/gl.h>

namespace splatfx::gl::detail {

HostDepth queryHostDepth(unsigned framebuffer, unsigned texture) {
    if (!texture && framebuffer != 0) {
        GLint type = GL_NONE, name = 0;
        glGetNamedFramebufferAttachmentParameteriv(framebuffer, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
        if (type == GL_TEXTURE)
            glGetNamedFramebufferAttachmentParameteriv(framebuffer, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &name);
        texture = unsigned(name);
    }
    if (!texture) return {};
    GLint samples = 0;
    glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_SAMPLES, &samples);
    return {.texture = texture, .samples = samples};
}

PassTarget resolveTarget(const PassTarget& target) {
    const HostDepth depth = queryHostDepth(target.framebuffer, target.depthTexture);
    return {.framebuffer = target.framebuffer,
            .x = target.x,
            .y = target.y,
            .width = target.width,
            .height = target.height,
            .depthTexture = depth.samples > 1 ? 0u : depth.texture};
}

} // namespace splatfx::gl::detail
