// Shader programs for the GL backend (private).
#pragma once

#include <initializer_list>

#include <epoxy/gl.h>

#include "splatfx/result.hpp"

namespace splatfx::gl::detail {

// Compiles and links a vertex + fragment program. Each stage's source may be
// given in pieces (e.g. "#version", "#define", body). On failure the message
// starts with `what` and names the stage, with the driver's log.
Result<GLuint> linkProgram(std::initializer_list<const char*> vertex, std::initializer_list<const char*> fragment, const char* what);

} // namespace splatfx::gl::detail
