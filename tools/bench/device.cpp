// splatfx-bench device: the GL context the benches get (HeadlessContext, so
// SPLATFX_EGL_DEVICE applies) as a markdown table: vendor, renderer, version,
// the sample and size limits the tests and benches depend on. Exit 1 with the
// context's message when there is none. tools/gpu-check.sh runs it first.
#include <cstdio>
#include <string>

#include <epoxy/gl.h>

#include "options.hpp"
#include "splatfx/context.hpp"

namespace device_cmd { // one namespace per command: the commands build as one unity translation unit

int runDevice(int argc, char** argv) {
    CLI::App app{"The OpenGL context the benches get (SPLATFX_EGL_DEVICE selects an EGL device): vendor, renderer, limits.",
                 "splatfx-bench device"};
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "device: %s\n", ctx.error().c_str());
        return 1;
    }
    auto str = [](GLenum e) {
        const GLubyte* s = glGetString(e);
        return std::string(s ? reinterpret_cast<const char*>(s) : "unknown");
    };
    auto integer = [](GLenum e) {
        GLint v = 0;
        glGetIntegerv(e, &v);
        return v;
    };
    std::printf("| GL | value |\n|---|---|\n");
    std::printf("| GL_VENDOR | %s |\n| GL_RENDERER | %s |\n| GL_VERSION | %s |\n", str(GL_VENDOR).c_str(), str(GL_RENDERER).c_str(),
                str(GL_VERSION).c_str());
    std::printf("| GL_MAX_SAMPLES | %d |\n| GL_MAX_DEPTH_TEXTURE_SAMPLES | %d |\n| GL_MAX_TEXTURE_SIZE | %d |\n", integer(GL_MAX_SAMPLES),
                integer(GL_MAX_DEPTH_TEXTURE_SAMPLES), integer(GL_MAX_TEXTURE_SIZE));
    return 0;
}
} // namespace device_cmd

int runDevice(int argc, char** argv) { return device_cmd::runDevice(argc, argv); }
