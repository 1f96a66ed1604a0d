// Hard cases of a lit ground fog layer (GroundFog::setLighting; docs/STABILITY.md,
// "Ground fog lighting"): the sun's transmittance T at each grid point's
// terrain and fog top where the geometry, the sun or a caster sits on an
// edge of the closed forms: thickness jumping to zero, a cliff, a sun along a
// ridge crest or one ulp off rays through grid vertices, extinction 0 and
// FLT_MAX, the smallest layer, a caster touching the top, holding a NaN,
// moving every frame, empty, or many.
//
// Tolerances (as ground_fog_light_test.cpp). The SDK integrates in closed
// form per triangle stretch in double and stores T as a float: half an ulp,
// 2^-24 relative (6e-8 absolute for T <= 1). The reference
// (integrateGroundFogRay's transmittance along the ray to the sun) halves
// 4-point Gauss-Legendre steps to 1e-11 per stretch; its summed last
// differences (errorEstimate) bound its own error, taken twice. A caster is
// traced in float (DensityField::opticalDepth's Simpson sums): a few float
// epsilons per lattice cell crossed, relative to its log2 depth; 1e-6 of the
// depth covers the <= 16 cells here.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/volume.hpp"

#include "ground_fog_test_helpers.hpp"

using namespace splatfx;
using namespace ground_fog_test;

namespace {

constexpr double kFloatT = 6e-8; // a float T in [0, 1]: half an ulp at 1

GroundFogDesc flat(glm::ivec2 dims, float bottom, float top) { return slab(dims, 1.0f, bottom, top); }

std::size_t at(const GroundFogDesc& d, int i, int j) { return std::size_t(i) + std::size_t(d.dims.x) * std::size_t(j); }

// The world point of grid point (i, j) on the terrain (top false) or the fog
// top, in the float arithmetic the SDK relights at.
glm::vec3 pointOf(const GroundFogDesc& d, int i, int j, bool top) {
    const std::size_t k = at(d, i, j);
    const float x = d.originWorld.x + float(i) * d.spacingWorld, z = d.originWorld.z + float(j) * d.spacingWorld;
    const float hb = d.terrainHeight[k], ht = hb + std::max(d.fogTop[k] - hb, 0.0f);
    return {x, top ? ht : hb, z};
}

// Every grid point's T (terrain and top) of a lit `fog` against the
// reference for `d`; returns the lowest reference T.
double expectTIsTheReference(const GroundFog& fog, const GroundFogDesc& d, glm::vec3 travel, float extinction) {
    const std::vector<float>& T = fog.sunTransmittance();
    double lowest = 1.0;
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i)
            for (int top = 0; top < 2; ++top) {
                const auto [want, err] = referenceT(d, extinction, pointOf(d, i, j, top != 0), travel);
                const float got = T[2 * at(d, i, j) + std::size_t(top)];
                EXPECT_TRUE(std::isfinite(got));
                EXPECT_NEAR(got, want, kFloatT + 2.0 * err) << i << ", " << j << (top ? " top" : " terrain");
                if (want > 0.0) lowest = std::min(lowest, want); // 0: the terrain hides the sun
            }
    return lowest;
}

double litAgainstTheReference(const GroundFogDesc& d, glm::vec3 travel, float extinction) {
    auto fog = GroundFog::create(d);
    EXPECT_TRUE(fog) << fog.error();
    if (!fog) return 1.0;
    EXPECT_TRUE(fog->setLighting(sunAlong(travel, extinction)));
    return expectTIsTheReference(*fog, d, travel, extinction);
}

// A caster: a box of voxels of log2 depth `tau` each (opacity 1 - 2^-tau),
// spacing 1, voxel (0, 0, 0)'s centre at world `lowest`.
Grid casterGrid(glm::ivec3 dims, glm::vec3 lowest, float tau) {
    Grid g = *Grid::box(dims);
    for (Voxel& v : g.voxels) v.opacity = 1.0f - std::exp2(-tau);
    g.transform = glm::translate(glm::mat4(1.0f), lowest - g.localPosition({0, 0, 0}));
    return g;
}

float T(const GroundFog& fog, const GroundFogDesc& d, int i, int j, bool top) { return fog.sunTransmittance()[2 * at(d, i, j) + (top ? 1u : 0u)]; }

} // namespace

// Thickness jumping from 0 to 2.5 between every pair of neighbours (a
// checkerboard of bare and fogged points): every triangle has a corner of
// zero thickness, where the paper's scalar g2 / (g1 + g2) is 0 / 0 and a
// stretch starting or ending there must take the ratio's limit, not a NaN or
// the log of 0. Both scalars, a slanted sun crossing cells on both axes.
TEST(GroundFogLightHardCases, ThicknessJumpingFromZeroBetweenNeighbours) {
    for (float depth : {0.0f, 2.5f}) {
        GroundFogDesc d = flat({7, 6}, 0.0f, 0.0f);
        d.densityDepthWorld = depth;
        for (int j = 0; j < d.dims.y; ++j)
            for (int i = 0; i < d.dims.x; ++i) {
                d.terrainHeight[at(d, i, j)] = 0.1f * float(i);
                d.fogTop[at(d, i, j)] = d.terrainHeight[at(d, i, j)] + (((i + j) & 1) ? 2.5f : 0.0f);
            }
        EXPECT_LT(litAgainstTheReference(d, {0.7f, -0.5f, 0.4f}, 1.5f), 0.9) << depth;
    }
}

// A cliff: the terrain steps from 0 to 40 units within one cell (40 times
// steeper than wide) under a fog top at 42, so the fog is 42 deep below the
// cliff and 2 on it. Rays from the foot toward a sun beyond the cliff meet
// the rock: the terrain hides the sun there (T = 0, the reference's
// terrainHides); rays from the top of the cliff toward a sun on the low side
// cross the deep fog. Prisms 40 times taller than wide, their scalar ratio
// varying 20-fold along one stretch.
TEST(GroundFogLightHardCases, ATerrainCliffFortyTimesTallerThanItsCell) {
    GroundFogDesc d = flat({8, 4}, 0.0f, 42.0f);
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 4; i < d.dims.x; ++i) d.terrainHeight[at(d, i, j)] = 40.0f;
    for (glm::vec3 travel : {glm::vec3(-0.8f, -0.6f, 0.1f), glm::vec3(0.8f, -0.5f, -0.2f)})
        EXPECT_LT(litAgainstTheReference(d, travel, 0.2f), 0.9) << travel.x;
    d.densityDepthWorld = 42.0f; // the affine scalar, reaching `density` at the foot; the sun on the low side
    EXPECT_LT(litAgainstTheReference(d, {0.8f, -0.5f, -0.2f}, 0.2f), 0.9);
}

// The sun at the horizon travelling along a ridge: the terrain rises from 0
// to 2 toward the crest on grid row j = 2 (a kink: the crest is the shared
// edge of two cells' triangles) and every row is level along x. Each
// terrain point's ray runs exactly on the terrain (g1 = 0 all along), on a
// triangle edge at the crest, where the scalar is `density`: T = exp(-k d x)
// with x the distance to the grid's edge toward the sun. The fog top is
// level: its rays see the scalar 0 (T = 1).
TEST(GroundFogLightHardCases, TheSunAlongARidgeCrestGrazesItsEdge) {
    GroundFogDesc d = flat({7, 5}, 0.0f, 3.0f);
    d.spacingWorld = 0.5f;
    d.density = 0.6f;
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i) d.terrainHeight[at(d, i, j)] = 2.0f - float(std::abs(j - 2));
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const float k = 0.9f;
    for (float travelX : {1.0f, -1.0f}) { // the sun at -x, then at +x
        ASSERT_TRUE(fog->setLighting(sunAlong({travelX, 0.0f, 0.0f}, k)));
        for (int j = 0; j < d.dims.y; ++j)
            for (int i = 0; i < d.dims.x; ++i) {
                const int cells = travelX > 0.0f ? i : d.dims.x - 1 - i;
                EXPECT_NEAR(T(*fog, d, i, j, false), std::exp(-double(k) * 0.6 * 0.5 * double(cells)), kFloatT) << i << ", " << j;
                EXPECT_EQ(T(*fog, d, i, j, true), 1.0f) << i << ", " << j;
            }
    }
}

// Extinction 0: the layer is clear to the sun (T exactly 1 at every point),
// and what it draws is finite: the lit table at rho = 0 and every vertex's
// scalar (s = phase / max phase, T being 1), the colour the model's source.
// Turning the extinction up again relights.
TEST(GroundFogLightHardCases, ExtinctionZeroIsClearAndFinite) {
    GroundFogDesc d = flat({5, 5}, 0.0f, 1.5f);
    d.terrainHeight[at(d, 2, 2)] = 0.7f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    GroundFogLighting L = sunAlong({0.3f, -0.8f, 0.2f}, 0.0f);
    const HgLobe lobe{.g = 0.5f};
    L.gas.phase = *PhaseFunction::create(std::span<const HgLobe>(&lobe, 1));
    ASSERT_TRUE(fog->setLighting(L));
    for (float t : fog->sunTransmittance()) EXPECT_EQ(t, 1.0f);
    for (float v : fog->litTable().data()) EXPECT_TRUE(std::isfinite(v));
    const Camera cam = Camera::lookAt({2.0f, 6.0f, 9.0f}, {2.0f, 0.5f, 2.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 50.0f);
    LodFrame frame;
    ASSERT_TRUE(fog->update(cam, frame));
    ASSERT_FALSE(frame.tets.empty());
    // kappa is affine in s: float rounding of s and kappa, 1e-5 of the peak.
    const glm::dvec3 peak = fog->litTransfer().color(1.0);
    const double tol = 1e-5 * std::max({peak.x, peak.y, peak.z});
    for (const Tetrahedron& t : frame.tets)
        for (int c = 0; c < 4; ++c) {
            const glm::vec3 p = t.position[std::size_t(c)];
            ASSERT_TRUE(std::isfinite(t.scalar[std::size_t(c)]));
            const glm::dvec3 want = fog->sourceAt(1.0, glm::normalize(cam.eye() - p));
            const glm::dvec3 got = fog->litTransfer().color(t.scalar[std::size_t(c)]);
            for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], tol);
        }
    const auto relights = fog->relights();
    L.extinctionPerWorld = 1.0f;
    ASSERT_TRUE(fog->setLighting(L));
    EXPECT_EQ(fog->relights(), relights + 1);
    EXPECT_LT(T(*fog, d, 1, 1, false), 1.0f);
}

// The largest finite extinction (FLT_MAX): every point with fog between it
// and the sun underflows to T = 0 exactly, never NaN (FLT_MAX times a depth
// overflows float, not the double it is taken in); points whose ray leaves
// at once (the level top, the edge toward the sun) keep T = 1, FLT_MAX x 0.
// The lit table at that rho stays finite.
TEST(GroundFogLightHardCases, HugeExtinctionUnderflowsToZeroNotNaN) {
    GroundFogDesc d = flat({5, 4}, 0.0f, 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    ASSERT_TRUE(fog->setLighting(sunAlong({0.6f, -0.8f, 0.0f}, FLT_MAX))); // the sun at -x
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i) {
            EXPECT_EQ(T(*fog, d, i, j, false), i == 0 ? 1.0f : 0.0f) << i << ", " << j;
            EXPECT_EQ(T(*fog, d, i, j, true), 1.0f) << i << ", " << j;
        }
    for (float v : fog->litTable().data()) EXPECT_TRUE(std::isfinite(v));
}

// The smallest layer: 2 x 2 points, one cell, two triangles, a sloped
// terrain and top; a sun from each quadrant so rays cross the split
// diagonal both ways and leave through every side.
TEST(GroundFogLightHardCases, TheSmallestLayerTwoByTwo) {
    GroundFogDesc d = flat({2, 2}, 0.0f, 0.0f);
    d.spacingWorld = 2.0f;
    d.terrainHeight = {0.0f, 0.3f, 0.5f, 0.1f};
    d.fogTop = {1.2f, 1.0f, 1.4f, 1.1f};
    double lowest = 1.0;
    for (glm::vec3 travel :
         {glm::vec3(0.5f, -0.6f, 0.4f), glm::vec3(-0.5f, -0.6f, 0.4f), glm::vec3(0.5f, -0.6f, -0.4f), glm::vec3(-0.5f, -0.6f, -0.4f)})
        lowest = std::min(lowest, litAgainstTheReference(d, travel, 2.0f));
    EXPECT_LT(lowest, 0.9);
}

// Fog at one vertex only (thickness 0 elsewhere): a tent one cell wide. Sun
// straight down: under the apex the column is the whole thickness H with the
// scalar falling from `density` to 0, T = exp(-k d H / 2); every other
// column is bare, T exactly 1. A slanted sun: against the reference, the
// rays of the points downwind of the tent crossing it.
TEST(GroundFogLightHardCases, FogAtASingleVertexIsATent) {
    GroundFogDesc d = flat({7, 7}, 0.0f, 0.0f);
    d.fogTop[at(d, 3, 3)] = 2.0f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    ASSERT_TRUE(fog->setLighting(sunAlong({0.0f, -1.0f, 0.0f}, 1.5f)));
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i) {
            const bool apex = i == 3 && j == 3;
            EXPECT_NEAR(T(*fog, d, i, j, false), apex ? std::exp(-1.5 * 2.0 / 2.0) : 1.0, kFloatT) << i << ", " << j;
            EXPECT_EQ(T(*fog, d, i, j, true), 1.0f);
        }
    EXPECT_LT(litAgainstTheReference(d, {0.5f, -0.4f, 0.3f}, 3.0f), 0.9);
}

// A LOD layer lights its padded (2^n + 1)^2 grid: 6 x 5 points padded to
// 9 x 9, so the field is read with a stride of 9, not 6. Heights and tops on
// a 1/64 lattice make every thickness exact in float, so the LOD's stored
// thickness is the full-resolution layer's and T must be bit for bit the
// same at every desc point; a wrong stride reads other rows.
TEST(GroundFogLightHardCases, ALodLayersPaddedGridIsReadWithItsOwnStride) {
    GroundFogDesc d = flat({6, 5}, 0.0f, 0.0f);
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i) {
            d.terrainHeight[at(d, i, j)] = float((i * 7 + j * 13) % 11) / 64.0f * 8.0f;
            d.fogTop[at(d, i, j)] = 1.5f + float((i * 5 + j * 3) % 7) / 64.0f * 4.0f;
        }
    const GroundFogLighting L = sunAlong({0.45f, -0.7f, 0.35f}, 1.2f);
    auto full = GroundFog::create(d);
    d.lod = true;
    auto lod = GroundFog::create(d);
    ASSERT_TRUE(full && lod);
    ASSERT_TRUE(full->setLighting(L));
    ASSERT_TRUE(lod->setLighting(L));
    const std::size_t n = 9;
    ASSERT_EQ(lod->sunTransmittance().size(), 2 * n * n);
    double lowest = 1.0;
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i)
            for (int top = 0; top < 2; ++top) {
                const float want = full->sunTransmittance()[2 * at(d, i, j) + std::size_t(top)];
                EXPECT_EQ(lod->sunTransmittance()[2 * (std::size_t(i) + n * std::size_t(j)) + std::size_t(top)], want)
                    << i << ", " << j << " " << top;
                lowest = std::min(lowest, double(want));
            }
    EXPECT_LT(lowest, 0.9);
}

// Phase lobes at g = +0.999 and -0.999 (peaks of 1.6e5 per steradian: s =
// T phase / max phase spans 11 decades) and albedo 0 and 1. Every vertex's
// scalar finite in [0, 1], its colour the model's source sourceAt(T, toEye)
// with T the reference's; albedo 0 draws black with the unlit extinction.
// Tolerance: the source's float rounding (s, kappa: 1e-5 of |source|), the
// phase's condition number x the float direction's error (3 |g| / (1 + g^2
// - 2 g cos) x 2e-7 <= 1e-5 relative with the eye kept 30 degrees or more
// off both peaks, as here), plus T's error times the sun term.
TEST(GroundFogLightHardCases, PhaseLobesAtPlusMinus0999AndAlbedoZeroAndOne) {
    GroundFogDesc d = flat({5, 5}, 0.0f, 1.2f);
    d.terrainHeight[at(d, 2, 2)] = 0.4f;
    const glm::vec3 travel{0.0f, -1.0f, 0.0f};
    const Camera cam = Camera::lookAt({2.0f, 3.0f, 12.0f}, {2.0f, 0.5f, 2.0f}, {0, 1, 0}, glm::radians(40.0f), {64, 48}, 0.1f, 50.0f);
    for (float g : {0.999f, -0.999f, 0.0f})
        for (float albedo : {0.0f, 1.0f}) {
            auto fog = GroundFog::create(d);
            ASSERT_TRUE(fog);
            GroundFogLighting L = sunAlong(travel, 1.3f);
            const HgLobe lobe{.g = g};
            L.gas.phase = *PhaseFunction::create(std::span<const HgLobe>(&lobe, 1));
            L.gas.albedo = albedo;
            L.gas.ambient = glm::vec3(0.1f);
            ASSERT_TRUE(fog->setLighting(L));
            LodFrame frame;
            ASSERT_TRUE(fog->update(cam, frame));
            ASSERT_FALSE(frame.tets.empty());
            const double b = 4.0 * std::numbers::pi * double(L.gas.phase(1.0f)) * double(albedo); // the sun term per unit s x phase max
            for (const Tetrahedron& t : frame.tets)
                for (int c = 0; c < 4; ++c) {
                    const float s = t.scalar[std::size_t(c)];
                    ASSERT_TRUE(std::isfinite(s) && s >= 0.0f && s <= 1.0f) << s;
                    const glm::vec3 p = t.position[std::size_t(c)];
                    const glm::vec3 toEye = glm::normalize(cam.eye() - p);
                    ASSERT_LT(std::abs(glm::dot(toEye, travel)), std::cos(glm::radians(30.0f)));
                    const auto [Tref, err] = referenceT(d, 1.3f, p, travel);
                    const glm::dvec3 want = fog->sourceAt(Tref, toEye);
                    const glm::dvec3 got = fog->litTransfer().color(s);
                    const double phaseRel = double(L.gas.phase(travel, toEye)) / double(L.gas.phase(1.0f));
                    for (int a = 0; a < 3; ++a) {
                        if (albedo == 0.0f) { EXPECT_EQ(got[a], 0.0); }
                        EXPECT_NEAR(got[a], want[a], 2e-5 * std::abs(want[a]) + b * phaseRel * (kFloatT + 2.0 * err)) << g << " " << albedo;
                    }
                    EXPECT_EQ(t.lengthScale[std::size_t(c)] > 0.0f, p.y < 1.2f - 1e-4f); // the unlit scalar: 0 only at the top
                }
        }
}

// A fog top exactly on a caster's box: the caster's voxel centres at y = 2
// and 3 (log2 depth tau each) make its field fall to zero at y = 1, the
// layer's top. Sun straight down. A top point under the caster starts on the
// field's boundary and must see its whole column, the two voxels and both
// half-cell ramps: 2 tau; a top point on the plane where the field's side
// ramp reaches zero (x = 2) runs along that face and sees nothing. The
// terrain under the caster: the layer's own exp(-k d H / 2) times the column.
TEST(GroundFogLightHardCases, AFogTopExactlyOnACastersBox) {
    GroundFogDesc d = flat({9, 9}, 0.0f, 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    const float tau = 0.75f;
    auto field = DensityField::fromGrid(casterGrid({3, 2, 3}, {3.0f, 2.0f, 3.0f}, tau));
    ASSERT_TRUE(field) << field.error();
    ASSERT_EQ(field->boundsMin().y, 1.0f);
    ASSERT_EQ(field->boundsMin().x, 2.0f);
    const DensityField* casters[] = {&*field};
    ASSERT_TRUE(fog->setLighting(sunAlong({0.0f, -1.0f, 0.0f}, 1.0f), casters));
    const double column = 2.0 * double(tau), self = std::exp(-1.0 * 1.0 / 2.0);
    const double tol = kFloatT + 1e-6 * column;
    for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 9; ++i) {
            const bool under = i >= 3 && i <= 5 && j >= 3 && j <= 5;
            const double c = under ? std::exp2(-column) : 1.0; // beside: outside the box or on its zero faces (x or z = 2, 6)
            EXPECT_NEAR(T(*fog, d, i, j, true), c, tol) << i << ", " << j;
            EXPECT_NEAR(T(*fog, d, i, j, false), self * c, tol) << i << ", " << j;
        }
}

// A caster holding a NaN and an infinite opacity inside its box: those
// voxels are skipped (DensityField::fromGrid), so the field and the fog's T
// are bit for bit those of the caster without them (opacity 0 there), never
// NaN; the fingerprints agree, so handing the fog the other one does not
// relight.
TEST(GroundFogLightHardCases, ANaNVoxelInACasterIsSkippedNotSpread) {
    GroundFogDesc d = flat({7, 7}, 0.0f, 1.0f);
    Grid bad = casterGrid({3, 3, 3}, {2.0f, 3.0f, 2.0f}, 1.0f), clean = bad;
    for (Voxel& v : bad.voxels)
        if (v.cell == glm::ivec3(1, 1, 1)) v.opacity = std::numeric_limits<float>::quiet_NaN();
        else if (v.cell == glm::ivec3(1, 0, 1)) v.opacity = std::numeric_limits<float>::infinity();
    for (Voxel& v : clean.voxels)
        if (v.cell == glm::ivec3(1, 1, 1) || v.cell == glm::ivec3(1, 0, 1)) v.opacity = 0.0f;
    auto fb = DensityField::fromGrid(bad), fc = DensityField::fromGrid(clean);
    ASSERT_TRUE(fb && fc);
    EXPECT_EQ(fb->fingerprint(), fc->fingerprint());
    const GroundFogLighting L = sunAlong({0.2f, -1.0f, 0.1f}, 1.0f);
    auto fog = GroundFog::create(d), ref = GroundFog::create(d);
    ASSERT_TRUE(fog && ref);
    const DensityField* withNaN[] = {&*fb};
    const DensityField* without[] = {&*fc};
    ASSERT_TRUE(fog->setLighting(L, withNaN));
    ASSERT_TRUE(ref->setLighting(L, without));
    ASSERT_EQ(fog->sunTransmittance().size(), ref->sunTransmittance().size());
    for (std::size_t k = 0; k < fog->sunTransmittance().size(); ++k) {
        EXPECT_TRUE(std::isfinite(fog->sunTransmittance()[k])) << k;
        EXPECT_EQ(fog->sunTransmittance()[k], ref->sunTransmittance()[k]) << k;
    }
    EXPECT_LT(T(*fog, d, 3, 3, false), 0.5f * T(*fog, d, 0, 6, false)); // the rest of the caster does shadow
    const auto relights = fog->relights();
    ASSERT_TRUE(fog->setLighting(L, without));
    EXPECT_EQ(fog->relights(), relights);
}

// A sun along (1, -1, 1): in plan every terrain point's ray runs through
// grid vertices and along the split diagonals of the even cells (the
// triangulation's edges), then the sun nudged one float ulp either way on
// x, so the rays pass just beside the vertices, inside one triangle or the
// other. Each must relight (a new direction, however close) and each T be
// its own reference's: a stretch dropped or doubled at a vertex is a jump
// the continuous reference does not make.
TEST(GroundFogLightHardCases, ASunOneUlpOffRaysThroughGridVertices) {
    GroundFogDesc d = flat({7, 7}, 0.0f, 0.0f);
    d.originWorld = {-1.0f, 0.0f, 2.0f};
    for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i) {
            d.terrainHeight[at(d, i, j)] = 0.25f * std::sin(1.3f * float(i) + 0.7f * float(j));
            d.fogTop[at(d, i, j)] = 1.6f + 0.2f * std::cos(0.9f * float(j));
        }
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    std::uint64_t relights = 0;
    for (float x : {1.0f, std::nextafter(1.0f, 2.0f), std::nextafter(1.0f, 0.0f)}) {
        const glm::vec3 travel{x, -1.0f, 1.0f};
        ASSERT_TRUE(fog->setLighting(sunAlong(travel, 1.1f)));
        EXPECT_EQ(fog->relights(), ++relights) << x;
        EXPECT_LT(expectTIsTheReference(*fog, d, travel, 1.1f), 0.9);
    }
}

// Sixteen casters, each one voxel of log2 depth tau_k, stacked above the
// layer with gaps (sun straight down): the terrain under them sees the
// layer's own T times 2^-(sum of tau_k) (each lone voxel's column, its ramps
// included, integrates to tau_k); beside them, the layer's own. Handed over
// in the reverse order the same to float rounding of the sum.
TEST(GroundFogLightHardCases, SixteenCastersMultiplyTheirTransmittances) {
    GroundFogDesc d = flat({5, 5}, 0.0f, 1.0f);
    std::vector<DensityField> fields;
    double sum = 0.0;
    for (int k = 0; k < 16; ++k) {
        const float tau = 0.05f + 0.01f * float(k);
        auto f = DensityField::fromGrid(casterGrid({1, 1, 1}, {2.0f, 3.0f + 3.0f * float(k), 2.0f}, tau));
        ASSERT_TRUE(f);
        fields.push_back(std::move(*f));
        sum += -std::log1p(-double(1.0f - std::exp2(-tau))) / std::numbers::ln2; // the float opacity's own depth
    }
    std::vector<const DensityField*> forward, backward;
    for (const DensityField& f : fields) forward.push_back(&f);
    backward.assign(forward.rbegin(), forward.rend());
    auto fog = GroundFog::create(d), rev = GroundFog::create(d);
    ASSERT_TRUE(fog && rev);
    const GroundFogLighting L = sunAlong({0.0f, -1.0f, 0.0f}, 1.0f);
    ASSERT_TRUE(fog->setLighting(L, forward));
    ASSERT_TRUE(rev->setLighting(L, backward));
    const double self = std::exp(-0.5), tol = kFloatT + 1e-6 * sum;
    EXPECT_NEAR(T(*fog, d, 2, 2, false), self * std::exp2(-sum), tol);
    EXPECT_NEAR(T(*fog, d, 2, 2, true), std::exp2(-sum), tol);
    EXPECT_NEAR(T(*rev, d, 2, 2, false), T(*fog, d, 2, 2, false), tol);
    EXPECT_NEAR(T(*fog, d, 0, 4, false), self, kFloatT);
    EXPECT_NEAR(T(*fog, d, 1, 2, true), 1.0, kFloatT); // the voxel's ramp reaches zero at x = 1: the plane along it
}

// A caster that moves one cell every frame (smoke drifting): each frame has
// a new fingerprint, so the fog relights, and its shadow is where the caster
// is now, not where it was (a stale field would leave it behind).
TEST(GroundFogLightHardCases, ACasterMovingEveryFrameShadowsWhereItIsNow) {
    GroundFogDesc d = flat({9, 5}, 0.0f, 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    const GroundFogLighting L = sunAlong({0.0f, -1.0f, 0.0f}, 1.0f);
    const float tau = 1.0f;
    const double self = std::exp(-0.5), under = self * std::exp2(-double(tau)), tol = kFloatT + 1e-6 * double(tau);
    for (int frame = 0; frame < 6; ++frame) {
        auto f = DensityField::fromGrid(casterGrid({1, 1, 1}, {1.0f + float(frame), 3.0f, 2.0f}, tau));
        ASSERT_TRUE(f);
        const DensityField* casters[] = {&*f};
        ASSERT_TRUE(fog->setLighting(L, casters));
        EXPECT_EQ(fog->relights(), std::uint64_t(frame + 1));
        for (int i = 0; i < 9; ++i) EXPECT_NEAR(T(*fog, d, i, 2, false), i == 1 + frame ? under : self, tol) << "frame " << frame << " x " << i;
    }
}

// An empty caster (a default DensityField, or a grid of zero-opacity voxels,
// as a lit effect with no gas yet hands over) changes nothing: T bit for bit
// the layer's own, and no NaN from an empty box.
TEST(GroundFogLightHardCases, AnEmptyCasterChangesNothing) {
    GroundFogDesc d = flat({6, 6}, 0.0f, 1.2f);
    d.terrainHeight[at(d, 3, 2)] = 0.5f;
    const GroundFogLighting L = sunAlong({0.4f, -0.7f, -0.3f}, 1.4f);
    Grid zero = casterGrid({2, 2, 2}, {2.0f, 2.0f, 2.0f}, 1.0f);
    for (Voxel& v : zero.voxels) v.opacity = 0.0f;
    auto zeroField = DensityField::fromGrid(zero);
    ASSERT_TRUE(zeroField);
    EXPECT_TRUE(zeroField->empty());
    const DensityField none;
    auto plain = GroundFog::create(d), fog = GroundFog::create(d);
    ASSERT_TRUE(plain && fog);
    ASSERT_TRUE(plain->setLighting(L));
    const DensityField* casters[] = {&none, &*zeroField};
    ASSERT_TRUE(fog->setLighting(L, casters));
    EXPECT_EQ(fog->sunTransmittance(), plain->sunTransmittance());
    EXPECT_LT(*std::min_element(plain->sunTransmittance().begin(), plain->sunTransmittance().end()), 0.9f);
}
