// Test helper: creates a headless context (or a renderer without one) and
// prints "ok: <renderer> | vendor <GL_VENDOR>" or "error: <message>". Run by context_gl_test in a
// child process so environment changes cannot leak into other tests.
#include <cstdio>
#include <cstring>

#include <epoxy/gl.h>

#include "splatfx/context.hpp"
#include "splatfx/gl/renderer.hpp"

int main(int argc, char** argv) {
    if (argc > 1 && std::strcmp(argv[1], "--renderer-without-context") == 0) {
        auto r = splatfx::gl::Renderer::create();
        std::printf(r ? "ok: renderer\n" : "error: %s\n", r ? "" : r.error().c_str());
        return r ? 0 : 1;
    }
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::printf("error: %s\n", ctx.error().c_str());
        return 1;
    }
    const GLubyte* vendor = glGetString(GL_VENDOR);
    std::printf("ok: %s | vendor %s\n", ctx->renderer().c_str(), vendor ? reinterpret_cast<const char*>(vendor) : "unknown");
    return 0;
}
