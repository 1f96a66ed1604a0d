// The host side the benches share: a frame whose opaque pass is only a clear.
#pragma once

#include <epoxy/gl.h>
#include <glm/glm.hpp>

#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"

namespace bench {

// The opaque pass of a scene without geometry: colour and depth cleared, depth writes on.
inline void clearHost(glm::vec4 colour) {
    glClearColor(colour.r, colour.g, colour.b, colour.a);
    glClearDepth(1.0);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

// The framebuffer with its depth texture, cleared to `colour` as the opaque pass.
inline splatfx::gl::HostTarget clearedTarget(const splatfx::gl::Framebuffer& fb, glm::vec4 colour) {
    splatfx::gl::HostTarget t;
    t.framebuffer = fb.handle();
    t.depthTexture = fb.depthTexture();
    t.drawOpaque = [colour] { clearHost(colour); };
    return t;
}

} // namespace bench
