#include "host_pass.hpp"

#include <cassert>

#include <epoxy/gl.h>

#include "render/gl/context_check.hpp"
#include "render/gl/saved_state.hpp"

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
    if (!contextIsCurrent()) return;
    if (mFbo) glDeleteFramebuffers(1, &mFbo);
    if (mTexture) glDeleteTextures(1, &mTexture);
    if (mSampleFbo) glDeleteFramebuffers(1, &mSampleFbo);
    if (mSampleTexture) glDeleteTextures(1, &mSampleTexture);
    if (mVao) glDeleteVertexArrays(1, &mVao);
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
    // A multisampled depth buffer blits only into one of the same sample count.
    const int copySamples = samples > 1 ? samples : 0;
    GLint bits = 0, component = GL_NONE, stencilType = GL_NONE, stencilBits = 0;
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, depthPoint, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &bits);
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, depthPoint, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &component);
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, stencilPoint, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &stencilType);
    if (stencilType != GL_NONE) glGetNamedFramebufferAttachmentParameteriv(framebuffer, stencilPoint, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE, &stencilBits);
    const GLenum format = matchingFormat(bits, component, stencilBits);
    if (!format)
        return {.missing = "no texture format matches the host framebuffer's depth buffer (" + std::to_string(bits) + " depth bits, " +
                           std::to_string(stencilBits) + " stencil bits) for a copy"};
    if (format != mFormat || width != mWidth || height != mHeight || copySamples != mSamples) {
        if (mFbo) glDeleteFramebuffers(1, &mFbo);
        if (mTexture) glDeleteTextures(1, &mTexture);
        mFbo = mTexture = 0;
        mFormat = 0;
        while (glGetError() != GL_NO_ERROR) {}
        if (copySamples) {
            glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &mTexture);
            glTextureStorage2DMultisample(mTexture, copySamples, format, width, height, GL_TRUE);
        } else {
            glCreateTextures(GL_TEXTURE_2D, 1, &mTexture);
            glTextureStorage2D(mTexture, 1, format, width, height);
            glTextureParameteri(mTexture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTextureParameteri(mTexture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            glTextureParameteri(mTexture, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            glTextureParameteri(mTexture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        }
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
        mFormat = format, mWidth = width, mHeight = height, mSamples = copySamples;
    }
    return {.texture = mTexture, .samples = copySamples, .copied = true, .missing = {}};
}

void HostPass::addSampleTexture(HostDepth& depth, int width, int height) {
    depth.sampleTexture = 0;
    mSource = 0;
    if (!depth.texture || depth.samples <= 1) return;
    if (auto p = mPrograms->get({glsl::ProgramId::DepthSample}); !p) {
        depth.missing = p.error();
        return;
    }
    if (width != mSampleWidth || height != mSampleHeight || !mSampleTexture) {
        if (mSampleFbo) glDeleteFramebuffers(1, &mSampleFbo);
        if (mSampleTexture) glDeleteTextures(1, &mSampleTexture);
        mSampleFbo = mSampleTexture = 0;
        mSampleWidth = mSampleHeight = 0;
        while (glGetError() != GL_NO_ERROR) {}
        // 32-bit float holds every sample of every depth format exactly (what texelFetch returns).
        glCreateTextures(GL_TEXTURE_2D, 1, &mSampleTexture);
        glTextureStorage2D(mSampleTexture, 1, GL_DEPTH_COMPONENT32F, width, height);
        glTextureParameteri(mSampleTexture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(mSampleTexture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glCreateFramebuffers(1, &mSampleFbo);
        glNamedFramebufferTexture(mSampleFbo, GL_DEPTH_ATTACHMENT, mSampleTexture, 0);
        glNamedFramebufferDrawBuffer(mSampleFbo, GL_NONE);
        glNamedFramebufferReadBuffer(mSampleFbo, GL_NONE);
        if (!mVao) glCreateVertexArrays(1, &mVao);
        const GLenum error = glGetError();
        if (error != GL_NO_ERROR || glCheckNamedFramebufferStatus(mSampleFbo, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            glDeleteFramebuffers(1, &mSampleFbo);
            glDeleteTextures(1, &mSampleTexture);
            mSampleFbo = mSampleTexture = 0;
            depth.missing = "the texture a multisampled host depth's samples are read into could not be made (" +
                            std::string(error == GL_OUT_OF_MEMORY ? "GL_OUT_OF_MEMORY" : "an incomplete framebuffer") + ")";
            return;
        }
        mSampleWidth = width, mSampleHeight = height;
    }
    mSource = depth.texture;
    mSourceSamples = depth.samples;
    depth.sampleTexture = mSampleTexture;
}

void HostPass::copySample(const PlanStep& step, StepContext& context) {
    if (!mMaskSaved) {
        mHostSampleMask = glIsEnabled(GL_SAMPLE_MASK);
        mHostMultisample = glIsEnabled(GL_MULTISAMPLE);
        GLint word = -1;
        glGetIntegeri_v(GL_SAMPLE_MASK_VALUE, 0, &word);
        mHostMaskWord = unsigned(word);
        mHostSampleShading = glIsEnabled(GL_SAMPLE_SHADING);
        glGetFloatv(GL_MIN_SAMPLE_SHADING_VALUE, &mHostMinSampleShading);
        mMaskSaved = true;
    }
    ++mSampleSteps;
    auto p = mPrograms->get({glsl::ProgramId::DepthSample});
    if (p && mSource && mSampleFbo) {
        SavedState saved;
        saved.save({.texture2DUnits = 0, .scissor = true});
        GLint hostMs = 0;
        GLdouble range[2] = {0.0, 1.0};
        glGetDoublev(GL_DEPTH_RANGE, range);
        glActiveTexture(GL_TEXTURE0);
        glGetIntegerv(GL_TEXTURE_BINDING_2D_MULTISAMPLE, &hostMs);
        glDisable(GL_SAMPLE_MASK);
        glDisable(GL_SCISSOR_TEST);
        glDisable(GL_BLEND);
        glDisable(GL_CULL_FACE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_ALWAYS);
        glDepthMask(GL_TRUE);
        glDepthRange(0.0, 1.0); // gl_FragDepth is clamped to it: the copy keeps every value
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, mSampleFbo);
        glViewport(0, 0, mSampleWidth, mSampleHeight);
        glUseProgram((*p)->id);
        glUniform1i((*p)->uniform(glsl::depth_sample::Sample), step.sample);
        glUniform1i((*p)->uniform(glsl::depth_sample::Samples), mSourceSamples);
        glUniform1i((*p)->uniform(glsl::depth_sample::Reversed), context.frame.camera().depth.reversed ? 1 : 0);
        glBindVertexArray(mVao);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, mSource);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, glIsTexture(GLuint(hostMs)) ? GLuint(hostMs) : 0u);
        glDepthRange(range[0], range[1]);
        saved.restore();
    }
    if (step.sample >= 0) {
        // The passes until the next step draw into this sample only: each sample is blended with its own depth's result.
        // Shaded at the sample's own position (sample shading): a sample that
        // a polygon covers is evaluated inside it, as a single-sampled frame
        // whose pixel centre were there would (at the pixel centre, the
        // attributes of a splat or tetrahedron would be read past its edge).
        glEnable(GL_MULTISAMPLE);
        glEnable(GL_SAMPLE_MASK);
        glSampleMaski(0, 1u << unsigned(step.sample));
        glEnable(GL_SAMPLE_SHADING);
        glMinSampleShading(1.0f);
    } else {
        if (mHostSampleShading) glEnable(GL_SAMPLE_SHADING);
        else glDisable(GL_SAMPLE_SHADING);
        glMinSampleShading(mHostMinSampleShading);
        if (mHostSampleMask) glEnable(GL_SAMPLE_MASK);
        else glDisable(GL_SAMPLE_MASK);
        if (mHostMultisample) glEnable(GL_MULTISAMPLE);
        else glDisable(GL_MULTISAMPLE);
        glSampleMaski(0, mHostMaskWord);
        mMaskSaved = false;
    }
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
    if (step.kind == StepKind::HostDepthSample) {
        copySample(step, context);
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
    mSampleSteps = 0;
    mMaskSaved = false;
}

void HostPass::report(FrameRenderStats& stats) const {
    stats.hostDepthCopied = mCopied && mCopyError.empty();
    stats.msaa.sampleCopies = mSampleSteps;
    if (!mCopyError.empty()) stats.notes.push_back(mCopyError);
}

} // namespace splatfx::gl::detail
