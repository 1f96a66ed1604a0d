// More hard cases of HDR lit colour (docs/STABILITY.md, "HDR lit colour and
// colour targets"): the packing's edges (a zero or NaN channel beside a huge
// one, the 8-bit steps, the switch between frames, the depth cut's byte)
// and the lit model's linearity at extreme brightness. Each test is named
// after what would go wrong.
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// Unshadowed, isotropic, albedo 1: a splat's lit colour is its table colour x
// the lights' colour x intensity (docs/lighting.md's closed form).
const EffectLighting kUnshadowed{.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off};
const glm::vec3 kSunDir{0.3f, -1.0f, 0.2f};

struct Lit {
    Materials materials{Footprint{}};
    Scene scene;
    Frame frame;
    Camera camera = Camera::lookAt({0.0f, 1.0f, 8.0f}, {0.0f, 1.0f, 0.0f}, {0, 1, 0}, 0.9f, {32, 32}, 0.1f, 100.0f);
    EffectId id = 0;
    Lit(const Grid& grid, const ColorTable& table, const std::vector<Light>& lights, EffectLighting lighting, bool hdr) {
        const std::uint32_t row = materials.addColorTable(table);
        id = test::addLitEffect(scene, grid, row, "gas", lighting);
        for (const Light& l : lights) EXPECT_TRUE(scene.addLight(l));
        scene.setHdrLit(hdr);
        prepare();
    }
    void prepare() {
        EXPECT_TRUE(scene.prepare(0.0, camera, materials, frame));
        EXPECT_TRUE(scene.lightingError().empty()) << scene.lightingError();
    }
    const std::vector<Splat>& splats() const { return frame.splats(); }
};

Grid voxels(glm::ivec3 dims, float opacity = 0.5f) {
    Grid g = *Grid::box(dims, glm::vec3(0.25f));
    for (Voxel& v : g.voxels) v.opacity = opacity;
    return g;
}

std::uint32_t byteOf(const Splat& s, int c) { return (s.color >> (8 * c)) & 255u; }

// Half a level of the brightest channel m, plus float rounding of the model's
// product and the chroma's division (a few ulps of m: 1e-6 m), as
// HdrLit.ColoursAboveOneKeepTheirBrightnessAsTheSplatsScale.
float chromaBound(float m) { return std::max(m, 1.0f) * (0.5f / 255.0f + 1e-6f); }

} // namespace

TEST(HdrLitHardCases, AZeroChannelUnderAnOverflowedLightIsDarkNotNaN) {
    // A table colour with no green under two suns of 3e38: the light's factor
    // is inf in every channel and green is 0 x inf = NaN. That NaN must not
    // become a NaN scale or a lit green: the colour has no green, so green's
    // byte is 0 and the scale is float's largest (the overflowed channels).
    Lit s(voxels({2, 2, 2}), ColorTable::constant({1.0f, 0.0f, 0.5f, 1.0f}),
          {Light::directional(kSunDir, glm::vec3(1.0f), 3e38f), Light::directional(kSunDir, glm::vec3(1.0f), 3e38f)}, kUnshadowed, true);
    ASSERT_FALSE(s.splats().empty());
    for (const Splat& sp : s.splats()) {
        EXPECT_EQ(-sp.colorCoord, std::numeric_limits<float>::max());
        EXPECT_EQ(byteOf(sp, 0), 255u);
        EXPECT_EQ(byteOf(sp, 1), 0u) << "0 x inf is no green";
        EXPECT_EQ(byteOf(sp, 2), 255u) << "0.5 x inf overflowed as red did";
        const glm::vec3 c = splatColor(sp);
        EXPECT_EQ(c.g, 0.0f);
        EXPECT_TRUE(std::isfinite(c.r) && std::isfinite(c.b));
    }
}

TEST(HdrLitHardCases, OneChannelZeroAndAnotherHugeDecodesTheZeroExactly) {
    // A pure red light of 10^30 (and one with a trace of green, 10^-38 of
    // it, whose chroma 10^-38 x 0.75 is a float denormal): the scale is the
    // red 0.8e30; green and blue decode to exactly 0 (0 x 10^30, never a
    // denormal's garbage or a NaN), within half a level of the scale where
    // the true green is not 0.
    for (float trace : {0.0f, 1e-38f}) {
        Lit s(voxels({2, 2, 2}), ColorTable::constant({0.8f, 0.6f, 0.4f, 1.0f}), {Light::directional(kSunDir, {1.0f, trace, 0.0f}, 1e30f)}, kUnshadowed,
              true);
        for (const Splat& sp : s.splats()) {
            EXPECT_NEAR(-sp.colorCoord, 0.8e30f, 0.8e30f * 1e-6f) << "the scale is the red channel (float rounding of the model: ulps)";
            EXPECT_EQ(byteOf(sp, 0), 255u);
            EXPECT_EQ(byteOf(sp, 1), 0u) << trace;
            EXPECT_EQ(byteOf(sp, 2), 0u);
            const glm::vec3 c = splatColor(sp);
            EXPECT_EQ(c.g, 0.0f);
            EXPECT_EQ(c.b, 0.0f);
            EXPECT_NEAR(c.g, 0.6f * trace * 1e30f, chromaBound(0.8e30f));
        }
    }
}

TEST(HdrLitHardCases, ChannelsOnTheEightBitStepsKeepTheirBytesAndHalfStepsStayWithinHalfALevel) {
    // 256 voxels, voxel k reading table entry k: red 1 (the brightest, 3 under
    // a sun of 3), green k / 255 (exactly on the 8-bit step k), blue
    // (k + 0.5) / 255 (exactly between two steps, where the rounding is
    // decided by the last bit). Green's byte must be k; blue's decoded value
    // within half a level of the scale (the bound is reached here, so any
    // extra rounding of the scale or the chroma fails it).
    ColorTable table;
    for (int k = 0; k < 256; ++k) table.entries.push_back({1.0f, float(k) / 255.0f, std::min(float(k) + 0.5f, 255.0f) / 255.0f, 1.0f});
    Grid g = voxels({16, 16, 1});
    for (Voxel& v : g.voxels) v.colorCoord = float(v.cell.x + 16 * v.cell.y) / 255.0f;
    Lit s(g, table, {Light::directional(kSunDir, glm::vec3(1.0f), 3.0f)}, kUnshadowed, true);
    ASSERT_EQ(s.splats().size(), 256u);
    std::vector<int> seen(256, 0);
    for (const Splat& sp : s.splats()) {
        ASSERT_LT(sp.colorCoord, 0.0f) << "red is 3: every splat is scaled";
        const float m = -sp.colorCoord;
        ASSERT_NEAR(m, 3.0f, 3.0f * 1e-6f);
        const int kk = int(byteOf(sp, 1));
        ++seen[std::size_t(kk)];
        const glm::vec3 c = splatColor(sp);
        EXPECT_NEAR(c.g, m * float(kk) / 255.0f, 3.0f * 1e-6f);
        const float blue = 3.0f * std::min(float(kk) + 0.5f, 255.0f) / 255.0f;
        EXPECT_NEAR(c.b, blue, chromaBound(m)) << "step " << kk;
    }
    for (int k = 0; k < 256; ++k) EXPECT_EQ(seen[std::size_t(k)], 1) << "green byte " << k << " must come from entry " << k << " alone";
}

TEST(HdrLitHardCases, SwitchingHdrBetweenFramesLeavesNoStaleScale) {
    // HDR on, off, on again in one scene: each frame's splats are bit for bit
    // those of a scene that always had that setting (no scale left in a
    // colour coordinate from the last frame, no colour kept from it).
    const std::vector<Light> sun{Light::directional(kSunDir, glm::vec3(1.0f), 4.0f)};
    const Grid g = test::smallLitBlob();
    const ColorTable table = ColorTable::constant(test::smallLitBlobBase());
    const EffectLighting traced{.enabled = true, .gas = {.albedo = 0.9f}, .selfShadow = SelfShadow::Traced};
    Lit toggled(g, table, sun, traced, true), on(g, table, sun, traced, true), off(g, table, sun, traced, false);
    auto same = [](const std::vector<Splat>& a, const std::vector<Splat>& b) {
        return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Splat)) == 0;
    };
    ASSERT_TRUE(same(toggled.splats(), on.splats()));
    int scaled = 0;
    for (const Splat& sp : on.splats()) scaled += sp.colorCoord < 0.0f ? 1 : 0;
    EXPECT_GT(scaled, 0) << "a sun of 4 must take some colours above 1";
    toggled.scene.setHdrLit(false);
    toggled.prepare();
    EXPECT_TRUE(same(toggled.splats(), off.splats()));
    for (const Splat& sp : toggled.splats()) EXPECT_GE(sp.colorCoord, 0.0f);
    toggled.scene.setHdrLit(true);
    toggled.prepare();
    EXPECT_TRUE(same(toggled.splats(), on.splats()));
}

TEST(HdrLitHardCases, AnEmissiveGasWithNoLightInTheSceneKeepsItsEmission) {
    // A fire's gas (emission 5, albedo 0.5) in a scene with no light: its
    // lit colour is base x 5 (docs/lighting.md's model: emission + albedo x
    // (ambient + the lights' sum), the sum empty). Adding a light of
    // intensity 0 adds nothing, so both frames must be the same bytes, each
    // splat's scale 5 x the base's brightest channel.
    const EffectLighting fire{.enabled = true, .gas = {.albedo = 0.5f, .emission = 5.0f}, .selfShadow = SelfShadow::Off};
    const ColorTable table = ColorTable::constant({1.0f, 0.45f, 0.1f, 1.0f});
    Lit dark(voxels({2, 3, 2}), table, {}, fire, true), zero(voxels({2, 3, 2}), table, {Light::directional(kSunDir, glm::vec3(1.0f), 0.0f)}, fire, true);
    ASSERT_EQ(dark.splats().size(), zero.splats().size());
    for (std::size_t i = 0; i < dark.splats().size(); ++i) {
        const Splat &a = dark.splats()[i], &b = zero.splats()[i];
        EXPECT_NEAR(-b.colorCoord, 5.0f, 5.0f * 1e-6f) << "the zero light's frame: base x emission";
        EXPECT_EQ(std::memcmp(&a, &b, sizeof(Splat)), 0) << "splat " << i << ": a light of intensity 0 changed the frame";
    }
}

TEST(HdrLitHardCases, TheDepthCutsByteSurvivesTheScale) {
    // A stretched kernel's along-ray scale rides in the colour's top byte
    // (splats.hpp, rayScaleCode); the lit colour replaces the low three
    // bytes only. With HDR on, off, and unlit, the top byte must be the
    // builder's, whatever the scale.
    Grid g = voxels({3, 3, 3});
    for (Voxel& v : g.voxels) v.stretch = glm::vec3(1.5f, 0.5f * float(v.cell.y), 0.0f);
    const ColorTable table = ColorTable::constant({0.9f, 0.5f, 0.2f, 1.0f});
    const std::vector<Light> sun{Light::directional(kSunDir, glm::vec3(1.0f), 7.0f)};
    Lit hdr(g, table, sun, kUnshadowed, true), ldr(g, table, sun, kUnshadowed, false), unlit(g, table, sun, EffectLighting{}, false);
    ASSERT_EQ(hdr.splats().size(), unlit.splats().size());
    int notOne = 0;
    for (std::size_t i = 0; i < hdr.splats().size(); ++i) {
        const std::uint32_t top = unlit.splats()[i].color >> 24;
        notOne += top != 255u ? 1 : 0;
        EXPECT_EQ(hdr.splats()[i].color >> 24, top) << "splat " << i;
        EXPECT_EQ(ldr.splats()[i].color >> 24, top) << "splat " << i;
        EXPECT_LT(hdr.splats()[i].colorCoord, -1.0f);
    }
    EXPECT_GT(notOne, 0) << "stretched kernels must carry a ray scale other than 1";
}

TEST(HdrLitHardCases, AGasUnderASunOfTenToTheThirtyIsTenToTheThirtyTimesTheGasUnderASunOfOne) {
    // Traced self-shadow: the lit model is linear in the light's intensity
    // (the transmittance does not depend on it), so every splat's colour at
    // 10^30 is 10^30 x its colour at 1, up to each one's 8-bit rounding:
    // half a level of its scale m at 10^30 (relative to 10^30: m / 10^30 x
    // 0.5/255) and half a level absolute at 1 (colours <= 1 there), plus float
    // rounding (1e-6 of each). No intermediate (a squared intensity, a sum
    // of lights) may overflow on the way.
    const Grid g = test::smallLitBlob();
    const ColorTable table = ColorTable::constant(test::smallLitBlobBase());
    const EffectLighting traced{.enabled = true, .gas = {.albedo = 0.9f}, .selfShadow = SelfShadow::Traced};
    Lit hi(g, table, {Light::directional(test::smallLitBlobSunDir(), glm::vec3(1.0f), 1e30f)}, traced, true),
        lo(g, table, {Light::directional(test::smallLitBlobSunDir(), glm::vec3(1.0f), 1.0f)}, traced, true);
    ASSERT_EQ(hi.splats().size(), lo.splats().size());
    for (std::size_t i = 0; i < hi.splats().size(); ++i) {
        ASSERT_GE(lo.splats()[i].colorCoord, 0.0f) << "a sun of 1 keeps this gas within 1";
        const float m = -hi.splats()[i].colorCoord;
        ASSERT_TRUE(std::isfinite(m) && m > 1e28f);
        const glm::vec3 a = splatColor(hi.splats()[i]) / 1e30f, b = splatColor(lo.splats()[i]);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], chromaBound(m / 1e30f) + chromaBound(1.0f)) << "splat " << i << " channel " << c;
    }
}

TEST(HdrLitHardCases, SeventeenLightsPastTheStackPathSumToTheScaleOfOneSeventeenTimesAsBright) {
    // The model prepares 16 lights on the stack and any more per voxel: 17
    // suns of 0.5 (the sum 8.5 x base) must give the scale and bytes of one
    // sun of 8.5, within the float rounding of a sum of 17 terms (17 ulps of
    // the sum: 17 x 2^-24 relative) and the chroma's half level.
    const ColorTable table = ColorTable::constant({0.8f, 0.6f, 0.4f, 1.0f});
    Lit many(voxels({2, 2, 2}), table, std::vector<Light>(17, Light::directional(kSunDir, glm::vec3(1.0f), 0.5f)), kUnshadowed, true),
        one(voxels({2, 2, 2}), table, {Light::directional(kSunDir, glm::vec3(1.0f), 8.5f)}, kUnshadowed, true);
    ASSERT_EQ(many.splats().size(), one.splats().size());
    for (std::size_t i = 0; i < many.splats().size(); ++i) {
        const float m = -one.splats()[i].colorCoord;
        EXPECT_NEAR(-many.splats()[i].colorCoord, m, m * 18.0f * 0x1p-24f);
        EXPECT_NEAR(m, 0.8f * 8.5f, 0.8f * 8.5f * 1e-6f);
        const glm::vec3 a = splatColor(many.splats()[i]), b = splatColor(one.splats()[i]);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 2.0f * chromaBound(m)) << "splat " << i;
    }
}

TEST(HdrLitHardCases, EmissionAndAmbientOfExactlyOneAreNotScaledAndOfTwoAreScaledExactly) {
    // No light: the lit colour is base x (emission + albedo x ambient), exact
    // in float for these values. At a brightest channel of exactly 1 there is
    // no scale (the switch is m > 1) and the splat is bit for bit the one
    // without HDR; at exactly 2 the scale is exactly 2 and the chroma's bytes
    // those of base (1, 0.5, 0.25): 255, 128 (127.5 rounded up), 64.
    const ColorTable table = ColorTable::constant({1.0f, 0.5f, 0.25f, 1.0f});
    for (float k : {1.0f, 2.0f}) {
        const EffectLighting emissive{.enabled = true, .gas = {.albedo = 0.0f, .emission = k}, .selfShadow = SelfShadow::Off};
        const EffectLighting ambient{.enabled = true, .gas = {.albedo = 1.0f, .ambient = glm::vec3(k)}, .selfShadow = SelfShadow::Off};
        for (const EffectLighting& L : {emissive, ambient}) {
            Lit hdr(voxels({2, 2, 2}), table, {}, L, true), ldr(voxels({2, 2, 2}), table, {}, L, false);
            ASSERT_EQ(hdr.splats().size(), ldr.splats().size());
            for (std::size_t i = 0; i < hdr.splats().size(); ++i) {
                const Splat &h = hdr.splats()[i], &l = ldr.splats()[i];
                EXPECT_EQ(h.color & 0xffffffu, 0x4080ffu) << k;
                if (k == 1.0f) {
                    EXPECT_EQ(std::memcmp(&h, &l, sizeof(Splat)), 0) << "splat " << i;
                } else {
                    EXPECT_EQ(h.colorCoord, -2.0f);
                }
            }
        }
    }
}

TEST(HdrLitHardCases, APointLightAtASplatsCentreGivesAFiniteScaleInClosedForm) {
    // A point light of 10^30 exactly at a voxel's centre, and one 10^-30 from
    // it: the inverse square would divide by 0 (or by 10^-60, an underflow).
    // The model lights a voxel closer than half its size isotropically with
    // the irradiance half a voxel away (docs/lighting.md): that splat's
    // scale is 0.8 x 10^30 / (0.125)^2 (a voxel of 0.25), within the model's
    // float rounding (1e-6), finite.
    Grid g = voxels({3, 3, 3});
    const glm::vec3 centre = g.worldPosition({1, 1, 1});
    for (glm::vec3 at : {centre, centre + glm::vec3(1e-30f, 0.0f, 0.0f)}) {
        Lit s(g, ColorTable::constant({0.8f, 0.6f, 0.4f, 1.0f}), {Light::point(at, glm::vec3(1.0f), 1e30f)}, kUnshadowed, true);
        const float want = 0.8f * 1e30f / (0.125f * 0.125f);
        int found = 0;
        for (const Splat& sp : s.splats()) {
            ASSERT_TRUE(std::isfinite(sp.colorCoord) && sp.colorCoord < -1.0f);
            if (glm::length(sp.center - centre) < 1e-4f) {
                EXPECT_NEAR(-sp.colorCoord, want, want * 1e-6f);
                ++found;
            }
        }
        EXPECT_EQ(found, 1);
    }
}

TEST(HdrLitHardCases, NegativeOrNaNLightColoursAreRefusedNamingTheField) {
    // The packing clamps a negative channel to 0 and reads NaN as no light,
    // but neither reaches it from a light: Scene::addLight refuses a
    // negative or NaN colour channel with the field named (validateLight),
    // and the scene keeps its lights.
    Scene scene;
    auto bad = scene.addLight(Light::directional(kSunDir, {1.0f, -0.5f, 1.0f}, 2.0f));
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("lights[0].color.g must be a finite number >= 0"), std::string::npos) << bad.error();
    auto nan = scene.addLight(Light::directional(kSunDir, {1.0f, 1.0f, std::nanf("")}, 2.0f));
    ASSERT_FALSE(nan);
    EXPECT_NE(nan.error().find("lights[0].color.b must be a finite number >= 0"), std::string::npos) << nan.error();
    EXPECT_TRUE(scene.lights().empty());
}

TEST(HdrLitHardCases, ANaNColourTableEntryIsDarkNotANaNScale) {
    // A colour table is the host's data; an entry with a NaN channel (the API
    // does not check table values) lit by a sun of 4: that channel is no
    // light (byte 0), the others keep their scale, never a NaN colorCoord.
    const float nan = std::nanf("");
    ColorTable table = ColorTable::constant({0.5f, nan, 0.25f, 1.0f});
    Lit s(voxels({2, 2, 2}), table, {Light::directional(kSunDir, glm::vec3(1.0f), 4.0f)}, kUnshadowed, true);
    ASSERT_FALSE(s.splats().empty());
    for (const Splat& sp : s.splats()) {
        ASSERT_FALSE(std::isnan(sp.colorCoord));
        EXPECT_NEAR(-sp.colorCoord, 2.0f, 2.0f * 1e-6f);
        EXPECT_EQ(byteOf(sp, 1), 0u);
        EXPECT_EQ(byteOf(sp, 0), 255u);
        EXPECT_EQ(byteOf(sp, 2), 128u);
    }
}
