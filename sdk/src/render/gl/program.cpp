#include "splatfx/gl/program.hpp"

#include <string>
#include <type_traits>
#include <vector>

#include <epoxy/gl.h>

namespace splatfx::gl {

static_assert(std::is_same_v<GLuint, unsigned>, "splatfx/gl/program.hpp hands out GL names as unsigned");

Result<unsigned> linkProgram(std::initializer_list<const char*> vertex, std::initializer_list<const char*> fragment, const char* what) {
    const std::vector<const char*> sources[2] = {vertex, fragment};
    GLuint stages[2] = {glCreateShader(GL_VERTEX_SHADER), glCreateShader(GL_FRAGMENT_SHADER)};
    std::string log;
    for (int i = 0; i < 2 && log.empty(); ++i) {
        glShaderSource(stages[i], GLsizei(sources[i].size()), sources[i].data(), nullptr);
        glCompileShader(stages[i]);
        GLint ok = 0;
        glGetShaderiv(stages[i], GL_COMPILE_STATUS, &ok);
        if (!ok) {
            char buf[4096] = {};
            glGetShaderInfoLog(stages[i], sizeof buf, nullptr, buf);
            log = std::string(what) + (i == 0 ? " vertex" : " fragment") + " shader failed to compile: " + buf;
        }
    }
    GLuint program = 0;
    if (log.empty()) {
        program = glCreateProgram();
        glAttachShader(program, stages[0]);
        glAttachShader(program, stages[1]);
        glLinkProgram(program);
        GLint ok = 0;
        glGetProgramiv(program, GL_LINK_STATUS, &ok);
        if (!ok) {
            char buf[4096] = {};
            glGetProgramInfoLog(program, sizeof buf, nullptr, buf);
            log = std::string(what) + " program failed to link: " + buf;
            glDeleteProgram(program);
        }
    }
    glDeleteShader(stages[0]);
    glDeleteShader(stages[1]);
    if (!log.empty()) return makeError(log);
    return program;
}

} // namespace splatfx::gl
