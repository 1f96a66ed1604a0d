// Effects shadow one another (scene.hpp): a lit effect between a light and a
// second lit effect darkens it by exactly the transmittance through the
// first, towards each light; a caster that cannot shadow the receiver for a
// light is not traced (Scene::shadowFallsOn) and changes nothing. The truth
// is the lit-volume reference (litFactor) over a VolumeField holding the
// OTHER effect as a continuous medium: each voxel's extinction
// -ln(1 - opacity) / spacing (nats per world unit, DensityField's definition
// in nats), trilinear between voxel centres and falling to zero one cell
// beyond (denseMedium, Trilinear), integrated in double.
//
// Tolerance, for every test (as tests/lighting/volume_shadows_test.cpp): the
// lit colour is packed to 8 bits (half a level, 0.5 / 255) and the scene
// traces in float: the caster's depth along a ray (at most ~8 nats here)
// carries a relative error of a few float epsilons per lattice cell crossed
// (< 1e-5 nats over the <= 12 cells), moving the colour (<= 1) by less than
// 1e-5. So |colour - base T| <= 0.5/255 + 1e-5.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

constexpr float kTolerance = 0.5f / 255.0f + 1e-5f;

glm::vec3 unpack(std::uint32_t c) { return glm::vec3(float(c & 255u), float((c >> 8) & 255u), float((c >> 16) & 255u)) / 255.0f; }

// A 4x4x4 grid (spacing 1) with its lowest voxel centre at `at`; opacity
// varies along all three axes (so the trilinear field is not constant along
// any ray) between 0.2 and 0.62.
Grid plumeGrid(glm::vec3 at) {
    Grid g = *Grid::box({4, 4, 4});
    for (Voxel& v : g.voxels) v.opacity = 0.2f + 0.05f * float(v.cell.x) + 0.04f * float(v.cell.y) + 0.05f * float(v.cell.z);
    g.transform = glm::translate(glm::mat4(1.0f), at - g.localPosition({0, 0, 0}));
    return g;
}

// The grid as the reference medium: one voxel per cell, extinction in nats.
ContinuousMedium plumeMedium(const Grid& g) {
    auto v = std::make_shared<DenseVoxels>();
    v->dims = g.dims;
    v->origin = glm::dvec3(g.worldPosition({0, 0, 0}));
    v->voxelSize = double(g.spacing.x);
    v->values.assign(std::size_t(g.dims.x) * std::size_t(g.dims.y) * std::size_t(g.dims.z), 0.0f);
    for (const Voxel& x : g.voxels)
        v->values[std::size_t(x.cell.x + g.dims.x * (x.cell.y + g.dims.y * x.cell.z))] =
            float(-std::log1p(-double(x.opacity)) / double(g.spacing.x));
    return denseMedium(v, DenseFilter::Trilinear, 1.0);
}

// Two plumes, each lit isotropically with albedo 1 and no self-shadowing: a
// splat's colour is its base colour times the OTHER plume's transmittance.
struct TwoPlumes {
    Materials materials{Footprint{}};
    Scene scene;
    Grid grids[2];
    EffectId ids[2] = {0, 0};
    std::uint32_t rows[2] = {0, 0};
    glm::vec4 bases[2] = {{0.8f, 0.6f, 0.4f, 1.0f}, {0.5f, 0.7f, 0.9f, 1.0f}};
    Frame frame;
    Camera camera = Camera::lookAt({0.0f, 10.0f, 40.0f}, {0.0f, 10.0f, 0.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 500.0f);

    TwoPlumes(glm::vec3 at0, glm::vec3 at1) {
        const glm::vec3 at[2] = {at0, at1};
        for (int k = 0; k < 2; ++k) {
            rows[k] = materials.addColorTable(ColorTable::constant(bases[k]));
            grids[k] = plumeGrid(at[k]);
            EffectDesc desc;
            desc.name = k == 0 ? "receiver" : "caster";
            desc.layers = {EffectLayer{.style = {.colorTable = rows[k], .textured = false}}};
            ids[k] = scene.add(*Effect::fromGrid(grids[k], desc),
                               {.name = desc.name, .lighting = {.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off}});
        }
    }

    // Every splat of plume k against base x f(centre), f the reference's lit
    // factor with the other plume in the field (or with nothing when `other`
    // is false); returns the smallest transmittance f / f(no other plume)
    // (and the largest and the mean, for tools/validate/cross_shadow.py).
    double check(const Light& light, int k, bool other = true, double* maxT = nullptr, double* meanT = nullptr) {
        VolumeField field(materials), empty(materials);
        if (other) field.addMedium(plumeMedium(grids[1 - k]));
        const LitVolumeDesc lit{.lights = {light}, .gas = {.albedo = 1.0f}};
        double minT = 1.0, hiT = 0.0, sumT = 0.0;
        std::size_t n = 0;
        for (const Splat& sp : frame.splats()) {
            if (std::lround(sp.colorRow) != long(rows[k])) continue;
            const glm::dvec3 f = litFactor(field, glm::dvec3(sp.center), glm::dvec3(camera.eye()), lit);
            const glm::dvec3 unshadowed = litFactor(empty, glm::dvec3(sp.center), glm::dvec3(camera.eye()), lit);
            EXPECT_GT(unshadowed.x, 0.1) << "the light must reach every splat for the comparison to mean something";
            minT = std::min(minT, f.x / unshadowed.x);
            hiT = std::max(hiT, f.x / unshadowed.x);
            sumT += f.x / unshadowed.x;
            const glm::vec3 got = unpack(sp.color);
            for (int a = 0; a < 3; ++a) {
                EXPECT_LE(double(bases[k][a]) * f[a], 1.0) << "a lit colour over 1 is scaled (packLit): keep the lights dimmer";
                EXPECT_NEAR(got[a], double(bases[k][a]) * f[a], kTolerance)
                    << "plume " << k << " splat at " << sp.center.x << "," << sp.center.y << "," << sp.center.z;
            }
            ++n;
        }
        EXPECT_EQ(n, 64u);
        if (maxT) *maxT = hiT;
        if (meanT) *meanT = n ? sumT / double(n) : 0.0;
        return minT;
    }
};

} // namespace

// A slanted sun over a plume above another: every ray from the lower plume
// to the sun crosses lattice planes on all three axes inside the upper one.
// Without the cross-shadow every lower splat would be its base colour (T = 1):
// the test asserts the upper plume takes at least a third of the light. The
// upper plume is not shadowed by the lower (it lies away from the sun): that
// pair is not traced, and the upper stays at its base colour.
TEST(CrossShadows, PlumeBetweenTheSunAndAnEffectDarkensItByThePlumesTransmittance) {
    TwoPlumes s({-1.5f, 4.0f, -1.5f}, {-2.0f, 11.0f, -1.0f}); // fields (one cell of padding) 2 units apart in y
    const Light sun = Light::directional({0.15f, -1.0f, -0.1f});
    ASSERT_TRUE(s.scene.addLight(sun));
    ASSERT_TRUE(s.scene.prepare(0.0, s.camera, s.materials, s.frame));
    ASSERT_TRUE(s.scene.status(s.ids[0]).lit);
    ASSERT_TRUE(s.scene.status(s.ids[1]).lit);
    double maxT = 0.0, meanT = 0.0;
    const double minT = s.check(sun, 0, true, &maxT, &meanT);
    EXPECT_LT(minT, 2.0 / 3.0);
    // The same case integrated outside the project: tools/validate/cross_shadow.py.
    std::printf("reference T: min %.9f, max %.9f, mean %.9f\n", minT, maxT, meanT);
    EXPECT_NEAR(s.check(sun, 1), 1.0, 1e-12); // no depth at all on its rays
    EXPECT_EQ(s.scene.counters().crossShadowPairs, 1u);
    EXPECT_EQ(s.scene.counters().crossShadowPairsSkipped, 1u);
    // The upper plume not casting: the lower sees the sun unattenuated.
    s.scene.options(s.ids[1]).lighting.castsShadow = false;
    ASSERT_TRUE(s.scene.prepare(0.1, s.camera, s.materials, s.frame));
    s.check(sun, 0, false);
    EXPECT_EQ(s.scene.counters().crossShadowPairs, 0u);
}

// The plumes overlap by half a plume on every axis: each shadows the other,
// and half of each plume's splats start their trace inside the other's
// field, mid-cell. Both plumes are checked against the reference holding
// only the other one.
TEST(CrossShadows, OverlappingEffectsShadowEachOther) {
    TwoPlumes s({-1.5f, 8.0f, -1.5f}, {-0.3f, 9.7f, -0.2f});
    const Light sun = Light::directional({-0.3f, -1.0f, 0.2f});
    ASSERT_TRUE(s.scene.addLight(sun));
    ASSERT_TRUE(s.scene.prepare(0.0, s.camera, s.materials, s.frame));
    EXPECT_LT(s.check(sun, 0), 0.5);
    EXPECT_LT(s.check(sun, 1), 0.9);
    EXPECT_EQ(s.scene.counters().crossShadowPairs, 2u);
}

// A point light between two plumes: each plume's rays end at the light,
// before the other plume, so neither shadows the other (both pairs are
// skipped, every splat is its base colour lit by 1/d^2 alone). Moving the
// light beyond the upper plume puts that plume on the lower one's rays, which
// converge on the light.
TEST(CrossShadows, PointLightBetweenTwoEffectsShadowsNeitherUntilItMovesPastOne) {
    TwoPlumes s({-1.5f, 2.0f, -1.5f}, {-1.5f, 14.0f, -1.5f});
    // Intensities so that the irradiance at the nearest splat (4.5 and 9 units away) is about 0.8.
    const Light between = Light::point({0.0f, 9.5f, 0.0f}, glm::vec3(1.0f), 16.0f);
    ASSERT_TRUE(s.scene.addLight(between));
    ASSERT_TRUE(s.scene.prepare(0.0, s.camera, s.materials, s.frame));
    s.check(between, 0, false);
    s.check(between, 1, false);
    EXPECT_EQ(s.scene.counters().crossShadowPairs, 0u);
    EXPECT_EQ(s.scene.counters().crossShadowPairsSkipped, 2u);
    const Light above = Light::point({0.5f, 26.0f, 0.3f}, glm::vec3(1.0f), 64.0f);
    ASSERT_TRUE(s.scene.setLight(0, above));
    ASSERT_TRUE(s.scene.prepare(0.1, s.camera, s.materials, s.frame));
    EXPECT_LT(s.check(above, 0), 0.5);
    s.check(above, 1, false);
    EXPECT_EQ(s.scene.counters().crossShadowPairs, 1u);
}

// The camera turned away from the caster (its box out of the frustum, the
// receiver still in view): the caster is advanced for its shadow only
// (castsIntoView), not drawn, and the receiver's splats are unchanged, with
// the scene shadow off (the cross-shadow alone must keep the caster scheduled).
TEST(CrossShadows, TurningTheCameraAwayFromTheCasterLeavesTheReceiverUnchanged) {
    TwoPlumes s({-1.5f, 4.0f, -1.5f}, {-2.0f, 11.0f, -1.0f});
    const Light sun = Light::directional({0.15f, -1.0f, -0.1f});
    ASSERT_TRUE(s.scene.addLight(sun));
    s.scene.setSceneShadow({.enabled = false});
    const glm::vec3 eye{0.0f, 5.5f, 40.0f};
    s.camera = Camera::lookAt(eye, {0.0f, 9.0f, 0.0f}, {0, 1, 0}, glm::radians(30.0f), {64, 48}, 0.1f, 500.0f);
    auto receiverColours = [&] {
        std::vector<std::pair<std::array<float, 3>, std::uint32_t>> c;
        for (const Splat& sp : s.frame.splats())
            if (std::lround(sp.colorRow) == long(s.rows[0])) c.push_back({{sp.center.x, sp.center.y, sp.center.z}, sp.color});
        std::sort(c.begin(), c.end());
        return c;
    };
    ASSERT_TRUE(s.scene.prepare(0.0, s.camera, s.materials, s.frame));
    ASSERT_TRUE(s.scene.status(s.ids[1]).needed);
    const auto both = receiverColours();
    // 8 degrees around the receiver: the caster (y 10 to 15) is above the view (y 2.7 to 8.3 at the plumes).
    s.camera = Camera::lookAt(eye, {0.0f, 5.5f, 0.0f}, {0, 1, 0}, glm::radians(8.0f), {64, 48}, 0.1f, 500.0f);
    ASSERT_TRUE(s.scene.prepare(0.1, s.camera, s.materials, s.frame));
    EXPECT_FALSE(s.scene.status(s.ids[1]).needed);
    EXPECT_TRUE(s.scene.status(s.ids[1]).castsIntoView);
    EXPECT_LT(s.check(sun, 0), 2.0 / 3.0); // still shadowed, against the reference
    EXPECT_EQ(receiverColours(), both);
}

// shadowFallsOn against boxes whose answer is known: the exact edge cases
// of the per-axis interval (a grazing ray, a light inside the caster, a
// caster beyond a point light, a ray parallel to an axis).
TEST(CrossShadows, ShadowFallsOnIsExactForBoxes) {
    const Aabb receiver{{0, 0, 0}, {1, 1, 1}};
    const Light down = Light::directional({0.0f, -1.0f, 0.0f});
    // Straight down: a caster above overlapping in x and z casts; one beside does not.
    EXPECT_TRUE(Scene::shadowFallsOn({{0.5f, 3, 0.5f}, {2, 4, 2}}, down, receiver));
    EXPECT_FALSE(Scene::shadowFallsOn({{1.5f, 3, 0}, {2, 4, 1}}, down, receiver));
    EXPECT_FALSE(Scene::shadowFallsOn({{0, -4, 0}, {1, -3, 1}}, down, receiver)); // below: behind the receiver
    // Touching in x (a grazing ray along the shared face) counts.
    EXPECT_TRUE(Scene::shadowFallsOn({{1, 3, 0}, {2, 4, 1}}, down, receiver));
    // A 45-degree sun: rays from the receiver reach y in [3, 4] at x in [2, 5].
    const Light slant = Light::directional({-1.0f, -1.0f, 0.0f});
    EXPECT_TRUE(Scene::shadowFallsOn({{3, 3, 0}, {4, 4, 1}}, slant, receiver));
    EXPECT_FALSE(Scene::shadowFallsOn({{-3, 3, 0}, {-2, 4, 1}}, slant, receiver));
    EXPECT_FALSE(Scene::shadowFallsOn({{5.5f, 3, 0}, {6, 4, 1}}, slant, receiver));
    // A point light at y = 2: casters between it and the receiver cast, those beyond it do not.
    const Light bulb = Light::point({0.5f, 2.0f, 0.5f}, glm::vec3(1.0f), 1.0f);
    EXPECT_TRUE(Scene::shadowFallsOn({{0, 1.5f, 0}, {1, 1.8f, 1}}, bulb, receiver));
    EXPECT_FALSE(Scene::shadowFallsOn({{0, 2.5f, 0}, {1, 3, 1}}, bulb, receiver));
    EXPECT_TRUE(Scene::shadowFallsOn({{0, 1.5f, 0}, {1, 3, 1}}, bulb, receiver)); // the light inside the caster's box
    // The rays fan out from the light to the receiver: at y = 1.4 they reach x = 0.8 at most (from the top corner).
    EXPECT_FALSE(Scene::shadowFallsOn({{0.85f, 1.4f, 0}, {1, 1.6f, 1}}, bulb, receiver));
    EXPECT_TRUE(Scene::shadowFallsOn({{0.7f, 1.4f, 0}, {1, 1.6f, 1}}, bulb, receiver));
}
