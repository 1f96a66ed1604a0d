// A Cloud relit as its sun moves (cloud.hpp): the relight equals the baked
// cloud of sec. 5 for the same sun, happens only when the light or the
// density changes, attenuates by the cloud's own extinction (closed forms for
// a uniform cloud with the sun straight down and at the horizon), and the
// low-albedo model's per-vertex source is the lighting model's.
#include <cmath>
#include <numbers>

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

// A uniform cloud (density f everywhere) with the sun straight down and at
// the horizon: the sweep is exact for a field that is constant across its
// planes, T = exp(-sigma * distance to the grid's sun-side face), sigma =
// maxExtinctionPerWorld f, in world units (spacing 0.5). Float transmittance
// through at most 16 steps: 1e-5 covers the rounding.
TEST(CloudLight, LowAlbedoSelfShadowThroughItsOwnExtinction) {
    CloudCreateDesc d = small();
    d.lighting.model = CloudLightModel::LowAlbedo;
    d.volume.spacingWorld = 0.5f;
    d.transfer.maxExtinctionPerWorld = 1.5f;
    auto cloud = Cloud::create(d);
    ASSERT_TRUE(cloud) << cloud.error();
    const float f = 0.4f;
    ASSERT_TRUE(cloud->setDensity(std::vector<float>(cloud->density().size(), f)));
    const glm::ivec3 n = cloud->dims();
    const double sigma = 1.5 * double(f);
    CloudLighting L = cloud->lighting();
    L.sun.direction = {0.0f, 0.0f, -1.0f}; // straight down: the sun is at +z
    ASSERT_TRUE(cloud->setLight(L));
    for (int z = 0; z < n.z; ++z)
        for (int x = 0; x < n.x; x += 5)
            EXPECT_NEAR(cloud->sunTransmittance()[index(n, x, 3, z)], std::exp(-sigma * 0.5 * double(n.z - 1 - z)), 1e-5) << x << " " << z;
    L.sun.direction = {1.0f, 0.0f, 0.0f}; // at the horizon, travelling +x: the sun is at -x
    ASSERT_TRUE(cloud->setLight(L));
    for (int x = 0; x < n.x; ++x)
        EXPECT_NEAR(cloud->sunTransmittance()[index(n, x, 5, 4)], std::exp(-sigma * 0.5 * double(x)), 1e-5) << x;
    // Below the threshold the cloud is air: nothing attenuates.
    ASSERT_TRUE(cloud->setDensity(std::vector<float>(cloud->density().size(), 0.5f * d.transfer.threshold)));
    for (float T : cloud->sunTransmittance()) EXPECT_EQ(T, 1.0f);
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
