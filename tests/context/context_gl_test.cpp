#include <array>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"

#ifndef SPLATFX_EGL_PROBE
#error "SPLATFX_EGL_PROBE must name the egl_probe executable"
#endif

namespace {
std::string run(const std::string& command) {
    std::string out;
    FILE* p = popen((command + " 2>&1").c_str(), "r");
    if (!p) return "popen failed";
    std::array<char, 512> buf{};
    while (fgets(buf.data(), int(buf.size()), p)) out += buf.data();
    pclose(p);
    return out;
}
} // namespace

TEST(Context, HeadlessContextGivesOpenGL45) {
    const std::string out = run(SPLATFX_EGL_PROBE);
    EXPECT_NE(out.find("ok:"), std::string::npos) << out;
}

TEST(ContextBadInput, NoEglDisplayIsAClearError) {
    // Point glvnd at no vendor library: EGL then has no display to offer, as on
    // a machine without Mesa's EGL or a GPU driver.
    const std::string out = run(std::string("__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl_vendor.json ") + SPLATFX_EGL_PROBE);
    EXPECT_NE(out.find("error: no EGL display"), std::string::npos) << out;
    EXPECT_NE(out.find("Install Mesa's EGL"), std::string::npos) << out;
}

TEST(ContextBadInput, RendererWithoutAContextIsAClearError) {
    const std::string out = run(std::string(SPLATFX_EGL_PROBE) + " --renderer-without-context");
    EXPECT_NE(out.find("error: splatfx::gl::Renderer::create: no OpenGL context is current on this thread"), std::string::npos) << out;
}
