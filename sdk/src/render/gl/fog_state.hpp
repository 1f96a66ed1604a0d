// The fog's uniforms as every fogged program takes them: one place sets them
// (the splat, tetrahedra and host-fog passes, and gl::setFogUniforms for hosts).
#pragma once

#include <span>

#include <glm/glm.hpp>

#include "splatfx/fog.hpp"

namespace splatfx::gl::detail {

// A program's locations of the fog include's uniforms; -1 where it has none.
struct FogLocations {
    int params = -1, colour = -1, far = -1;
};

// Sets the parameters (Fog::glslParameters: relative to the eye, rounded to
// float once), the fog's colour and far cut-off on `program` (need not be bound).
void setFogUniforms(unsigned program, const FogLocations& at, const Fog& fog, std::span<const glm::vec4> params);

} // namespace splatfx::gl::detail
