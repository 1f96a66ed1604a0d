// The splat vertex layout (splat_vertex.hpp).
#include "splat_vertex.hpp"

#include <cstddef>

#include <epoxy/gl.h>

#include "splatfx/splats.hpp"

namespace splatfx::gl::detail {

void setSplatVertexLayout(unsigned vao) {
    glVertexArrayBindingDivisor(vao, 0, 1);
    // glsl/splat.vert's inputs: three vec4s, the layer pair as two u16, blend, and the RGBA8 colour.
    for (GLuint a = 0; a < 3; ++a) glVertexArrayAttribFormat(vao, a, 4, GL_FLOAT, GL_FALSE, a * 16);
    glVertexArrayAttribIFormat(vao, 3, 2, GL_UNSIGNED_SHORT, offsetof(Splat, layer));
    glVertexArrayAttribFormat(vao, 4, 1, GL_FLOAT, GL_FALSE, offsetof(Splat, blend));
    glVertexArrayAttribFormat(vao, 5, 4, GL_UNSIGNED_BYTE, GL_TRUE, offsetof(Splat, color));
    for (GLuint a = 0; a < 6; ++a) {
        glEnableVertexArrayAttrib(vao, a);
        glVertexArrayAttribBinding(vao, a, 0);
    }
}

} // namespace splatfx::gl::detail
