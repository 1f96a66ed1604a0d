// splatfx/gl/framebuffer.hpp: an offscreen colour + depth target (for headless use, tests, tools).
//
// Hosts normally draw into their own framebuffer; this one exists so the
// samples, tools and tests can render without a window and read pixels back.
//
//   auto fb = splatfx::gl::Framebuffer::create({.width = 640, .height = 480});
//   fb->clear({0, 0, 0, 1});
//   ... draw ...
//   splatfx::Image img = fb->read();
//
// Threading: GL thread only. Move-only.
#pragma once

#include <glm/glm.hpp>

#include "splatfx/image.hpp"
#include "splatfx/result.hpp"

namespace splatfx::gl {

enum class Precision { U8, F16, F32 };

struct FramebufferDesc {
    int width = 640;                 // default 640
    int height = 480;                // default 480
    Precision color = Precision::U8; // colour attachment format; default RGBA8
    bool floatDepth = false;         // depth attachment DEPTH_COMPONENT32F (reverse-Z hosts) instead of DEPTH_COMPONENT24; default false
    // 0 or 1: single-sampled; 2, 4, 8 or 16 (up to GL_MAX_SAMPLES): colour
    // and depth multisampled (MSAA), read() resolves. Default 0.
    int samples = 0;
    // Colour GL_SRGB8_ALPHA8 (with color U8): draw with GL_FRAMEBUFFER_SRGB on
    // and GL blends in linear and stores sRGB; read() returns the stored
    // (sRGB-encoded) values. Default false.
    bool srgb = false;
};

class Framebuffer {
public:
    static Result<Framebuffer> create(const FramebufferDesc& desc);
    Framebuffer(Framebuffer&&) noexcept;
    Framebuffer& operator=(Framebuffer&&) noexcept;
    ~Framebuffer();

    unsigned handle() const { return mFbo; }
    int width() const { return mDesc.width; }
    int height() const { return mDesc.height; }
    // The depth attachment, a DEPTH_COMPONENT24 (or 32F) texture, multisampled with samples > 1 (HostTarget::depthTexture).
    unsigned depthTexture() const { return mDepth; }
    void clear(glm::vec4 color, float depth = 1.0f);
    // RGBA float, top row first (flipped from GL's bottom-up order).
    Image read() const;
    // Depth values in [0, 1], top row first, one channel (single-sampled
    // only: an empty image when multisampled).
    Image readDepth() const;

private:
    Framebuffer() = default;
    FramebufferDesc mDesc;
    unsigned mFbo = 0, mColor = 0, mDepth = 0;
    unsigned mResolveFbo = 0, mResolved = 0; // multisampled: the single-sampled colour read() resolves into
};

} // namespace splatfx::gl
