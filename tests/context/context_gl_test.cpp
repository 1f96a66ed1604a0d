#include <cstdlib>
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
// The probe beside the test binary in a bundle run elsewhere (tools/gpu-check.sh sets SPLATFX_EGL_PROBE).
std::string probe() {
    const char* env = std::getenv("SPLATFX_EGL_PROBE");
    return env && *env ? env : SPLATFX_EGL_PROBE;
}
} // namespace

TEST(Context, HeadlessContextGivesOpenGL45) {
    const std::string out = run({probe()});
    EXPECT_NE(out.find("ok:"), std::string::npos) << out;
}

TEST(ContextBadInput, NoEglDisplayIsAClearError) {
    // Point glvnd at no vendor library: EGL then has no display to offer, as on
    // a machine without Mesa's EGL or a GPU driver.
    // SPLATFX_EGL_DEVICE emptied: the default choice even under tools/gpu-check.sh (which sets it).
    const std::string out = run({probe()}, {"__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl_vendor.json", "SPLATFX_EGL_DEVICE="});
    EXPECT_NE(out.find("error: no EGL display"), std::string::npos) << out;
    EXPECT_NE(out.find("Install Mesa's EGL"), std::string::npos) << out;
}

TEST(ContextBadInput, RendererWithoutAContextIsAClearError) {
    const std::string out = run({probe(), "--renderer-without-context"});
    EXPECT_NE(out.find("error: splatfx::gl::Renderer::create: no OpenGL context is current on this thread"), std::string::npos) << out;
}

// SPLATFX_EGL_DEVICE (tools/gpu-check.sh): EGL's device platform alone, an NVIDIA device or nothing.
TEST(ContextBadInput, AnUnknownEglDeviceChoiceIsNamed) {
    const std::string out = run({probe()}, {"SPLATFX_EGL_DEVICE=quantum"});
    EXPECT_NE(out.find("error: SPLATFX_EGL_DEVICE expects any, gpu, nvidia or a device index in [0, 15], got 'quantum'"), std::string::npos)
        << out;
}

TEST(Context, AnNvidiaDeviceIsTakenOrItsAbsenceSaidExactly) {
    const std::string out = run({probe()}, {"SPLATFX_EGL_DEVICE=nvidia"});
    if (out.rfind("ok:", 0) == 0) {
        EXPECT_NE(out.find("| vendor NVIDIA"), std::string::npos) << out; // taken only when GL_VENDOR says NVIDIA
    } else {
        // Without one: every device found is listed with what it is, and the platform's requirements are named.
        EXPECT_NE(out.find("error: SPLATFX_EGL_DEVICE=nvidia: no nvidia device among the EGL devices (found:"), std::string::npos) << out;
        EXPECT_NE(out.find("EGL_EXT_platform_device"), std::string::npos) << out;
    }
}

TEST(ContextBadInput, NoEglDeviceAtAllIsSaid) {
    const std::string out =
        run({probe()}, {"__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl_vendor.json", "SPLATFX_EGL_DEVICE=nvidia"});
    EXPECT_NE(out.find("error: SPLATFX_EGL_DEVICE=nvidia: no nvidia device among the EGL devices (found: none)"), std::string::npos) << out;
}
