#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "spawn.hpp"

#ifndef SPLATFX_EGL_PROBE
#error "SPLATFX_EGL_PROBE must name the egl_probe executable"
#endif

namespace {
// The probe runs as a separate process (a fresh EGL state each time) from an
// argument vector, never a shell line (tools/common/spawn.hpp).
std::string run(std::vector<std::string> argv, std::vector<std::string> env = {}) {
    auto r = cli::spawn({.argv = std::move(argv), .env = std::move(env), .output = cli::ChildOutput::Capture});
    return r.started ? r.output : r.error;
}
} // namespace

TEST(Context, HeadlessContextGivesOpenGL45) {
    const std::string out = run({SPLATFX_EGL_PROBE});
    EXPECT_NE(out.find("ok:"), std::string::npos) << out;
}

TEST(ContextBadInput, NoEglDisplayIsAClearError) {
    // Point glvnd at no vendor library: EGL then has no display to offer, as on
    // a machine without Mesa's EGL or a GPU driver.
    const std::string out = run({SPLATFX_EGL_PROBE}, {"__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl_vendor.json"});
    EXPECT_NE(out.find("error: no EGL display"), std::string::npos) << out;
    EXPECT_NE(out.find("Install Mesa's EGL"), std::string::npos) << out;
}

TEST(ContextBadInput, RendererWithoutAContextIsAClearError) {
    const std::string out = run({SPLATFX_EGL_PROBE, "--renderer-without-context"});
    EXPECT_NE(out.find("error: splatfx::gl::Renderer::create: no OpenGL context is current on this thread"), std::string::npos) << out;
}
