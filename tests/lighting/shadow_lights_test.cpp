// Every light casts (issue 27 item 1): one scene-shadow table per shadowing
// light, up to kMaxShadowLights, each the ShadowTable of that light over the
// casters it reaches; rebuilt per light; the lights past the count or the
// memory budget dropped least influential first, and counted.
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

const Light kSun = test::shadowSun();
// A torch up and to the right of the gas, and a spot up to the left aimed at its centre.
const Light kTorch = test::shadowTorch();
const Light kSpot = Light::spot({-3.0f, 6.0f, 0.5f}, glm::vec3(0.0f, 2.6f, 0.0f) - glm::vec3(-3.0f, 6.0f, 0.5f), 0.3f, 0.5f);

Camera camera() { return Camera::lookAt({0.0f, 6.0f, 10.0f}, {0.0f, 1.0f, 0.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 100.0f); }

// A lit (unshadowed itself: only the scene shadows are built) gas blob, 2.2
// wide, floating from y = 1.5 to 3.7 over the origin.
struct LightsScene {
    Materials materials{Footprint{}};
    Scene scene;
    Frame frame;
    EffectId id = 0;
    LightsScene() {
        const std::uint32_t table = materials.addColorTable(ColorTable::constant({0.8f, 0.8f, 0.8f, 1.0f}));
        id = test::addLitEffect(scene, test::floatingBlob(), table, "gas", {.enabled = true, .selfShadow = SelfShadow::Off});
        scene.setSceneShadow({.dims = glm::ivec3(16)});
    }
    void prepare(double t) { ASSERT_TRUE(scene.prepare(t, camera(), materials, frame)) << scene.lightingError(); }
    DensityField field() const { return *DensityField::fromGrid(scene.effect(id).grid()); }
    // The table a host would build by hand for one light at the scene's dims.
    ShadowTable tableFor(const Light& light, glm::ivec3 dims = glm::ivec3(16)) const {
        ShadowTable t({.dims = dims});
        const DensityField f = field();
        EXPECT_TRUE(t.update(f, light));
        return t;
    }
    // The scene lights with a table this frame, slot order.
    std::vector<int> slotLights() const {
        std::vector<int> out;
        for (const FrameShadow& s : frame.shadows())
            if (s.valid) out.push_back(s.light);
        return out;
    }
};

Light dimSun(float intensity, float tilt) {
    Light l = Light::directional({tilt, -1.0f, 0.0f});
    l.intensity = intensity;
    return l;
}

} // namespace

TEST(ShadowLights, EveryShadowingLightHasItsOwnTableEqualToAShadowTableForIt) {
    LightsScene s;
    for (const Light& l : {kSun, kTorch, kSpot}) ASSERT_TRUE(s.scene.addLight(l));
    s.prepare(0.0);
    EXPECT_EQ(s.scene.lightingError(), "");
    EXPECT_EQ(s.slotLights(), (std::vector<int>{0, 1, 2}));
    EXPECT_EQ(s.scene.counters().sceneShadowLights, 3u);
    EXPECT_EQ(s.frame.counters().shadowLights, 3u);
    EXPECT_EQ(s.frame.counters().shadowLightsDropped, 0u);
    EXPECT_FALSE(s.frame.shadows()[3].valid);
    // Sun, torch (a point light) and spot: each slot is exactly what ShadowTable builds for that light.
    const Light lights[] = {kSun, kTorch, kSpot};
    glm::vec3 darkestAt[3];
    for (int k = 0; k < 3; ++k) {
        const FrameShadow& fs = s.frame.shadows()[std::size_t(k)];
        const ShadowTable ref = s.tableFor(lights[k]);
        ASSERT_EQ(fs.depth, ref.data()) << "slot " << k;
        EXPECT_EQ(fs.worldToTable, ref.worldToTable());
        EXPECT_EQ(fs.lightInTable, ref.lightInTable());
        EXPECT_EQ(s.scene.sceneShadowBuilds(std::size_t(k)), 1u);
        // Where each light's shadow falls on the ground (y = 0): its darkest point on a 0.1 grid.
        float darkest = 1.0f;
        for (float x = -8.0f; x <= 8.0f; x += 0.1f)
            for (float z = -4.0f; z <= 4.0f; z += 0.1f)
                if (const float T = ref.transmittance({x, 0.0f, z}); T < darkest) darkest = T, darkestAt[k] = {x, 0.0f, z};
        EXPECT_LT(darkest, 0.7f) << "light " << k << " should cast a visible shadow on the ground";
    }
    // Three shadows, in three places: the sun's straight under-and-beyond, the torch's to the left, the spot's to the right.
    EXPECT_GT(glm::length(darkestAt[0] - darkestAt[1]), 1.0f);
    EXPECT_GT(glm::length(darkestAt[0] - darkestAt[2]), 1.0f);
    EXPECT_GT(glm::length(darkestAt[1] - darkestAt[2]), 1.0f);
    EXPECT_LT(darkestAt[1].x, 0.0f) << "the torch at x = +2.5 throws the shadow to -x";
    EXPECT_GT(darkestAt[2].x, 0.0f) << "the spot at x = -3 throws it to +x";
}

TEST(ShadowLights, MovingOneLightRebuildsOnlyThatLightsTable) {
    LightsScene s;
    ASSERT_TRUE(s.scene.addLight(kSun));
    ASSERT_TRUE(s.scene.addLight(kTorch));
    s.prepare(0.0);
    ASSERT_EQ(s.slotLights(), (std::vector<int>{0, 1}));
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 2u);
    const std::uint64_t v0 = s.frame.shadows()[0].version, v1 = s.frame.shadows()[1].version;
    // Nothing moved: nothing built, nothing copied.
    s.prepare(1 / 30.0);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 0u);
    EXPECT_EQ(s.scene.sceneShadowBuilds(0), 1u);
    EXPECT_EQ(s.scene.sceneShadowBuilds(1), 1u);
    EXPECT_EQ(s.frame.shadows()[0].version, v0);
    EXPECT_EQ(s.frame.shadows()[1].version, v1);
    // The torch moves: its table only.
    Light moved = kTorch;
    moved.position.x += 0.5f;
    ASSERT_TRUE(s.scene.setLight(1, moved));
    s.prepare(2 / 30.0);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 1u);
    EXPECT_EQ(s.scene.sceneShadowBuilds(0), 1u) << "moving light B must not rebuild light A's table";
    EXPECT_EQ(s.scene.sceneShadowBuilds(1), 2u);
    EXPECT_EQ(s.frame.shadows()[0].version, v0) << "the sun's slot is not copied again";
    EXPECT_NE(s.frame.shadows()[1].version, v1);
    EXPECT_EQ(s.frame.shadows()[1].depth, s.tableFor(moved).data());
    // The sun turns: its table only.
    ASSERT_TRUE(s.scene.setLight(0, Light::directional({-0.3f, -1.0f, 0.2f})));
    s.prepare(3 / 30.0);
    EXPECT_EQ(s.scene.sceneShadowBuilds(0), 2u);
    EXPECT_EQ(s.scene.sceneShadowBuilds(1), 2u);
    // New dims: every table is made again, and the frame gets the new ones (not the old data
    // under a build count that happens to match).
    s.scene.setSceneShadow({.dims = glm::ivec3(12)});
    s.prepare(4 / 30.0);
    EXPECT_EQ(s.frame.shadows()[0].depth, s.tableFor(s.scene.lights()[0], glm::ivec3(12)).data());
    EXPECT_EQ(s.frame.shadows()[1].depth, s.tableFor(moved, glm::ivec3(12)).data());
}

TEST(ShadowLights, NPlusOneLightsKeepTheMostInfluentialAndCountTheRest) {
    // kMaxShadowLights + 1 suns; light 0 is slot 0's (SceneShadowDesc::light) however dim. Of the
    // rest the three brightest (irradiance = intensity here: one caster, white suns) get tables:
    // 4 (0.9), 2 (0.8), 3 (0.5); light 1 (0.2) does not.
    LightsScene s;
    const float intensity[] = {0.1f, 0.2f, 0.8f, 0.5f, 0.9f};
    static_assert(std::size(intensity) == std::size_t(kMaxShadowLights) + 1);
    for (int i = 0; i < kMaxShadowLights + 1; ++i) ASSERT_TRUE(s.scene.addLight(dimSun(intensity[i], 0.1f * float(i))));
    s.prepare(0.0);
    EXPECT_EQ(s.slotLights(), (std::vector<int>{0, 2, 3, 4})) << "slot 0, then the kept lights in light order";
    EXPECT_EQ(s.scene.counters().sceneShadowLightsOverMax, 1u);
    EXPECT_EQ(s.scene.counters().sceneShadowLightsOverBudget, 0u);
    EXPECT_EQ(s.frame.counters().shadowLightsDropped, 1u);
    EXPECT_EQ(s.scene.sceneShadowBuilds(1), 0u);
    // A host asking for light 1's shadow gets none (splatfx_shadowTo returns 1): no slot names it.
    // Fewer slots asked for: the same ranking, cut shorter.
    s.scene.setSceneShadow({.maxLights = 2, .dims = glm::ivec3(16)});
    s.prepare(1 / 30.0);
    EXPECT_EQ(s.slotLights(), (std::vector<int>{0, 4}));
    EXPECT_EQ(s.scene.counters().sceneShadowLightsOverMax, 3u);
    EXPECT_FALSE(s.frame.shadows()[2].valid);
    EXPECT_EQ(s.frame.shadows()[2].light, -1);
    // Out of range: an error naming the field, not a silent clamp.
    s.scene.setSceneShadow({.maxLights = kMaxShadowLights + 1, .dims = glm::ivec3(16)});
    s.prepare(2 / 30.0);
    EXPECT_EQ(s.scene.lightingError(), "sceneShadow.maxLights: expected 1 to 4, got 5");
    EXPECT_FALSE(s.frame.shadow().valid);
}

TEST(ShadowLights, OverTheMemoryBudgetTheLeastInfluentialLightIsDroppedAndCounted) {
    const std::uint64_t each = ShadowTable::memoryBytes(glm::ivec3(16)); // 16^3 x 17 bytes
    LightsScene s;
    for (float i : {1.0f, 0.3f, 0.7f}) ASSERT_TRUE(s.scene.addLight(dimSun(i, 0.2f * i)));
    // Room for two tables (and a bit): slot 0's and the brighter of the other two.
    s.scene.setSceneShadow({.dims = glm::ivec3(16), .memoryBudgetBytes = 2 * each + 1000});
    s.prepare(0.0);
    EXPECT_EQ(s.scene.lightingError(), "");
    EXPECT_EQ(s.slotLights(), (std::vector<int>{0, 2}));
    EXPECT_EQ(s.scene.counters().sceneShadowLightsOverBudget, 1u);
    EXPECT_EQ(s.scene.counters().sceneShadowLightsOverMax, 0u);
    EXPECT_EQ(s.frame.counters().shadowLightsDropped, 1u);
    // The same from Budgets::lightingBytes: slot 0's table is required (checked before any
    // build), the others only take what is left: here one more.
    s.scene.setSceneShadow({.dims = glm::ivec3(16)});
    Budgets b;
    b.lightingBytes = 2 * each;
    s.scene.setBudgets(b);
    s.prepare(1 / 30.0);
    EXPECT_EQ(s.scene.lightingError(), "");
    EXPECT_EQ(s.slotLights(), (std::vector<int>{0, 2}));
    EXPECT_EQ(s.scene.counters().sceneShadowLightsOverBudget, 1u);
    // Room for all three.
    b.lightingBytes = 3 * each;
    s.scene.setBudgets(b);
    s.prepare(2 / 30.0);
    EXPECT_EQ(s.slotLights(), (std::vector<int>{0, 1, 2}));
    EXPECT_EQ(s.frame.counters().shadowLightsDropped, 0u);
}

TEST(ShadowLights, ACasterOutOfViewIsAdvancedWhenAnyLightsShadowReachesTheView) {
    // tests/lighting/shadow_schedule_test.cpp's camera B: the plume just outside its left edge.
    const Camera camB = Camera::lookAt({1.0f, 9.0f, 6.0f}, {1.5f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(36.0f), {64, 64}, 0.1f, 100.0f);
    const Light away = Light::directional({-1.0f, -1.0f, 0.0f}); // throws the plume's shadow further left, out of view
    const Light into = Light::directional({1.0f, -1.0f, 0.0f});  // throws it right, onto the ground in view
    Materials materials{Footprint{}};
    const std::uint32_t row = materials.addColorTable(ColorTable::constant({0.8f, 0.8f, 0.8f, 1.0f}));
    Scene scene;
    Grid g = test::gaussianBlob(12, 0.2f, 0.9f);
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-4.0f, 3.0f, -1.1f));
    const EffectId plume = test::addLitEffect(scene, g, row, "plume", {.enabled = true, .selfShadow = SelfShadow::Off});
    ASSERT_TRUE(scene.addLight(away));
    Frame frame;
    ASSERT_TRUE(scene.prepare(0.0, camB, materials, frame));
    ASSERT_FALSE(scene.status(plume).inView);
    EXPECT_FALSE(scene.status(plume).castsIntoView) << "light 0 alone throws the shadow away from the view";
    EXPECT_EQ(scene.counters().castersCulled, 1u);
    // A second light whose shadow of the plume does reach the view: the plume is advanced and
    // cast (undrawn), and light 1 gets its table although it is not slot 0's light.
    ASSERT_TRUE(scene.addLight(into));
    ASSERT_TRUE(scene.prepare(1 / 30.0, camB, materials, frame));
    EXPECT_TRUE(scene.status(plume).castsIntoView);
    EXPECT_EQ(scene.status(plume).splatsDrawn, 0u);
    EXPECT_TRUE(scene.status(plume).inSceneShadow);
    ASSERT_TRUE(frame.shadows()[1].valid);
    EXPECT_EQ(frame.shadows()[1].light, 1);
    ShadowTable ref({.dims = glm::ivec3(64)});
    ASSERT_TRUE(ref.update(*DensityField::fromGrid(g), into));
    EXPECT_EQ(frame.shadows()[1].depth, ref.data());
}

// ---- Named hard cases (docs/STABILITY.md, lighting)

TEST(ShadowLightsHardCases, TwoLightsAtTheSamePositionGetEqualIndependentTables) {
    // Equal influence (a tie broken by light order), equal tables; moving one leaves the other's.
    LightsScene s;
    Light red = kTorch, blue = kTorch;
    red.color = {1.0f, 0.0f, 0.0f}, blue.color = {0.0f, 0.0f, 1.0f};
    ASSERT_TRUE(s.scene.addLight(red));
    ASSERT_TRUE(s.scene.addLight(blue));
    s.prepare(0.0);
    ASSERT_EQ(s.slotLights(), (std::vector<int>{0, 1}));
    EXPECT_EQ(s.frame.shadows()[0].depth, s.frame.shadows()[1].depth);
    EXPECT_EQ(s.frame.shadows()[1].depth, s.tableFor(blue).data());
    blue.position.y += 1.0f;
    ASSERT_TRUE(s.scene.setLight(1, blue));
    s.prepare(1 / 30.0);
    EXPECT_EQ(s.frame.shadows()[0].depth, s.tableFor(red).data());
    EXPECT_EQ(s.frame.shadows()[1].depth, s.tableFor(blue).data());
    EXPECT_EQ(s.scene.sceneShadowBuilds(0), 1u);
}

TEST(ShadowLightsHardCases, APointLightInsideTheCasterShadowsTheGroundInEveryDirection) {
    // A torch at the gas's centre: every ray to the ground leaves through gas, so the ground is
    // shadowed under it and far to every side (a light inside treated as outside, or its caster
    // culled, would leave T = 1 somewhere). The table's error against tracing for this case is
    // measured in docs/lighting.md ("A point light inside"), not asserted here.
    LightsScene s;
    const DensityField f = s.field();
    const glm::vec3 centre = 0.5f * (f.boundsMin() + f.boundsMax());
    ASSERT_TRUE(s.scene.addLight(Light::point(centre)));
    s.prepare(0.0);
    ASSERT_TRUE(s.frame.shadow().valid);
    const ShadowTable ref = s.tableFor(Light::point(centre));
    ASSERT_EQ(s.frame.shadow().depth, ref.data());
    for (float a = 0.0f; a < 6.28f; a += 0.5f)
        for (float radius : {0.0f, 1.0f, 4.0f}) {
            const glm::vec3 g(radius * std::cos(a), 0.0f, radius * std::sin(a));
            const float traced = f.opticalDepthToLight(g, Light::point(centre));
            const float table = ref.opticalDepth(g);
            ASSERT_TRUE(std::isfinite(table));
            EXPECT_GT(traced, 0.0f) << g.x << "," << g.z;
            EXPECT_GT(table, 0.0f) << g.x << "," << g.z << ": the table must shadow it too";
        }
}

TEST(ShadowLightsHardCases, APointLightExactlyAtASceneTableNodeIsFiniteAndZeroThere) {
    // The scene table spans the gas's support; put the light on node (5, 9, 7) of 16^3.
    LightsScene s;
    const DensityField f = s.field();
    const glm::vec3 lo = f.boundsMin(), hi = f.boundsMax();
    const glm::ivec3 node(5, 9, 7);
    const glm::vec3 at = lo + (hi - lo) * glm::vec3(node) / 15.0f;
    ASSERT_TRUE(s.scene.addLight(Light::point(at)));
    s.prepare(0.0);
    const FrameShadow& fs = s.frame.shadow();
    ASSERT_TRUE(fs.valid);
    ASSERT_EQ(fs.depth, s.tableFor(Light::point(at)).data());
    for (float d : fs.depth) ASSERT_TRUE(std::isfinite(d) && d >= 0.0f);
    const std::size_t i = std::size_t(node.x + 16 * (node.y + 16 * node.z));
    EXPECT_EQ(fs.depth[i], 0.0f) << "no distance to the light, no depth (not 0/0)";
}

TEST(ShadowLightsHardCases, ASpotConeGrazingTheCasterBuildsItsTableAndOneJustMissingDoesNot) {
    // Scene::lightReaches: a spot reaches the caster when the angle from its axis to the caster's
    // bounding-sphere centre is within outer + asin(r / distance). Aim the axis just inside and
    // just outside that edge (1 mrad either side).
    LightsScene s;
    const DensityField f = s.field();
    const glm::vec3 c = 0.5f * (f.boundsMin() + f.boundsMax());
    const float r = 0.5f * glm::length(f.boundsMax() - f.boundsMin());
    const glm::vec3 pos(-6.0f, 2.6f, 0.0f);
    const float dist = glm::length(c - pos), outer = 0.2f;
    const float edge = outer + std::asin(r / dist);
    auto spotAt = [&](float angle) {
        // The axis turned `angle` away from the caster's centre, in a plane through it.
        const glm::vec3 toCentre = glm::normalize(c - pos), across = glm::normalize(glm::cross(toCentre, glm::vec3(0.0f, 0.0f, 1.0f)));
        return Light::spot(pos, std::cos(angle) * toCentre + std::sin(angle) * across, 0.1f, outer);
    };
    ASSERT_TRUE(s.scene.addLight(kSun));
    ASSERT_TRUE(s.scene.addLight(spotAt(edge - 1e-3f)));
    s.prepare(0.0);
    EXPECT_EQ(s.slotLights(), (std::vector<int>{0, 1})) << "grazing: the cone touches the caster's sphere";
    ASSERT_TRUE(s.scene.setLight(1, spotAt(edge + 1e-3f)));
    s.prepare(1 / 30.0);
    EXPECT_EQ(s.slotLights(), (std::vector<int>{0})) << "just missing: no table, and not counted as dropped";
    EXPECT_EQ(s.frame.counters().shadowLightsDropped, 0u);
    EXPECT_EQ(s.frame.counters().shadowTableBuilds, 0u) << "the miss builds nothing";
    EXPECT_EQ(s.scene.sceneShadowBuilds(1), 0u) << "and the spot's table is freed";
}
