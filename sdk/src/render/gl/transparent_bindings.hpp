// Where the fragment lists' storage is bound while the host's transparent
// hook and the lists' passes run (FragmentListPass). The GLSL side is
// glsl/transparent_lists.glsl (SPLATFX_NODE_BINDING, SPLATFX_COUNTER_BINDING,
// SPLATFX_HEAD_UNIT); the build-time GLSL check (sdk/glsl_check) fails when
// the two disagree. Plain constants: no GL header.
#pragma once

namespace splatfx::gl::detail {

inline constexpr int kTransparentNodeBinding = 6;    // shader storage buffer: the node pool
inline constexpr int kTransparentCounterBinding = 7; // shader storage buffer: counters and the viewport
inline constexpr int kTransparentHeadImageUnit = 6;  // image unit: the surface list heads (r32ui)

} // namespace splatfx::gl::detail
