#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/lighting.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// Depth of one voxel of opacity a, log2 units, as the splat builder: -log2(1 - a).
double tau(double a) { return -std::log2(1.0 - a); }

// Double-precision midpoint rule on DensityField::at along a segment: an
// independent check of the exact piecewise-Simpson integral.
double brute(const DensityField& f, glm::vec3 a, glm::vec3 b, int n) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += f.at(glm::mix(a, b, (float(i) + 0.5f) / float(n)));
    return sum * double(glm::length(b - a)) / n;
}

struct Errors {
    double mean = 0.0, max = 0.0;
};
// Table against tracing, in transmittance, at every voxel centre.
Errors tableError(const Grid& grid, const DensityField& field, const Light& light, int n) {
    ShadowTable table({.dims = glm::ivec3(n)});
    EXPECT_TRUE(table.update(field, light));
    Errors e;
    for (const Voxel& v : grid.voxels) {
        const glm::vec3 x = grid.worldPosition(v.cell);
        const double d = std::abs(double(table.transmittance(x)) - std::exp2(-double(field.opticalDepthToLight(x, light))));
        e.mean += d;
        e.max = std::max(e.max, d);
    }
    e.mean /= double(grid.voxels.size());
    return e;
}

} // namespace

TEST(DensityField, RowOfVoxelsGivesTheirSplatDepth) {
    // 8^3 voxels of opacity 0.5 and spacing 0.5: from the lattice point at
    // x = 4 out along +x the field is tau per voxel for 3 cells, then falls
    // linearly to 0 over the padding cell: 3.5 voxels' depth in all.
    auto g = Grid::box({8, 8, 8}, glm::vec3(0.5f));
    ASSERT_TRUE(g);
    for (Voxel& v : g->voxels) v.opacity = 0.5f;
    auto f = DensityField::fromGrid(*g);
    ASSERT_TRUE(f) << f.error();
    const glm::vec3 from = g->worldPosition({4, 3, 3});
    const double d = f->opticalDepth(from, from + glm::vec3(10.0f, 0.0f, 0.0f));
    // Float rounding of a sum of ~10 terms each ~1: 1e-5 relative is ~100 ulps.
    EXPECT_NEAR(d, 3.5 * tau(0.5), 1e-5 * 3.5);
    // A voxel's depth through its centre is independent of the spacing: the same at spacing 2.
    auto g2 = *g;
    g2.spacing = glm::vec3(2.0f);
    auto f2 = DensityField::fromGrid(g2);
    const glm::vec3 from2 = g2.worldPosition({4, 3, 3});
    EXPECT_NEAR(f2->opticalDepth(from2, from2 + glm::vec3(40.0f, 0.0f, 0.0f)), 3.5 * tau(0.5), 1e-5 * 3.5);
}

TEST(DensityField, ExactSegmentIntegralMatchesDenseQuadrature) {
    Grid g = test::gaussianBlob(10, 0.3f);
    g.transform = glm::mat4(glm::vec4(0.8f, 0.6f, 0, 0), glm::vec4(-0.6f, 0.8f, 0, 0), glm::vec4(0, 0, 1, 0), glm::vec4(1, 2, 3, 1));
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    const glm::vec3 a = g.worldPosition({1, 2, 3}) + glm::vec3(-2.0f, -1.0f, 0.3f), b = g.worldPosition({8, 9, 6}) + glm::vec3(1.0f, 1.5f, 0.2f);
    const double exact = f->opticalDepth(a, b);
    // The midpoint rule's error on a piecewise cubic with kinks: O(h) at each
    // of ~30 kinks times h^2 f''... with 2e5 steps it is below 1e-6 relative;
    // the float sum of the exact pieces is good to ~1e-6 too.
    const double ref = brute(*f, a, b, 200000);
    EXPECT_GT(exact, 0.5);
    EXPECT_NEAR(exact, ref, 1e-5 * ref);
}

TEST(DensityField, BadGridNamesTheField) {
    Grid g = *Grid::box({2, 2, 2});
    g.spacing.y = 0.0f;
    auto f = DensityField::fromGrid(g);
    ASSERT_FALSE(f);
    EXPECT_NE(f.error().find("grid.spacing.y"), std::string::npos) << f.error();
    g.spacing.y = 1.0f;
    g.voxels[0].cell = {1 << 20, 0, 0};
    auto h = DensityField::fromGrid(g);
    ASSERT_FALSE(h);
    EXPECT_NE(h.error().find("cell limit"), std::string::npos) << h.error();
}

TEST(ShadowStability, FullyOpaqueVoxelsShadowCompletelyWithoutNaN) {
    auto g = Grid::box({6, 6, 6}, glm::vec3(0.5f));
    ASSERT_TRUE(g);
    auto f = DensityField::fromGrid(*g); // opacity 1 everywhere: 24 log2 units per voxel
    ASSERT_TRUE(f);
    const Light sun = Light::directional({0.3f, -1.0f, 0.2f});
    ShadowTracer tracer(*f, std::span(&sun, 1));
    ShadowTable table({.dims = glm::ivec3(32)});
    ASSERT_TRUE(table.update(*f, sun));
    for (float d : table.data()) ASSERT_TRUE(std::isfinite(d));
    // The bottom voxels are 5+ voxels deep: T <= 2^-100, i.e. 0 at any precision that matters.
    const glm::vec3 bottom = g->worldPosition({3, 0, 3});
    const float tt = tracer.transmittance(0, bottom), tb = table.transmittance(bottom);
    EXPECT_TRUE(std::isfinite(tt) && std::isfinite(tb));
    EXPECT_LT(tt, 1e-20f);
    EXPECT_LT(tb, 1e-20f);
    ShadowTables tables({.dims = glm::ivec3(32)});
    ASSERT_TRUE(tables.update(*f, std::span(&sun, 1)));
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightVoxels(*g, {0, 0, 10}, std::span(&sun, 1), &tables, {}, out));
    for (const glm::vec3& c : out) ASSERT_TRUE(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b));
}

TEST(ShadowStability, EmptyGridShadowsNothing) {
    Grid g;
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    EXPECT_TRUE(f->empty());
    const Light lights[] = {Light::directional({0, -1, 0}), Light::point({1, 2, 3})};
    ShadowTracer tracer(*f, lights);
    ShadowTables tables({.dims = glm::ivec3(16)});
    ASSERT_TRUE(tables.update(*f, lights));
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ(tracer.transmittance(i, {0, 0, 0}), 1.0f);
        EXPECT_EQ(tables.transmittance(i, {0, 0, 0}), 1.0f);
    }
    std::vector<glm::vec3> out(5);
    ASSERT_TRUE(lightVoxels(g, {0, 0, 5}, lights, &tables, {}, out));
    EXPECT_TRUE(out.empty());
}

TEST(ShadowStability, OneCubedTable) {
    Grid g = test::gaussianBlob(8, 0.25f);
    auto f = DensityField::fromGrid(g);
    const Light sun = Light::directional({0, -1, 0});
    ShadowTable table({.dims = glm::ivec3(1)});
    ASSERT_TRUE(table.update(*f, sun)) << "1^3";
    ASSERT_EQ(table.data().size(), 1u);
    ASSERT_EQ(table.dims(), glm::ivec3(1));
    // One node at the centre: its value is the trapezoid from it to the box's
    // top face, where the field is 0: half the box height times half the centre's density.
    const glm::vec3 c = 0.5f * (f->boundsMin() + f->boundsMax());
    const float expected = 0.5f * (f->boundsMax().y - f->boundsMin().y) * 0.5f * f->at(c);
    EXPECT_NEAR(table.data()[0], expected, 1e-5f * expected);
    // Every look-up inside reads that one value.
    EXPECT_FLOAT_EQ(table.opticalDepth(f->boundsMin()), expected);
    EXPECT_FLOAT_EQ(table.opticalDepth(c + glm::vec3(0.1f, -0.2f, 0.3f)), expected);
    ShadowTable point({.dims = glm::ivec3(1)});
    ASSERT_TRUE(point.update(*f, Light::point(c)));
    EXPECT_TRUE(std::isfinite(point.data()[0]));
}

TEST(ShadowStability, TableOverTheMemoryBudgetIsAClearError) {
    Grid g = test::gaussianBlob(4, 1.0f);
    auto f = DensityField::fromGrid(g);
    ShadowTable table({.dims = glm::ivec3(256)}); // 16.8M entries x 17 B = 272 MiB > 64 MiB
    const Status s = table.update(*f, Light{});
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("ShadowTableDesc.dims 256x256x256 needs 272 MiB"), std::string::npos) << s.error();
    EXPECT_NE(s.error().find("ShadowTableDesc.memoryBudgetBytes = 64 MiB"), std::string::npos) << s.error();
    EXPECT_TRUE(table.data().empty());
    EXPECT_EQ(table.transmittance({0, 0, 0}), 1.0f);
    ShadowTable zero({.dims = {0, 4, 4}});
    const Status z = zero.update(*f, Light{});
    ASSERT_FALSE(z);
    EXPECT_NE(z.error().find("ShadowTableDesc.dims.x must be in [1, 1024], got 0"), std::string::npos) << z.error();
    ShadowTables tables({.dims = glm::ivec3(128), .memoryBudgetBytes = 1u << 20});
    const Light two[] = {Light{}, Light{}};
    const Status t = tables.update(*f, two);
    ASSERT_FALSE(t);
    EXPECT_EQ(t.error().rfind("lights[0]: ShadowTableDesc.dims 128x128x128", 0), 0u) << t.error();
}

TEST(ShadowStability, LightExactlyAtTheDensestVoxelCentre) {
    Grid g = test::gaussianBlob(9, 0.25f, 0.9f); // odd: the peak is a lattice point
    auto f = DensityField::fromGrid(g);
    const glm::vec3 peak = g.worldPosition({4, 4, 4});
    const Light bulb = Light::point(peak, glm::vec3(1.0f), 2.0f);
    for (int n : {16, 17, 64}) { // 17: the light falls exactly on a table node
        ShadowTable table({.dims = glm::ivec3(n)});
        ASSERT_TRUE(table.update(*f, bulb));
        for (float d : table.data()) ASSERT_TRUE(std::isfinite(d) && d >= 0.0f);
        // On a node the light sees no depth at itself (1e-5: the look-up's
        // coordinate rounding, times a neighbour's depth of ~2).
        if (n == 17) { EXPECT_LT(table.opticalDepth(peak), 1e-4f); }
    }
    ShadowTracer tracer(*f, std::span(&bulb, 1));
    EXPECT_EQ(tracer.transmittance(0, peak), 1.0f); // zero-length path
    // The voxel holding the light: irradiance at half a voxel (0.125), isotropic phase, unshadowed:
    // out = albedo * intensity / 0.125^2 * (4 pi / 4 pi) * 1.
    std::vector<glm::vec3> out;
    ASSERT_TRUE(lightVoxels(g, {0, 0, 5}, std::span(&bulb, 1), &tracer, {.albedo = 0.5f}, out));
    std::size_t centre = 0;
    for (std::size_t i = 0; i < g.voxels.size(); ++i)
        if (g.voxels[i].cell == glm::ivec3(4)) centre = i;
    EXPECT_NEAR(out[centre].r, 0.5f * 2.0f / (0.125f * 0.125f), 1e-4f);
    for (const glm::vec3& c : out) ASSERT_TRUE(std::isfinite(c.r));
}

TEST(ShadowTable, RebuildsOnlyWhenDensityOrLightChanged) {
    Grid g = test::gaussianBlob(8, 0.25f);
    auto f = DensityField::fromGrid(g);
    ShadowTable table({.dims = glm::ivec3(16)});
    const Light sun = Light::directional({0.2f, -1.0f, 0.1f});
    ASSERT_TRUE(table.update(*f, sun));
    ASSERT_TRUE(table.update(*f, sun));
    EXPECT_EQ(table.builds(), 1u);
    EXPECT_EQ(table.reuses(), 1u);
    // The same density rebuilt into a new field object: same fingerprint, reused.
    auto same = DensityField::fromGrid(g);
    ASSERT_TRUE(table.update(*same, sun));
    EXPECT_EQ(table.builds(), 1u);
    EXPECT_EQ(table.reuses(), 2u);
    // The density changed: rebuilt.
    g.voxels[10].opacity *= 0.5f;
    auto changed = DensityField::fromGrid(g);
    EXPECT_NE(changed->fingerprint(), f->fingerprint());
    ASSERT_TRUE(table.update(*changed, sun));
    EXPECT_EQ(table.builds(), 2u);
    // The light changed (colour only still counts: the light is a value).
    Light moved = sun;
    moved.direction.x = 0.3f;
    ASSERT_TRUE(table.update(*changed, moved));
    EXPECT_EQ(table.builds(), 3u);
    EXPECT_EQ(table.reuses(), 2u);
    // The grid moved: rebuilt (the fingerprint holds the transform).
    g.transform[3].x += 1.0f;
    auto shifted = DensityField::fromGrid(g);
    ASSERT_TRUE(table.update(*shifted, moved));
    EXPECT_EQ(table.builds(), 4u);
}

// The table against tracing for a smooth field. The bound asserted is the
// issue's target, 1/255 mean error in transmittance: the 8-bit step of the
// splat colour the result feeds, below which the two are indistinguishable
// on screen. The scheme is first order (each step's bilinear interpolation
// adds O(h^2) over O(1/h) steps), so the error must also shrink as the
// table is refined; that is asserted as a strict decrease from 16^3 to 64^3
// (bench on this blob: sun 3.2, 1.5, 0.71, 0.37 /255 mean at 16, 32, 64, 128).
TEST(ShadowTable, MeanErrorAgainstTracingIsBelowOneLevel) {
    Grid g = test::gaussianBlob(20, 0.1f, 0.5f);
    auto f = DensityField::fromGrid(g);
    ASSERT_TRUE(f);
    const glm::vec3 c = 0.5f * (f->boundsMin() + f->boundsMax());
    const Light lights[] = {
        Light::directional({0.3f, -1.0f, 0.45f}),          // oblique sun
        Light::point(c + glm::vec3(0.3f, 2.5f, -0.4f)),    // outside the table
        Light::point(c + glm::vec3(0.35f, 0.27f, -0.18f)), // inside the gas
    };
    for (const Light& l : lights) {
        const Errors e16 = tableError(g, *f, l, 16), e64 = tableError(g, *f, l, 64);
        EXPECT_LE(e64.mean, 1.0 / 255.0) << "light type " << int(l.type);
        // Convergence of the recursive fill, for the lights outside the gas:
        // near the light inside it the table traces its nodes directly (8
        // node steps), which at 16^3 is most of this blob.
        if (&l != &lights[2]) { EXPECT_LT(e64.mean, e16.mean) << "light type " << int(l.type); }
        // The traced shadow is not trivial here (else the bound says nothing).
        const glm::vec3 far = g.worldPosition({10, 1, 10});
        EXPECT_LT(std::exp2(-f->opticalDepthToLight(far, l)), 0.5f);
    }
}

TEST(ShadowTable, PointsOutsideTheTableReadTheDepthWhereTheirRayEntersIt) {
    Grid g = test::gaussianBlob(12, 0.2f);
    auto f = DensityField::fromGrid(g);
    const Light sun = Light::directional({0.2f, -1.0f, 0.1f});
    ShadowTable table({.dims = glm::ivec3(64)});
    ASSERT_TRUE(table.update(*f, sun));
    const glm::vec3 c = 0.5f * (f->boundsMin() + f->boundsMax());
    // A ground point under the gas: shadowed as by tracing (within the
    // mean-error target above, here at one point).
    const glm::vec3 ground = c + glm::normalize(sun.direction) * 5.0f + glm::vec3(0.1f, 0.0f, 0.0f);
    const float traced = std::exp2(-f->opticalDepthToLight(ground, sun));
    EXPECT_LT(traced, 0.9f);
    EXPECT_NEAR(table.transmittance(ground), traced, 2.0f / 255.0f);
    // A point whose ray to the sun misses the table: unshadowed.
    EXPECT_EQ(table.transmittance(c + glm::vec3(10.0f, 0.0f, 0.0f)), 1.0f);
    // A point above the gas (between it and the sun): unshadowed.
    EXPECT_EQ(table.transmittance(c + glm::vec3(0.0f, 5.0f, 0.0f)), 1.0f);
}
