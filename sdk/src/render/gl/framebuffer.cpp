#include "splatfx/gl/framebuffer.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <utility>

#include "context_check.hpp"
#include "formats.hpp"

namespace splatfx::gl {

Result<Framebuffer> Framebuffer::create(const FramebufferDesc& desc) {
    if (!detail::contextIsCurrent()) return makeError("splatfx::gl::Framebuffer::create: no OpenGL context is current");
    if (desc.width <= 0 || desc.height <= 0 || desc.width > 16384 || desc.height > 16384)
        return makeError("FramebufferDesc size " + std::to_string(desc.width) + "x" + std::to_string(desc.height) +
                         " must be between 1 and 16384 on each side");
    GLint maxSamples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
    if (desc.samples < 0 || desc.samples > 16 || (desc.samples > 1 && (desc.samples & (desc.samples - 1)) != 0))
        return makeError("FramebufferDesc::samples must be 0, 1, 2, 4, 8 or 16, got " + std::to_string(desc.samples));
    if (desc.samples > maxSamples)
        return makeError("FramebufferDesc::samples " + std::to_string(desc.samples) + " is above this driver's GL_MAX_SAMPLES (" +
                         std::to_string(maxSamples) + ")");
    if (desc.srgb && desc.color != Precision::U8) return makeError("FramebufferDesc::srgb needs color Precision::U8 (GL_SRGB8_ALPHA8)");
    Framebuffer fb;
    fb.mDesc = desc;
    const GLenum format = desc.srgb ? GL_SRGB8_ALPHA8 : detail::colorFormat(desc.color);
    const GLenum depthFormat = desc.floatDepth ? GL_DEPTH_COMPONENT32F : GL_DEPTH_COMPONENT24;
    if (desc.samples > 1) {
        glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &fb.mColor);
        glTextureStorage2DMultisample(fb.mColor, desc.samples, format, desc.width, desc.height, GL_TRUE);
        glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &fb.mDepth);
        glTextureStorage2DMultisample(fb.mDepth, desc.samples, depthFormat, desc.width, desc.height, GL_TRUE);
        glCreateTextures(GL_TEXTURE_2D, 1, &fb.mResolved);
        glTextureStorage2D(fb.mResolved, 1, format, desc.width, desc.height);
        glCreateFramebuffers(1, &fb.mResolveFbo);
        glNamedFramebufferTexture(fb.mResolveFbo, GL_COLOR_ATTACHMENT0, fb.mResolved, 0);
    } else {
        glCreateTextures(GL_TEXTURE_2D, 1, &fb.mColor);
        glTextureStorage2D(fb.mColor, 1, format, desc.width, desc.height);
        glCreateTextures(GL_TEXTURE_2D, 1, &fb.mDepth);
        glTextureStorage2D(fb.mDepth, 1, depthFormat, desc.width, desc.height);
    }
    glCreateFramebuffers(1, &fb.mFbo);
    glNamedFramebufferTexture(fb.mFbo, GL_COLOR_ATTACHMENT0, fb.mColor, 0);
    glNamedFramebufferTexture(fb.mFbo, GL_DEPTH_ATTACHMENT, fb.mDepth, 0);
    if (glCheckNamedFramebufferStatus(fb.mFbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return makeError("offscreen framebuffer is incomplete for this colour format");
    return fb;
}

Framebuffer::Framebuffer(Framebuffer&& o) noexcept { *this = std::move(o); }
Framebuffer& Framebuffer::operator=(Framebuffer&& o) noexcept {
    std::swap(mDesc, o.mDesc);
    std::swap(mFbo, o.mFbo);
    std::swap(mColor, o.mColor);
    std::swap(mDepth, o.mDepth);
    std::swap(mResolveFbo, o.mResolveFbo);
    std::swap(mResolved, o.mResolved);
    return *this;
}
Framebuffer::~Framebuffer() {
    if (!detail::contextIsCurrent()) return; // the context, and our objects with it, are already gone
    if (mFbo) glDeleteFramebuffers(1, &mFbo);
    if (mColor) glDeleteTextures(1, &mColor);
    if (mDepth) glDeleteTextures(1, &mDepth);
    if (mResolveFbo) glDeleteFramebuffers(1, &mResolveFbo);
    if (mResolved) glDeleteTextures(1, &mResolved);
}

void Framebuffer::clear(glm::vec4 color, float depth) {
    glClearNamedFramebufferfv(mFbo, GL_COLOR, 0, &color.x);
    glClearNamedFramebufferfv(mFbo, GL_DEPTH, 0, &depth);
}

namespace {
Image readBack(GLuint tex, int w, int h, GLenum format, int channels) {
    Image img;
    img.width = w;
    img.height = h;
    img.channels = channels;
    std::vector<float> rows(size_t(w) * h * channels);
    glGetTextureImage(tex, 0, format, GL_FLOAT, GLsizei(rows.size() * sizeof(float)), rows.data());
    img.pixels.resize(rows.size());
    const size_t stride = size_t(w) * channels;
    for (int y = 0; y < h; ++y) std::copy_n(&rows[size_t(h - 1 - y) * stride], stride, &img.pixels[size_t(y) * stride]);
    return img;
}
} // namespace

Image Framebuffer::read() const {
    if (!mResolveFbo) return readBack(mColor, mDesc.width, mDesc.height, GL_RGBA, 4);
    // The resolve (the mean of each pixel's samples) obeys the scissor test: off for it, as the caller had it after.
    const GLboolean scissor = glIsEnabled(GL_SCISSOR_TEST);
    glDisable(GL_SCISSOR_TEST);
    glBlitNamedFramebuffer(mFbo, mResolveFbo, 0, 0, mDesc.width, mDesc.height, 0, 0, mDesc.width, mDesc.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    if (scissor) glEnable(GL_SCISSOR_TEST);
    return readBack(mResolved, mDesc.width, mDesc.height, GL_RGBA, 4);
}
Image Framebuffer::readDepth() const {
    if (mResolveFbo) return {};
    return readBack(mDepth, mDesc.width, mDesc.height, GL_DEPTH_COMPONENT, 1);
}

} // namespace splatfx::gl
