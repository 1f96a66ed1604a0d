// More hard cases of a Cloud relit as its sun moves (cloud.hpp;
// docs/STABILITY.md, "Cloud lighting"): suns along negative axes and below
// the horizon, the smallest clouds, extinction 0, 1e-30 and FLT_MAX, a sun
// moved by one ulp off an axis and off the diagonal where the sweep changes
// its axis, albedo 0 and 1 with Henyey-Greenstein lobes at g = +-0.999 and 0,
// and the Roettger model's light at its limits. And, in a Scene, clouds
// shadowing a lit plume: a cloud whose density changes every frame (going
// empty in between) and four clouds stacked over it.
//
// As cloud_light_test.cpp: a uniform cloud (density f everywhere) with the
// sun along an axis or a diagonal makes the sweep exact, T = exp(-sigma L),
// L the ray's length inside the grid, sigma = maxExtinctionPerWorld f; float
// transmittance through at most 16 steps: 1e-5 covers the rounding.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numbers>
#include <memory>
#include <optional>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/cloud.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

std::size_t index(glm::ivec3 n, int x, int y, int z) {
    return std::size_t(x) + std::size_t(n.x) * (std::size_t(y) + std::size_t(n.y) * std::size_t(z));
}

CloudCreateDesc lowAlbedo(glm::ivec3 dims, float maxExtinction) {
    CloudCreateDesc d;
    d.cloud = {.dims = dims, .seed = 3, .featureCells = 6.0f, .coverage = 0.6f};
    d.table = {.scalarResolution = 8, .lengthResolution = 8};
    d.lighting.model = CloudLightModel::LowAlbedo;
    d.volume.spacingWorld = 0.5f;
    d.transfer.maxExtinctionPerWorld = maxExtinction;
    return d;
}

// A cloud of uniform density f.
std::optional<Cloud> uniform(const CloudCreateDesc& d, float f) {
    auto c = Cloud::create(d);
    EXPECT_TRUE(c) << c.error();
    if (!c) return std::nullopt;
    EXPECT_TRUE(c->setDensity(std::vector<float>(c->density().size(), f)));
    return std::move(*c);
}

Status setSun(Cloud& c, glm::vec3 travel) {
    CloudLighting L = c.lighting();
    L.sun.direction = travel;
    return c.setLight(L);
}

float T(const Cloud& c, int x, int y, int z) { return c.sunTransmittance()[index(c.dims(), x, y, z)]; }

constexpr float kF = 0.4f, kH = 0.5f;
constexpr double kSigma = 1.5 * double(kF); // maxExtinctionPerWorld 1.5

} // namespace

// The sun exactly along -x and along +-y (the sweep toward a sun on the
// positive side of its axis runs from the last plane down; a sign slip
// attenuates from the wrong face): T = exp(-sigma h (cells to the sun's face)).
TEST(CloudRelightHardCases, SunAlongANegativeAxisSweepsFromTheFarFace) {
    auto c = uniform(lowAlbedo({9, 7, 5}, 1.5f), kF);
    ASSERT_TRUE(c);
    const glm::ivec3 n = c->dims();
    ASSERT_TRUE(setSun(*c, {-1.0f, 0.0f, 0.0f})); // the sun at +x
    for (int z = 0; z < n.z; z += 2)
        for (int x = 0; x < n.x; ++x) EXPECT_NEAR(T(*c, x, 3, z), std::exp(-kSigma * kH * double(n.x - 1 - x)), 1e-5) << x << " " << z;
    ASSERT_TRUE(setSun(*c, {0.0f, -1.0f, 0.0f})); // the sun at +y
    for (int y = 0; y < n.y; ++y) EXPECT_NEAR(T(*c, 4, y, 2), std::exp(-kSigma * kH * double(n.y - 1 - y)), 1e-5) << y;
    ASSERT_TRUE(setSun(*c, {0.0f, 1.0f, 0.0f})); // the sun at -y
    for (int y = 0; y < n.y; ++y) EXPECT_NEAR(T(*c, 4, y, 2), std::exp(-kSigma * kH * double(y)), 1e-5) << y;
}

// The sun below the horizon, travelling straight up: a directional light is
// accepted in any direction (a cloud has no ground to hide it), and lights
// the cloud from beneath: T = 1 on the bottom face, exp(-sigma h z) above.
TEST(CloudRelightHardCases, SunBelowTheHorizonLightsTheCloudFromBeneath) {
    auto c = uniform(lowAlbedo({9, 9, 6}, 1.5f), kF);
    ASSERT_TRUE(c);
    ASSERT_TRUE(setSun(*c, {0.0f, 0.0f, 1.0f}));
    for (int z = 0; z < c->dims().z; ++z)
        for (int x = 0; x < 9; x += 4) EXPECT_NEAR(T(*c, x, 4, z), std::exp(-kSigma * kH * double(z)), 1e-5) << x << " " << z;
    for (int x = 0; x < 9; ++x) EXPECT_EQ(T(*c, x, 2, 0), 1.0f);
}

// The smallest clouds: one cell (2 x 2 x 2 points) and one cell thick (9 x 9
// x 2). One sweep step: under a vertical sun the bottom plane is exp(-sigma
// h), the top 1; under a slanted one (toward the sun (-0.3, 0, 1)) the
// points whose step stays inside see exp(-sigma h sqrt(1.09)), those on the
// face toward the sun (x = 0) 1. They relight, build a field and draw finite
// tetrahedra; a single grid point is not a cloud (refused by name).
TEST(CloudRelightHardCases, TheSmallestCloudsOneCellAndOneCellThick) {
    for (glm::ivec3 dims : {glm::ivec3(2, 2, 2), glm::ivec3(9, 9, 2)}) {
        auto c = uniform(lowAlbedo(dims, 1.5f), kF);
        ASSERT_TRUE(c);
        ASSERT_TRUE(setSun(*c, {0.0f, 0.0f, -1.0f}));
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x) {
                EXPECT_NEAR(T(*c, x, y, 0), std::exp(-kSigma * kH), 1e-6) << x << " " << y;
                EXPECT_EQ(T(*c, x, y, 1), 1.0f);
            }
        ASSERT_TRUE(setSun(*c, {0.3f, 0.0f, -1.0f}));
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x) EXPECT_NEAR(T(*c, x, y, 0), x == 0 ? 1.0 : std::exp(-kSigma * kH * std::sqrt(1.09)), 1e-6) << x;
        EXPECT_FALSE(c->densityField().empty());
        LodFrame frame;
        const Camera cam = Camera::lookAt({2.0f, -6.0f, 3.0f}, {1.0f, 1.0f, 0.25f}, {0.0f, 0.0f, 1.0f}, 0.8f, {64, 48});
        ASSERT_TRUE(c->update(cam, {.zeroOpacityTest = false}, frame));
        ASSERT_FALSE(frame.tets.empty());
        for (const Tetrahedron& t : frame.tets)
            for (int k = 0; k < 4; ++k) EXPECT_TRUE(std::isfinite(t.scalar[std::size_t(k)]) && std::isfinite(t.lengthScale[std::size_t(k)]));
    }
    CloudCreateDesc d = lowAlbedo({9, 9, 1}, 1.5f);
    auto flat = Cloud::create(d);
    ASSERT_FALSE(flat);
    EXPECT_EQ(flat.error(), "CloudDesc.dims must be in [2, 4097] along every axis");
}

// Extinction 0, 1e-30 and FLT_MAX per world unit (all finite, all
// accepted). 0: clear air, no field to cast. 1e-30: T rounds to exactly 1 in
// float, yet the cloud still casts its tiny depth (a field of opacity 2e-31
// per voxel, not flushed, not NaN): down a column of nz voxels it is nz tau,
// tau = sigma h / ln 2, to float rounding (1e-6 relative). FLT_MAX: T
// underflows to exactly 0 one plane in (1 on the face toward the sun), the
// field is opaque (24 log2 units per voxel, the cap), and the lit table at
// that rho is finite.
TEST(CloudRelightHardCases, ExtinctionZeroTinyAndTheLargestFloat) {
    {
        auto c = uniform(lowAlbedo({9, 9, 5}, 0.0f), kF);
        ASSERT_TRUE(c);
        for (float v : c->sunTransmittance()) EXPECT_EQ(v, 1.0f);
        EXPECT_TRUE(c->densityField().empty());
    }
    {
        auto c = uniform(lowAlbedo({9, 9, 5}, 1e-30f), kF);
        ASSERT_TRUE(c);
        for (float v : c->sunTransmittance()) EXPECT_EQ(v, 1.0f);
        ASSERT_FALSE(c->densityField().empty());
        const double tau = 1e-30 * double(kF) * double(kH) / std::numbers::ln2;
        const glm::vec3 top = c->volume().originWorld() + glm::vec3(2.0f, 2.0f, 10.0f);
        const double depth = c->densityField().opticalDepth(top, top - glm::vec3(0.0f, 0.0f, 20.0f));
        EXPECT_NEAR(depth, 5.0 * tau, 1e-6 * 5.0 * tau);
    }
    {
        auto c = uniform(lowAlbedo({9, 9, 5}, FLT_MAX), kF);
        ASSERT_TRUE(c);
        ASSERT_TRUE(setSun(*c, {0.0f, 0.0f, -1.0f}));
        for (int z = 0; z < 5; ++z)
            for (int x = 0; x < 9; ++x) EXPECT_EQ(T(*c, x, 4, z), z == 4 ? 1.0f : 0.0f) << x << " " << z;
        const glm::vec3 top = c->volume().originWorld() + glm::vec3(2.0f, 2.0f, 10.0f);
        EXPECT_NEAR(c->densityField().opticalDepth(top, top - glm::vec3(0.0f, 0.0f, 20.0f)), 5.0 * 24.0, 1e-6 * 5.0 * 24.0);
        for (float v : c->table().data()) EXPECT_TRUE(std::isfinite(v));
    }
}

// The sun one float ulp off straight down (the smallest tilt there is: x =
// the smallest subnormal). A new direction however close relights (never a
// stale light); the step's sideways part (1.4e-45 cells) cannot move a
// lookup in double, so every point but those on the face toward the sun is
// bit for bit the vertical sun's, and those, whose ray now leaves the box at
// once, see the sun unattenuated: the box's exact value (the face flips from
// its column's T to 1 as the sun crosses the vertical: a boundary layer
// thinner than the cell the vertices sample; documented, not smoothed).
TEST(CloudRelightHardCases, SunOneUlpOffVerticalRelightsAndMovesOnlyTheFaceItLeavesBy) {
    auto c = uniform(lowAlbedo({9, 9, 5}, 1.5f), kF);
    ASSERT_TRUE(c);
    ASSERT_TRUE(setSun(*c, {0.0f, 0.0f, -1.0f}));
    const std::vector<float> vertical = c->sunTransmittance();
    const auto relights = c->relights();
    const float ulp = std::nextafter(0.0f, 1.0f);
    ASSERT_TRUE(setSun(*c, {ulp, 0.0f, -1.0f})); // travelling +x: the sun leans to -x
    EXPECT_EQ(c->relights(), relights + 1);
    const glm::ivec3 n = c->dims();
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const float want = x == 0 ? 1.0f : vertical[index(n, x, y, z)];
                EXPECT_EQ(T(*c, x, y, z), want) << x << " " << y << " " << z;
            }
    EXPECT_LT(vertical[index(n, 0, 4, 0)], 0.5f); // the flip is real: the face's column was shadowed
}

// The sun one ulp either side of the 45-degree diagonal: the sweep's main
// axis switches from x (|x| >= |z|, the tie) to z. Every step still lands
// within an ulp of grid points, so both orders give the diagonal's closed
// form exp(-sigma h sqrt 2 min(x, nz - 1 - z)): a jump at the switch (a
// plane's face interpolation, a different first plane) would show. The
// ulp's own effect, at most 16 steps of 6e-8, is inside the 1e-5.
TEST(CloudRelightHardCases, SunAcrossTheDiagonalSwitchesTheSweepAxisWithoutAJump) {
    auto c = uniform(lowAlbedo({9, 5, 7}, 1.5f), kF);
    ASSERT_TRUE(c);
    const glm::ivec3 n = c->dims();
    for (float zUp : {std::nextafter(1.0f, 0.0f), 1.0f, std::nextafter(1.0f, 2.0f)}) {
        ASSERT_TRUE(setSun(*c, {1.0f, 0.0f, -zUp}));
        for (int z = 0; z < n.z; ++z)
            for (int x = 0; x < n.x; ++x)
                EXPECT_NEAR(T(*c, x, 2, z), std::exp(-kSigma * kH * std::sqrt(2.0) * double(std::min(x, n.z - 1 - z))), 1e-5)
                    << zUp << ": " << x << " " << z;
    }
}

// Albedo 0: the cloud absorbs but scatters nothing, so its colour table is
// black at every s while its extinction, its sun transmittance and its cast
// field are the albedo-0.9 cloud's, untouched: going from 0.9 to 0 rebuilds
// the table only. Albedo 1 back: the table again, still no relight.
TEST(CloudRelightHardCases, AlbedoZeroIsBlackWithTheSameExtinctionAndNoRelight) {
    auto c = uniform(lowAlbedo({9, 9, 5}, 1.5f), kF);
    ASSERT_TRUE(c);
    ASSERT_TRUE(setSun(*c, {0.3f, -0.2f, -1.0f}));
    const std::vector<float> trans = c->sunTransmittance();
    const std::uint64_t print = c->densityField().fingerprint();
    const auto relights = c->relights(), tables = c->tableBuilds();
    CloudLighting L = c->lighting();
    L.gas.albedo = 0.0f;
    L.gas.ambient = glm::vec3(0.3f);
    L.gas.multipleScattering = 0.5f;
    ASSERT_TRUE(c->setLight(L));
    EXPECT_EQ(c->relights(), relights);
    EXPECT_EQ(c->tableBuilds(), tables + 1);
    for (double s : {0.0, 0.37, 1.0}) {
        EXPECT_EQ(c->transfer().color(s), glm::dvec3(0.0)) << s;
        EXPECT_EQ(c->transfer().extinction(s), 1.5) << s;
    }
    EXPECT_EQ(c->sourceAt(0.5, {0.0f, 0.0f, 1.0f}), glm::dvec3(0.0));
    EXPECT_EQ(c->sunTransmittance(), trans);
    EXPECT_EQ(c->densityField().fingerprint(), print);
    L.gas.albedo = 1.0f;
    ASSERT_TRUE(c->setLight(L));
    EXPECT_EQ(c->relights(), relights);
    EXPECT_EQ(c->tableBuilds(), tables + 2);
    // s = 0: ambient plus multiple scattering, albedo 1 (float table, 1e-7).
    const glm::dvec3 a = c->sourceAt(0.0, {0.0f, 0.0f, 1.0f});
    EXPECT_NEAR(a.x, 0.3 + 0.5, 1e-6);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c->transfer().color(0.0)[k], a[k], 1e-6);
}

// Henyey-Greenstein lobes at g = +0.999 and -0.999 (peaks of 1.6e5 per
// steradian: s = T phase / max phase spans eleven decades) and g = 0 (the
// isotropic path: s is T itself, bit for bit). Fully refined, so each
// vertex is a grid point and its T the stored (8-bit) light field there.
// Every s finite in [0, 1]; its colour the model's source sourceAt(T, toEye).
// Tolerance: float rounding of s and kappa (1e-5 of |source|) plus the
// phase's condition number times the float direction's error (3 |g| / (1 +
// g^2 - 2 g cos) x 2e-7 < 1e-5 relative, the eye kept 30 degrees or more off
// both peaks, as asserted).
TEST(CloudRelightHardCases, PhaseLobesAtPlusMinus0999AndIsotropic) {
    for (float g : {0.999f, -0.999f, 0.0f}) {
        CloudCreateDesc d = lowAlbedo({9, 9, 5}, 1.5f);
        d.volume.spacingWorld = 1.0f;
        d.lighting.sun = Light::directional({0.0f, 0.0f, -1.0f});
        const HgLobe lobe{.g = g};
        d.lighting.gas.phase = *PhaseFunction::create(std::span<const HgLobe>(&lobe, 1));
        d.lighting.gas.albedo = 1.0f;
        d.lighting.gas.ambient = glm::vec3(0.05f);
        auto c = Cloud::create(d);
        ASSERT_TRUE(c) << c.error();
        const Camera cam = Camera::lookAt({4.0f, -14.0f, 3.0f}, {4.0f, 4.0f, 2.0f}, {0.0f, 0.0f, 1.0f}, 0.8f, {64, 48});
        LodFrame frame;
        ASSERT_TRUE(c->update(cam, {.detailC = 1e6f, .zeroOpacityTest = false, .clipNear = false}, frame));
        ASSERT_FALSE(frame.tets.empty());
        const glm::vec3 travel = glm::normalize(c->lighting().sun.direction);
        for (const Tetrahedron& t : frame.tets)
            for (int k = 0; k < 4; ++k) {
                const float s = t.scalar[std::size_t(k)];
                ASSERT_TRUE(std::isfinite(s) && s >= 0.0f && s <= 1.0f) << s;
                const glm::vec3 p = t.position[std::size_t(k)];
                const glm::ivec3 gp = glm::ivec3(glm::round(p));
                ASSERT_LT(glm::length(p - glm::vec3(gp)), 1e-4f) << "fully refined vertices are grid points";
                const double Tv = c->volume().scalarAt(gp);
                const glm::vec3 toEye = glm::normalize(cam.eye() - p);
                ASSERT_LT(std::abs(glm::dot(toEye, travel)), std::cos(glm::radians(30.0f)));
                if (g == 0.0f) { EXPECT_EQ(s, float(Tv)); }
                const glm::dvec3 want = c->sourceAt(Tv, toEye), got = c->transfer().color(s);
                for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], 2e-5 * want[a]) << g;
            }
    }
}

// The Roettger model under a vertical sun: gamma = min(1, ambient + diffuse
// T) with T = exp(-c f k) through the raw density (c = lightExtinctionPerCell,
// k cells below the top: no threshold in this model), stored as 8 bits (half
// a level). At ambient + diffuse = 1 the top is exactly 1 (the min's edge);
// ambient = diffuse = 0 is a cloud whose every segment has length 0: drawn
// as nothing, never NaN.
TEST(CloudRelightHardCases, RoettgerLightAtItsLimits) {
    CloudCreateDesc d = lowAlbedo({9, 9, 6}, 1.5f);
    d.lighting.model = CloudLightModel::Roettger;
    d.lighting.sun = Light::directional({0.0f, 0.0f, -1.0f});
    const float f = 0.05f; // under the LowAlbedo threshold: Roettger still attenuates by it
    auto c = uniform(d, f);
    ASSERT_TRUE(c);
    const double ext = double(d.cloud.lightExtinctionPerCell);
    for (auto [amb, dif] : {std::pair{0.35f, 0.65f}, std::pair{0.2f, 0.5f}, std::pair{0.0f, 0.0f}}) {
        CloudLighting L = c->lighting();
        L.ambient = amb, L.diffuse = dif;
        ASSERT_TRUE(c->setLight(L));
        for (int z = 0; z < 6; ++z) {
            const double want = std::min(1.0, double(amb) + double(dif) * std::exp(-ext * double(f) * double(5 - z)));
            EXPECT_NEAR(c->volume().lengthScaleAt({4, 4, z}), want, 0.5 / 255.0 + 1e-6) << amb << " " << z;
        }
        if (amb + dif == 1.0f) { EXPECT_EQ(c->volume().lengthScaleAt({4, 4, 5}), 1.0f); }
        LodFrame frame;
        const Camera cam = Camera::lookAt({4.0f, -14.0f, 3.0f}, {4.0f, 4.0f, 2.0f}, {0.0f, 0.0f, 1.0f}, 0.8f, {64, 48});
        ASSERT_TRUE(c->update(cam, {.zeroOpacityTest = false}, frame));
        for (const Tetrahedron& t : frame.tets)
            for (int k = 0; k < 4; ++k) {
                EXPECT_TRUE(std::isfinite(t.lengthScale[std::size_t(k)]));
                if (amb + dif == 0.0f) { EXPECT_EQ(t.lengthScale[std::size_t(k)], 0.0f); }
            }
    }
}

namespace {

// Clouds shadowing a lit plume in a Scene, against the lit-volume reference
// with each cloud as a continuous medium (as tests/lighting/volume_shadows_test.cpp):
// its extinction maxExtinction f (f >= threshold) at each grid point,
// trilinear, zero one cell beyond; VolumeField::opticalDepthToLight in
// double. Tolerance: the lit colour's 8 bits (half a level) plus the
// scene's float trace (a few float epsilons per lattice cell, relative to
// depths of at most ~10 nats over <= 40 cells: < 1e-5 in the colour).
constexpr float kShadowTolerance = 0.5f / 255.0f + 1e-5f;
constexpr float kCloudExtinction = 2.0f, kCloudThreshold = 0.08f;

glm::vec3 unpack(std::uint32_t c) { return glm::vec3(float(c & 255u), float((c >> 8) & 255u), float((c >> 16) & 255u)) / 255.0f; }

// A 9x5x9-point cloud, spacing 1, grid point (0, 0, 0) at `origin`.
Cloud sceneCloud(glm::vec3 origin, std::vector<float> density) {
    CloudCreateDesc cd;
    cd.cloud = {.dims = {9, 5, 9}, .seed = 2, .featureCells = 6.0f, .coverage = 0.6f};
    cd.volume.originWorld = origin;
    cd.transfer.maxExtinctionPerWorld = kCloudExtinction;
    cd.transfer.threshold = kCloudThreshold;
    cd.table = {.scalarResolution = 8, .lengthResolution = 8};
    auto made = Cloud::create(cd);
    EXPECT_TRUE(made) << made.error();
    if (!density.empty()) { EXPECT_TRUE(made->setDensity(std::move(density))); }
    return std::move(*made);
}

// Density varying on all three axes, with a hole under the threshold.
std::vector<float> slopedDensity(float shift) {
    std::vector<float> f(9 * 5 * 9);
    for (int z = 0, i = 0; z < 9; ++z)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 9; ++x, ++i)
                f[std::size_t(i)] = (x == 0 && z == 0) ? 0.05f : std::min(1.0f, shift + 0.05f * float(x) + 0.06f * float(y) + 0.03f * float(z));
    return f;
}

// Cloud only in its two lowest grid layers (about two units thick with the
// field's ramps), so four stacked still let a fifth of the light through.
std::vector<float> thinDensity(float shift) {
    std::vector<float> f(9 * 5 * 9, 0.0f);
    for (int z = 0, i = 0; z < 9; ++z)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 9; ++x, ++i)
                if (y <= 1) f[std::size_t(i)] = (x == 0 && z == 0) ? 0.05f : shift + 0.09f + 0.01f * float(x) + 0.005f * float(z);
    return f;
}

ContinuousMedium cloudMedium(const Cloud& c) {
    auto v = std::make_shared<DenseVoxels>();
    v->dims = c.dims();
    v->origin = glm::dvec3(c.volume().originWorld());
    v->voxelSize = double(c.volume().spacingWorld());
    v->values = c.density();
    for (float& x : v->values) x = x >= kCloudThreshold ? x : 0.0f;
    return denseMedium(v, DenseFilter::Trilinear, double(kCloudExtinction));
}

struct PlumeUnderClouds {
    Materials materials{Footprint{}};
    Scene scene;
    EffectId plume = 0;
    std::vector<EffectId> clouds;
    Frame frame;
    glm::vec4 base{0.8f, 0.6f, 0.4f, 1.0f};
    Camera camera = Camera::lookAt({0.0f, 10.0f, 40.0f}, {0.0f, 12.0f, 0.0f}, {0, 1, 0}, glm::radians(60.0f), {320, 240}, 0.1f, 500.0f);

    // A 4x4x4 plume (opacity 0.5) with its lowest voxel at plumeAt, lit
    // isotropically with albedo 1 and no self-shadowing: base x T.
    explicit PlumeUnderClouds(glm::vec3 plumeAt) {
        const std::uint32_t table = materials.addColorTable(ColorTable::constant(base));
        Grid g = *Grid::box({4, 4, 4});
        for (Voxel& v : g.voxels) v.opacity = 0.5f;
        g.transform = glm::translate(glm::mat4(1.0f), plumeAt - g.localPosition({0, 0, 0}));
        EffectDesc desc;
        desc.name = "plume";
        desc.layers = {EffectLayer{.style = {.colorTable = table, .textured = false}}};
        plume = scene.add(*Effect::fromGrid(g, desc),
                          {.name = "plume", .lighting = {.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off}});
    }
    void addCloud(glm::vec3 at, std::vector<float> density) {
        clouds.push_back(
            scene.add(sceneCloud(at, std::move(density)), {.name = "cloud" + std::to_string(clouds.size()), .lighting = {.enabled = true}}));
    }

    // Prepares frame t and checks every plume splat against base x T(centre)
    // through all the clouds as they are now; returns the smallest T.
    double check(double t, const Light& light) {
        EXPECT_TRUE(scene.prepare(t, camera, materials, frame));
        EXPECT_TRUE(scene.status(plume).lit);
        VolumeField field(materials);
        for (EffectId id : clouds) field.addMedium(cloudMedium(*scene.findCloud(id)));
        const LitVolumeDesc lit{.lights = {light}, .gas = {.albedo = 1.0f}};
        double minT = 1.0;
        std::size_t n = 0;
        for (const Splat& sp : frame.splats()) {
            const glm::dvec3 f = litFactor(field, glm::dvec3(sp.center), glm::dvec3(camera.eye()), lit);
            minT = std::min(minT, f.x);
            const glm::vec3 got = unpack(sp.color);
            for (int a = 0; a < 3; ++a)
                EXPECT_NEAR(got[a], double(base[a]) * f[a], kShadowTolerance)
                    << "t " << t << " splat " << sp.center.x << "," << sp.center.y << "," << sp.center.z;
            ++n;
        }
        EXPECT_EQ(n, 64u);
        return minT;
    }
};

} // namespace

// A cloud whose density the host replaces every frame (a simulated cloud),
// one frame with no cloud left at all: the plume under it must be shadowed
// by the density of this frame, never the last one's (the scene copies the
// cloud's field only when its fingerprint changed: a stale copy, or an empty
// field not replacing a full one, would darken the empty frame).
TEST(CloudShadowHardCases, ACloudChangingEveryFrameShadowsByItsCurrentDensity) {
    PlumeUnderClouds s({-1.5f, 4.0f, -1.5f});
    s.addCloud({-4.0f, 20.0f, -4.0f}, slopedDensity(0.12f));
    const Light sun = Light::directional({0.25f, -1.0f, 0.15f});
    ASSERT_TRUE(s.scene.addLight(sun));
    const std::vector<float> frames[] = {slopedDensity(0.12f), std::vector<float>(9 * 5 * 9, 0.0f), slopedDensity(0.4f), slopedDensity(0.12f)};
    for (int k = 0; k < 4; ++k) {
        ASSERT_TRUE(s.scene.findCloud(s.clouds[0])->setDensity(frames[k]));
        const double minT = s.check(0.1 * k, sun);
        if (k == 1) {
            EXPECT_EQ(minT, 1.0);
            EXPECT_EQ(s.scene.counters().crossShadowPairs, 0u) << "an empty cloud is no caster";
        } else {
            EXPECT_LT(minT, 0.5) << k;
        }
    }
}

// Four clouds stacked over the plume, the sun slanted so each ray crosses
// all four fields: the plume's light is the product of the four
// transmittances (their depths add: one cloud traced twice or left out
// would show), against the reference holding all four.
TEST(CloudShadowHardCases, FourStackedCloudsMultiplyTheirTransmittances) {
    PlumeUnderClouds s({-1.5f, 4.0f, -1.5f});
    for (int k = 0; k < 4; ++k) s.addCloud({-4.0f, 12.0f + 7.0f * float(k), -4.0f}, thinDensity(0.01f * float(k)));
    const Light sun = Light::directional({0.08f, -1.0f, 0.05f});
    ASSERT_TRUE(s.scene.addLight(sun));
    const double minT = s.check(0.0, sun);
    EXPECT_LT(minT, 0.5);
    EXPECT_GT(minT, 0.05); // light enough left for the comparison to mean something
    EXPECT_EQ(s.scene.counters().crossShadowPairs, 4u);
}
