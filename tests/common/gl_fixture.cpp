#include "gl_fixture.hpp"

#include <cstdlib>
#include <filesystem>
#include <memory>

#include <epoxy/gl.h>

namespace splatfx::test {

namespace {
struct Shared {
    std::unique_ptr<HeadlessContext> ctx;
    std::string error;
};
Shared& shared() {
    // One context per process: creating EGL displays per test is slow on llvmpipe.
    static Shared s = [] {
        Shared out;
        auto c = HeadlessContext::create();
        if (c) out.ctx = std::make_unique<HeadlessContext>(std::move(*c));
        else out.error = c.error();
        return out;
    }();
    return s;
}
} // namespace

void GLTest::SetUp() {
    Shared& s = shared();
    ASSERT_TRUE(s.ctx) << "headless OpenGL 4.5 is required for this test: " << s.error;
    s.ctx->makeCurrent();
    while (glGetError() != GL_NO_ERROR) {}
}

void GLTest::TearDown() {
    if (!shared().ctx) return;
    const GLenum e = glGetError();
    EXPECT_EQ(e, GLenum(GL_NO_ERROR)) << "a GL call in this test raised error 0x" << std::hex << e;
}

std::string outputDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "unknown";
    for (char& c : name)
        if (c == '/') c = '_';
    const char* env = std::getenv("SPLATFX_TEST_OUTPUT_DIR"); // a bundle run elsewhere (tools/gpu-check.sh)
    const std::string dir = std::string(env && *env ? env : SPLATFX_TEST_OUTPUT_DIR) + "/" + name;
    std::filesystem::create_directories(dir);
    return dir;
}

// SPLATFX_SOURCE_DIR in the environment wins: tools/gpu-check.sh runs the binaries in another checkout.
std::string sourcePath(const std::string& relative) {
    const char* env = std::getenv("SPLATFX_SOURCE_DIR");
    return std::string(env && *env ? env : SPLATFX_SOURCE_DIR) + "/" + relative;
}

Image drawSplats(gl::Renderer& r, const std::vector<Splat>& splats, const Camera& cam, gl::Precision precision, glm::vec4 bg) {
    auto fb = gl::Framebuffer::create({.width = cam.viewport.x, .height = cam.viewport.y, .color = precision});
    EXPECT_TRUE(fb) << fb.error();
    if (!fb) return {};
    fb->clear(bg);
    r.draw(splats, cam, {.framebuffer = fb->handle(), .width = cam.viewport.x, .height = cam.viewport.y});
    return fb->read();
}

} // namespace splatfx::test
