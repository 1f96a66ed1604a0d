#include "host_pass.hpp"

#include <cassert>

#include <epoxy/gl.h>

namespace splatfx::gl::detail {
namespace {

// The texture format a depth buffer of these sizes and type blits into: a
// depth blit needs the source's and destination's depth and stencil formats
// to be the same. 0 when none is.
GLenum matchingFormat(GLint depthBits, GLint componentType, GLint stencilBits) {
    const bool stencil = stencilBits > 0;
    if (stencilBits != 0 && stencilBits != 8) return 0;
    if (componentType == GL_FLOAT) return depthBits == 32 ? (stencil ? GL_DEPTH32F_STENCIL8 : GL_DEPTH_COMPONENT32F) : 0;
    switch (depthBits) {
    case 16: return stencil ? 0 : GL_DEPTH_COMPONENT16;
    case 24: return stencil ? GL_DEPTH24_STENCIL8 : GL_DEPTH_COMPONENT24;
    case 32: return stencil ? 0 : GL_DEPTH_COMPONENT32;
    default: return 0;
    }
}

} // namespace

HostPass::~HostPass() {
    if (mFbo) glDeleteFramebuffers(1, &mFbo);
    if (mTexture) glDeleteTextures(1, &mTexture);
}

HostDepth HostPass::depthCopy(unsigned framebuffer, int width, int height) {
    const GLenum depthPoint = framebuffer == 0 ? GL_DEPTH : GL_DEPTH_ATTACHMENT;
    const GLenum stencilPoint = framebuffer == 0 ? GL_STENCIL : GL_STENCIL_ATTACHMENT;
    GLint type = GL_NONE;
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, depthPoint, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
    // A context without a default framebuffer (surfaceless) answers with an error: no depth
    // either way, and the error must not reach a later pass's own check.
    while (glGetError() != GL_NO_ERROR) {}
    if (type == GL_NONE) return {.missing = "the host framebuffer has no depth buffer"};
    GLint samples = 0;
    glGetNamedFramebufferParameteriv(framebuffer, GL_SAMPLES, &samples);
    if (samples > 1)
        return {.missing = "the host framebuffer's depth buffer is multisampled (" + std::to_string(samples) +
                           " samples): resolve it into a single-sample depth texture (HostTarget::depthTexture)"};
    GLint bits = 0, component = GL_NONE, stencilType = GL_NONE, stencilBits = 0;
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, depthPoint, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &bits);
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, depthPoint, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &component);
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, stencilPoint, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &stencilType);
    if (stencilType != GL_NONE) glGetNamedFramebufferAttachmentParameteriv(framebuffer, stencilPoint, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE, &stencilBits);
    const GLenum format = matchingFormat(bits, component, stencilBits);
    if (!format)
        return {.missing = "no texture format matches the host framebuffer's depth buffer (" + std::to_string(bits) + " depth bits, " +
                           std::to_string(stencilBits) + " stencil bits) for a copy"};
    if (format != mFormat || width != mWidth || height != mHeight) {
        if (mFbo) glDeleteFramebuffers(1, &mFbo);
        if (mTexture) glDeleteTextures(1, &mTexture);
        mFbo = mTexture = 0;
        mFormat = 0;
        while (glGetError() != GL_NO_ERROR) {}
        glCreateTextures(GL_TEXTURE_2D, 1, &mTexture);
        glTextureStorage2D(mTexture, 1, format, width, height);
        glTextureParameteri(mTexture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(mTexture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTextureParameteri(mTexture, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTextureParameteri(mTexture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glCreateFramebuffers(1, &mFbo);
        glNamedFramebufferTexture(mFbo, stencilBits > 0 ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT, mTexture, 0);
        glNamedFramebufferDrawBuffer(mFbo, GL_NONE);
        glNamedFramebufferReadBuffer(mFbo, GL_NONE);
        const GLenum error = glGetError();
        if (error != GL_NO_ERROR || glCheckNamedFramebufferStatus(mFbo, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            glDeleteFramebuffers(1, &mFbo);
            glDeleteTextures(1, &mTexture);
            mFbo = mTexture = 0;
            return {.missing = "the copy of the host depth could not be made (" +
                               std::string(error == GL_OUT_OF_MEMORY ? "GL_OUT_OF_MEMORY" : "an incomplete framebuffer") + ")"};
        }
        mFormat = format, mWidth = width, mHeight = height;
    }
    return {.texture = mTexture, .samples = 0, .copied = true, .missing = {}};
}

void HostPass::execute(const PlanStep& step, StepContext& context) {
    const PassTarget& t = context.plan.target;
    if (step.kind == StepKind::CopyHostDepth) {
        // The blit obeys the scissor test: off for the copy, as the host had it after.
        const GLboolean scissor = glIsEnabled(GL_SCISSOR_TEST);
        glDisable(GL_SCISSOR_TEST);
        while (glGetError() != GL_NO_ERROR) {}
        glBlitNamedFramebuffer(t.framebuffer, mFbo, t.x, t.y, t.x + t.width, t.y + t.height, t.x, t.y, t.x + t.width, t.y + t.height,
                               GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        const GLenum error = glGetError();
        if (scissor) glEnable(GL_SCISSOR_TEST);
        mCopied = true;
        mCopyError = error == GL_NO_ERROR ? std::string() : "copying the host depth buffer failed (GL error " + std::to_string(error) +
                                                                "): the passes that read it read the previous frame's";
        return;
    }
    assert(step.kind == StepKind::HostOpaque || step.kind == StepKind::HostTransparent);
    glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
    glViewport(t.x, t.y, t.width, t.height);
    if (step.kind == StepKind::HostOpaque) context.host.drawOpaque();
    else context.host.drawTransparent();
}

void HostPass::prepare(const FramePlan&, const Frame&) {
    mCopied = false;
    mCopyError.clear();
}

void HostPass::report(FrameRenderStats& stats) const {
    stats.hostDepthCopied = mCopied && mCopyError.empty();
    if (!mCopyError.empty()) stats.notes.push_back(mCopyError);
}

} // namespace splatfx::gl::detail
