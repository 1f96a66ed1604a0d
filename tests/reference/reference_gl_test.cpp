// The GL renderer against the splat-exact reference, with a bound derived
// from the real-time path's known approximations.
#include <algorithm>
#include <cmath>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_bounds.hpp"
#include "gl_fixture.hpp"
#include "scenes.hpp"
#include "splatfx/reference.hpp"

namespace splatfx {
namespace {

class GLvsReference : public test::GLTest {};

TEST_F(GLvsReference, LoneSplatAgreesWithinTheDerivedBoundWithAndWithoutHostDepth) {
    const test::LoneSplat lone;
    const Materials& mat = lone.mat;
    const Camera& cam = lone.cam;
    const glm::ivec2 size = cam.viewport;
    ASSERT_EQ(lone.splats().size(), 1u);
    const double density = lone.splats()[0].density;

    // The bound below is derived for bilinear sampling, so name it (Auto may
    // pick upsampled layers; UpsampledSamplingApproachesBilinear covers those).
    auto r = gl::Renderer::create({.sampling = gl::TextureSampling::Bilinear});
    ASSERT_TRUE(r) << r.error();
    ASSERT_TRUE(r->upload(mat));
    for (bool withDepth : {false, true}) {
        auto fb = gl::Framebuffer::create({.width = size.x, .height = size.y, .color = gl::Precision::F32});
        ASSERT_TRUE(fb);
        const glm::vec4 bg{0.1f, 0.2f, 0.3f, 1.0f};
        fb->clear(bg);
        if (withDepth) {
            // Host geometry at the near plane over the left 27 columns hides the splat there.
            glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
            glEnable(GL_SCISSOR_TEST);
            glScissor(0, 0, 27, size.y);
            glClearDepth(0.0);
            glClear(GL_DEPTH_BUFFER_BIT);
            glDisable(GL_SCISSOR_TEST);
            glClearDepth(1.0);
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
        }
        const Image depth = fb->readDepth();
        r->draw(lone.splats(), cam, {.framebuffer = fb->handle(), .width = size.x, .height = size.y});
        const Image got = fb->read();
        SplatExactDesc rd;
        rd.host.background = bg;
        rd.host.depth = &depth;
        auto ref = renderSplatExact(lone.splats(), cam, mat, rd);
        ASSERT_TRUE(ref) << ref.error();
        // d alpha / d detail = ln2 density 2^(-density detail) <= ln2 density; the
        // colour row is RGBA16F (relative error 2^-11); F32 blending adds ~1e-7.
        const double alphaBound = std::log(2.0) * density * test::windowErrorBound(mat);
        const double bound = alphaBound + std::ldexp(1.0, -11) + 1e-6;
        double worst = 0.0, peak = 0.0;
        for (size_t i = 0; i < got.pixels.size(); ++i) worst = std::max(worst, double(std::abs(got.pixels[i] - ref->pixels[i])));
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x) peak = std::max(peak, double(std::abs(ref->at(x, y, 3) - bg.a) + std::abs(ref->at(x, y, 0) - bg.r)));
        EXPECT_LT(bound, 0.05) << "the bound must be tight enough to catch a half-pixel slip";
        EXPECT_GT(peak, 0.3) << "the splat must be visible";
        EXPECT_LE(worst, bound) << (withDepth ? "with" : "without") << " host depth";
        if (withDepth) {
            for (int y = 0; y < size.y; ++y)
                for (int x = 0; x < 27; ++x) ASSERT_EQ(got.at(x, y, 0), bg.r) << "host depth must hide the splat at " << x << "," << y;
        }
    }
}

} // namespace
} // namespace splatfx
