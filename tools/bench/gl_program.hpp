// A vertex + fragment program for the benchmarks' own probes and host geometry.
#pragma once

#include <string>

#include <epoxy/gl.h>

namespace bench {

// Compiles and links; on failure returns 0 and sets `error` to the driver's log.
inline GLuint compileProgram(const char* vs, const char* fs, std::string& error) {
    GLuint p = glCreateProgram();
    for (auto [type, src] : {std::pair{GL_VERTEX_SHADER, vs}, std::pair{GL_FRAGMENT_SHADER, fs}}) {
        GLuint s = glCreateShader(type);
        glShaderSource(s, 1, &src, nullptr);
        glCompileShader(s);
        GLint ok = 0;
        glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
        if (!ok && error.empty()) {
            char log[2048] = {};
            glGetShaderInfoLog(s, sizeof log, nullptr, log);
            error = log;
        }
        glAttachShader(p, s);
        glDeleteShader(s);
    }
    glLinkProgram(p);
    if (!error.empty()) {
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

} // namespace bench
