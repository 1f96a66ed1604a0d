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
    // The depth attachment, a DEPTH_COMPONENT24 (or 32F) texture (HostTarget::depthTexture).
    unsigned depthTexture() const { return mDepth; }
    void clear(glm::vec4 color, float depth = 1.0f);
    // RGBA float, top row first (flipped from GL's bottom-up order).
    Image read() const;
    // Depth values in [0, 1], top row first, one channel.
    Image readDepth() const;

private:
    Framebuffer() = default;
    FramebufferDesc mDesc;
    unsigned mFbo = 0, mColor = 0, mDepth = 0;
};

} // namespace splatfx::gl
