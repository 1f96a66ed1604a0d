// splatfx/gl/program.hpp: one vertex + fragment (or compute) shader program,
// compiled and linked with both steps checked.
//
// The GL backend builds its programs with it, and hosts (the samples'
// geometry, the benchmarks' probes, the tests' stand-in hosts) may use it for
// theirs, so that a shader that fails to compile or link is an error with the
// driver's log, never a silent program 0. It does not cache programs, look up
// uniforms or check the context version.
//
//   auto program = splatfx::gl::linkProgram({"#version 450 core\n", vsBody}, {"#version 450 core\n", fsBody}, "my pass");
//   if (!program) return fail(program.error()); // "my pass fragment shader failed to compile: ..."
//   glUseProgram(*program); // ...; glDeleteProgram(*program) when done
//
// Threading: call with a current OpenGL context on the calling thread; the
// program belongs to that context (and those sharing with it).
#pragma once

#include <initializer_list>

#include "splatfx/result.hpp"

namespace splatfx::gl {

// Compiles each stage from its pieces (e.g. "#version", "#define", body, in
// order) and links them. Returns the program's GL name (a GLuint, never 0).
// On failure nothing is left behind and the message starts with `what`, names
// the stage that failed to compile ("vertex"/"fragment") or says the link
// failed, and ends with the driver's log.
Result<unsigned> linkProgram(std::initializer_list<const char*> vertex, std::initializer_list<const char*> fragment, const char* what);
// The same for a compute shader (the "compute" stage in messages); GL 4.3+.
Result<unsigned> linkComputeProgram(std::initializer_list<const char*> compute, const char* what);

} // namespace splatfx::gl
