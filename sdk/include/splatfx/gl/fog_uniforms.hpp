// splatfx/gl/fog_uniforms.hpp: feeds the fog GLSL include in the host's own shaders.
//
// fogGlsl(fog) (fog.hpp) returns GLSL that a host pastes into its own vertex
// or fragment shaders to fog forward-shaded or transparent surfaces exactly
// as gl::FrameRenderer fogs its opaque image and the splats (per fragment, or
// per vertex: Biri et al.'s "buffer method", sec. 4.3). This sets that
// include's uniforms in one of the host's programs for a frame: the
// parameters at timeSec relative to the eye, the fog colour and far cut-off.
// It does not compile, bind or draw anything. docs/integration.md has a
// snippet (compiled by tests/fog/fog_include_gl_test.cpp).
//
//   auto glsl = splatfx::fogGlsl(*fog);              // once per fog: paste glsl->source into your shader
//   splatfx::gl::setFogUniforms(myProgram, *fog, timeSec, eye);   // every frame
//   // in the shader: splatfx_fog_apply(vec3(0), worldPos - eye, colour)
//
// Threading: the GL thread (context current). Uses glProgramUniform*: the
// program need not be bound.
#pragma once

#include <glm/glm.hpp>

#include "splatfx/fog.hpp"
#include "splatfx/result.hpp"

namespace splatfx::gl {

// Positions in the shader must be relative to `eye` (world - eye), the same
// point the parameters are computed relative to (in double, docs/fog.md).
// Fails when the program has none of the include's uniforms (wrong program
// or prefix) or the include's layout does not match this fog.
Status setFogUniforms(unsigned program, const Fog& fog, double timeSec, glm::dvec3 eye, const FogGlslOptions& options = {});

} // namespace splatfx::gl
