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

glm::vec3 hostDepthMap(const Camera& camera) {
    const DepthUnprojection u = depthUnprojection(camera);
    return {float(u.ends.x), float(u.ends.y), u.perspective ? 1.0f : 0.0f};
}

glm::vec2 generalNdcZ(const Camera& camera) {
    const DepthConvention& c = camera.depth;
    const double inward = c.farNdc() > c.nearNdc() ? 1.0 : -1.0;
    // (ndc z - A) depth = B for ndc = A + B / depth (perspective): at 1024 near when the far end is at infinity.
    double rayZ = c.farNdc();
    const glm::dmat4 P(camera.proj);
    if (camera.perspective() && P[2][2] / P[2][3] == rayZ) {
        const double depth = 1024.0 * double(camera.nearPlane());
        rayZ = P[2][2] / P[2][3] - P[3][2] / (P[2][3] * depth);
    }
    return {float(c.nearNdc() + inward * 1e-5), float(rayZ)};
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
