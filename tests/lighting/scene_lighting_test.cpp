// Lights in a Scene (issue 16, items 1-4): lit splat colours follow the
// low-albedo model exactly, self-shadow tables are rebuilt only when density
// or a light changed, and the frame carries the scene shadow as plain data.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/cloud.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/volume.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// Everything a lit-scene test needs: materials with one constant colour table
// and a 1560-voxel effect drawn untextured with it.
struct LitScene {
    Materials materials{Footprint{}};
    Scene scene;
    EffectId id = 0;
    Frame frame;
    Camera camera = Camera::lookAt({0.0f, 3.0f, 12.0f}, {0.0f, 3.0f, 0.0f}, {0, 1, 0}, glm::radians(50.0f), {320, 240}, 0.1f, 100.0f);
    glm::vec4 base{0.8f, 0.6f, 0.4f, 1.0f};

    explicit LitScene(EffectLighting lighting, Motion motion = {}) {
        const std::uint32_t table = materials.addColorTable(ColorTable::constant(base));
        EffectDesc desc;
        desc.name = "gas";
        desc.motion = std::move(motion);
        desc.layers = {EffectLayer{.style = {.colorTable = table, .textured = false}}};
        id = scene.add(*Effect::fromGrid(test::effect1560(), desc), {.name = "gas", .lighting = lighting});
    }
    void prepare(double t) { EXPECT_TRUE(scene.prepare(t, camera, materials, frame)); }
};

glm::vec3 unpack(std::uint32_t c) { return glm::vec3(float(c & 255u), float((c >> 8) & 255u), float((c >> 16) & 255u)) / 255.0f; }

} // namespace

TEST(SceneLighting, UnlitEffectKeepsTableColoursAndBuildsNoTables) {
    LitScene s({.enabled = false});
    ASSERT_TRUE(s.scene.addLight(Light::directional({0, -1, 0})));
    s.prepare(0.0);
    ASSERT_GT(s.frame.splats().size(), 0u);
    // The builder's own packing of the constant table: round(c * 255).
    const std::uint32_t expected =
        std::uint32_t(0.8f * 255 + 0.5f) | std::uint32_t(0.6f * 255 + 0.5f) << 8 | std::uint32_t(0.4f * 255 + 0.5f) << 16 | 0xff000000u;
    for (const Splat& sp : s.frame.splats()) ASSERT_EQ(sp.color, expected);
    EXPECT_EQ(s.frame.counters().litEffects, 0u);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 0u);
    EXPECT_FALSE(s.frame.shadow().valid);
}

TEST(SceneLighting, UnshadowedIsotropicGasOfAlbedoOneShowsItsBaseColourScaledByAlbedo) {
    // Closed form (docs/lighting.md): out = base * albedo * 4 pi * (1 / 4 pi) * E = base * albedo for a
    // white sun of intensity 1 and no shadowing. Tolerance: the 8-bit packing (half a level) plus
    // float rounding of the product (well under a level): 1 level.
    for (float albedo : {1.0f, 0.5f}) {
        LitScene s({.enabled = true, .gas = {.albedo = albedo}, .selfShadow = SelfShadow::Off});
        ASSERT_TRUE(s.scene.addLight(Light::directional({0.3f, -1, 0.2f})));
        s.prepare(0.0);
        ASSERT_GT(s.frame.splats().size(), 0u);
        EXPECT_EQ(s.frame.counters().litEffects, 1u);
        for (const Splat& sp : s.frame.splats()) {
            const glm::vec3 c = unpack(sp.color);
            for (int a = 0; a < 3; ++a) ASSERT_NEAR(c[a], s.base[a] * albedo, 1.0f / 255.0f) << "albedo " << albedo;
        }
    }
}

TEST(SceneLighting, TracedSelfShadowMatchesTheFieldsTransmittance) {
    // Each splat's colour = base * T with T = exp2(-depth to the light) through the field the light
    // sees; for an opaque-table, single-layer effect that field is DensityField::fromGrid(grid).
    LitScene s({.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Traced});
    const Light sun = Light::directional({0.4f, -1.0f, 0.1f});
    ASSERT_TRUE(s.scene.addLight(sun));
    s.prepare(0.0);
    auto field = DensityField::fromGrid(s.scene.effect(s.id).grid());
    ASSERT_TRUE(field);
    double darkest = 1.0;
    for (const Splat& sp : s.frame.splats()) {
        const float T = std::exp2(-field->opticalDepthToLight(sp.center, sun));
        darkest = std::min(darkest, double(T));
        const glm::vec3 c = unpack(sp.color);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(c[a], s.base[a] * T, 1.0f / 255.0f);
    }
    EXPECT_LT(darkest, 0.5) << "the gas should shadow itself noticeably";
}

TEST(SceneLighting, TableSelfShadowIsTheTablesTransmittanceAndCloseToTraced) {
    // Wiring: each splat's colour = base * T_table(centre) for the table over the field the light sees
    // (1 level: the 8-bit packing). Accuracy: docs/lighting.md measures a 64^3 table on this effect at
    // 0.37/255 mean error in transmittance; the packing adds up to half a level per colour, i.e.
    // 0.5 / 255 / base.r in T: the mean bound is their sum rounded up, 1.5/255.
    LitScene traced({.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Traced});
    LitScene table({.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(64)});
    const Light sun = Light::directional({0.4f, -1.0f, 0.1f});
    ASSERT_TRUE(traced.scene.addLight(sun));
    ASSERT_TRUE(table.scene.addLight(sun));
    traced.prepare(0.0);
    table.prepare(0.0);
    auto field = DensityField::fromGrid(table.scene.effect(table.id).grid());
    ASSERT_TRUE(field);
    ShadowTable reference({.dims = glm::ivec3(64)});
    ASSERT_TRUE(reference.update(*field, sun));
    ASSERT_EQ(traced.frame.splats().size(), table.frame.splats().size());
    double sum = 0.0;
    for (std::size_t i = 0; i < table.frame.splats().size(); ++i) {
        const Splat& sp = table.frame.splats()[i];
        const glm::vec3 c = unpack(sp.color);
        const float T = reference.transmittance(sp.center);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(c[a], table.base[a] * T, 1.0f / 255.0f);
        sum += std::abs(c.r - unpack(traced.frame.splats()[i].color).r) / table.base.r;
    }
    EXPECT_LE(sum / double(table.frame.splats().size()), 1.5 / 255.0);
}

TEST(SceneLighting, StaticEffectsTablesAreNotRebuilt) {
    LitScene s({.enabled = true, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(16)});
    ASSERT_TRUE(s.scene.addLight(Light::directional({0.4f, -1.0f, 0.1f})));
    ASSERT_TRUE(s.scene.addLight(Light::point({1.0f, 4.0f, 1.0f})));
    s.prepare(0.0);
    // First frame: one self-shadow table per light and one scene shadow per light.
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 4u);
    const std::uint64_t version = s.frame.shadow().version;
    EXPECT_TRUE(s.frame.shadow().valid);
    for (int f = 1; f < 5; ++f) {
        s.prepare(f / 30.0); // a grid effect at rest: the same density every frame
        EXPECT_EQ(s.frame.counters().shadowTableBuilds, 0u) << "frame " << f;
        EXPECT_EQ(s.frame.counters().shadowTableReuses, 4u) << "frame " << f;
    }
    EXPECT_EQ(s.scene.status(s.id).shadowTableBuilds, 2u);
    EXPECT_EQ(s.scene.status(s.id).shadowTableReuses, 8u);
    EXPECT_EQ(s.frame.shadow().version, version) << "an unchanged scene shadow is not copied again";
    // A light that moves rebuilds its own two tables (self-shadow and scene shadow), not the other's.
    ASSERT_TRUE(s.scene.setLight(1, Light::point({1.5f, 4.0f, 1.0f})));
    s.prepare(5 / 30.0);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 2u);
    EXPECT_EQ(s.frame.shadow().version, version) << "light 0's scene shadow is untouched";
    ASSERT_TRUE(s.scene.setLight(0, Light::directional({0.5f, -1.0f, 0.1f})));
    s.prepare(6 / 30.0);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 2u);
    EXPECT_NE(s.frame.shadow().version, version);
}

TEST(SceneLighting, MovingEffectRebuildsEveryFrame) {
    const Motion motion({}, ProceduralMotion{.velocity = {1.0f, 0.0f, 0.0f}});
    LitScene s({.enabled = true, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(8)}, motion);
    ASSERT_TRUE(s.scene.addLight(Light::directional({0.4f, -1.0f, 0.1f})));
    s.prepare(0.0);
    s.prepare(0.5);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 2u) << "self shadow and scene shadow of a moved gas";
}

TEST(SceneLighting, FrameShadowIsTheTableOverTheLitEffects) {
    LitScene s({.enabled = true, .selfShadow = SelfShadow::Off});
    const Light sun = Light::directional({0.4f, -1.0f, 0.1f});
    ASSERT_TRUE(s.scene.addLight(sun));
    s.scene.setSceneShadow({.dims = glm::ivec3(24, 32, 16)});
    s.prepare(0.0);
    const FrameShadow& fs = s.frame.shadow();
    ASSERT_TRUE(fs.valid);
    EXPECT_EQ(fs.dims, glm::ivec3(24, 32, 16));
    ShadowTable reference({.dims = glm::ivec3(24, 32, 16)});
    auto field = DensityField::fromGrid(s.scene.effect(s.id).grid());
    ASSERT_TRUE(field);
    ASSERT_TRUE(reference.update(*field, sun));
    ASSERT_EQ(fs.depth.size(), reference.data().size());
    for (std::size_t i = 0; i < fs.depth.size(); ++i) ASSERT_EQ(fs.depth[i], reference.data()[i]) << i;
    EXPECT_EQ(fs.worldToTable, reference.worldToTable());
    EXPECT_EQ(fs.lightInTable, reference.lightInTable());
    // Switched off: the frame says so.
    s.scene.setSceneShadow({.enabled = false});
    s.prepare(1 / 30.0);
    EXPECT_FALSE(s.frame.shadow().valid);
}

TEST(SceneLighting, BadOptionsNameTheFieldAndLeaveTheEffectUnlit) {
    LitScene s({.enabled = true, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(0, 8, 8)});
    ASSERT_TRUE(s.scene.addLight(Light::directional({0, -1, 0})));
    s.prepare(0.0);
    EXPECT_NE(s.scene.lightingError().find("tableDims"), std::string::npos) << s.scene.lightingError();
    EXPECT_EQ(s.frame.counters().litEffects, 0u);
    Light bad = Light::directional({0, -1, 0});
    bad.intensity = -1.0f;
    auto r = s.scene.addLight(bad);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("lights[1].intensity"), std::string::npos) << r.error();
    EXPECT_FALSE(s.scene.setLight(7, Light{}));
}

TEST(SceneLighting, TablesOverTheLightingBudgetAreNeverBuiltAndTheErrorNamesTheField) {
    // Four lights x a 128^3 table (17 bytes an entry: 34 MiB each, under the
    // 64 MiB a table may take) plus the default 64^3 scene shadow: 147 MiB,
    // over a 100 MiB lightingBytes. Checked before any table is built.
    LitScene s({.enabled = true, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(128)});
    for (int i = 0; i < 4; ++i) ASSERT_TRUE(s.scene.addLight(Light::directional({0.1f * float(i), -1.0f, 0.0f})));
    Budgets b;
    b.lightingBytes = 100ull << 20;
    s.scene.setBudgets(b);
    s.prepare(0.0);
    const std::string& e = s.scene.lightingError();
    EXPECT_NE(e.find("lighting: the shadow tables of 4 light(s) x 1 table-lit effect(s) and the scene shadow needs 147062784 bytes"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("(raise Budgets::lightingBytes)"), std::string::npos) << e;
    EXPECT_EQ(s.frame.counters().litEffects, 0u);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 0u);
    EXPECT_FALSE(s.frame.shadow().valid);
    // Within the budget the same scene is lit and shadows.
    b.lightingBytes = 200ull << 20;
    s.scene.setBudgets(b);
    s.prepare(0.1);
    EXPECT_EQ(s.scene.lightingError(), "");
    EXPECT_EQ(s.frame.counters().litEffects, 1u);
    EXPECT_TRUE(s.frame.shadow().valid);
}

TEST(SceneLighting, TheLightingBudgetCountsOnlyTheTablesThatAreBuilt) {
    // A lit ground fog and a lit cloud keep the default options (SelfShadow::Table, 32^3) but
    // build no self-shadow tables (the fog's light is a closed form, the cloud's its relight):
    // a budget that holds exactly the effect's four tables and the scene shadow still holds
    // with them in the scene, and the error counts one table-lit effect.
    LitScene s({.enabled = true, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(128)});
    for (int i = 0; i < 4; ++i) ASSERT_TRUE(s.scene.addLight(Light::directional({0.1f * float(i), -1.0f, 0.0f})));
    const TransferFunction fogTransfer = *makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, 1.2f);
    GroundFogDesc fog;
    fog.dims = {9, 9};
    fog.terrainHeight.assign(81, 0.0f);
    fog.fogTop.assign(81, 1.5f);
    s.scene.add(*GroundFog::create(fog), fogTransfer, *PreIntegrationTable::create(fogTransfer, {.scalarResolution = 4, .lengthResolution = 4}),
                {.name = "fog", .lighting = {.enabled = true}});
    CloudLighting cloudLight;
    cloudLight.model = CloudLightModel::LowAlbedo;
    s.scene.add(*Cloud::create({.cloud = {.dims = {9, 9, 5}}, .lighting = cloudLight}), {.name = "cloud", .lighting = {.enabled = true}});
    const std::uint64_t needed = 147062784; // 4 x 128^3 x 17 bytes + the 64^3 scene shadow (the test above)
    Budgets b;
    b.lightingBytes = needed;
    s.scene.setBudgets(b);
    s.prepare(0.0);
    EXPECT_EQ(s.scene.lightingError(), "");
    EXPECT_TRUE(s.frame.shadow().valid);
    b.lightingBytes = needed - 1;
    s.scene.setBudgets(b);
    s.prepare(0.1);
    EXPECT_NE(s.scene.lightingError().find("4 light(s) x 1 table-lit effect(s) and the scene shadow needs 147062784 bytes"), std::string::npos)
        << s.scene.lightingError();
}

TEST(SceneLighting, ASceneShadowLightPastTheLightsIsAnErrorNotNoShadow) {
    LitScene s({.enabled = true, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(16)});
    ASSERT_TRUE(s.scene.addLight(Light::directional({0, -1, 0})));
    s.scene.setSceneShadow({.light = 63});
    s.prepare(0.0);
    EXPECT_EQ(s.scene.lightingError(), "sceneShadow.light: expected the index of one of the scene's 1 light(s), 0 to 0, got 63");
    EXPECT_FALSE(s.frame.shadow().valid);
    EXPECT_EQ(s.frame.counters().litEffects, 1u) << "the effect itself is still lit";
    // No lights at all: a scene without lights has nothing to shadow, and that is not an error.
    s.scene.clearLights();
    s.prepare(0.1);
    EXPECT_EQ(s.scene.lightingError(), "");
}

TEST(SceneLighting, OneCasterWithTheSceneShadowsDimsSharesItsTable) {
    LitScene s({.enabled = true, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(40)});
    const Light sun = Light::directional({0.4f, -1.0f, 0.1f});
    ASSERT_TRUE(s.scene.addLight(sun));
    s.scene.setSceneShadow({.dims = glm::ivec3(40)});
    s.prepare(0.0);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 1u) << "the self-shadow table is the scene shadow";
    EXPECT_EQ(s.scene.counters().sceneShadowBuilds, 0u);
    ASSERT_TRUE(s.frame.shadow().valid);
    ShadowTable reference({.dims = glm::ivec3(40)});
    auto field = DensityField::fromGrid(s.scene.effect(s.id).grid());
    ASSERT_TRUE(field && reference.update(*field, sun));
    ASSERT_EQ(s.frame.shadow().depth, reference.data());
}

TEST(SceneLighting, ReferenceRendererIntegratesTheLitColours) {
    // Lighting scales every splat's colour by albedo 0.5 here (closed form above); compositing is
    // linear in the splat colours at fixed alphas, so the reference image with the packed (lit)
    // colours is 0.5 x the one read from the table, up to the 8-bit packing: at most half a level
    // per splat, and "over" weights sum to at most 1, so 0.5/255 per pixel (plus double rounding).
    LitScene s({.enabled = true, .gas = {.albedo = 0.5f}, .selfShadow = SelfShadow::Off});
    s.camera = Camera::lookAt({0.0f, 3.0f, 12.0f}, {0.0f, 3.0f, 0.0f}, {0, 1, 0}, glm::radians(50.0f), {48, 36}, 0.1f, 100.0f);
    ASSERT_TRUE(s.scene.addLight(Light::directional({0.3f, -1, 0.2f})));
    s.prepare(0.0);
    auto lit = renderSplatExact(s.frame.splats(), s.camera, s.materials, {.threads = 1, .packedColor = true});
    auto table = renderSplatExact(s.frame.splats(), s.camera, s.materials, {.threads = 1});
    ASSERT_TRUE(lit && table);
    double brightest = 0.0;
    for (int y = 0; y < lit->height; ++y)
        for (int x = 0; x < lit->width; ++x)
            for (int c = 0; c < 3; ++c) {
                ASSERT_NEAR(lit->at(x, y, c), 0.5f * table->at(x, y, c), 0.5f / 255.0f + 1e-6f) << x << "," << y;
                brightest = std::max(brightest, double(table->at(x, y, c)));
            }
    EXPECT_GT(brightest, 0.2) << "the gas should cover some pixels";
}
