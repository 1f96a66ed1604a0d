// The fog include's uniforms in a host program (fog_uniforms.hpp).
#include "splatfx/gl/fog_uniforms.hpp"

#include <string>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

#include "fog_state.hpp"

namespace splatfx::gl {

Status setFogUniforms(unsigned program, const Fog& fog, double timeSec, glm::dvec3 eye, const FogGlslOptions& options) {
    auto glsl = fogGlsl(fog, options);
    if (!glsl) return makeError("setFogUniforms: " + glsl.error());
    const GLint params = glGetUniformLocation(program, glsl->uniformName.c_str());
    const GLint colour = glGetUniformLocation(program, (options.prefix + "_colour").c_str());
    const GLint far = glGetUniformLocation(program, (options.prefix + "_far").c_str());
    if (params < 0 && colour < 0 && far < 0)
        return makeError("setFogUniforms: program " + std::to_string(program) + " uses none of " + glsl->uniformName + ", " + options.prefix +
                         "_colour, " + options.prefix + "_far (not the fog include, or another prefix)");
    const std::vector<glm::vec4> p = fog.glslParameters(timeSec, eye);
    if (int(p.size()) != glsl->vec4Count)
        return makeError("setFogUniforms: the include expects " + std::to_string(glsl->vec4Count) + " parameters, this fog has " +
                         std::to_string(p.size()));
    detail::setFogUniforms(program, {.params = params, .colour = colour, .far = far}, fog, p);
    return {};
}

namespace detail {

Result<FogChange> fogChange(const Fog* fog, std::uint64_t builtKey) {
    if (!fog || fog->empty()) return FogChange{};
    if (fog->glslKey() == builtKey) return FogChange{.fog = fog, .rebuild = std::nullopt}; // the same structure: the same programs
    auto glsl = fogGlsl(*fog);
    if (!glsl) return makeError(glsl.error());
    return FogChange{.fog = fog, .rebuild = std::move(glsl->source)};
}

} // namespace detail

namespace detail {

void setFogUniforms(unsigned program, const FogLocations& at, const Fog& fog, std::span<const glm::vec4> params) {
    if (at.params >= 0 && !params.empty()) glProgramUniform4fv(program, at.params, GLsizei(params.size()), glm::value_ptr(params[0]));
    const glm::dvec3 c = fog.desc().colour;
    if (at.colour >= 0) glProgramUniform3f(program, at.colour, float(c.x), float(c.y), float(c.z));
    if (at.far >= 0) glProgramUniform1f(program, at.far, float(fog.desc().farDistanceWorld));
}

} // namespace detail

} // namespace splatfx::gl
