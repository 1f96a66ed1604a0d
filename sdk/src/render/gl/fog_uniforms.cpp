// The fog include's uniforms in a host program (fog_uniforms.hpp).
#include "splatfx/gl/fog_uniforms.hpp"

#include <string>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

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
    if (params >= 0) glProgramUniform4fv(program, params, GLsizei(p.size()), glm::value_ptr(p[0]));
    const glm::dvec3 c = fog.desc().colour;
    if (colour >= 0) glProgramUniform3f(program, colour, float(c.x), float(c.y), float(c.z));
    if (far >= 0) glProgramUniform1f(program, far, float(fog.desc().farDistanceWorld));
    return {};
}

} // namespace splatfx::gl
