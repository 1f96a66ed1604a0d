// splatfx/transparency.hpp: the GLSL include through which a host's
// transparent surfaces join the frame's per-pixel fragment lists.
//
// With HostTarget::transparentToLists set, gl::FrameRenderer runs the host's
// transparent hook with the lists bound; every fragment of the host's
// transparent surfaces calls splatfx_emitTransparent() (from the source
// transparentGlsl() returns) with its premultiplied colour and window depth.
// The splats are then inserted cut into sections at those depths (Ebert &
// Parent 1990, Fig. 1: in front of, between and behind the surfaces) and a
// resolve pass sorts every pixel's list and composites it over the opaque
// image. See docs/integration.md, "Transparent surfaces".
// It does not draw, bind or allocate anything (gl::FrameRenderer does), and
// it is GL-free: the text is plain GLSL for the host to compile.
//
//   std::string fs = "#version 450 core\n" + splatfx::transparentGlsl() + myBody;
//   // in myBody:  oColour = splatfx_emitTransparent(premultipliedColour, gl_FragCoord.z);
//   frameRenderer->render(frame, {.drawTransparent = drawGlass, .transparentToLists = true});
//
// Threading: pure functions; any thread.
#pragma once

#include <cstddef>
#include <string>

namespace splatfx {

// Bytes one surface node takes on the GPU: premultiplied RGBA as four
// halves (8), the window depth (4), the link (4).
inline constexpr std::size_t kTransparentNodeBytes = 16;
// Bytes per pixel beside the nodes: the list head.
inline constexpr std::size_t kTransparentHeadBytesPerPixel = 4;
// The splats are not stored per fragment: each pixel's splat sections (in
// front of, between and behind its surfaces: Ebert & Parent 1990, Fig. 1)
// are composited in the splats' back-to-front order into one RGBA16F target
// per section, at most this many (so 7 surfaces on one pixel are exact; the
// gas behind more is merged into the last section and counted).
inline constexpr int kTransparentMaxSections = 8;
inline constexpr std::size_t kTransparentSectionBytesPerPixel = 8; // per section target in use

// GLSL (no #version; needs 4.3+, written for 4.50 core) declaring the lists
// and
//   vec4 splatfx_emitTransparent(vec4 premultipliedColour, float windowDepth)
// which appends one node to this pixel's surface list and returns vec4(0);
// when the frame's node pool is full it stores nothing, counts the fragment
// (FrameRenderStats::transparentFallback) and returns the colour itself, so
// a shader that writes the result with premultiplied blending (the state the
// frame renderer sets before the hook) blends it into the image instead: the
// ordered blend for that fragment, never a silent drop. windowDepth is
// gl_FragCoord.z (or any value in [0, 1] in the same mapping). Fragments of
// zero colour and zero alpha are not stored (they change nothing). It also
// declares layout(early_fragment_tests), so the host's opaque depth hides
// transparent fragments behind it before they are stored. The storage's
// binding points are written in the text (the frame renderer binds them only
// while the transparent hook runs, and restores them after): the host binds
// nothing.
std::string transparentGlsl();

} // namespace splatfx
