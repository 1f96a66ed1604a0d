// The fog's uniforms as every fogged program takes them: one place sets them
// (the splat, tetrahedra and host-fog passes, and gl::setFogUniforms for hosts).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include <glm/glm.hpp>

#include "splatfx/fog.hpp"
#include "splatfx/result.hpp"

namespace splatfx::gl::detail {

// A program's locations of the fog include's uniforms; -1 where it has none.
struct FogLocations {
    int params = -1, colour = -1, far = -1;
};

// Sets the parameters (Fog::glslParameters: relative to the eye, rounded to
// float once), the fog's colour and far cut-off on `program` (need not be bound).
void setFogUniforms(unsigned program, const FogLocations& at, const Fog& fog, std::span<const glm::vec4> params);

// What a fogged pass's setFog does first: the fog it draws with (nullptr for
// none or a fog of zero terms, clear air: the plain programs) and, when that
// fog's structure is not the one its programs were built for (builtKey,
// Fog::glslKey), the GLSL to rebuild them from. Fails only if the GLSL
// cannot be generated.
struct FogChange {
    const Fog* fog = nullptr;
    std::optional<std::string> rebuild;
};
Result<FogChange> fogChange(const Fog* fog, std::uint64_t builtKey);

} // namespace splatfx::gl::detail
