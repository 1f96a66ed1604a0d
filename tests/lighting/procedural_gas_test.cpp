#include <cmath>

#include <gtest/gtest.h>

#include "splatfx/procedural_gas.hpp"

using namespace splatfx;

namespace {

Grid lattice() {
    Grid g = *Grid::box({16, 20, 16}, glm::vec3(0.125f));
    return g;
}

ProceduralGasDesc gas(GasKind kind) {
    ProceduralGasDesc d{.kind = kind};
    d.fog.frontStart = 0.0f; // the fog's front starts mid-lattice
    d.cloud.center = {0.0f, 1.2f, 0.0f};
    d.cloud.radii = {0.9f, 0.6f, 0.8f};
    return d;
}

// Largest change of any cell's density between two times.
float maxChange(const ProceduralGasDesc& d, float t0, float t1) {
    const Grid l = lattice();
    float m = 0.0f;
    for (const Voxel& v : l.voxels) {
        const glm::vec3 x = l.worldPosition(v.cell);
        m = std::max(m, std::abs(proceduralGasDensity(d, x, t1) - proceduralGasDensity(d, x, t0)));
    }
    return m;
}

} // namespace

TEST(ProceduralGas, DeterministicBySeed) {
    for (GasKind k : {GasKind::Steam, GasKind::Fog, GasKind::Cloud}) {
        auto a = sampleProceduralGas(gas(k), lattice(), 5.0f), b = sampleProceduralGas(gas(k), lattice(), 5.0f);
        ASSERT_TRUE(a && b) << a.error();
        ASSERT_GT(a->voxels.size(), 10u) << int(k);
        ASSERT_EQ(a->voxels.size(), b->voxels.size());
        for (std::size_t i = 0; i < a->voxels.size(); ++i) {
            ASSERT_EQ(a->voxels[i].cell, b->voxels[i].cell);
            ASSERT_EQ(a->voxels[i].opacity, b->voxels[i].opacity);
        }
        ProceduralGasDesc other = gas(k);
        other.turbulence.seed = 99;
        auto c = sampleProceduralGas(other, lattice(), 5.0f);
        bool differs = c->voxels.size() != a->voxels.size();
        for (std::size_t i = 0; !differs && i < a->voxels.size(); ++i) differs = a->voxels[i].opacity != c->voxels[i].opacity;
        EXPECT_TRUE(differs) << int(k);
    }
}

// Every term is continuous in time (noise, the front, the growth factor and
// the helix are continuous; the exponents are >= 1, so Lipschitz): at most
// L * dt with L of order the speeds times the noise gradient (~10 per
// second here). A jump, e.g. a frame-quantized motion, would show up as a
// change of order the density (0.1 and more) at any dt. So the change over
// 1e-4 s must stay below 0.01 and shrink with dt.
TEST(ProceduralGas, ContinuousInTime) {
    for (GasKind k : {GasKind::Steam, GasKind::Fog, GasKind::Cloud}) {
        const ProceduralGasDesc d = gas(k);
        for (float t : {0.5f, 3.7f, 9.25f}) {
            const float big = maxChange(d, t, t + 1e-2f), small = maxChange(d, t, t + 1e-4f);
            EXPECT_LT(small, 0.01f) << int(k) << " t " << t;
            EXPECT_LE(small, big) << int(k) << " t " << t;
        }
    }
}

TEST(ProceduralGas, SteamRisesFromItsSourceAndDissipates) {
    const ProceduralGasDesc d = gas(GasKind::Steam);
    auto g = sampleProceduralGas(d, lattice(), 2.0f);
    ASSERT_TRUE(g);
    double low = 0.0, high = 0.0;
    for (const Voxel& v : g->voxels) {
        const glm::vec3 x = g->worldPosition(v.cell);
        ASSERT_GE(x.y, d.steam.source.y);
        ASSERT_LT(x.y, d.steam.source.y + d.steam.height);
        (x.y < 0.8f ? low : high) += v.opacity;
    }
    // Lattice heights 0..2.375: [0, 0.8) and [0.8, 2.375); the lower part is denser per cell count too.
    EXPECT_GT(low / 7.0, high / 13.0);
}

TEST(ProceduralGas, FogRollsInBehindItsFrontAndThickens) {
    const ProceduralGasDesc d = gas(GasKind::Fog);
    // At t = 0 the fog has no density yet (min(t / fullDensitySec, 1) = 0).
    auto g0 = sampleProceduralGas(d, lattice(), 0.0f);
    EXPECT_TRUE(g0->voxels.empty());
    // |noise| <= 1.5 (a gradient dot offset is at most |a| + |b| + |c| <= 3,
    // halved, and interpolation does not exceed its corners), octave weights
    // sum below 2: turbulence < 3, so the front lies behind
    // frontStart + speed t + amplitude * (3 - 0.5).
    for (float t : {1.0f, 2.0f}) {
        auto g = sampleProceduralGas(d, lattice(), t);
        ASSERT_FALSE(g->voxels.empty());
        const float limit = d.fog.frontStart + d.fog.frontSpeed * t + d.fog.frontTurbulence * 2.5f;
        for (const Voxel& v : g->voxels) ASSERT_LE(g->worldPosition(v.cell).x, limit);
    }
    auto early = sampleProceduralGas(d, lattice(), 1.0f), late = sampleProceduralGas(d, lattice(), 4.0f);
    double a = 0, b = 0;
    for (const Voxel& v : early->voxels) a += v.opacity;
    for (const Voxel& v : late->voxels) b += v.opacity;
    EXPECT_GT(b, a);
}

TEST(ProceduralGas, CloudStaysInsideItsDriftingEllipsoid) {
    const ProceduralGasDesc d = gas(GasKind::Cloud);
    for (float t : {0.0f, 2.0f}) {
        auto g = sampleProceduralGas(d, lattice(), t);
        ASSERT_FALSE(g->voxels.empty());
        for (const Voxel& v : g->voxels) {
            const glm::vec3 e = (g->worldPosition(v.cell) - d.cloud.center - d.cloud.windPerSec * t) / d.cloud.radii;
            ASSERT_LT(glm::dot(e, e), 1.0f);
        }
    }
}

TEST(ProceduralGas, BadDescNamesTheField) {
    ProceduralGasDesc d;
    d.fog.power = 0.0f;
    auto g = sampleProceduralGas(d, lattice(), 1.0f);
    ASSERT_FALSE(g);
    EXPECT_NE(g.error().find("fog.power must be a finite number > 0"), std::string::npos) << g.error();
    ProceduralGasDesc o;
    o.turbulence.octaves = 0;
    EXPECT_NE(validateProceduralGas(o).error().find("turbulence.octaves"), std::string::npos);
    Grid none;
    auto n = sampleProceduralGas(ProceduralGasDesc{}, none, 1.0f);
    ASSERT_FALSE(n);
    EXPECT_NE(n.error().find("lattice.dims.x"), std::string::npos);
    EXPECT_FALSE(sampleProceduralGas(ProceduralGasDesc{}, lattice(), INFINITY));
    EXPECT_EQ(proceduralGasDensity(ProceduralGasDesc{}, {NAN, 0, 0}, 1.0f), 0.0f);
}

// ProceduralGasDesc::cellLength: the density is the opacity of a cell that
// size; a lattice of half the spacing gets half the optical depth per cell
// (-ln(1 - opacity) halved), so a column through the gas has the same depth at
// both spacings up to the sampling. 0 keeps opacity = density.
TEST(ProceduralGas, CellLengthKeepsTheOpticalDepthPerLengthAtAnySpacing) {
    ProceduralGasDesc d = gas(GasKind::Steam);
    d.threshold = 0.0f;
    const Grid coarse = *Grid::box({16, 20, 16}, glm::vec3(0.125f)), fine = *Grid::box({32, 40, 32}, glm::vec3(0.0625f));
    const Grid plain = *sampleProceduralGas(d, fine, 1.5);
    d.cellLength = 0.125f;
    const Grid same = *sampleProceduralGas(d, coarse, 1.5), scaled = *sampleProceduralGas(d, fine, 1.5);
    ASSERT_FALSE(same.voxels.empty());
    ASSERT_EQ(scaled.voxels.size(), plain.voxels.size());
    // At its own spacing the density is the opacity, bit for bit.
    for (const Voxel& v : same.voxels) EXPECT_EQ(v.opacity, proceduralGasDensity(d, same.worldPosition(v.cell), 1.5)) << v.cell.x;
    double worst = 0.0;
    for (std::size_t i = 0; i < scaled.voxels.size(); ++i) {
        const double density = plain.voxels[i].opacity; // cellLength 0: the density itself
        if (density >= 1.0) continue;                   // opaque stays opaque
        const double depth = -std::log1p(-double(scaled.voxels[i].opacity)), want = -0.5 * std::log1p(-density);
        // The opacity is stored in float: its rounding (2^-24 relative) moves the depth by
        // 2^-24 o / (1 - o); the density's own float rounding by half that.
        const double o = scaled.voxels[i].opacity, tol = std::ldexp(1.0, -23) * (o + density) / (1.0 - std::max(o, density)) + 1e-12;
        worst = std::max(worst, std::abs(depth - want) / tol);
        EXPECT_NEAR(depth, want, tol) << "cell " << i;
    }
    RecordProperty("worst_over_tolerance", std::to_string(worst));
    ProceduralGasDesc bad;
    bad.cellLength = -0.1f;
    EXPECT_NE(validateProceduralGas(bad).error().find("cellLength"), std::string::npos);
}
