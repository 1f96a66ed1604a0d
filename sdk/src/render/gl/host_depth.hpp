// The one lookup of the host's depth texture (frame_plan.hpp, HostDepth).
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "splatfx/camera.hpp"
#include "splatfx/gl/frame_plan.hpp"

namespace splatfx::gl::detail {

// `texture` if non-zero, else the texture behind `framebuffer`'s depth
// attachment (the default framebuffer's depth is never one); with its sample count.
HostDepth queryHostDepth(unsigned framebuffer, unsigned texture);

// A bare renderer's target with its depth looked up: single-sampled, or 0.
PassTarget resolveTarget(const PassTarget& target);

// Empty, or a line for FrameRenderStats::notes saying how the camera's depth
// convention disagrees with the current context's glClipControl or with its
// own projection (the host depth is then read other than it was written).
std::string depthConventionNote(const Camera& camera);

// host_depth.glsl's uHostDepthMap for `camera` (depthUnprojection rounded to
// float once): every pass that reads the host depth sets it from here.
glm::vec3 hostDepthMap(const Camera& camera);
// splat.vert / splat_plane.glsl's uNdcZ: the general variant's screen-covering
// polygon just inside the near plane, and a finite point beyond it on each
// pixel's ray (the far plane's when finite).
glm::vec2 generalNdcZ(const Camera& camera);

} // namespace splatfx::gl::detail
