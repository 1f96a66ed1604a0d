// HDR lit colour (issue 27 item 5, docs/lighting.md "HDR lit colour"): with
// Scene::setHdrLit a lit colour brighter than 1 keeps its brightness as the
// splat's scale (-colorCoord) beside its 8-bit chroma; colours <= 1, and every
// colour without HDR, are packed exactly as before.
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// A 1560-voxel gas under a white sun, untextured with one constant table.
struct HdrScene {
    Materials materials{Footprint{}};
    Scene scene;
    Frame frame;
    Camera camera = Camera::lookAt({0.0f, 3.0f, 12.0f}, {0.0f, 3.0f, 0.0f}, {0, 1, 0}, 0.87f, {48, 36}, 0.1f, 100.0f);
    glm::vec4 base{0.8f, 0.6f, 0.4f, 1.0f};
    HdrScene(bool hdr, std::vector<Light> lights, EffectLighting lighting) {
        const std::uint32_t table = materials.addColorTable(ColorTable::constant(base));
        EffectDesc desc;
        desc.name = "gas";
        desc.layers = {EffectLayer{.style = {.colorTable = table, .textured = false}}};
        (void)scene.add(*Effect::fromGrid(test::effect1560(), desc), {.name = "gas", .lighting = lighting});
        for (const Light& l : lights) EXPECT_TRUE(scene.addLight(l));
        scene.setHdrLit(hdr);
        EXPECT_TRUE(scene.prepare(0.0, camera, materials, frame));
        EXPECT_TRUE(scene.lightingError().empty()) << scene.lightingError();
        EXPECT_GT(frame.splats().size(), 0u);
    }
};

// Unshadowed, isotropic, albedo 1: every splat's lit colour is base x intensity exactly
// (the closed form of docs/lighting.md, as SceneLighting.UnshadowedIsotropicGas... uses).
const EffectLighting kUnshadowed{.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off};
Light sun(float intensity) { return Light::directional({0.3f, -1.0f, 0.2f}, glm::vec3(1.0f), intensity); }

// The 8-bit chroma rounds each channel by half a level of the brightest
// channel m: |decoded - exact| <= m * 0.5 / 255, plus float rounding of the
// product and the division (a few ulps of m: 1e-6 m).
float chromaBound(float m) { return std::max(m, 1.0f) * (0.5f / 255.0f + 1e-6f); }

} // namespace

TEST(HdrLit, ColoursAboveOneKeepTheirBrightnessAsTheSplatsScale) {
    const float k = 6.0f; // base x 6 = (4.8, 3.6, 2.4)
    HdrScene hdr(true, {sun(k)}, kUnshadowed), ldr(false, {sun(k)}, kUnshadowed);
    ASSERT_EQ(hdr.frame.splats().size(), ldr.frame.splats().size());
    const glm::vec3 want = glm::vec3(hdr.base) * k;
    for (std::size_t i = 0; i < hdr.frame.splats().size(); ++i) {
        const Splat &h = hdr.frame.splats()[i], &l = ldr.frame.splats()[i];
        ASSERT_NEAR(-h.colorCoord, 4.8f, 4.8f * 1e-6f) << "the scale is the brightest channel (float rounding of the model: ulps)";
        const glm::vec3 got = splatColor(h);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(got[a], want[a], chromaBound(4.8f)) << "splat " << i;
        // Without HDR: the same chroma (hue kept), brightness stopped at 1, the coordinate kept.
        EXPECT_EQ(l.color, h.color);
        EXPECT_GE(l.colorCoord, 0.0f);
        const glm::vec3 clamped = splatColor(l);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(clamped[a], want[a] / 4.8f, chromaBound(1.0f));
    }
}

TEST(HdrLit, ColoursAtOrBelowOneAreBitIdenticalWithHdrOnOrOff) {
    // A shadowed sun of intensity 1.6: the lit side's colours exceed 1 (0.8 x 1.6 = 1.28),
    // the shadowed ones do not. Those <= 1 must be the same 64 bytes with HDR on and off
    // (an 8-bit host sees no change); those above differ only in colorCoord.
    const EffectLighting traced{.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Traced};
    HdrScene hdr(true, {sun(1.6f)}, traced), ldr(false, {sun(1.6f)}, traced);
    ASSERT_EQ(hdr.frame.splats().size(), ldr.frame.splats().size());
    int same = 0, scaled = 0;
    for (std::size_t i = 0; i < hdr.frame.splats().size(); ++i) {
        const Splat &h = hdr.frame.splats()[i], &l = ldr.frame.splats()[i];
        if (h.colorCoord >= 0.0f) {
            ASSERT_EQ(std::memcmp(&h, &l, sizeof(Splat)), 0) << "splat " << i;
            ++same;
        } else {
            Splat h2 = h;
            h2.colorCoord = l.colorCoord;
            ASSERT_EQ(std::memcmp(&h2, &l, sizeof(Splat)), 0) << "splat " << i;
            ASSERT_GT(-h.colorCoord, 1.0f);
            ++scaled;
        }
    }
    EXPECT_GT(same, 50) << "the shadowed side must stay within 1";
    EXPECT_GT(scaled, 50) << "the lit side must exceed 1";
}

TEST(HdrLit, TheSplatReferenceIntegratesTheScaleAsTheLinearImageOfTheInRangeOne) {
    // Compositing is linear in the splat colours at fixed alphas, and the lit colours at
    // intensity 6 are 6x those at 1: so the reference image of the HDR splats is 6x the
    // in-range one, up to each splat's 8-bit rounding (4.8 x 0.5/255 for the HDR chroma,
    // 6 x 0.5/255 for the in-range colour scaled up); "over" weights sum to <= 1.
    HdrScene hi(true, {sun(6.0f)}, kUnshadowed), lo(true, {sun(1.0f)}, kUnshadowed);
    auto a = renderSplatExact(hi.frame.splats(), hi.camera, hi.materials, {.threads = 1, .packedColor = true});
    auto b = renderSplatExact(lo.frame.splats(), lo.camera, lo.materials, {.threads = 1, .packedColor = true});
    ASSERT_TRUE(a && b);
    const double bound = (4.8 + 6.0) * 0.5 / 255.0 + 1e-5;
    double brightest = 0.0;
    for (int y = 0; y < a->height; ++y)
        for (int x = 0; x < a->width; ++x)
            for (int c = 0; c < 3; ++c) {
                ASSERT_NEAR(a->at(x, y, c), 6.0 * b->at(x, y, c), bound) << x << "," << y;
                brightest = std::max(brightest, double(a->at(x, y, c)));
            }
    EXPECT_GT(brightest, 2.0) << "values above 1 must reach the image";
}

// ---- Hard cases (docs/STABILITY.md, "HDR lit colour and colour targets") ----

TEST(HdrLitStability, AMillionTimesWhiteKeepsItsHueAndBrightness) {
    // 10^6: the scale is a float (24 bits), so only the chroma's 8-bit rounding is lost.
    HdrScene s(true, {sun(1e6f)}, kUnshadowed);
    const glm::vec3 want = glm::vec3(s.base) * 1e6f;
    for (const Splat& sp : s.frame.splats()) {
        const glm::vec3 got = splatColor(sp);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(got[a], want[a], chromaBound(8e5f));
    }
}

TEST(HdrLitStability, TheBrightestChannelAtOneAndOneUlpAboveAgreeAcrossTheSwitch) {
    // Intensities one float ulp apart around 1 / 0.8, where the red channel crosses 1: the
    // last one without a scale (the 8-bit packing) and the first with one (scale 1 + a few
    // ulps, the same chroma bytes) draw colours a few ulps apart, not a jump: no rounding of
    // the scale, no division changing a byte. Every splat has the same colour here (an
    // unshadowed sun), so splat 0 stands for all.
    float intensity = std::nextafter(1.0f / 0.8f, 0.0f);
    for (int i = 0; i < 8; ++i) intensity = std::nextafter(intensity, 0.0f);
    std::optional<Splat> below;
    for (int i = 0; i < 32; ++i, intensity = std::nextafter(intensity, 2.0f)) {
        HdrScene s(true, {sun(intensity)}, kUnshadowed);
        const Splat sp = s.frame.splats()[0];
        if (sp.colorCoord >= 0.0f) {
            below = sp;
            continue;
        }
        ASSERT_TRUE(below) << "the search must start below 1";
        EXPECT_GT(-sp.colorCoord, 1.0f);
        EXPECT_LT(-sp.colorCoord, 1.0f + 1e-6f);
        EXPECT_EQ(below->color & 0xffffffu, sp.color & 0xffffffu);
        const glm::vec3 a = splatColor(*below), b = splatColor(sp);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6f);
        return;
    }
    FAIL() << "no intensity in the search crossed 1";
}

TEST(HdrLitStability, AColourOverflowingFloatIsTheBrightestFloatNotBlack) {
    // Two suns of 3e38 sum past float's range: every channel of the product is inf.
    // Before, a non-finite colour was packed as black (the brightest splat drawn
    // dark); now inf is float's largest value: white at that scale, finite.
    HdrScene s(true, {sun(3e38f), sun(3e38f)}, kUnshadowed);
    for (const Splat& sp : s.frame.splats()) {
        ASSERT_TRUE(std::isfinite(sp.colorCoord));
        EXPECT_EQ(-sp.colorCoord, std::numeric_limits<float>::max());
        EXPECT_EQ(sp.color & 0xffffffu, 0xffffffu) << "every channel overflowed alike";
    }
}

TEST(HdrLitStability, DenormalAndZeroLightsPackToBlackWithoutAScale) {
    // 10^-40 is a float denormal; x 0.8 and the phase it stays one (or flushes to 0):
    // either way under half a level, so black, and no scale (colorCoord keeps its >= 0 value).
    for (float intensity : {1e-40f, 0.0f}) {
        HdrScene s(true, {sun(intensity)}, kUnshadowed);
        for (const Splat& sp : s.frame.splats()) {
            EXPECT_EQ(sp.color & 0xffffffu, 0u) << intensity;
            EXPECT_GE(sp.colorCoord, 0.0f) << intensity;
            EXPECT_EQ(splatColor(sp), glm::vec3(0.0f));
        }
    }
}
