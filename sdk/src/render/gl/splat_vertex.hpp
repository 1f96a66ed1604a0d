// The Splat struct (splats.hpp) as splat.vert's per-instance vertex inputs:
// the one vertex layout of the splat pass and the fragment lists' sections.
#pragma once

namespace splatfx::gl::detail {

// Sets `vao`'s attributes 0-5 to read one Splat per instance from binding 0
// (the caller attaches the buffer with glVertexArrayVertexBuffer, stride sizeof(Splat)).
void setSplatVertexLayout(unsigned vao);

} // namespace splatfx::gl::detail
