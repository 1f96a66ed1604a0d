// An sRGB host target against the double-precision reference (issue 26
// item 3): with GL_FRAMEBUFFER_SRGB on an GL_SRGB8_ALPHA8 attachment, GL
// decodes the destination, blends in linear and encodes the result, so the
// stored codes are the linear reference encoded to sRGB, within the bound
// derived below. Blending the codes themselves (what a gamma-space blend
// would give) misses by far more, so the test tells the two apart.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "../reference/gl_bounds.hpp"
#include "gl_fixture.hpp"
#include "scenes.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/splats.hpp"

namespace splatfx {
namespace {

double encode(double l) { return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055; }
// The encoding's slope is largest at the low end of an interval (it is 12.92
// below 0.0031308 and decreasing above): its sup over [l, ...].
double encodeSlopeFrom(double l) { return l <= 0.0031308 ? 12.92 : 1.055 / 2.4 * std::pow(l, 1.0 / 2.4 - 1.0); }
// The decoding's slope is largest at the high end: its sup over [..., s].
double decodeSlopeTo(double s) { return s <= 0.04045 ? 1.0 / 12.92 : 2.4 / 1.055 * std::pow((s + 0.055) / 1.055, 1.4); }

class SrgbReferenceGL : public test::GLTest {};

} // namespace

TEST_F(SrgbReferenceGL, StoredCodesAreTheLinearReferenceEncodedWithinTheDerivedBound) {
    const test::LoneSplat lone; // GLvsReference.LoneSplat's splat, materials and camera
    const Materials& mat = lone.mat;
    const Camera& cam = lone.cam;
    const glm::ivec2 size = cam.viewport;
    const std::vector<Splat>& splats = lone.splats();
    ASSERT_EQ(splats.size(), 1u);
    auto r = gl::Renderer::create({.sampling = gl::TextureSampling::Bilinear}); // GLvsReference's bound is bilinear's
    ASSERT_TRUE(r && r->upload(mat));
    auto fb = gl::Framebuffer::create({.width = size.x, .height = size.y, .srgb = true});
    ASSERT_TRUE(fb) << fb.error();
    const glm::vec4 bg{0.1f, 0.2f, 0.3f, 1.0f}; // linear: the clear is encoded too
    glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
    glEnable(GL_FRAMEBUFFER_SRGB);
    glClearColor(bg.r, bg.g, bg.b, bg.a);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    r->draw(splats, cam, {.framebuffer = fb->handle(), .width = size.x, .height = size.y});
    glDisable(GL_FRAMEBUFFER_SRGB);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    const Image got = fb->read(); // sRGB codes / 255, as stored
    SplatExactDesc rd;
    rd.host.background = bg;
    auto ref = renderSplatExact(splats, cam, mat, rd);
    rd.host.background = glm::vec4(0.0f); // the splat alone: its alpha and premultiplied colour
    auto splat = renderSplatExact(splats, cam, mat, rd);
    ASSERT_TRUE(ref && splat) << ref.error();

    // In linear, GL against the reference: GLvsReference.LoneSplat's bound L (the window's
    // alpha error, the colour's 2^-11, F32 rounding), plus the stored clear's rounding (half a
    // code, decoded at the clear's slope, passed on times 1 - alpha <= 1). Encoding that linear
    // difference moves it by at most the encoding's largest slope over it, and the stored
    // result is rounded to the nearest code: half a code more. Alpha is stored linear (8 bits).
    const double L = std::log(2.0) * splats[0].density * test::windowErrorBound(mat) + std::ldexp(1.0, -11) + 1e-6;
    double worst = 0.0, gammaWorst = 0.0, maxBound = 0.0;
    for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) {
            const double a = splat->at(x, y, 3);
            for (int c = 0; c < 4; ++c) {
                const double want = ref->at(x, y, c), stored = got.at(x, y, c);
                double bound = 0.0, e = 0.0;
                if (c == 3) {
                    bound = L + 0.5 / 255.0;
                    e = std::abs(stored - want);
                } else {
                    const double clearCode = std::round(encode(bg[c]) * 255.0) / 255.0;
                    const double lin = L + decodeSlopeTo(clearCode + 0.5 / 255.0) * 0.5 / 255.0;
                    bound = 0.5 / 255.0 + encodeSlopeFrom(std::max(want - lin, 0.0)) * lin;
                    e = std::abs(stored - encode(want));
                    maxBound = std::max(maxBound, bound);
                    // A blend of the codes in gamma space: code(colour) alpha + (1 - alpha) code(bg).
                    const double premul = splat->at(x, y, c); // colour x alpha
                    if (a > 0.05) {
                        const double gamma = encode(premul / a) * a + (1.0 - a) * encode(bg[c]);
                        gammaWorst = std::max(gammaWorst, std::abs(gamma - encode(want)));
                    }
                }
                worst = std::max(worst, e / bound);
                ASSERT_LE(e, bound) << x << "," << y << " channel " << c;
            }
        }
    EXPECT_GT(gammaWorst, 3.0 * maxBound) << "a gamma-space blend must fall outside the bound, or the test cannot tell the two apart";
    std::printf("[ sRGB vs reference ] worst error / bound %.2f (largest bound %.4f); a gamma-space blend would miss by %.4f\n", worst, maxBound,
                gammaWorst);
}

} // namespace splatfx
