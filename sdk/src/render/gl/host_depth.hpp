// The one lookup of the host's depth texture (frame_plan.hpp, HostDepth).
#pragma once

#include "splatfx/gl/frame_plan.hpp"

namespace splatfx::gl::detail {

// `texture` if non-zero, else the texture behind `framebuffer`'s depth
// attachment (the default framebuffer's depth is never one); with its sample count.
HostDepth queryHostDepth(unsigned framebuffer, unsigned texture);

// A bare renderer's target with its depth looked up: single-sampled, or 0.
PassTarget resolveTarget(const PassTarget& target);

} // namespace splatfx::gl::detail
