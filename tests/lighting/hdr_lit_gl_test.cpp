// HDR lit colour through the GL pass into floating-point targets (issue 27
// item 5, issue 26 item 3): a bright fire and a brightly lit gas keep their
// values above 1 in an RGBA16F target, against the double-precision
// references (the splat reference for the same splats, the lit volume
// reference for the whole chain), each within a bound derived below.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "../reference/gl_bounds.hpp"
#include "gl_fixture.hpp"
#include "image_stats.hpp"
#include "scenes.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

constexpr double kHalfUlp = 1.0 / 2048.0; // half float: 11 significant bits, a rounding <= 2^-11 relative



// GLvsReference.LoneSplat's voxel as fire (emission 5, lit by a sun too), as a Scene lights it.
struct Fire {
    Materials m{Footprint{}};
    Camera cam = test::loneSplatCamera();
    std::vector<Splat> splats;
    explicit Fire(bool hdr) {
        const std::uint32_t row = m.addColorTable(ColorTable::constant({1.0f, 0.45f, 0.1f, 1.0f}));
        Scene scene;
        EXPECT_TRUE(scene.addLight(test::shadowSun()));
        (void)test::addLitEffect(scene, test::loneVoxel(), row, "fire",
                                 {.enabled = true, .gas = {.albedo = 0.5f, .emission = 5.0f}, .selfShadow = SelfShadow::Off});
        scene.setHdrLit(hdr);
        Frame frame;
        EXPECT_TRUE(scene.prepare(0.0, cam, m, frame));
        EXPECT_TRUE(scene.lightingError().empty()) << scene.lightingError();
        splats = frame.splats();
    }
};

class HdrLitGL : public test::GLTest {};

} // namespace

TEST_F(HdrLitGL, ABrightFireKeepsValuesAboveOneInAHalfFloatTargetAgainstTheDoubleReference) {
    Fire fire(true);
    ASSERT_EQ(fire.splats.size(), 1u);
    const double m = -double(fire.splats[0].colorCoord); // the brightest channel: 1.0 x (5 + 0.5)
    ASSERT_NEAR(m, 5.5, 1e-5);
    auto r = gl::Renderer::create({.sampling = gl::TextureSampling::Bilinear}); // the bound below is bilinear's
    ASSERT_TRUE(r) << r.error();
    ASSERT_TRUE(r->upload(fire.m));
    const glm::vec4 bg{0.1f, 0.2f, 0.3f, 1.0f};
    const Image got = test::drawSplats(*r, fire.splats, fire.cam, gl::Precision::F16, bg);
    SplatExactDesc rd;
    rd.host.background = bg;
    rd.packedColor = true;
    auto ref = renderSplatExact(fire.splats, fire.cam, fire.m, rd);
    ASSERT_TRUE(ref) << ref.error();
    // GLvsReference.LoneSplat's bound (the window's error in alpha, the colour's 2^-11 on
    // the way) scales with the colour: out = c alpha + (1 - alpha) bg, so d out / d alpha =
    // c - bg, at most m. The RGBA16F target rounds each of its two writes (the clear, the
    // splat) by half an ulp of the value stored: 2 x 2^-11 x |value|.
    const double alphaBound = std::log(2.0) * fire.splats[0].density * test::windowErrorBound(fire.m);
    double worst = 0.0;
    for (int y = 0; y < got.height; ++y)
        for (int x = 0; x < got.width; ++x)
            for (int c = 0; c < 4; ++c) {
                const double want = ref->at(x, y, c);
                const double bound = (c < 3 ? m : 1.0) * (alphaBound + kHalfUlp) + 2.0 * kHalfUlp * std::abs(want) + 1e-6;
                const double e = std::abs(double(got.at(x, y, c)) - want);
                worst = std::max(worst, e / bound);
                ASSERT_LE(e, bound) << x << "," << y << " channel " << c;
            }
    EXPECT_GT(test::maxRgb(*ref), 2.0) << "the fire must be brighter than white";
    EXPECT_GT(test::maxRgb(got), 2.0);
    // Without HDR the same fire stops at 1: the values above 1 are what setHdrLit keeps.
    Fire ldr(false);
    const Image clamped = test::drawSplats(*r, ldr.splats, ldr.cam, gl::Precision::F16, bg);
    EXPECT_LE(test::maxRgb(clamped), 1.0 + 2.0 * kHalfUlp);
    std::printf("[ HDR fire ] peak %.3f (reference %.3f; without HDR %.3f), worst error / bound %.2f\n", test::maxRgb(got), test::maxRgb(*ref), test::maxRgb(clamped),
                worst);
}

TEST_F(HdrLitGL, ABrightlyLitGasIsSixTimesItsInRangeFrameAgainstTheLitVolumeReference) {
    // A 3x3x3 blob under a sun of intensity 1 (every lit colour < 1) and of 6 (up to 4.3),
    // traced self-shadow, isotropic, no ambient or emission: the model is linear in the
    // intensity, so the frame at 6 is 6x the one at 1 up to each path's 8-bit colour.
    Materials m{Footprint{}};
    const std::uint32_t row = m.addColorTable(ColorTable::constant(test::smallLitBlobBase())); // LitReferenceGL's blob and camera
    const Grid grid = test::smallLitBlob();
    const Camera cam = test::smallLitBlobCamera(grid, {32, 24});
    const GasLightingDesc gas{.albedo = 0.9f};
    auto frameAt = [&](float intensity, bool hdr) {
        Scene scene;
        EXPECT_TRUE(scene.addLight(Light::directional(test::smallLitBlobSunDir(), glm::vec3(1.0f), intensity)));
        (void)test::addLitEffect(scene, grid, row, "blob", {.enabled = true, .gas = gas, .selfShadow = SelfShadow::Traced});
        scene.setHdrLit(hdr);
        Frame frame;
        EXPECT_TRUE(scene.prepare(0.0, cam, m, frame));
        return frame.splats();
    };
    const std::vector<Splat> lo = frameAt(1.0f, true), hi = frameAt(6.0f, true), hiLdr = frameAt(6.0f, false);
    ASSERT_EQ(lo.size(), grid.voxels.size());
    double mMax = 0.0;
    for (const Splat& s : lo) ASSERT_GE(s.colorCoord, 0.0f) << "intensity 1 must stay within 1";
    for (const Splat& s : hi) mMax = std::max(mMax, s.colorCoord < 0.0f ? -double(s.colorCoord) : 1.0);
    ASSERT_GT(mMax, 2.0);

    auto r = gl::Renderer::create();
    ASSERT_TRUE(r) << r.error();
    ASSERT_TRUE(r->upload(m));
    const glm::vec4 clear(0.0f);
    const Image gLo = test::drawSplats(*r, lo, cam, gl::Precision::F32, clear), gHi = test::drawSplats(*r, hi, cam, gl::Precision::F16, clear),
                gLdr = test::drawSplats(*r, hiLdr, cam, gl::Precision::F16, clear);

    VolumeField field(m);
    field.add(grid, {.textured = false});
    // The reference at 6 only: the lit model's light term is linear in the intensity (the
    // transmittance does not depend on it; no ambient, no emission), so the reference at 1 is
    // it divided by 6, exactly in the model and within 6x its error estimate in the quadrature.
    VolumeExactStats s6;
    const std::vector<Light> six = {Light::directional(test::smallLitBlobSunDir(), glm::vec3(1.0f), 6.0f)};
    const LitVolumeDesc lit6{.lights = six, .gas = gas};
    auto e6 = renderVolumeExact(field, cam, {.tolerance = 1e-4, .lighting = &lit6}, &s6);
    ASSERT_TRUE(e6);
    Image e1 = *e6;
    for (float& v : e1.pixels) v /= 6.0f;
    ASSERT_EQ(s6.unconverged, 0u);

    // GL at 6 against 6 x GL at 1: the same alphas, so the images differ by at most the largest
    // alpha times the largest difference of a splat's colour: the HDR chroma's rounding (half a
    // level of its brightest channel, <= mMax x 0.5/255) plus 6 x the in-range rounding (6 x
    // 0.5/255); plus the RGBA16F target's rounding at each of its 28 writes (the clear and 27
    // splats, each passed on scaled by <= 1: 28 x 2^-11 x the largest value) and F32's (1e-5).
    const double alpha = test::maxAlpha(gLo);
    const double linear = alpha * (mMax + 6.0) * 0.5 / 255.0 + 28.0 * kHalfUlp * test::maxRgb(gHi) + 1e-5;
    const double eLinear = test::maxDiff(gHi, gLo, 3, 6.0);
    EXPECT_LE(eLinear, linear);
    // So, by the triangle inequality, the HDR frame's error against the reference at 6 is at most
    // 6x the in-range frame's error against the reference divided by 6, plus the above: the
    // HDR path adds no error of its own beyond its rounding (printed; it follows from the above,
    // so it is not asserted again). What HDR must show: values above 1 in both, and a frame
    // without the scale missing the reference by far more than that.
    const double eLo = test::maxDiff(gLo, e1), eHi = test::maxDiff(gHi, *e6);
    const double bound = 6.0 * eLo + linear + 1e-6;
    EXPECT_GT(test::maxRgb(*e6), 2.0) << "the reference must exceed 1";
    EXPECT_GT(test::maxRgb(gHi), 2.0) << "so must the half-float frame";
    // Without HDR the frame stops at the colour's saturation and misses the reference by far more.
    const double eLdr = test::maxDiff(gLdr, *e6);
    EXPECT_GT(eLdr, 2.0 * bound) << "dropping the scale must fail this test";
    std::printf("[ HDR gas ] peak %.3f (reference %.3f); error vs the lit reference: at 1 %.4f, at 6 %.4f (bound %.4f), "
                "at 6 without HDR %.4f; |GL(6) - 6 GL(1)| %.4f (bound %.4f)\n",
                test::maxRgb(gHi), test::maxRgb(*e6), eLo, eHi, bound, eLdr, eLinear, linear);
}

TEST_F(HdrLitGL, AColourBeyondHalfFloatsRangeSaturatesTheTargetNeverNaN) {
    // Hard case (docs/STABILITY.md): a splat of colour 10^6 (a scale no half float holds;
    // its largest finite value is 65504). GL converts an overflowing value to the largest
    // half or to +inf (either is allowed); never a NaN, a wrap or a small value. An RGBA32F
    // target keeps it within the lone splat's bound scaled by 10^6.
    Fire fire(true);
    std::vector<Splat> splats = fire.splats;
    splats[0].colorCoord = -1e6f;
    splats[0].color = 0xffffffffu; // white chroma
    auto r = gl::Renderer::create({.sampling = gl::TextureSampling::Bilinear});
    ASSERT_TRUE(r && r->upload(fire.m));
    const glm::vec4 bg{0.0f, 0.0f, 0.0f, 1.0f};
    const Image half = test::drawSplats(*r, splats, fire.cam, gl::Precision::F16, bg), full = test::drawSplats(*r, splats, fire.cam, gl::Precision::F32, bg);
    SplatExactDesc rd;
    rd.host.background = bg;
    rd.packedColor = true;
    auto ref = renderSplatExact(splats, fire.cam, fire.m, rd);
    ASSERT_TRUE(ref);
    const double alphaBound = std::log(2.0) * splats[0].density * test::windowErrorBound(fire.m);
    int saturated = 0;
    for (int y = 0; y < half.height; ++y)
        for (int x = 0; x < half.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double want = ref->at(x, y, c), h = half.at(x, y, c), f = full.at(x, y, c);
                ASSERT_FALSE(std::isnan(h)) << x << "," << y;
                ASSERT_LE(std::abs(f - want), 1e6 * (alphaBound + kHalfUlp) + 1e-6 * want + 1e-6) << x << "," << y;
                if (want > 65504.0 * 1.01) {
                    ASSERT_GE(h, 65504.0) << "an overflowing value must saturate, at " << x << "," << y;
                    ++saturated;
                } else if (want < 65504.0 * 0.99) {
                    ASSERT_NEAR(h, want, 1e6 * (alphaBound + kHalfUlp) + 2.0 * kHalfUlp * want + 1e-6) << x << "," << y;
                }
            }
    EXPECT_GT(saturated, 0) << "the splat's centre must overflow a half float";
}
