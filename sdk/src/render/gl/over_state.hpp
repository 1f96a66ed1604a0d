// The GL state every pass composites with: premultiplied "over" into a
// framebuffer, depth never written.
#pragma once

#include "splatfx/camera.hpp"
#include "splatfx/gl/renderer.hpp"

namespace splatfx::gl::detail {

enum class DepthTest { Off, LessEqual, GreaterEqual };
// The host's "in front or equal" test: GEQUAL under a reversed depth convention.
inline DepthTest nearerOrEqual(const Camera& camera) { return camera.depth.reversed ? DepthTest::GreaterEqual : DepthTest::LessEqual; }

// Binds `framebuffer` for drawing with the viewport of `target`, blends
// (ONE, ONE_MINUS_SRC_ALPHA) on colour and alpha with FUNC_ADD, turns depth
// writes off and the depth test to `test` (LessEqual / GreaterEqual, as
// nearerOrEqual() picks for the camera's convention: the host's surfaces
// hide what is behind them; Off: the pass cuts at the host depth itself or
// draws full-screen layers).
void setOverState(unsigned framebuffer, const PassTarget& target, DepthTest test);

} // namespace splatfx::gl::detail
