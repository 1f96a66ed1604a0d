// A ground fog layer lit by the sun (GroundFog::setLighting): the sun's
// transmittance at every grid point against the layer's continuous field
// integrated by the reference (integrateGroundFogRay's transmittance along
// the ray to the sun), closed forms for its hard cases (docs/STABILITY.md,
// "Ground fog lighting"), a caster's shadow, what the tetrahedra draw per
// vertex, and when it relights.
//
// Tolerances. The SDK integrates the scalar in closed form per triangle
// stretch in double and stores T as a float: half an ulp, 2^-24 relative (T
// <= 1: 6e-8 absolute). The reference halves 4-point Gauss-Legendre steps
// until two results differ by less than its tolerance per stretch; its summed
// last differences (errorEstimate) bound its own error. Both see the same
// float vertex positions.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/reference.hpp"
#include "splatfx/volume.hpp"

#include "ground_fog_test_helpers.hpp"

using namespace splatfx;
using namespace ground_fog_test;

namespace {

constexpr double kFloatT = 6e-8; // a float T in [0, 1]: half an ulp at 1

// A wavy terrain under a top that is sometimes below it (no fog there).
GroundFogDesc hills(glm::ivec2 dims, float densityDepth) {
    GroundFogDesc d;
    d.dims = dims;
    d.originWorld = {-4.0f, 0.0f, -3.0f};
    d.spacingWorld = 1.0f;
    d.densityDepthWorld = densityDepth;
    d.density = 0.8f;
    for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) {
            const float x = float(i) / float(dims.x - 1), z = float(j) / float(dims.y - 1);
            d.terrainHeight.push_back(1.2f * std::sin(5.0f * x) * std::cos(4.0f * z) + 0.3f * x);
            d.fogTop.push_back(1.0f + 0.4f * std::cos(3.0f * z));
        }
    return d;
}

void expectSelfShadowIsTheReference(const GroundFogDesc& d, glm::vec3 travel, float extinction) {
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    ASSERT_TRUE(fog->setLighting(sunAlong(travel, extinction)));
    const std::vector<float>& T = fog->sunTransmittance();
    ASSERT_EQ(T.size(), 2 * d.terrainHeight.size());
    double lowest = 1.0;
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i) {
            const std::size_t k = std::size_t(i) + std::size_t(d.dims.x) * std::size_t(j);
            const float x = d.originWorld.x + float(i) * d.spacingWorld, z = d.originWorld.z + float(j) * d.spacingWorld;
            const float hb = d.terrainHeight[k], ht = hb + std::max(d.fogTop[k] - hb, 0.0f);
            for (int top = 0; top < 2; ++top) {
                const auto [want, err] = referenceT(d, extinction, {x, top ? ht : hb, z}, travel);
                EXPECT_NEAR(T[2 * k + std::size_t(top)], want, kFloatT + 2.0 * err) << i << ", " << j << (top ? " top" : " terrain");
                if (want > 0.0) lowest = std::min(lowest, want); // 0: the terrain hides the sun
            }
        }
    EXPECT_LT(lowest, 0.9); // the layer does shadow itself
}

} // namespace

// Every grid point's T, terrain and top, against the reference, for the
// paper's scalar (density at the terrain, 0 at the top: a ratio of linear
// functions along a ray, integrated with a logarithm) and the affine one.
TEST(GroundFogLight, SelfShadowIsTheContinuousFieldsTransmittance) {
    expectSelfShadowIsTheReference(hills({9, 7}, 0.0f), {0.5f, -0.6f, 0.3f}, 1.5f);
    expectSelfShadowIsTheReference(hills({9, 7}, 3.0f), {-0.4f, -0.5f, 0.7f}, 1.5f);
}

// Hard cases (docs/STABILITY.md, "Ground fog lighting").
// Sun straight down on a flat layer of thickness H: the scalar falls
// linearly from density to 0, so T at the terrain is exp(-k d H / 2) and 1
// at the top.
TEST(GroundFogLight, SunStraightDownThroughAFlatLayer) {
    GroundFogDesc d = slab({5, 4}, 1.0f, 0.0f, 2.0f);
    d.density = 0.5f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    ASSERT_TRUE(fog->setLighting(sunAlong({0.0f, -1.0f, 0.0f}, 1.2f)));
    const double want = std::exp(-1.2 * 0.5 * 2.0 / 2.0);
    for (std::size_t k = 0; k < d.terrainHeight.size(); ++k) {
        EXPECT_NEAR(fog->sunTransmittance()[2 * k], want, kFloatT) << k;
        EXPECT_EQ(fog->sunTransmittance()[2 * k + 1], 1.0f) << k;
    }
}

// A ridge across the layer under a low sun: the fog in its lee gets no
// direct light (T = 0 at every point whose ray to the sun passes under the
// terrain), the sunward side and the points above the crest's line are as
// before (the layer's own transmittance); a sun below the horizon lights
// nothing (the ground goes on past the grid). Both against the reference's
// brute-force test over every triangle (terrainHides).
TEST(GroundFogLight, TheTerrainHidesTheSunFromTheFogInItsLee) {
    GroundFogDesc d = slab({12, 4}, 0.5f, 0.0f, 1.2f);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 12; ++i) {
            const float h = std::max(0.0f, 2.5f - 1.5f * std::abs(float(i) - 4.0f)); // a ridge 2.5 high at i = 4
            d.terrainHeight[std::size_t(i) + 12u * std::size_t(j)] = h;
            d.fogTop[std::size_t(i) + 12u * std::size_t(j)] = h + 1.2f;
        }
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const glm::vec3 travel{0.9f, -0.35f, 0.1f}; // the sun low at -x: the lee is at i > 4
    ASSERT_TRUE(fog->setLighting(sunAlong(travel, 0.8f)));
    int hidden = 0, lit = 0;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 12; ++i)
            for (int top = 0; top < 2; ++top) {
                const std::size_t k = std::size_t(i) + 12u * std::size_t(j);
                const glm::vec3 p(d.originWorld.x + float(i) * d.spacingWorld, top ? d.fogTop[k] : d.terrainHeight[k], d.originWorld.z + float(j) * d.spacingWorld);
                const auto [want, err] = referenceT(d, 0.8f, p, travel);
                EXPECT_NEAR(fog->sunTransmittance()[2 * k + std::size_t(top)], want, kFloatT + 2.0 * err) << i << ", " << j << (top ? " top" : " terrain");
                (want == 0.0 ? hidden : lit) += 1;
                if (i <= 3) {
                    EXPECT_GT(want, 0.0) << "the sunward side is lit";
                }
            }
    EXPECT_GT(hidden, 8) << "the lee must be in the ridge's shadow";
    EXPECT_GT(lit, 40);
    // Below the horizon: no direct light anywhere.
    ASSERT_TRUE(fog->setLighting(sunAlong({0.9f, 0.05f, 0.1f}, 0.8f)));
    for (float T : fog->sunTransmittance()) EXPECT_EQ(T, 0.0f);
}

// The sun at the horizon grazes the terrain: a terrain point's ray runs along
// the layer's bottom, where the scalar is `density`, to the grid's edge
// toward the sun: T = exp(-k d x) with x its distance from that edge. The
// ray lies exactly on the layer's boundary (g1 = 0), which must count as in.
TEST(GroundFogLight, SunAtTheHorizonGrazesTheTerrain) {
    GroundFogDesc d = slab({6, 3}, 0.5f, 1.0f, 1.5f);
    d.density = 0.7f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    ASSERT_TRUE(fog->setLighting(sunAlong({1.0f, 0.0f, 0.0f}, 0.9f))); // travelling +x: the sun is at -x
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 6; ++i) {
            const std::size_t k = std::size_t(i) + 6u * std::size_t(j);
            EXPECT_NEAR(fog->sunTransmittance()[2 * k], std::exp(-0.9 * 0.7 * 0.5 * i), kFloatT) << i << ", " << j;
            EXPECT_EQ(fog->sunTransmittance()[2 * k + 1], 1.0f); // the top: scalar 0 along it
        }
}

// Fog a thousandth of a cell thick, the sun 37 degrees off vertical: every
// terrain ray leaves through the top (H tan(theta) << one cell) before the
// edge, so T = exp(-k d H / (2 cos theta)) exactly, however thin.
TEST(GroundFogLight, FogThinnerThanACell) {
    const float H = 1e-3f;
    GroundFogDesc d = slab({5, 5}, 1.0f, 0.0f, H);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    const glm::vec3 travel{0.6f, -0.8f, 0.0f};
    ASSERT_TRUE(fog->setLighting(sunAlong(travel, 300.0f)));
    const double want = std::exp(-300.0 * double(H) / (2.0 * 0.8)); // cos theta = 0.8 (|travel| = 1)
    ASSERT_LT(want, 0.9);
    for (int j = 0; j < 5; ++j)
        for (int i = 1; i < 5; ++i) { // i = 0 is on the edge toward the sun: its ray leaves the grid at once
            const std::size_t k = std::size_t(i) + 5u * std::size_t(j);
            EXPECT_NEAR(fog->sunTransmittance()[2 * k], want, kFloatT + 1e-12) << i << ", " << j;
        }
}

// No fog anywhere (top on the terrain): nothing is drawn, nothing shadows,
// and lighting it is not an error.
TEST(GroundFogLight, ZeroThicknessEverywhere) {
    GroundFogDesc d = slab({4, 4}, 1.0f, 2.0f, 2.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    ASSERT_TRUE(fog->setLighting(sunAlong({0.3f, -0.2f, 0.1f}, 5.0f)));
    for (float t : fog->sunTransmittance()) EXPECT_EQ(t, 1.0f);
    LodFrame frame;
    const Camera cam = Camera::lookAt({1.5f, 6.0f, 9.0f}, {1.5f, 2.0f, 1.5f}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.1f, 50.0f);
    ASSERT_TRUE(fog->update(cam, frame));
    EXPECT_TRUE(frame.tets.empty());
}

// A caster (a DensityField, as a Scene passes a lit smoke's or cloud's) over
// part of the layer, the sun straight down: under its interior the terrain's
// T is the layer's own times exp2(-n tau) (n voxels of log2 depth tau each:
// the trilinear field integrates to n tau along a column through voxel
// centres, its ramps half a cell beyond the end voxels included); away from
// it, the layer's own. Float: the field's Simpson sums in float, relative
// 1e-6 of the depth.
TEST(GroundFogLight, ACasterShadowsTheFogUnderIt) {
    GroundFogDesc d = slab({9, 9}, 1.0f, 0.0f, 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    Grid g;
    g.dims = {3, 2, 3};
    g.spacing = glm::vec3(1.0f);
    // Grid::localPosition centres x and z; place cell (0, 0, 0) at world (2, 4, 2).
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(3.0f, 4.0f, 3.0f));
    const float opacity = 0.5f; // tau = 1 (log2) per voxel
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 3; ++x) {
                Voxel v;
                v.cell = {x, y, z};
                v.opacity = opacity;
                g.voxels.push_back(v);
            }
    ASSERT_NEAR(g.worldPosition({0, 0, 0}).x, 2.0f, 1e-6f);
    auto field = DensityField::fromGrid(g);
    ASSERT_TRUE(field) << field.error();
    const DensityField* casters[] = {&*field};
    const GroundFogLighting L = sunAlong({0.0f, -1.0f, 0.0f}, 1.0f);
    ASSERT_TRUE(fog->setLighting(L, casters));
    const double self = std::exp(-1.0 * 1.0 * 1.0 / 2.0);
    const double under = self * std::exp2(-2.0 * 1.0);
    auto at = [&](int i, int j) { return double(fog->sunTransmittance()[2 * (std::size_t(i) + 9u * std::size_t(j))]); };
    EXPECT_NEAR(at(3, 3), under, kFloatT + 1e-6 * 2.0);
    EXPECT_NEAR(at(0, 0), self, kFloatT);
    EXPECT_NEAR(at(8, 8), self, kFloatT);
    EXPECT_LT(at(3, 3), 0.5 * at(0, 0)); // the darker patch under the smoke
    // The same caster again: no relight; a changed one (a new fingerprint): one.
    const auto relights = fog->relights();
    ASSERT_TRUE(fog->setLighting(L, casters));
    EXPECT_EQ(fog->relights(), relights);
    g.voxels[0].opacity = 0.25f;
    auto moved = DensityField::fromGrid(g);
    ASSERT_TRUE(moved);
    const DensityField* casters2[] = {&*moved};
    ASSERT_TRUE(fog->setLighting(L, casters2));
    EXPECT_EQ(fog->relights(), relights + 1);
    // No casters: the layer's own again.
    ASSERT_TRUE(fog->setLighting(L));
    EXPECT_NEAR(at(3, 3), self, kFloatT);
}

// Relit only when the sun's direction (or the extinction) changes; the table
// rebuilt only when a colour term does.
TEST(GroundFogLight, RelightsOnlyWhenTheSunMoves) {
    auto fog = GroundFog::create(hills({6, 5}, 0.0f));
    ASSERT_TRUE(fog);
    EXPECT_FALSE(fog->lit());
    GroundFogLighting L = sunAlong({0.2f, -1.0f, 0.1f}, 1.0f);
    ASSERT_TRUE(fog->setLighting(L));
    EXPECT_TRUE(fog->lit());
    EXPECT_EQ(fog->relights(), 1u);
    EXPECT_EQ(fog->litTableBuilds(), 1u);
    ASSERT_TRUE(fog->setLighting(L)); // unchanged
    L.sun.color = {1.0f, 0.6f, 0.3f}; // sunset colour: table only
    ASSERT_TRUE(fog->setLighting(L));
    EXPECT_EQ(fog->relights(), 1u);
    EXPECT_EQ(fog->litTableBuilds(), 2u);
    L.sun.direction = {0.5f, -0.4f, 0.1f}; // the sun moves: relight only
    ASSERT_TRUE(fog->setLighting(L));
    EXPECT_EQ(fog->relights(), 2u);
    EXPECT_EQ(fog->litTableBuilds(), 2u);
    fog->clearLighting();
    EXPECT_FALSE(fog->lit());
}

// What the tetrahedra draw at each vertex, kappa(s) with s = T phase / max
// phase, is the model's source sourceAt(T, toEye) with T the reference's, for
// a forward-scattering lobe; the length scale is the unlit layer's scalar, so
// the extinction drawn is the unlit one. Full resolution, camera far enough
// that nothing is clipped: every vertex is a grid point. kappa is affine in s:
// float rounding of s and kappa, relative 1e-5 of the peak (A + B), plus the
// T error above times the sun term B.
TEST(GroundFogLight, VertexSourceIsTheModel) {
    const GroundFogDesc d = hills({6, 5}, 0.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    GroundFogLighting L = sunAlong({0.4f, -0.7f, 0.2f}, 1.3f);
    const HgLobe lobe{.g = 0.6f};
    L.gas.phase = *PhaseFunction::create(std::span<const HgLobe>(&lobe, 1));
    L.gas.ambient = {0.1f, 0.12f, 0.15f};
    L.gas.multipleScattering = 0.2f;
    L.color = {0.9f, 0.92f, 0.95f};
    ASSERT_TRUE(fog->setLighting(L));
    const Camera cam = Camera::lookAt({0.0f, 9.0f, 14.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 100.0f);
    LodFrame lit, unlit;
    ASSERT_TRUE(fog->update(cam, lit));
    ASSERT_FALSE(lit.tets.empty());
    EXPECT_EQ(lit.stats.clippedInput, 0u);
    auto plain = GroundFog::create(d);
    ASSERT_TRUE(plain->update(cam, unlit));
    ASSERT_EQ(lit.tets.size(), unlit.tets.size());
    const glm::dvec3 peak = glm::dvec3(fog->litTransfer().color(1.0));
    const double tol = 1e-5 * std::max({peak.x, peak.y, peak.z});
    for (std::size_t n = 0; n < lit.tets.size(); ++n)
        for (int k = 0; k < 4; ++k) {
            const glm::vec3 p = lit.tets[n].position[std::size_t(k)];
            EXPECT_EQ(p, unlit.tets[n].position[std::size_t(k)]);
            EXPECT_EQ(lit.tets[n].lengthScale[std::size_t(k)], unlit.tets[n].scalar[std::size_t(k)]);
            // Terrain or top: the unlit scalar is 0 exactly at the top.
            const bool top = unlit.tets[n].scalar[std::size_t(k)] == 0.0f;
            const auto [T, err] = referenceT(d, 1.3f, p, L.sun.direction);
            const glm::dvec3 want = fog->sourceAt(T, glm::normalize(cam.eye() - p));
            const glm::dvec3 got = fog->litTransfer().color(lit.tets[n].scalar[std::size_t(k)]);
            const double b = 4.0 * std::numbers::pi * double(fog->lighting().gas.phase(1.0f)) * 0.95 * 0.9;
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], tol + b * (kFloatT + 2.0 * err)) << n << " " << k << (top ? " top" : "");
        }
}

TEST(GroundFogLight, BadLightingIsRejectedNamingTheField) {
    auto fog = GroundFog::create(hills({4, 4}, 0.0f));
    ASSERT_TRUE(fog);
    GroundFogLighting L;
    L.sun = Light::point({0, 5, 0});
    Status s = fog->setLighting(L);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("GroundFogLighting.sun"), std::string::npos) << s.error();
    L = GroundFogLighting{};
    L.extinctionPerWorld = -1.0f;
    s = fog->setLighting(L);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("GroundFogLighting.extinctionPerWorld"), std::string::npos) << s.error();
    L = GroundFogLighting{};
    L.gas.albedo = 2.0f;
    EXPECT_NE(fog->setLighting(L).error().find("GroundFogLighting.gas.albedo"), std::string::npos);
    L = GroundFogLighting{};
    const DensityField* casters[] = {nullptr};
    EXPECT_NE(fog->setLighting(L, casters).error().find("casters[0]"), std::string::npos);
    EXPECT_FALSE(fog->lit()); // nothing changed
    EXPECT_EQ(fog->relights(), 0u);
}
