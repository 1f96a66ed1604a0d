#include "splatfx/gl/program.hpp"

#include <string>
#include <type_traits>
#include <vector>

#include <epoxy/gl.h>

namespace splatfx::gl {

static_assert(std::is_same_v<GLuint, unsigned>, "splatfx/gl/program.hpp hands out GL names as unsigned");

namespace {

struct Stage {
    GLenum type;
    const char* name; // in messages
    std::vector<const char*> pieces;
};

// Compiles every stage, links them, and reports the first failure with the driver's log.
Result<unsigned> link(const std::vector<Stage>& stages, const char* what) {
    std::vector<GLuint> shaders;
    std::string log;
    for (const Stage& st : stages) {
        if (!log.empty()) break;
        const GLuint s = glCreateShader(st.type);
        shaders.push_back(s);
        glShaderSource(s, GLsizei(st.pieces.size()), st.pieces.data(), nullptr);
        glCompileShader(s);
        GLint ok = 0;
        glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            char buf[4096] = {};
            glGetShaderInfoLog(s, sizeof buf, nullptr, buf);
            log = std::string(what) + " " + st.name + " shader failed to compile: " + buf;
        }
    }
    GLuint program = 0;
    if (log.empty()) {
        program = glCreateProgram();
        for (GLuint s : shaders) glAttachShader(program, s);
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
    for (GLuint s : shaders) glDeleteShader(s);
    if (!log.empty()) return makeError(log);
    return program;
}

} // namespace

Result<unsigned> linkProgram(std::initializer_list<const char*> vertex, std::initializer_list<const char*> fragment, const char* what) {
    return link({{GL_VERTEX_SHADER, "vertex", vertex}, {GL_FRAGMENT_SHADER, "fragment", fragment}}, what);
}

Result<unsigned> linkComputeProgram(std::initializer_list<const char*> compute, const char* what) {
    return link({{GL_COMPUTE_SHADER, "compute", compute}}, what);
}

} // namespace splatfx::gl
