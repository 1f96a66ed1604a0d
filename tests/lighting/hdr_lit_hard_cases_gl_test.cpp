// More hard cases of HDR lit colour through GL (docs/STABILITY.md, "HDR lit
// colour and colour targets"): the CPU's packing read back by the GLSL's
// unpacking at the encoding's edges, and the frame renderer's reduced
// resolution keeping values above 1.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "../reference/gl_bounds.hpp"
#include "gl_fixture.hpp"
#include "image_stats.hpp"
#include "scenes.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

constexpr double kHalfUlp = 1.0 / 2048.0; // half float: 11 significant bits, a rounding <= 2^-11 relative

// HdrLitGL's lone fire voxel (emission 5, a sun of 1): one splat of scale 5.5,
// seen at 32x24 (the same projection at half its size: the references' cost).
struct Fire {
    Materials m{Footprint{}};
    Camera cam = test::loneSplatCamera();
    Frame frame;
    explicit Fire(bool hdr) {
        cam.viewport = {32, 24};
        const std::uint32_t row = m.addColorTable(ColorTable::constant({1.0f, 0.45f, 0.1f, 1.0f}));
        Scene scene;
        EXPECT_TRUE(scene.addLight(test::shadowSun()));
        (void)test::addLitEffect(scene, test::loneVoxel(), row, "fire",
                                 {.enabled = true, .gas = {.albedo = 0.5f, .emission = 5.0f}, .selfShadow = SelfShadow::Off});
        scene.setHdrLit(hdr);
        EXPECT_TRUE(scene.prepare(0.0, cam, m, frame));
        EXPECT_TRUE(scene.lightingError().empty()) << scene.lightingError();
    }
};


class HdrLitHardCasesGL : public test::GLTest {};

} // namespace

TEST_F(HdrLitHardCasesGL, EdgeEncodingsReadTheSameInTheGlslAsOnTheCpu) {
    // One splat, its colour word and scale set to the encoding's edges, drawn
    // into RGBA32F and integrated by the splat reference, which decodes the
    // colour on the CPU (splatColor's rule). Each must meet the reference
    // within HdrLitGL's lone-splat bound scaled by the colour (m x (alpha's
    // window error + 2^-11)): a scale one ulp above 1; a pure red of 10^4
    // (green and blue exactly 0 in GL too: 0 x 10^4, no NaN); a colour
    // coordinate of -0.0 (not a scale: -0.0 < 0 is false on both sides, the
    // 8-bit colour); float's largest scale (the pixel finite: c alpha <= c).
    Fire fire(true);
    ASSERT_EQ(fire.frame.splats().size(), 1u);
    auto r = gl::Renderer::create({.sampling = gl::TextureSampling::Bilinear}); // the bound is bilinear's
    ASSERT_TRUE(r && r->upload(fire.m));
    struct Edge {
        const char* name;
        float colorCoord;
        std::uint32_t rgb;
    };
    const Edge edges[] = {{"one ulp above 1", std::nextafter(-1.0f, -2.0f), 0x3264c8u},
                          {"pure red of 10^4", -1e4f, 0x0000ffu},
                          {"-0.0", -0.0f, 0x3264c8u},
                          {"float's largest", -std::numeric_limits<float>::max(), 0xffffffu}};
    const glm::vec4 bg{0.0f, 0.0f, 0.0f, 1.0f};
    for (const Edge& e : edges) {
        std::vector<Splat> splats = fire.frame.splats();
        splats[0].colorCoord = e.colorCoord;
        splats[0].color = (splats[0].color & 0xff000000u) | e.rgb;
        const double m = e.colorCoord < 0.0f ? -double(e.colorCoord) : 1.0;
        const Image got = test::drawSplats(*r, splats, fire.cam, gl::Precision::F32, bg);
        SplatExactDesc rd;
        rd.host.background = bg;
        rd.packedColor = true;
        auto ref = renderSplatExact(splats, fire.cam, fire.m, rd);
        ASSERT_TRUE(ref) << ref.error();
        const double alphaBound = std::log(2.0) * splats[0].density * test::windowErrorBound(fire.m);
        double peak = 0.0;
        for (int y = 0; y < got.height; ++y)
            for (int x = 0; x < got.width; ++x)
                for (int c = 0; c < 3; ++c) {
                    const double want = ref->at(x, y, c), g = got.at(x, y, c);
                    ASSERT_TRUE(std::isfinite(g)) << e.name << " at " << x << "," << y;
                    if (((e.rgb >> (8 * c)) & 255u) == 0u) {
                        ASSERT_EQ(g, 0.0) << e.name << ": a zero byte is no light at any scale, channel " << c;
                    }
                    // F32: each write rounds by 2^-24 of its value (1e-6 x want covers the two).
                    ASSERT_LE(std::abs(g - want), m * (alphaBound + kHalfUlp) + 1e-6 * want + 1e-6) << e.name << " at " << x << "," << y;
                    peak = std::max(peak, want);
                }
        // Its brightest byte is at least 0xc8 and the voxel's opacity 0.6: a peak of at least 0.47 m.
        EXPECT_GT(peak, 0.4 * m) << e.name << ": the splat must be drawn";
    }
}

TEST_F(HdrLitHardCasesGL, AnOpaqueSplatOverAnOverflowedHalfFloatPixelIsNotNaN) {
    // Two splats over one pixel in RGBA16F: the back one of colour 10^6
    // saturates the pixel (65504 or +inf, as GL converts); the front one is
    // opaque (alpha 1 at its centre), so the blend multiplies the stored
    // pixel by 1 - alpha = 0. inf x 0 is NaN: the front splat's colour must
    // show, never a NaN.
    Fire fire(true);
    std::vector<Splat> splats = fire.frame.splats();
    splats[0].colorCoord = -1e6f;
    splats[0].color = (splats[0].color & 0xff000000u) | 0xffffffu;
    Splat front = splats[0];
    front.colorCoord = 0.5f; // an 8-bit colour
    front.color = (front.color & 0xff000000u) | 0x204080u;
    front.density = 1e3f;                                   // alpha 1 - 2^-1000: exactly 1 in float over the core
    front.center += 0.01f * glm::normalize(fire.cam.eye() - front.center); // in front, drawn last
    front.depth = splats[0].depth - 0.01f;
    splats.push_back(front);
    auto r = gl::Renderer::create({.sampling = gl::TextureSampling::Bilinear});
    ASSERT_TRUE(r && r->upload(fire.m));
    const Image got = test::drawSplats(*r, splats, fire.cam, gl::Precision::F16, {0.0f, 0.0f, 0.0f, 1.0f});
    int nan = 0, front8 = 0;
    for (int y = 0; y < got.height; ++y)
        for (int x = 0; x < got.width; ++x) {
            for (int c = 0; c < 4; ++c) nan += std::isnan(got.at(x, y, c)) ? 1 : 0;
            front8 += std::abs(got.at(x, y, 2) - 0x20 / 255.0f) < 1e-3f ? 1 : 0;
        }
    EXPECT_EQ(nan, 0);
    EXPECT_GT(front8, 0) << "the opaque front splat's own colour must show over its core";
}

namespace {

// The lone fire through a FrameRenderer of `desc` into an RGBA32F host target
// with a depth buffer cleared to the far plane: the HDR frame (scale m) and
// the frame without HDR (the same chroma bytes, no scale). Every path is
// linear in the splats' colours at fixed alphas and depths, so the first is
// m x the second up to `relative` rounding of each side's values. Returns
// the HDR frame's peak.
double hdrOverLdr(const gl::FrameRendererDesc& desc, double relative, const char* what) {
    Fire hdr(true), ldr(false);
    EXPECT_EQ(hdr.frame.splats().size(), 1u);
    const double m = -double(hdr.frame.splats()[0].colorCoord);
    EXPECT_NEAR(m, 5.5, 1e-5);
    auto fr = gl::FrameRenderer::create(desc);
    EXPECT_TRUE(fr && fr->upload(hdr.m));
    if (!fr) return 0.0;
    auto render = [&](const Frame& f) {
        auto fb = gl::Framebuffer::create({.width = hdr.cam.viewport.x, .height = hdr.cam.viewport.y, .color = gl::Precision::F32});
        EXPECT_TRUE(fb) << fb.error();
        fr->render(f, {.framebuffer = fb->handle(), .drawOpaque = [] {
                           glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
                           glClearDepth(1.0);
                           glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                       }});
        return fb->read();
    };
    const Image a = render(hdr.frame), b = render(ldr.frame);
    double peak = 0.0, worst = 0.0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double va = a.at(x, y, c), vb = b.at(x, y, c);
                const double bound = relative * (std::abs(va) + m * std::abs(vb)) + 1e-6;
                worst = std::max(worst, std::abs(va - m * vb) / bound);
                peak = std::max(peak, va);
            }
    EXPECT_LE(worst, 1.0) << what << ": |HDR - m x LDR| over its bound";
    std::printf("[ %s ] peak %.3f, worst error / bound %.3f\n", what, peak, worst);
    return peak;
}

} // namespace

TEST_F(HdrLitHardCasesGL, ReducedResolutionKeepsValuesAboveOne) {
    // Half and quarter resolution draw the splats into an RGBA16F image
    // (FrameRendererDesc::reducedPrecision) and upsample it with depth-aware
    // weights: linear in the colours. Rounding: the half float's 2^-11 at
    // each of its writes (the clear, the splat, the composite: 3). A path
    // that clamped at 1 would miss by most of the peak.
    for (int scale : {2, 4}) {
        const double peak = hdrOverLdr({.resolutionScale = scale}, 3.0 * kHalfUlp, scale == 2 ? "half resolution" : "quarter resolution");
        EXPECT_GT(peak, 1.5) << "scale " << scale << ": values above 1 must reach the target";
    }
}

TEST_F(HdrLitHardCasesGL, AnEightBitReducedLayerOnAFloatHostClampsAndSaysSo) {
    // The host asks for an 8-bit reduced layer (reducedPrecision U8) under an
    // RGBA32F target: the values above 1 are clamped there, and the frame's
    // notes say so; with the default RGBA16F layer they reach the target and
    // nothing is noted. On an 8-bit host the U8 layer loses nothing more: no note.
    Fire hdr(true);
    auto draw = [&](gl::Precision layer, gl::Precision host, std::vector<std::string>& notes) {
        auto fr = gl::FrameRenderer::create({.resolutionScale = 2, .reducedPrecision = layer});
        EXPECT_TRUE(fr && fr->upload(hdr.m));
        if (!fr) return 0.0;
        auto fb = gl::Framebuffer::create({.width = hdr.cam.viewport.x, .height = hdr.cam.viewport.y, .color = host});
        EXPECT_TRUE(fb) << fb.error();
        fr->render(hdr.frame, {.framebuffer = fb->handle(), .drawOpaque = [] {
                                   glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
                                   glClearDepth(1.0);
                                   glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                               }});
        notes = fr->stats().notes;
        return test::maxRgb(fb->read());
    };
    const std::string said = "reducedPrecision U8 on a floating-point host: the reduced layer clamps the volumes' colours to [0, 1]";
    auto noted = [&](const std::vector<std::string>& notes) {
        return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.rfind(said, 0) == 0; });
    };
    std::vector<std::string> notes;
    EXPECT_LE(draw(gl::Precision::U8, gl::Precision::F32, notes), 1.0) << "the U8 layer clamps";
    EXPECT_TRUE(noted(notes)) << "the clamp must be noted";
    EXPECT_GT(draw(gl::Precision::F16, gl::Precision::F32, notes), 1.5) << "the default layer keeps values above 1";
    EXPECT_FALSE(noted(notes));
    draw(gl::Precision::U8, gl::Precision::U8, notes);
    EXPECT_FALSE(noted(notes)) << "an 8-bit host loses nothing more to an 8-bit layer";
}

TEST_F(HdrLitHardCasesGL, FullResolutionThroughTheHostDepthKeepsValuesAboveOne) {
    // Full resolution against the host's depth (the splats cut at it): the
    // splat straight into the RGBA32F host target. Rounding: float's 2^-24
    // at the scale's product, the premultiply, the blend and the clear (4),
    // on either side (8).
    const double peak = hdrOverLdr({}, 8.0 * 0x1p-24, "full resolution, host depth");
    EXPECT_GT(peak, 1.5) << "values above 1 must reach the target";
}
