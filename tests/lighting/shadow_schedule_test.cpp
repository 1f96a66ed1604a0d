// Shadows scheduled by light influence, not visibility (issue 24 item 4,
// issue 27 "a shadow depends on the camera, not the light"): a lit caster
// out of view whose shadow falls into the view is advanced and stays in the
// scene shadow, undrawn; one whose shadow cannot reach the view is not
// advanced; a light that cannot reach an effect builds no table for it.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// The sun travels along +x and down: a gas at height h shadows the ground h further along +x.
const Light kSun = Light::directional({1.0f, -1.0f, 0.0f});

// One eye, two directions: towards the plume (A), and turned right onto its
// shadow on the ground (B), where the plume is just outside the left edge.
Camera cameraA() { return Camera::lookAt({1.0f, 9.0f, 6.0f}, {-1.5f, 2.0f, 0.0f}, {0, 1, 0}, glm::radians(36.0f), {64, 64}, 0.1f, 100.0f); }
Camera cameraB() { return Camera::lookAt({1.0f, 9.0f, 6.0f}, {1.5f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(36.0f), {64, 64}, 0.1f, 100.0f); }

struct ShadowScene {
    Materials materials{Footprint{}};
    Scene scene;
    Frame frame;
    std::uint32_t table = 0;
    ShadowScene() { table = materials.addColorTable(ColorTable::constant({0.8f, 0.8f, 0.8f, 1.0f})); }
    // A lit gas blob (x, y, z extent 2.2) with its low corner at `corner`.
    EffectId addBlob(const char* name, glm::vec3 corner, EffectLighting lighting = {.enabled = true, .selfShadow = SelfShadow::Off}) {
        Grid g = test::gaussianBlob(12, 0.2f, 0.9f);
        g.transform = glm::translate(glm::mat4(1.0f), corner);
        EffectDesc desc;
        desc.name = name;
        desc.layers = {EffectLayer{.style = {.colorTable = table, .textured = false}}};
        return scene.add(*Effect::fromGrid(g, desc), {.name = name, .lighting = lighting});
    }
    void prepare(double t, const Camera& c) { ASSERT_TRUE(scene.prepare(t, c, materials, frame)); }
};

// The ground points (y = 0) seen through pixel centres of `camera` (the ground in view).
std::vector<glm::vec3> groundInView(const Camera& camera) {
    std::vector<glm::vec3> points;
    const glm::mat4 inv = glm::inverse(camera.proj * camera.view);
    for (int y = 0; y < camera.viewport.y; ++y)
        for (int x = 0; x < camera.viewport.x; ++x) {
            const glm::vec2 ndc((x + 0.5f) / float(camera.viewport.x) * 2.0f - 1.0f, (y + 0.5f) / float(camera.viewport.y) * 2.0f - 1.0f);
            glm::vec4 n = inv * glm::vec4(ndc, -1.0f, 1.0f), f = inv * glm::vec4(ndc, 1.0f, 1.0f);
            const glm::vec3 a = glm::vec3(n) / n.w, b = glm::vec3(f) / f.w;
            if (!(a.y > 0.0f && b.y < 0.0f)) continue;
            points.push_back(a + (b - a) * (a.y / (a.y - b.y)));
        }
    return points;
}

} // namespace

TEST(ShadowSchedule, ACasterThatLeavesTheViewKeepsShadowingTheGroundInView) {
    ShadowScene s;
    ASSERT_TRUE(s.scene.addLight(kSun));
    const EffectId plume = s.addBlob("plume", {-4.0f, 3.0f, -1.1f});
    s.prepare(0.0, cameraA());
    ASSERT_TRUE(s.scene.status(plume).needed) << "camera A sees the plume";
    ASSERT_TRUE(s.frame.shadow().valid);
    const FrameShadow seen = s.frame.shadow();
    s.prepare(1 / 30.0, cameraB());
    const EffectStatus& st = s.scene.status(plume);
    ASSERT_FALSE(st.inView) << "camera B must not see the plume for this test to mean anything";
    EXPECT_FALSE(st.needed);
    EXPECT_TRUE(st.castsIntoView);
    EXPECT_TRUE(st.inSceneShadow);
    EXPECT_EQ(st.splatsDrawn, 0u) << "cast, not drawn";
    EXPECT_EQ(s.frame.splats().size(), 0u);
    EXPECT_EQ(s.scene.counters().castOnly, 1u);
    EXPECT_EQ(s.scene.counters().simulated, 1u);
    EXPECT_EQ(s.scene.counters().needed, 0u);
    EXPECT_DOUBLE_EQ(s.scene.kind(plume).time(), 1 / 30.0) << "advanced to the frame's time, so its shadow is current";
    // The shadow is the same data, so every ground point in view gets the same shadow term bit for
    // bit (GL: tests/lighting/frame_shadow_gl_test.cpp renders it).
    const FrameShadow& out = s.frame.shadow();
    ASSERT_TRUE(out.valid);
    EXPECT_EQ(out.depth, seen.depth);
    EXPECT_EQ(out.dims, seen.dims);
    EXPECT_EQ(out.worldToTable, seen.worldToTable);
    EXPECT_EQ(out.lightInTable, seen.lightInTable);
    // And that shadow does fall on the ground in view: without the plume camera B would see T = 1
    // everywhere, so this test fails if the caster is dropped.
    auto field = DensityField::fromGrid(s.scene.effect(plume).grid());
    ASSERT_TRUE(field);
    ShadowTable table({.dims = out.dims});
    ASSERT_TRUE(table.update(*field, kSun));
    EXPECT_EQ(table.data(), out.depth);
    float darkest = 1.0f;
    const std::vector<glm::vec3> ground = groundInView(cameraB());
    ASSERT_GT(ground.size(), 1000u);
    for (glm::vec3 p : ground) darkest = std::min(darkest, table.transmittance(p));
    EXPECT_LT(darkest, 0.6f) << "the plume should shadow the ground camera B sees";
}

TEST(ShadowSchedule, ACasterWhoseShadowCannotReachTheViewIsNotAdvanced) {
    ShadowScene s;
    ASSERT_TRUE(s.scene.addLight(kSun));
    const EffectId plume = s.addBlob("plume", {-4.0f, 3.0f, -1.1f});
    // Right of camera B's view with the sun travelling further right: its shadow falls away from the view.
    const EffectId away = s.addBlob("away", {9.0f, 3.0f, -1.1f});
    // Unlit, so it casts nothing: only visibility counts.
    const EffectId unlit = s.addBlob("unlit", {-4.0f, 3.0f, 3.0f}, {.enabled = false});
    s.prepare(0.0, cameraB());
    EXPECT_TRUE(s.scene.status(plume).castsIntoView);
    for (EffectId id : {away, unlit}) {
        EXPECT_FALSE(s.scene.status(id).inView) << id;
        EXPECT_FALSE(s.scene.status(id).castsIntoView) << id;
        EXPECT_FALSE(s.scene.status(id).inSceneShadow) << id;
        EXPECT_EQ(s.scene.status(id).framesSkipped, 1u) << id;
    }
    EXPECT_EQ(s.scene.counters().simulated, 1u);
    EXPECT_EQ(s.scene.counters().castOnly, 1u);
    EXPECT_EQ(s.scene.counters().castersCulled, 1u) << "the lit 'away' caster";
    EXPECT_EQ(s.scene.counters().sceneShadowCasters, 1u);
    // The culled caster was never advanced; turning to it resumes it like any skipped effect.
    s.prepare(0.5, cameraB());
    EXPECT_EQ(s.scene.status(away).framesNeeded + s.scene.status(away).framesCastOnly, 0u);
    EXPECT_EQ(s.scene.status(plume).framesCastOnly, 2u);
}

TEST(ShadowSchedule, ShadowReachUsesTheLightsGeometry) {
    const Camera c = cameraB();
    const Aabb left{{-4.0f, 3.0f, -1.1f}, {-1.8f, 5.2f, 1.1f}};
    ASSERT_FALSE(Scene::inFrustum(left, c));
    EXPECT_TRUE(Scene::shadowReachesView(left, kSun, c));
    // The sun the other way round throws the shadow away from the view.
    EXPECT_FALSE(Scene::shadowReachesView(left, Light::directional({-1.0f, -1.0f, 0.0f}), c));
    // A point light right of the box pushes its shadow left, away from the view; left of it, into the view.
    EXPECT_FALSE(Scene::shadowReachesView(left, Light::point({0.0f, 4.0f, 0.0f}), c));
    EXPECT_TRUE(Scene::shadowReachesView(left, Light::point({-8.0f, 9.0f, 0.0f}), c));
    // A spot light pointing away from the box: no light, no shadow, whatever the geometry.
    EXPECT_FALSE(Scene::shadowReachesView(left, Light::spot({-8.0f, 9.0f, 0.0f}, {-1.0f, 0.0f, 0.0f}, 0.2f, 0.3f), c));
    EXPECT_TRUE(Scene::shadowReachesView(left, Light::spot({-8.0f, 9.0f, 0.0f}, {1.0f, -1.0f, 0.0f}, 0.2f, 0.3f), c));
    // A box in view casts into it whatever the light.
    EXPECT_TRUE(Scene::shadowReachesView({{0.0f, 0.0f, -0.5f}, {1.0f, 1.0f, 0.5f}}, Light::directional({-1.0f, 1.0f, 0.0f}), c));
}

TEST(ShadowSchedule, ALightThatCannotReachAnEffectBuildsNoTableForIt) {
    ShadowScene s;
    const EffectId gas = s.addBlob("gas", {-1.1f, 1.5f, -1.1f}, {.enabled = true, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(16)});
    ASSERT_TRUE(s.scene.addLight(kSun));
    s.scene.setSceneShadow({.maxLights = 1}); // one scene shadow, the sun's: the counts below are the self-shadowing tables'

    // A spot light well above the gas, pointing straight up: its cone (0.3 rad) misses the gas.
    ASSERT_TRUE(s.scene.addLight(Light::spot({0.0f, 8.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0.2f, 0.3f)));
    s.prepare(0.0, cameraA());
    ASSERT_TRUE(s.scene.status(gas).lit);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 2u) << "the sun's self-shadowing table and the scene shadow, not the spot's";
    EXPECT_EQ(s.scene.counters().shadowTableSkips, 1u);
    EXPECT_EQ(s.scene.status(gas).shadowTableSkips, 1u);
    // The spot turned down onto the gas: now it reaches it, and its table is built.
    ASSERT_TRUE(s.scene.setLight(1, Light::spot({0.0f, 8.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, 0.2f, 0.3f)));
    s.prepare(1 / 30.0, cameraA());
    EXPECT_EQ(s.scene.counters().shadowTableSkips, 0u);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 1u) << "only the spot's table (the sun's is reused)";
    // The scene shadow cast by a spot that misses every caster: no table at all.
    ASSERT_TRUE(s.scene.setLight(1, Light::spot({0.0f, 8.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0.2f, 0.3f)));
    s.scene.setSceneShadow({.light = 1, .maxLights = 1});
    const std::uint64_t before = s.scene.counters().sceneShadowBuilds;
    s.prepare(2 / 30.0, cameraA());
    EXPECT_FALSE(s.frame.shadow().valid);
    EXPECT_EQ(s.scene.counters().sceneShadowCasters, 0u);
    EXPECT_EQ(s.scene.counters().sceneShadowBuilds, before);
}
