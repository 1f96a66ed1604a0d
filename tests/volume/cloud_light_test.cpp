// A Cloud relit as its sun moves (cloud.hpp): the relight equals the baked
// cloud of sec. 5 for the same sun, happens only when the light or the
// density changes, attenuates by the cloud's own extinction (closed forms for
// a uniform cloud with the sun straight down and at the horizon), and the
// low-albedo model's per-vertex source is the lighting model's.
#include <cmath>
#include <numbers>
#include <optional>

#include <gtest/gtest.h>

#include "splatfx/cloud.hpp"

using namespace splatfx;

namespace {

CloudCreateDesc small() {
    CloudCreateDesc d;
    d.cloud = {.dims = {17, 17, 9}, .seed = 3, .featureCells = 6.0f, .coverage = 0.6f};
    d.table = {.scalarResolution = 8, .lengthResolution = 8};
    return d;
}

std::size_t index(glm::ivec3 n, int x, int y, int z) { return std::size_t(x) + std::size_t(n.x) * (std::size_t(y) + std::size_t(n.y) * std::size_t(z)); }

} // namespace

// The Roettger model relit for a sun is the cloud makeCloudVolume bakes for
// it: same density, same light field. The two sweeps differ only in how the
// step toward the sun is normalised (float rounding, ~1e-7 relative), so a
// stored 8-bit value may differ by one code where it sits on a rounding edge.
TEST(CloudLight, RoettgerRelightIsTheBakedCloud) {
    for (glm::vec3 toSun : {glm::vec3(0.3f, 0.2f, 1.0f), glm::vec3(-1.0f, 0.4f, 0.2f)}) {
        CloudCreateDesc d = small();
        auto cloud = Cloud::create(d);
        ASSERT_TRUE(cloud) << cloud.error();
        CloudLighting L = cloud->lighting();
        L.sun.direction = -toSun;
        ASSERT_TRUE(cloud->setLight(L));
        CloudDesc baked = d.cloud;
        baked.sunDirection = toSun;
        auto field = makeCloudVolume(baked);
        ASSERT_TRUE(field);
        auto ref = LodVolume::create(*field, d.volume);
        ASSERT_TRUE(ref);
        const glm::ivec3 n = ref->pointDims();
        int maxDiff = 0;
        for (int z = 0; z < n.z; ++z)
            for (int y = 0; y < n.y; ++y)
                for (int x = 0; x < n.x; ++x) {
                    EXPECT_EQ(cloud->volume().scalarAt({x, y, z}), ref->scalarAt({x, y, z}));
                    const float a = cloud->volume().lengthScaleAt({x, y, z}), b = ref->lengthScaleAt({x, y, z});
                    maxDiff = std::max(maxDiff, int(std::lround(std::fabs(a - b) * 255.0f)));
                }
        EXPECT_LE(maxDiff, 1);
    }
}

TEST(CloudLight, RelightsOnlyWhenTheLightOrTheDensityChanges) {
    auto cloud = Cloud::create(small());
    ASSERT_TRUE(cloud) << cloud.error();
    EXPECT_EQ(cloud->relights(), 1u);
    EXPECT_EQ(cloud->tableBuilds(), 1u);
    CloudLighting L = cloud->lighting();
    ASSERT_TRUE(cloud->setLight(L)); // same light
    L.sun.color = {1.0f, 0.5f, 0.2f}; // Roettger draws no sun colour
    ASSERT_TRUE(cloud->setLight(L));
    EXPECT_EQ(cloud->relights(), 1u);
    EXPECT_EQ(cloud->tableBuilds(), 1u);
    L.sun.direction = {1.0f, 0.0f, -1.0f}; // the sun moves
    ASSERT_TRUE(cloud->setLight(L));
    EXPECT_EQ(cloud->relights(), 2u);
    L.ambient = 0.2f; // gamma changes: the length field does
    ASSERT_TRUE(cloud->setLight(L));
    EXPECT_EQ(cloud->relights(), 3u);
    EXPECT_EQ(cloud->tableBuilds(), 1u);

    std::vector<float> density = cloud->density();
    ASSERT_TRUE(cloud->setDensity(density)); // unchanged
    EXPECT_EQ(cloud->relights(), 3u);
    density[index(cloud->dims(), 8, 8, 4)] = 1.0f - density[index(cloud->dims(), 8, 8, 4)];
    ASSERT_TRUE(cloud->setDensity(density));
    EXPECT_EQ(cloud->relights(), 4u);

    // LowAlbedo: a new sun colour rebuilds the table only; a new direction relights only.
    L.model = CloudLightModel::LowAlbedo;
    ASSERT_TRUE(cloud->setLight(L));
    EXPECT_EQ(cloud->relights(), 5u);
    EXPECT_EQ(cloud->tableBuilds(), 2u);
    L.sun.intensity = 2.0f;
    ASSERT_TRUE(cloud->setLight(L));
    EXPECT_EQ(cloud->relights(), 5u);
    EXPECT_EQ(cloud->tableBuilds(), 3u);
    L.sun.direction = {0.0f, 1.0f, -1.0f};
    ASSERT_TRUE(cloud->setLight(L));
    EXPECT_EQ(cloud->relights(), 6u);
    EXPECT_EQ(cloud->tableBuilds(), 3u);
}

// Hard cases of the relight (docs/STABILITY.md, "Cloud lighting"). A uniform
// cloud (density f everywhere, spacing 0.5) in the low-albedo model: with
// the sun along an axis or a diagonal the sweep is exact for it, T =
// exp(-sigma * length of the ray to the sun inside the grid), sigma =
// maxExtinctionPerWorld f. Float
// transmittance through at most 16 steps: 1e-5 covers the rounding.
class CloudLightHardCases : public ::testing::Test {
protected:
    static constexpr float kF = 0.4f, kH = 0.5f;
    static constexpr double kSigma = 1.5 * double(kF);
    void SetUp() override {
        CloudCreateDesc d = small();
        d.lighting.model = CloudLightModel::LowAlbedo;
        d.volume.spacingWorld = kH;
        d.transfer.maxExtinctionPerWorld = 1.5f;
        auto c = Cloud::create(d);
        ASSERT_TRUE(c) << c.error();
        cloud.emplace(std::move(*c));
        ASSERT_TRUE(cloud->setDensity(std::vector<float>(cloud->density().size(), kF)));
        n = cloud->dims();
    }
    void sun(glm::vec3 travel) {
        CloudLighting L = cloud->lighting();
        L.sun.direction = travel;
        ASSERT_TRUE(cloud->setLight(L));
    }
    float T(int x, int y, int z) const { return cloud->sunTransmittance()[index(n, x, y, z)]; }
    std::optional<Cloud> cloud;
    glm::ivec3 n{0};
};

TEST_F(CloudLightHardCases, SunStraightDown) {
    sun({0.0f, 0.0f, -1.0f}); // the sun is at +z: the sweep runs plane by plane from the top
    for (int z = 0; z < n.z; ++z)
        for (int x = 0; x < n.x; x += 4) EXPECT_NEAR(T(x, 3, z), std::exp(-kSigma * kH * double(n.z - 1 - z)), 1e-5) << x << " " << z;
}

TEST_F(CloudLightHardCases, SunAtTheHorizon) {
    sun({1.0f, 0.0f, 0.0f}); // travelling +x, grazing every z plane: the sun is at -x
    for (int z = 0; z < n.z; z += 2)
        for (int x = 0; x < n.x; ++x) EXPECT_NEAR(T(x, 5, z), std::exp(-kSigma * kH * double(x)), 1e-5) << x << " " << z;
}

// A sun at exactly 45 degrees ties the sweep's main axis (|x| = |z|), and its
// rays leave through the top face as well as the far side: every step lands
// on grid points, so the sweep is exact. At a shallower angle the bilinear
// lookup between rows smears the kink where rays switch from leaving through
// the side to leaving through the top; a point whose lookups stay on the
// side-exit rows (x <= nz - 1 - z: k steps reach at most k rows up) is exact,
// and points on the top face toward the sun see it unattenuated.
TEST_F(CloudLightHardCases, SunOnADiagonalAndRaysLeavingThroughTheSideFaces) {
    sun({1.0f, 0.0f, -1.0f}); // toward the sun: (-1, 0, +1)
    for (int z = 0; z < n.z; ++z)
        for (int x = 0; x < n.x; ++x)
            EXPECT_NEAR(T(x, 2, z), std::exp(-kSigma * kH * std::sqrt(2.0) * double(std::min(x, n.z - 1 - z))), 1e-5) << x << " " << z;
    sun({1.0f, 0.0f, -0.4f}); // toward the sun: (-1, 0, 0.4), main axis x
    const double len = std::sqrt(1.0 + 0.4 * 0.4);
    for (int z = 0; z < n.z; ++z)
        for (int x = 0; x <= n.z - 1 - z; ++x) EXPECT_NEAR(T(x, 2, z), std::exp(-kSigma * kH * len * double(x)), 1e-5) << x << " " << z;
    for (int x = 0; x < n.x; ++x) EXPECT_EQ(T(x, 2, n.z - 1), 1.0f) << x;
}

// The transfer's step: density exactly at the threshold is cloud, a float
// below it is air (nothing attenuates, nothing casts).
TEST_F(CloudLightHardCases, DensityExactlyAtTheThreshold) {
    const float t = CloudTransferDesc{}.threshold;
    sun({0.0f, 0.0f, -1.0f});
    ASSERT_TRUE(cloud->setDensity(std::vector<float>(cloud->density().size(), t)));
    EXPECT_NEAR(T(4, 4, 0), std::exp(-1.5 * double(t) * kH * double(n.z - 1)), 1e-5);
    EXPECT_FALSE(cloud->densityField().empty());
    ASSERT_TRUE(cloud->setDensity(std::vector<float>(cloud->density().size(), std::nextafter(t, 0.0f))));
    for (float v : cloud->sunTransmittance()) EXPECT_EQ(v, 1.0f);
    EXPECT_TRUE(cloud->densityField().empty());
}

// An empty cloud: T = 1 everywhere, no field to cast, and what it draws is
// finite: every vertex's source is the lit-air value (s = phase / max phase).
TEST_F(CloudLightHardCases, EmptyCloud) {
    ASSERT_TRUE(cloud->setDensity(std::vector<float>(cloud->density().size(), 0.0f)));
    for (float v : cloud->sunTransmittance()) EXPECT_EQ(v, 1.0f);
    EXPECT_TRUE(cloud->densityField().empty());
    LodFrame frame;
    const Camera cam = Camera::lookAt({4.0f, -12.0f, 6.0f}, {4.0f, 4.0f, 2.0f}, {0.0f, 0.0f, 1.0f}, 0.8f, {64, 48});
    ASSERT_TRUE(cloud->update(cam, {.zeroOpacityTest = false}, frame));
    for (const Tetrahedron& t : frame.tets)
        for (int k = 0; k < 4; ++k) {
            EXPECT_TRUE(std::isfinite(t.scalar[std::size_t(k)]));
            EXPECT_EQ(t.lengthScale[std::size_t(k)], 0.0f); // no extinction: draws nothing
        }
}

// An opaque cloud (extinction 10^6 per unit): T underflows to 0 one cell in,
// and the source there is the ambient and multiple-scattering part alone.
TEST_F(CloudLightHardCases, OpaqueCloudUnderflowsToItsAmbientLight) {
    CloudCreateDesc d = small();
    d.lighting.model = CloudLightModel::LowAlbedo;
    d.lighting.gas.ambient = glm::vec3(0.2f);
    d.transfer.maxExtinctionPerWorld = 1e6f;
    auto c = Cloud::create(d);
    ASSERT_TRUE(c) << c.error();
    ASSERT_TRUE(c->setDensity(std::vector<float>(c->density().size(), 1.0f)));
    for (std::size_t i = 0; i < c->sunTransmittance().size(); ++i) {
        const float v = c->sunTransmittance()[i];
        EXPECT_TRUE(v == 0.0f || v == 1.0f) << i; // 1 only on the faces toward the sun
    }
    const glm::dvec3 a = c->sourceAt(0.0, {0.0f, 0.0f, 1.0f});
    EXPECT_NEAR(a.x, 0.9 * 0.2, 1e-7); // albedo x ambient
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c->transfer().color(0.0)[k], a[k], 1e-7); // the table's colour at s = 0 (float)
}

// What the tetrahedra draw at each vertex, kappa(s) with s = T phase /
// max phase, is the lighting model's source sourceAt(T, toEye), for a
// forward-scattering lobe (the phase varies across the cloud). Fully refined
// (every vertex a grid point), so T is the stored value there. kappa is
// affine in s: float rounding of s and kappa, relative 1e-5 of the source's
// largest value (the peak, A + B).
TEST(CloudLight, LowAlbedoVertexSourceIsTheModel) {
    CloudCreateDesc d = small();
    d.cloud.dims = {9, 9, 5};
    d.lighting.model = CloudLightModel::LowAlbedo;
    d.lighting.sun = Light::directional({0.5f, -0.3f, -1.0f}, {1.0f, 0.9f, 0.8f}, 1.5f);
    const HgLobe lobes[] = {{0.6f, 0.7f}, {-0.3f, 0.3f}};
    d.lighting.gas.phase = *PhaseFunction::create(lobes);
    d.lighting.gas.ambient = {0.1f, 0.12f, 0.15f};
    d.lighting.gas.multipleScattering = 0.2f;
    auto cloud = Cloud::create(d);
    ASSERT_TRUE(cloud) << cloud.error();
    const Camera cam = Camera::lookAt({4.0f, -12.0f, 6.0f}, {4.0f, 4.0f, 2.0f}, {0.0f, 0.0f, 1.0f}, 0.8f, {64, 48});
    LodFrame frame;
    ASSERT_TRUE(cloud->update(cam, {.detailC = 1e6f, .zeroOpacityTest = false, .clipNear = false}, frame));
    ASSERT_FALSE(frame.tets.empty());
    const glm::dvec3 peak = cloud->transfer().color(1.0);
    const double tol = 1e-5 * std::max({peak.x, peak.y, peak.z});
    for (const Tetrahedron& t : frame.tets)
        for (int k = 0; k < 4; ++k) {
            const glm::vec3 p = t.position[std::size_t(k)];
            const glm::ivec3 g = glm::ivec3(glm::round(p));
            ASSERT_LT(glm::length(p - glm::vec3(g)), 1e-4f) << "fully refined vertices are grid points";
            const double T = cloud->volume().scalarAt(g);
            const glm::dvec3 want = cloud->sourceAt(T, glm::normalize(cam.eye() - p));
            const glm::dvec3 got = cloud->transfer().color(t.scalar[std::size_t(k)]);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], tol);
        }
}

// A y-up cloud is the z-up one turned: density and sun transmittance at
// world (x, y, z) are the z-up cloud's at (x, z, y) under the turned sun. The
// sweep's two in-plane axes swap roles, so its bilinear sums add in another
// order: float rounding, 1e-6.
TEST(CloudLight, YUpIsTheGeneratorTurned) {
    CloudCreateDesc d = small();
    d.lighting.model = CloudLightModel::LowAlbedo;
    d.lighting.sun = Light::directional({0.3f, -0.5f, -1.0f});
    auto zUp = Cloud::create(d);
    d.yUp = true;
    d.lighting.sun = Light::directional({0.3f, -1.0f, -0.5f});
    auto yUp = Cloud::create(d);
    ASSERT_TRUE(zUp && yUp);
    const glm::ivec3 n = zUp->dims();
    ASSERT_EQ(yUp->dims(), glm::ivec3(n.x, n.z, n.y));
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const std::size_t a = index(n, x, y, z), b = index(yUp->dims(), x, z, y);
                EXPECT_EQ(zUp->density()[a], yUp->density()[b]);
                EXPECT_NEAR(zUp->sunTransmittance()[a], yUp->sunTransmittance()[b], 1e-6);
            }
}

TEST(CloudLight, BadLightingIsRejectedNamingTheField) {
    auto cloud = Cloud::create(small());
    ASSERT_TRUE(cloud);
    CloudLighting L = cloud->lighting();
    L.sun = Light::point({0.0f, 0.0f, 10.0f});
    Status s = cloud->setLight(L);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "CloudLighting.sun must be a directional light");
    L = cloud->lighting();
    L.sun.direction = glm::vec3(0.0f);
    s = cloud->setLight(L);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("CloudLighting.sun.direction"), std::string::npos) << s.error();
    L = cloud->lighting();
    L.gas.albedo = 2.0f;
    s = cloud->setLight(L);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "CloudLighting.gas.albedo must be in [0, 1]");
    EXPECT_EQ(cloud->relights(), 1u); // nothing changed
    s = cloud->setDensity({0.5f});
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("Cloud::setDensity: 1 values"), std::string::npos) << s.error();
    std::vector<float> bad = cloud->density();
    bad[7] = std::numeric_limits<float>::quiet_NaN();
    s = cloud->setDensity(bad);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "Cloud::setDensity: density[7] must be finite and in [0, 1]");
    auto c2 = Cloud::create({.lighting = {.sun = Light::spot({}, {0, 0, -1}, 0.2f, 0.4f)}});
    ASSERT_FALSE(c2);
    EXPECT_EQ(c2.error(), "CloudLighting.sun must be a directional light");
}
