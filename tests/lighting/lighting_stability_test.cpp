// Lighting and shadow tables (Ebert & Parent 1990) at their numerical edges
// (docs/STABILITY.md, "Lighting and shadow tables"): each test is named after
// what would go wrong. References: the tracer (DensityField's exact segment
// integral) for tables, and the low-albedo model's closed form for lit colours.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/lighting.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// Mean |table - traced| transmittance over the grid's voxel centres.
double meanTableError(const Grid& g, const DensityField& f, const Light& light, int n) {
    ShadowTable table({.dims = glm::ivec3(n)});
    EXPECT_TRUE(table.update(f, light));
    double sum = 0.0;
    for (const Voxel& v : g.voxels) {
        const glm::vec3 x = g.worldPosition(v.cell);
        const float t = table.transmittance(x);
        EXPECT_TRUE(t >= 0.0f && t <= 1.0f);
        sum += std::abs(double(t) - std::exp2(-double(f.opticalDepthToLight(x, light))));
    }
    return sum / double(g.voxels.size());
}

bool finite3(glm::vec3 c) { return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b); }

} // namespace

// ---- Light directions that make the table's sweep degenerate ----------------------

// A sun exactly along -y (rays along the lattice: the face interpolation
// degenerates to a single node) and tilted by 10^-6 rad (the sweep picks
// another face order): both within one 8-bit level of tracing, and of each
// other (the table must be continuous in the light's direction).
TEST(LightingStability, ASunExactlyAlongAnAxisAndTiltedBy1e6AgreeWithTracing) {
    Grid g = test::gaussianBlob(16, 0.1f, 0.5f);
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    const Light axis = Light::directional({0.0f, -1.0f, 0.0f}), tilted = Light::directional({1e-6f, -1.0f, 0.0f});
    EXPECT_LE(meanTableError(g, *f, axis, 48), 1.0 / 255.0);
    EXPECT_LE(meanTableError(g, *f, tilted, 48), 1.0 / 255.0);
    ShadowTable a({.dims = glm::ivec3(48)}), b({.dims = glm::ivec3(48)});
    ASSERT_TRUE(a.update(*f, axis) && b.update(*f, tilted));
    double diff = 0.0;
    for (const Voxel& v : g.voxels) diff = std::max(diff, double(std::abs(a.transmittance(g.worldPosition(v.cell)) - b.transmittance(g.worldPosition(v.cell)))));
    EXPECT_LT(diff, 1e-3) << "10^-6 rad moves a ray by 10^-6 of the box: no visible change";
}

// A sun along the cube's diagonal: every step's ray pierces its neighbour
// cube exactly through a corner, where three faces meet (the interpolation's
// grazing case).
TEST(LightingStability, ASunAlongTheDiagonalPiercesCornersAndStaysAccurate) {
    Grid g = test::gaussianBlob(16, 0.1f, 0.5f);
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    EXPECT_LE(meanTableError(g, *f, Light::directional({1.0f, -1.0f, 1.0f}), 48), 1.0 / 255.0);
    EXPECT_LE(meanTableError(g, *f, Light::directional({-1.0f, -1.0f, -1.0f}), 48), 1.0 / 255.0);
}

// A point outside the table whose ray to the light runs exactly along the
// plane of a table face (a sun parallel to the face): it is either moved
// onto the face or unshadowed, never NaN, and matches the tracer, which sees
// no material there (the field is zero on the box's faces).
TEST(LightingStability, AShadowRayGrazingATableFaceReadsNoMaterial) {
    Grid g = test::gaussianBlob(12, 0.1f, 0.6f);
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    const Light sun = Light::directional({1.0f, 0.0f, 0.0f});
    ShadowTable table({.dims = glm::ivec3(32)});
    ASSERT_TRUE(table.update(*f, sun));
    const glm::vec3 lo = f->boundsMin(), hi = f->boundsMax();
    for (const glm::vec3 p : {glm::vec3(hi.x + 1.0f, hi.y, 0.5f * (lo.z + hi.z)), glm::vec3(lo.x - 1.0f, lo.y, lo.z)}) {
        const float t = table.transmittance(p);
        ASSERT_TRUE(std::isfinite(t));
        EXPECT_NEAR(t, std::exp2(-f->opticalDepthToLight(p, sun)), 1e-5f);
    }
}

// ---- Point and spot lights at the table's edges --------------------------------

// A point light exactly on a face, an edge and a corner of the table's box:
// the fill order starts on the boundary; every node finite and >= 0, within
// one 8-bit level of tracing on average.
TEST(LightingStability, APointLightOnTheTablesFaceEdgeAndCorner) {
    Grid g = test::gaussianBlob(16, 0.1f, 0.5f);
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    const glm::vec3 lo = f->boundsMin(), hi = f->boundsMax(), c = 0.5f * (lo + hi);
    for (const glm::vec3 at : {glm::vec3(c.x, hi.y, c.z), glm::vec3(hi.x, hi.y, c.z), hi}) {
        const Light bulb = Light::point(at);
        ShadowTable table({.dims = glm::ivec3(40)});
        ASSERT_TRUE(table.update(*f, bulb));
        for (float d : table.data()) ASSERT_TRUE(std::isfinite(d) && d >= 0.0f);
        EXPECT_LE(meanTableError(g, *f, bulb, 40), 1.0 / 255.0);
    }
}

// A spot whose inner and outer cones are equal (a hard edge: the smooth step
// between them has zero width) and one of 10^-6 rad: finite, zero outside,
// full inside, never 0/0.
TEST(LightingStability, ASpotWithEqualConesOrAMicroradianConeHasAHardFiniteEdge) {
    Grid g = *Grid::box({9, 1, 9}, glm::vec3(0.25f));
    for (Voxel& v : g.voxels) v.opacity = 0.5f;
    const glm::vec3 above = g.worldPosition({4, 0, 4}) + glm::vec3(0.0f, 2.0f, 0.0f);
    for (float cone : {0.3f, 1e-6f}) {
        const Light spot = Light::spot(above, {0.0f, -1.0f, 0.0f}, cone, cone);
        ASSERT_TRUE(validateLight(spot)) << cone;
        std::vector<glm::vec3> out;
        ASSERT_TRUE(lightVoxels(g, {0.0f, 5.0f, 5.0f}, std::span(&spot, 1), nullptr, {.albedo = 1.0f}, out));
        std::size_t centre = 0;
        for (std::size_t i = 0; i < g.voxels.size(); ++i) {
            ASSERT_TRUE(finite3(out[i]));
            if (g.voxels[i].cell == glm::ivec3(4, 0, 4)) centre = i;
        }
        // Straight below the spot, on its axis: full intensity 1 / 2^2.
        EXPECT_NEAR(out[centre].r, 0.25f, 1e-5f) << cone;
        // A corner voxel is 45 degrees off the axis: outside either cone.
        EXPECT_EQ(out[0].r, 0.0f) << cone;
    }
}

// ---- Points where the model's angles or distances vanish ----------------------

// The eye exactly at a lit point: the view direction is zero, so the phase
// angle is undefined. The colour is finite (the phase is taken as isotropic
// there), not NaN (which a splat would show as black).
TEST(LightingStability, TheEyeExactlyAtALitPointGivesAFiniteColour) {
    const std::vector<glm::vec3> points{{1.0f, 2.0f, 3.0f}};
    const Light sun = Light::directional({0.2f, -1.0f, 0.1f});
    auto phase = PhaseFunction::create(std::vector<HgLobe>{{.g = 0.9f, .weight = 1.0f}});
    ASSERT_TRUE(phase);
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightPoints(points, 0.1f, points[0], std::span(&sun, 1), nullptr, {.phase = *phase, .albedo = 1.0f}, out));
    ASSERT_EQ(out.size(), 1u);
    EXPECT_TRUE(finite3(out[0])) << out[0].r;
    EXPECT_GT(out[0].r, 0.0f);
}

// A point light exactly on a point that stands for a voxel of size 0 (a
// particle): the distance is 0, the inverse square infinite. The light's
// radiusWorld bounds it; with radiusWorld 0 as well, the colour must still
// be finite (not inf, which packs as black).
TEST(LightingStability, APointLightOnAZeroSizedPointIsFinite) {
    const std::vector<glm::vec3> points{{0.5f, 0.5f, 0.5f}};
    Light bulb = Light::point(points[0], glm::vec3(1.0f), 3.0f);
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightPoints(points, 0.0f, {0.0f, 0.0f, 5.0f}, std::span(&bulb, 1), nullptr, {.albedo = 1.0f}, out));
    EXPECT_TRUE(finite3(out[0])) << out[0].r;
    bulb.radiusWorld = 0.5f; // irradiance at 0.5: 3 / 0.25 = 12, isotropic, albedo 1
    ASSERT_TRUE(lightPoints(points, 0.0f, {0.0f, 0.0f, 5.0f}, std::span(&bulb, 1), nullptr, {.albedo = 1.0f}, out));
    EXPECT_NEAR(out[0].r, 12.0f, 1e-4f);
}

// ---- Degenerate tables and fields ------------------------------------------------------

// A table of 1 x 1 x 64 entries (one column) for a sun across it: finite,
// and every look-up inside the box reads the column's interpolation.
TEST(LightingStability, ATableOfOneColumnIsFiniteAndMonotoneAlongTheLight) {
    Grid g = test::gaussianBlob(10, 0.1f, 0.6f);
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    const Light sun = Light::directional({0.0f, -1.0f, 0.0f});
    ShadowTable table({.dims = {1, 64, 1}});
    ASSERT_TRUE(table.update(*f, sun));
    for (float d : table.data()) ASSERT_TRUE(std::isfinite(d) && d >= 0.0f);
    // Deeper along the light, never less depth.
    for (std::size_t i = 1; i < table.data().size(); ++i) EXPECT_GE(table.data()[i - 1], table.data()[i] - 1e-6f);
}

// A field of one voxel (its support: one cell each side, a tent): the
// sharpest field a table can see. The table's error is first order in its
// node spacing: it falls at least 2x per doubling of the dims and is within
// one 8-bit level of tracing at 128^3 (measured: 0.032, 0.010, 0.0028,
// 0.0008 at 16 to 128 for the sun).
TEST(LightingStability, AOneVoxelFieldConvergesToTracing) {
    Grid g = *Grid::box({1, 1, 1}, glm::vec3(0.5f));
    g.voxels[0].opacity = 0.9f;
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    const glm::vec3 c = g.worldPosition({0, 0, 0});
    for (const Light& l : {Light::directional({0.3f, -1.0f, 0.2f}), Light::point({0.2f, 2.0f, -0.3f})}) {
        const float traced = std::exp2(-f->opticalDepthToLight(c, l));
        float previous = 1.0f;
        for (int n : {16, 32, 64, 128}) {
            ShadowTable table({.dims = glm::ivec3(n)});
            ASSERT_TRUE(table.update(*f, l));
            const float err = std::abs(table.transmittance(c) - traced);
            EXPECT_LE(err, 0.5f * previous) << int(l.type) << " at " << n;
            previous = err;
        }
        EXPECT_LE(previous, 1.0f / 255.0f) << int(l.type);
    }
}

// A gas 10^5 units from the origin, where a float step is 0.008 (a
// twelfth of its 0.1 voxels): the table's error against tracing grows by
// the float positions of its nodes, but stays within 1.5x of the same gas at
// the origin (measured 1.3x) and within one and a half 8-bit levels.
TEST(LightingStability, AGasAHundredThousandUnitsOutIsShadowedNearlyAsAtTheOrigin) {
    Grid g = test::gaussianBlob(16, 0.1f, 0.5f);
    auto near = DensityField::fromGrid(g);
    Grid out = g;
    out.transform[3] = glm::vec4(1e5f, 2e4f, -1e5f, 1.0f);
    auto far = DensityField::fromGrid(out);
    ASSERT_TRUE(near && far);
    const Light sun = Light::directional({0.3f, -1.0f, 0.45f});
    const double atOrigin = meanTableError(g, *near, sun, 48), outThere = meanTableError(out, *far, sun, 48);
    EXPECT_LE(atOrigin, 1.0 / 255.0);
    EXPECT_LE(outThere, 1.5 * atOrigin);
}

// ---- Light values at their limits -------------------------------------------------------

// Intensity 0, a colour with zero channels, albedo 0: each removes exactly
// its term of the model (the closed form), no NaN from 0 x inf.
TEST(LightingStability, ZeroIntensityZeroChannelsAndZeroAlbedoRemoveExactlyTheirTerms) {
    const std::vector<glm::vec3> points{{0.0f, 0.0f, 0.0f}};
    Light dark = Light::directional({0.0f, -1.0f, 0.0f}, glm::vec3(1.0f, 0.0f, 0.5f), 0.0f);
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightPoints(points, 0.1f, {0.0f, 0.0f, 5.0f}, std::span(&dark, 1), nullptr,
                            {.albedo = 1.0f, .emission = 0.25f, .ambient = glm::vec3(0.1f)}, out));
    EXPECT_NEAR(out[0].r, 0.25f + 0.1f, 1e-6f); // emission + albedo x ambient
    dark.intensity = 2.0f;
    ASSERT_TRUE(lightPoints(points, 0.1f, {0.0f, 0.0f, 5.0f}, std::span(&dark, 1), nullptr, {.albedo = 1.0f}, out));
    EXPECT_NEAR(out[0].r, 2.0f, 1e-5f); // isotropic, albedo 1: intensity x colour
    EXPECT_EQ(out[0].g, 0.0f);
    EXPECT_NEAR(out[0].b, 1.0f, 1e-5f);
    ASSERT_TRUE(lightPoints(points, 0.1f, {0.0f, 0.0f, 5.0f}, std::span(&dark, 1), nullptr, {.albedo = 0.0f, .emission = 0.5f}, out));
    EXPECT_EQ(out[0], glm::vec3(0.5f));
}

// 64 lights of intensity 10^6 each: the sum is large (the host's exposure
// handles it) but finite.
TEST(LightingStability, SixtyFourBlindingLightsSumFinite) {
    std::vector<Light> lights;
    for (int i = 0; i < 64; ++i) lights.push_back(Light::point({float(i % 8) - 4.0f, 3.0f, float(i / 8) - 4.0f}, glm::vec3(1.0f), 1e6f));
    const std::vector<glm::vec3> points{{0.0f, 0.0f, 0.0f}, {1.0f, 0.5f, -1.0f}};
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightPoints(points, 0.1f, {0.0f, 1.0f, 9.0f}, lights, nullptr, {.albedo = 1.0f}, out));
    for (const glm::vec3& c : out) EXPECT_TRUE(finite3(c));
}
