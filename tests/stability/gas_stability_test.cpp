// Procedural gases (Ebert & Parent 1990) at their numerical edges: each test
// is named after what would go wrong, and docs/STABILITY.md lists them with
// the failure each guards against. The densities are pure functions of
// (point, time), so the references here are the same functions at points or
// times where the answer is known: a period away, a reduced time, a closed form.
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include "splatfx/effect.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/procedural_gas.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/splats.hpp"

using namespace splatfx;

namespace {

Grid lattice(glm::ivec3 dims = {16, 20, 16}, float spacing = 0.125f) { return *Grid::box(dims, glm::vec3(spacing)); }

ProceduralGasDesc gas(GasKind kind) {
    ProceduralGasDesc d{.kind = kind};
    d.fog.frontStart = 0.0f;
    d.cloud.center = {0.0f, 1.2f, 0.0f};
    d.cloud.radii = {0.9f, 0.6f, 0.8f};
    d.cloud.windPerSec = {0.0f, 0.0f, 0.0f};
    return d;
}

// Largest change of any lattice point's density between t0 and t1, and the
// number of points with density.
struct Change {
    float largest = 0.0f;
    int present = 0;
};
Change change(const ProceduralGasDesc& d, double t0, double t1, const Grid& l = lattice()) {
    Change c;
    for (const Voxel& v : l.voxels) {
        const glm::vec3 x = l.worldPosition(v.cell);
        const float a = proceduralGasDensity(d, x, t0), b = proceduralGasDensity(d, x, t1);
        c.largest = std::max(c.largest, std::abs(b - a));
        c.present += b > 0.0f ? 1 : 0;
    }
    return c;
}

bool allFiniteInUnit(const Grid& g) {
    for (const Voxel& v : g.voxels)
        if (!(v.opacity >= 0.0f && v.opacity <= 1.0f)) return false;
    return true;
}

} // namespace

// ---- Long times -------------------------------------------------------------

// In float, t = 10^6 s has a step of 0.0625 s: 60 Hz frames would repeat four
// times and jump. Each kind's motion over one frame at 10^6 s must be the
// size of its motion over one frame at 10 s: a ratio far from 1 means
// frozen or jumping frames. Bounds [0.25, 4]: the noise gradient differs from
// place to place by about 2x; a frozen frame gives 0, a jump about 15x.
TEST(GasStability, SteamAtAMillionSecondsMovesAsSmoothlyAsAtTen) {
    for (GasKind k : {GasKind::Steam, GasKind::Fog}) {
        ProceduralGasDesc d = gas(k);
        d.fog.frontSpeed = 0.0f; // keep the fog's front mid-lattice at any time
        d.fog.fullDensitySec = 1.0f;
        const double dt = 1.0 / 60.0;
        double early = 0.0;
        for (int f = 0; f < 8; ++f) early += change(d, 10.0 + f * dt, 10.0 + (f + 1) * dt).largest / 8.0;
        ASSERT_GT(early, 0.0) << int(k);
        for (int f = 0; f < 8; ++f) {
            const double late = change(d, 1e6 + f * dt, 1e6 + (f + 1) * dt).largest;
            EXPECT_GT(late / early, 0.25) << int(k) << ": a frozen frame at 10^6 s (frame " << f << ")";
            EXPECT_LT(late / early, 4.0) << int(k) << ": a jump at 10^6 s (frame " << f << ")";
        }
    }
}

// Travel through turbulent space is reduced by the turbulence's period
// (256 / frequency world units): the gas at t and at t + one travel period
// is the same gas. Checked for the steam's rise at the scene clock's limit.
TEST(GasStability, RiseByOneTurbulencePeriodAtTheClockLimitGivesTheSameGas) {
    ProceduralGasDesc d = gas(GasKind::Steam);
    d.steam.swirlRadius = 0.0f;    // no swirl: the rise alone moves the gas
    d.turbulence.frequency = 2.0f; // period 128 world units
    d.steam.riseSpeed = 0.5f;      // 256 s per period
    const double t = kMaxTimeSec - 256.0;
    EXPECT_LE(change(d, t, t + 256.0).largest, 1e-5f) << "float rounding of the density only";
    EXPECT_GT(change(d, t, t + 1.0).present, 10);
}

// The swirl angle 2 pi t / period is reduced to one turn first: with a period
// of 10^-30 s, t / period is 10^30 and the cosine of it in float is noise or
// NaN (and a NaN gave a gas that silently vanished).
TEST(GasStability, SwirlPeriodOfTenToTheMinusThirtyKeepsTheGasPresent) {
    ProceduralGasDesc d = gas(GasKind::Steam);
    d.steam.swirlPeriodSec = 1e-30f;
    auto g = sampleProceduralGas(d, lattice(), 3.7);
    ASSERT_TRUE(g) << g.error();
    EXPECT_GT(g->voxels.size(), 50u);
    EXPECT_TRUE(allFiniteInUnit(*g));
}

// A cloud drifting with the wind for 10^6 s is 2 * 10^5 units away: the
// ellipsoid test in double still finds it where it went, and it is empty where it was.
TEST(GasStability, CloudDriftedForAMillionSecondsIsWhereTheWindTookIt) {
    ProceduralGasDesc d = gas(GasKind::Cloud);
    d.cloud.windPerSec = {0.2f, 0.0f, 0.0f};
    const double t = 1e6;
    Grid there = lattice();
    there.transform = glm::translate(glm::mat4(1.0f), glm::vec3(2e5f - 1.0f, 0.0f, -1.0f));
    auto moved = sampleProceduralGas(d, there, t);
    auto home = sampleProceduralGas(d, lattice({16, 20, 16}), t);
    ASSERT_TRUE(moved && home);
    EXPECT_GT(moved->voxels.size(), 20u);
    EXPECT_EQ(home->voxels.size(), 0u);
    EXPECT_TRUE(allFiniteInUnit(*moved));
}

// Sampling is stateless: scrubbing back to an earlier time gives that time's
// gas bit for bit, whatever was sampled in between.
TEST(GasStability, ScrubbingBackInTimeGivesTheSameGasBitForBit) {
    for (GasKind k : {GasKind::Steam, GasKind::Fog, GasKind::Cloud}) {
        auto a = sampleProceduralGas(gas(k), lattice(), 4.25);
        ASSERT_TRUE(sampleProceduralGas(gas(k), lattice(), 9000.0));
        auto b = sampleProceduralGas(gas(k), lattice(), 4.25);
        ASSERT_EQ(a->voxels.size(), b->voxels.size());
        for (std::size_t i = 0; i < a->voxels.size(); ++i) ASSERT_EQ(a->voxels[i].opacity, b->voxels[i].opacity);
    }
}

// ---- Far from the origin ------------------------------------------------------

// The noise lattice index was int(floor(x)): a point 10^12 units out
// overflowed it (undefined behaviour). Each octave is reduced modulo the
// noise's 256-unit period in double, so the turbulence there equals the
// turbulence at the point reduced by whole periods (exact: 10^12 is a
// multiple of 256 / 0.5 = 512 in double's integers).
TEST(GasStability, TurbulenceTenToTheTwelveUnitsOutEqualsItsPeriodicImage) {
    const GasTurbulenceDesc t{.seed = 3, .octaves = 6, .frequency = 0.5f};
    const double far = 1e12 - std::fmod(1e12, 512.0); // a multiple of the period
    for (const glm::vec3 p : {glm::vec3(0.3f, 0.7f, 0.1f), glm::vec3(12.25f, -3.5f, 100.0f)}) {
        const float near = gasTurbulence(t, p);
        const float out = gasTurbulence(t, glm::vec3(glm::dvec3(p) + glm::dvec3(far, 0.0, 0.0)));
        // The far point itself is a float: 10^12 has a float step of 65536, so
        // compare with the float point's own image, computed in double.
        const glm::dvec3 pf = glm::dvec3(glm::vec3(glm::dvec3(p) + glm::dvec3(far, 0.0, 0.0)));
        const glm::vec3 image(glm::dvec3(pf.x - 512.0 * std::floor(pf.x / 512.0), pf.y, pf.z));
        EXPECT_TRUE(std::isfinite(out));
        EXPECT_NEAR(out, gasTurbulence(t, image), 1e-6f);
        EXPECT_GE(near, 0.0f);
    }
}

// Turbulence repeats with the period 256 / frequency on every axis (what the
// reductions rely on); across the wrap at 0 it is continuous.
TEST(GasStability, TurbulenceIsPeriodicAndContinuousAcrossItsWrap) {
    const GasTurbulenceDesc t{.seed = 11, .octaves = 5, .frequency = 4.0f}; // period 64
    const glm::vec3 p(1.3f, 2.6f, -0.45f);
    EXPECT_NEAR(gasTurbulence(t, p), gasTurbulence(t, p + glm::vec3(64.0f, 0.0f, 0.0f)), 1e-5f);
    EXPECT_NEAR(gasTurbulence(t, p), gasTurbulence(t, p - glm::vec3(0.0f, 0.0f, 64.0f)), 1e-5f);
    // Either side of the wrap point 0 (x reduced to 255.99... and 0.00...):
    // Lipschitz with the noise's gradient (a few per lattice unit) times
    // 2 x 10^-6 lattice units apart, summed over 5 octaves: under 1e-4.
    const float below = gasTurbulence(t, {-1e-7f, 0.3f, 0.3f}), above = gasTurbulence(t, {1e-7f, 0.3f, 0.3f});
    EXPECT_NEAR(below, above, 1e-4f);
}

// At noise lattice points every octave's noise is exactly 0: turbulence 0,
// steam density 0, and nothing divides by it.
TEST(GasStability, NoiseLatticePointsGiveZeroTurbulenceNotNaN) {
    const GasTurbulenceDesc t{.seed = 5, .octaves = 4, .frequency = 1.0f};
    for (int i = -3; i <= 3; ++i) EXPECT_EQ(gasTurbulence(t, glm::vec3(float(i), 2.0f, float(-i))), 0.0f);
}

// ---- Parameters at their limits -------------------------------------------------

// The most octaves the desc allows: the sum of |noise| 2^-i stays under twice
// the largest |noise| (about 1), finite everywhere.
TEST(GasStability, TwelveOctavesStayBoundedByTheGeometricSum) {
    const GasTurbulenceDesc t{.seed = 9, .octaves = 12, .frequency = 1.0f};
    float largest = 0.0f;
    for (int i = 0; i < 2000; ++i) {
        const float v = gasTurbulence(t, glm::vec3(0.0137f * i, 0.071f * i, -0.029f * i));
        ASSERT_TRUE(std::isfinite(v));
        largest = std::max(largest, v);
    }
    EXPECT_LT(largest, 2.0f * 1.1f) << "|noise| <= about 1.1 for 4D gradient noise, times sum 2^-i < 2";
    EXPECT_GT(largest, 0.1f);
}

// Frequency 10^6: the noise is finer than the lattice (aliasing, the user's
// choice) but finite; 10^-9: the period is 2.56 * 10^11 units and the field
// is nearly constant over the lattice. Neither is NaN.
TEST(GasStability, ExtremeTurbulenceFrequenciesStayFinite) {
    for (float f : {1e6f, 1e-9f}) {
        ProceduralGasDesc d = gas(GasKind::Steam);
        d.turbulence.frequency = f;
        auto g = sampleProceduralGas(d, lattice(), 2.0);
        ASSERT_TRUE(g) << g.error();
        EXPECT_TRUE(allFiniteInUnit(*g)) << f;
    }
}

// The steam's source plane (h = 0) is inside, its top (h = height) outside,
// and its rim (radial = 0) has density exactly 0: no cell appears or blinks
// at a boundary because of a rounding step.
TEST(GasStability, SteamBoundariesAreClosedBelowAndOpenAtTheTopAndRim) {
    ProceduralGasDesc d = gas(GasKind::Steam);
    d.steam.source = {0.0f, 0.0f, 0.0f};
    d.steam.height = 2.0f;
    d.steam.sourceRadius = 0.5f;
    d.steam.spread = 0.0f;
    EXPECT_EQ(proceduralGasDensity(d, {0.0f, 2.0f, 0.0f}, 1.0), 0.0f);
    EXPECT_EQ(proceduralGasDensity(d, {0.5f, 1.0f, 0.0f}, 1.0), 0.0f); // on the rim
    EXPECT_EQ(proceduralGasDensity(d, {0.0f, -1e-7f, 0.0f}, 1.0), 0.0f);
    // Just inside the rim the density is tiny (radial ~ 4e-6) but not negative.
    const float inside = proceduralGasDensity(d, {0.499999f, 1.0f, 0.0f}, 1.0);
    EXPECT_GE(inside, 0.0f);
    EXPECT_LT(inside, 1e-3f);
}

// The fog's density is 0 exactly at its front and grows continuously behind
// it: thickenDistance 10^-30 makes the growth a step, not an inf * 0.
TEST(GasStability, FogFrontWithAVanishingThickenDistanceIsAStepNotANaN) {
    ProceduralGasDesc d = gas(GasKind::Fog);
    d.fog.thickenDistance = 1e-30f;
    d.fog.frontTurbulence = 0.0f; // the front is the plane x = frontStart + frontSpeed t
    d.fog.frontStart = 0.5f;
    d.fog.frontSpeed = 0.0f;
    d.fog.fullDensitySec = 1.0f;
    EXPECT_EQ(proceduralGasDensity(d, {0.5000001f, 0.5f, 0.5f}, 5.0), 0.0f);
    auto g = sampleProceduralGas(d, lattice(), 5.0);
    ASSERT_TRUE(g);
    EXPECT_TRUE(allFiniteInUnit(*g));
    EXPECT_GT(g->voxels.size(), 20u);
}

// fullDensitySec 10^-30: full density from the first instant after 0, none at 0.
TEST(GasStability, FogThatThickensInstantlyIsEmptyAtZeroAndFullRightAfter) {
    ProceduralGasDesc d = gas(GasKind::Fog);
    d.fog.fullDensitySec = 1e-30f;
    auto at0 = sampleProceduralGas(d, lattice(), 0.0), after = sampleProceduralGas(d, lattice(), 1e-20);
    ASSERT_TRUE(at0 && after);
    EXPECT_EQ(at0->voxels.size(), 0u);
    EXPECT_GT(after->voxels.size(), 20u);
    EXPECT_TRUE(allFiniteInUnit(*after));
}

// A cloud's semi-axes at 10^-30 (it is a point: only a lattice point exactly
// at its centre is inside, with 0 / 10^-30 = 0, not a 0/0) and at 10^30 (it
// fills all space: the falloff is 1 everywhere).
TEST(GasStability, CloudOfVanishingOrEnormousRadiiIsAPointOrUniformlyFull) {
    ProceduralGasDesc d = gas(GasKind::Cloud);
    d.cloud.radii = glm::vec3(1e-30f);
    d.cloud.center = lattice().worldPosition({8, 10, 8}); // exactly on a lattice point
    d.threshold = 0.0f;
    auto tiny = sampleProceduralGas(d, lattice(), 1.0);
    ASSERT_TRUE(tiny);
    ASSERT_LE(tiny->voxels.size(), 1u);
    for (const Voxel& v : tiny->voxels) EXPECT_EQ(v.cell, glm::ivec3(8, 10, 8));
    EXPECT_TRUE(allFiniteInUnit(*tiny));
    d.cloud.radii = glm::vec3(1e30f);
    d.threshold = 0.0f;
    auto huge = sampleProceduralGas(d, lattice(), 1.0);
    ASSERT_TRUE(huge);
    EXPECT_TRUE(allFiniteInUnit(*huge));
    EXPECT_GT(huge->voxels.size(), 16u * 20u * 16u / 4u);
}

// cloud.power 10^4: (s + 1)^power overflows to infinity; the density clamps
// to 0 there instead of becoming NaN.
TEST(GasStability, CloudPowerThatOverflowsClampsToZeroNotNaN) {
    ProceduralGasDesc d = gas(GasKind::Cloud);
    d.cloud.power = 1e4f;
    auto g = sampleProceduralGas(d, lattice(), 1.0);
    ASSERT_TRUE(g);
    EXPECT_TRUE(allFiniteInUnit(*g));
}

// power 10^-6 makes any density 1 (a binary gas); 10^3 makes all but
// density 1 vanish. Both finite, the first non-empty.
TEST(GasStability, DensityExponentsAtTheirExtremesGiveBinaryOrVanishingGas) {
    ProceduralGasDesc d = gas(GasKind::Steam);
    d.steam.power = 1e-6f;
    auto binary = sampleProceduralGas(d, lattice(), 2.0);
    ASSERT_TRUE(binary);
    ASSERT_GT(binary->voxels.size(), 10u);
    for (const Voxel& v : binary->voxels) EXPECT_GT(v.opacity, 0.99f);
    d.steam.power = 1e3f;
    auto faint = sampleProceduralGas(d, lattice(), 2.0);
    ASSERT_TRUE(faint);
    EXPECT_TRUE(allFiniteInUnit(*faint));
}

// ---- Sampling onto the lattice ----------------------------------------------------

// threshold 0 keeps every cell of positive density and drops only exact zeros
// (the rule is density > threshold); a threshold just under 1 leaves an
// empty grid, and an effect of it draws nothing without an error.
TEST(GasStability, ThresholdsAtZeroAndJustUnderOneKeepAllOrNothing) {
    ProceduralGasDesc d = gas(GasKind::Steam);
    d.threshold = 0.0f;
    auto all = sampleProceduralGas(d, lattice(), 2.0);
    ASSERT_TRUE(all);
    const Grid l = lattice();
    std::size_t positive = 0;
    for (const Voxel& v : l.voxels) positive += proceduralGasDensity(d, l.worldPosition(v.cell), 2.0) > 0.0f ? 1 : 0;
    EXPECT_EQ(all->voxels.size(), positive);
    d.threshold = std::nextafter(1.0f, 0.0f);
    auto none = sampleProceduralGas(d, lattice(), 2.0);
    ASSERT_TRUE(none);
    EXPECT_EQ(none->voxels.size(), 0u);
    Materials materials{Footprint{}};
    const std::uint32_t table = materials.addColorTable(ColorTable::constant({1, 1, 1, 1}));
    EffectDesc desc;
    desc.layers = {EffectLayer{.style = {.colorTable = table, .textured = false}}};
    auto effect = Effect::fromProceduralGas(d, lattice(), desc);
    ASSERT_TRUE(effect) << effect.error();
    effect->update(2.0);
    SplatBuilder builder;
    builder.begin(Camera::lookAt({0, 1, 6}, {0, 1, 0}, {0, 1, 0}, 0.8f, {64, 48}));
    EXPECT_EQ(effect->emit(builder, materials), 0u);
}

// One cell: the smallest lattice samples and colours by height without
// dividing by a zero extent.
TEST(GasStability, ALatticeOfOneCellSamplesAndColoursWithoutDividingByZero) {
    ProceduralGasDesc d = gas(GasKind::Cloud);
    d.threshold = 0.0f;
    d.cloud.radii = glm::vec3(1e3f);
    auto g = sampleProceduralGas(d, lattice({1, 1, 1}), 1.0);
    ASSERT_TRUE(g);
    ASSERT_LE(g->voxels.size(), 1u);
    for (const Voxel& v : g->voxels) EXPECT_TRUE(std::isfinite(v.colorCoord));
}

// opaque 0: no density anywhere (every kind), so no cell.
TEST(GasStability, ZeroOpacityScaleGivesNoCellsInAnyKind) {
    for (GasKind k : {GasKind::Steam, GasKind::Fog, GasKind::Cloud}) {
        ProceduralGasDesc d = gas(k);
        d.steam.opaque = d.fog.opaque = d.cloud.opaque = 0.0f;
        d.threshold = 0.0f;
        auto g = sampleProceduralGas(d, lattice(), 3.0);
        ASSERT_TRUE(g);
        EXPECT_EQ(g->voxels.size(), 0u) << int(k);
    }
}

// A steam source that sinks (riseSpeed < 0) moves down through turbulent
// space as smoothly as it rises: the motion is an offset, not a direction.
TEST(GasStability, NegativeRiseSpeedMovesAsSmoothlyAsPositive) {
    ProceduralGasDesc up = gas(GasKind::Steam), down = up;
    up.steam.swirlRadius = down.steam.swirlRadius = 0.0f;
    down.steam.riseSpeed = -up.steam.riseSpeed;
    const float a = change(up, 3.0, 3.0 + 1.0 / 60.0).largest, b = change(down, 3.0, 3.0 + 1.0 / 60.0).largest;
    ASSERT_GT(a, 0.0f);
    EXPECT_GT(b / a, 0.25f);
    EXPECT_LT(b / a, 4.0f);
}

// ---- The exact reference (proceduralGasMedium through renderVolumeExact) ----

// A lattice rotated 30 degrees about y: its world box is wider than its
// cells, and the reference must be empty in the corners between (where the
// gas itself has density, but no cell of the lattice samples it), and equal
// to the gas at a point inside the rotated cells.
TEST(GasStability, ARotatedLatticesReferenceIsEmptyOutsideItsCellsInsideItsWorldBox) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::constant({1.0f, 1.0f, 1.0f, 1.0f}));
    ProceduralGasDesc d = gas(GasKind::Fog); // fog fills all space behind its front
    d.fog.frontStart = 50.0f;
    Grid l = lattice({9, 9, 9}, 0.25f); // x, z in [-1, 1], y in [0, 2]
    l.transform = glm::rotate(glm::mat4(1.0f), glm::radians(30.0f), glm::vec3(0, 1, 0));
    const ContinuousMedium m = proceduralGasMedium(d, l, 5.0, mat, {.cellLength = 0.25});
    // (1.1, 1, 1.1) is inside the world box (its x, z reach 1.125 (cos 30 + sin 30) = 1.54)
    // but outside the cells: rotated back it is at x' = 1.1 cos 30 - 1.1 sin 30 = 0.40,
    // z' = 1.1 sin 30 + 1.1 cos 30 = 1.50 > 1.125.
    const glm::dvec3 corner(1.1, 1.0, 1.1);
    ASSERT_TRUE(glm::all(glm::lessThan(corner, m.boxMax)));
    ASSERT_GT(proceduralGasDensity(d, glm::vec3(corner), 5.0), 0.0f);
    EXPECT_EQ(m.sample(corner).extinction, 0.0);
    // The centre is inside: the medium is the gas there.
    const glm::dvec3 inside(0.1, 1.0, 0.2);
    const double dens = double(proceduralGasDensity(d, glm::vec3(inside), 5.0));
    ASSERT_GT(dens, 0.0);
    EXPECT_NEAR(m.sample(inside).extinction * 0.25, -std::log1p(-dens), 1e-12);
}
