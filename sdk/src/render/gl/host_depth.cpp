#include "host_depth.hpp"

#include <epoxy/gl.h>

#include "context_check.hpp"
#include "splatfx/gl/frame_renderer.hpp"

namespace splatfx::gl {

Result<DepthConvention> depthConventionOfContext(const glm::mat4& proj) {
    if (!detail::contextIsCurrent()) return makeError("depthConventionOfContext: no OpenGL context is current");
    GLint origin = GL_LOWER_LEFT, mode = GL_NEGATIVE_ONE_TO_ONE;
    glGetIntegerv(GL_CLIP_ORIGIN, &origin);
    glGetIntegerv(GL_CLIP_DEPTH_MODE, &mode);
    if (origin != GL_LOWER_LEFT)
        return makeError("depthConventionOfContext: GL_CLIP_ORIGIN is GL_UPPER_LEFT, which splatfx does not support (flip y in the projection instead)");
    return conventionOfProjection(proj, mode == GL_ZERO_TO_ONE ? ClipDepth::ZeroToOne : ClipDepth::MinusOneToOne);
}

} // namespace splatfx::gl

namespace splatfx::gl::detail {

std::string depthConventionNote(const Camera& camera) {
    const DepthConvention& c = camera.depth;
    GLint origin = GL_LOWER_LEFT, mode = GL_NEGATIVE_ONE_TO_ONE;
    glGetIntegerv(GL_CLIP_ORIGIN, &origin);
    glGetIntegerv(GL_CLIP_DEPTH_MODE, &mode);
    const ClipDepth context = mode == GL_ZERO_TO_ONE ? ClipDepth::ZeroToOne : ClipDepth::MinusOneToOne;
    std::string note;
    if (context != c.clip)
        note = std::string("depth convention: Camera::depth has clip depth ") + (c.clip == ClipDepth::ZeroToOne ? "[0,1]" : "[-1,1]") +
               " but the context's glClipControl depth mode is " + (context == ClipDepth::ZeroToOne ? "GL_ZERO_TO_ONE" : "GL_NEGATIVE_ONE_TO_ONE") +
               " (the host depth is read as the camera says, splatfx's own geometry clipped as the context says)";
    else if (origin != GL_LOWER_LEFT)
        note = "depth convention: the context's GL_CLIP_ORIGIN is GL_UPPER_LEFT, which splatfx does not support (flip y in the projection)";
    else if (conventionOfProjection(camera.proj, c.clip).reversed != c.reversed)
        note = std::string("depth convention: Camera::depth.reversed is ") + (c.reversed ? "true" : "false") + " but the camera's projection is " +
               (c.reversed ? "not reversed" : "reversed") + " (the depth test and the farthest depth of a block follow Camera::depth)";
    return note;
}

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
    return {.texture = texture, .samples = samples, .copied = false, .missing = {}};
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
