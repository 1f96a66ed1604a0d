#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/lighting.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {
constexpr float kPi = 3.14159265f;
}

TEST(GasLighting, IsotropicWhiteLightShowsTheBaseColour) {
    // albedo 1, isotropic phase, unshadowed white sun of intensity 1:
    // 4 pi * (1 / 4 pi) * 1 = 1 times the colour table's entry.
    Grid g = *Grid::box({3, 5, 2});
    const ColorTable smoke = ColorTable::smoke();
    const Light sun = Light::directional({0.4f, -1.0f, 0.0f});
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightVoxels(g, {0, 2, 10}, std::span(&sun, 1), nullptr, {.albedo = 1.0f, .colorTable = &smoke}, out));
    ASSERT_EQ(out.size(), g.voxels.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const glm::vec3 base(smoke.sample(g.voxels[i].colorCoord));
        // One float product and the phase function's few roundings: 1e-6 relative.
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(out[i][a], base[a], 1e-6f);
    }
}

TEST(GasLighting, EmissionAloneIsTheTableColour) {
    Grid g = *Grid::box({2, 6, 2});
    const ColorTable fire = ColorTable::fire();
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightVoxels(g, {0, 0, 5}, {}, nullptr, {.emission = 1.0f, .colorTable = &fire}, out));
    for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i], glm::vec3(fire.sample(g.voxels[i].colorCoord)));
}

TEST(GasLighting, ForwardScatteringIsBrightestLookingIntoTheLight) {
    // One voxel at the origin, sun travelling along -y. Eye below (looking
    // up into the light: cos theta = 1) and above (cos theta = -1): the ratio
    // is HG's ((1 + g) / (1 - g))^3.
    Grid g;
    g.voxels.push_back(Voxel{});
    const float gg = 0.6f;
    const HgLobe lobe[] = {{gg, 1.0f}};
    const GasLightingDesc desc{.phase = *PhaseFunction::create(lobe), .albedo = 1.0f};
    const Light sun = Light::directional({0, -1, 0});
    std::vector<glm::vec3> below, above;
    ASSERT_TRUE(lightVoxels(g, {0, -5, 0}, std::span(&sun, 1), nullptr, desc, below));
    ASSERT_TRUE(lightVoxels(g, {0, 5, 0}, std::span(&sun, 1), nullptr, desc, above));
    EXPECT_NEAR(below[0].r / above[0].r, std::pow((1 + gg) / (1 - gg), 3.0f), 1e-3f);
    EXPECT_NEAR(below[0].r, 4 * kPi * PhaseFunction::henyeyGreenstein(gg, 1.0f), 1e-3f);
}

TEST(GasLighting, AmbientAndMultipleScatteringTerms) {
    Grid g;
    g.voxels.push_back(Voxel{});
    const Light sun = Light::directional({0, -1, 0}, {1.0f, 0.5f, 0.25f}, 2.0f);
    // A shadow provider that blocks everything: only the unshadowed terms remain.
    struct Opaque final : ShadowProvider {
        float transmittance(std::size_t, glm::vec3) const override { return 0.0f; }
    } opaque;
    std::vector<glm::vec3> out;
    ASSERT_TRUE(
        lightVoxels(g, {0, 0, 5}, std::span(&sun, 1), &opaque, {.albedo = 0.8f, .multipleScattering = 0.25f, .ambient = glm::vec3(0.1f)}, out));
    const glm::vec3 expected = 0.8f * (glm::vec3(0.1f) + glm::vec3(1.0f, 0.5f, 0.25f) * 2.0f * 0.25f);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(out[0][a], expected[a], 1e-6f);
}

TEST(GasLighting, SpotLightsOnlyInsideTheirCone) {
    Grid g = *Grid::box({9, 1, 1});
    const Light spot = Light::spot({0, 5, 0}, {0, -1, 0}, 0.05f, 0.1f);
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightVoxels(g, {0, 0, 5}, std::span(&spot, 1), nullptr, {.albedo = 1.0f}, out));
    for (std::size_t i = 0; i < out.size(); ++i) {
        const glm::vec3 x = g.worldPosition(g.voxels[i].cell);
        const float angle = std::atan2(std::abs(x.x), 5.0f);
        if (angle > 0.1f) { EXPECT_EQ(out[i].r, 0.0f) << x.x; }
        if (angle < 0.05f) { EXPECT_NEAR(out[i].r, 1.0f / glm::dot(x - spot.position, x - spot.position), 1e-6f) << x.x; }
    }
}

// A point light far away, with intensity scaled by distance^2 so the
// irradiance at the effect's centre equals the sun's, converges to the
// directional light: irradiance (D / (D + delta))^2 differs by ~2 r / D
// and the directions by ~r / D radian, both first order in r / D. So
// 100 times farther must mean about 100 times closer; 50x is asserted to
// leave room for the second-order terms at the nearer distance.
TEST(GasLighting, FarPointLightConvergesToDirectional) {
    Grid g = test::gaussianBlob(10, 0.2f, 0.7f);
    auto f = DensityField::fromGrid(g);
    const glm::vec3 c = 0.5f * (f->boundsMin() + f->boundsMax());
    const glm::vec3 dir = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
    const HgLobe lobes[] = {{0.5f, 0.8f}, {-0.3f, 0.2f}};
    const GasLightingDesc desc{.phase = *PhaseFunction::create(lobes), .albedo = 0.7f};
    const Light sun = Light::directional(dir);
    ShadowTracer sunShadow(*f, std::span(&sun, 1));
    std::vector<glm::vec3> ref, near, far;
    const glm::vec3 eye = c + glm::vec3(0.0f, 0.5f, 6.0f);
    ASSERT_TRUE(lightVoxels(g, eye, std::span(&sun, 1), &sunShadow, desc, ref));
    auto maxRel = [&](float D, std::vector<glm::vec3>& out) {
        const Light p = Light::point(c - dir * D, glm::vec3(1.0f), D * D);
        ShadowTracer sh(*f, std::span(&p, 1));
        EXPECT_TRUE(lightVoxels(g, eye, std::span(&p, 1), &sh, desc, out));
        double m = 0.0;
        for (std::size_t i = 0; i < out.size(); ++i) m = std::max(m, double(std::abs(out[i].g - ref[i].g) / ref[i].g));
        return m;
    };
    const float r = 0.5f * glm::length(f->boundsMax() - f->boundsMin());
    const double e10 = maxRel(10.0f * r, near), e1000 = maxRel(1000.0f * r, far);
    EXPECT_GT(e10, 0.0);
    EXPECT_LT(e1000, e10 / 50.0);
    EXPECT_LT(e1000, 5.0 / 1000.0); // ~2 r / D plus the direction's effect on phase and path
}

TEST(GasLighting, BadInputIsAnErrorNamingTheField) {
    Grid g = *Grid::box({2, 2, 2});
    std::vector<glm::vec3> out(3, glm::vec3(7.0f));
    Light bad = Light::point({0, 0, 0});
    bad.intensity = -1.0f;
    const Light lights[] = {Light{}, bad};
    const Status s = lightVoxels(g, {0, 0, 5}, lights, nullptr, {}, out);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("lights[1].intensity must be a finite number >= 0, got -1"), std::string::npos) << s.error();
    EXPECT_EQ(out.size(), 3u); // untouched
    EXPECT_EQ(out[0], glm::vec3(7.0f));
    const Status a = lightVoxels(g, {0, 0, 5}, {}, nullptr, {.albedo = 2.0f}, out);
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("GasLightingDesc.albedo"), std::string::npos);
    Light zeroDir = Light::directional({0, 0, 0});
    EXPECT_NE(validateLight(zeroDir, "sun").error().find("sun.direction must not be zero"), std::string::npos);
    Light cone = Light::spot({0, 0, 0}, {0, -1, 0}, 0.5f, 0.2f);
    EXPECT_NE(validateLight(cone).error().find("light.innerConeRad must be in [0, outerConeRad"), std::string::npos);
    EXPECT_FALSE(lightVoxels(g, {NAN, 0, 0}, {}, nullptr, {}, out));
}

TEST(GasLighting, NonFiniteVoxelsGetZeroAndOutputMemoryIsReused) {
    Grid g = *Grid::box({4, 4, 4});
    g.voxels[3].opacity = std::nanf("");
    const Light sun{};
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightVoxels(g, {0, 0, 5}, std::span(&sun, 1), nullptr, {}, out));
    EXPECT_EQ(out[3], glm::vec3(0.0f));
    EXPECT_GT(out[4].r, 0.0f);
    const glm::vec3* data = out.data();
    ASSERT_TRUE(lightVoxels(g, {1, 0, 5}, std::span(&sun, 1), nullptr, {}, out));
    EXPECT_EQ(out.data(), data);
}

TEST(GasLighting, TableShadowsDarkenTheFarSide) {
    Grid g = test::gaussianBlob(12, 0.2f, 0.8f);
    auto f = DensityField::fromGrid(g);
    const Light sun = Light::directional({0, -1, 0});
    ShadowTables tables({.dims = glm::ivec3(32)});
    ASSERT_TRUE(tables.update(*f, std::span(&sun, 1)));
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightVoxels(g, {0, 1, 8}, std::span(&sun, 1), &tables, {}, out));
    auto at = [&](glm::ivec3 cell) {
        for (std::size_t i = 0; i < g.voxels.size(); ++i)
            if (g.voxels[i].cell == cell) return out[i].r;
        return -1.0f;
    };
    EXPECT_LT(at({6, 1, 6}), 0.5f * at({6, 10, 6})); // the bottom is in the gas's own shadow
}
