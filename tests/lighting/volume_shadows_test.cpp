// Volumes shadow each other (scene.hpp): a lit effect under a lit cloud is
// darker by exactly the transmittance through the cloud towards each light.
// The truth is the lit-volume reference (litFactor) over a VolumeField that
// holds the cloud as a continuous medium: its extinction at each grid point,
// trilinear between them and falling to zero one cell beyond (denseMedium,
// Trilinear), integrated in double by VolumeField::opticalDepthToLight.
//
// Tolerance, for every test: the lit colour is packed to 8 bits (half a level,
// 0.5 / 255) and the scene traces in float: the cloud's depth along a ray
// (at most ~10 nats here) carries a relative error of a few float epsilons per
// lattice cell crossed (< 1e-5 nats over the <= 40 cells), moving the colour
// (<= 1) by less than 1e-5. So |colour - base T| <= 0.5/255 + 1e-5.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/cloud.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

constexpr float kTolerance = 0.5f / 255.0f + 1e-5f;

glm::vec3 unpack(std::uint32_t c) { return glm::vec3(float(c & 255u), float((c >> 8) & 255u), float((c >> 16) & 255u)) / 255.0f; }

constexpr float kMaxExtinction = 2.0f, kThreshold = 0.08f;

// A 9x5x9-point cloud (spacing 1; grid y is world y) at `origin`.
Cloud makeCloud(glm::vec3 origin) {
    CloudCreateDesc cd;
    cd.cloud = {.dims = {9, 5, 9}, .seed = 2, .featureCells = 6.0f, .coverage = 0.6f};
    cd.volume.originWorld = origin;
    cd.transfer.maxExtinctionPerWorld = kMaxExtinction;
    cd.transfer.threshold = kThreshold;
    cd.table = {.scalarResolution = 8, .lengthResolution = 8};
    auto made = Cloud::create(cd);
    EXPECT_TRUE(made) << made.error();
    return std::move(*made);
}

// The cloud's field as the reference medium (cloud.hpp, densityField: one
// voxel per grid point of extinction maxExtinction f, f >= threshold).
std::shared_ptr<const DenseVoxels> cloudVoxels(const Cloud& c) {
    auto v = std::make_shared<DenseVoxels>();
    v->dims = c.dims();
    v->origin = glm::dvec3(c.volume().originWorld());
    v->voxelSize = double(c.volume().spacingWorld());
    v->values = c.density();
    for (float& x : v->values) x = x >= kThreshold ? x : 0.0f;
    return v;
}

struct PlumeUnderCloud {
    Materials materials{Footprint{}};
    Scene scene;
    EffectId plume = 0, cloud = 0;
    Frame frame;
    glm::vec4 base{0.8f, 0.6f, 0.4f, 1.0f};
    Camera camera = Camera::lookAt({0.0f, 10.0f, 40.0f}, {0.0f, 12.0f, 0.0f}, {0, 1, 0}, glm::radians(60.0f), {320, 240}, 0.1f, 500.0f);

    // A 4x4x4 plume with its lowest corner at plumeAt, lit isotropically with
    // albedo 1 and no self-shadowing: its colour is base x the cloud's transmittance.
    PlumeUnderCloud(glm::vec3 plumeAt, glm::vec3 cloudAt, std::vector<float> density) {
        const std::uint32_t table = materials.addColorTable(ColorTable::constant(base));
        Grid g = *Grid::box({4, 4, 4});
        for (Voxel& v : g.voxels) v.opacity = 0.5f;
        g.transform = glm::translate(glm::mat4(1.0f), plumeAt - g.localPosition({0, 0, 0}));
        EffectDesc desc;
        desc.name = "plume";
        desc.layers = {EffectLayer{.style = {.colorTable = table, .textured = false}}};
        plume = scene.add(*Effect::fromGrid(g, desc),
                          {.name = "plume", .lighting = {.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off}});
        Cloud c = makeCloud(cloudAt);
        EXPECT_TRUE(c.setDensity(std::move(density)));
        cloud = scene.add(std::move(c), {.name = "cloud", .lighting = {.enabled = true}});
    }

    // Every plume splat against base x T(centre), T from the reference; returns the smallest T seen
    // (and the largest and the mean, for tools/validate/cloud_shadow.py).
    double check(const Light& light, double* maxT = nullptr, double* meanT = nullptr) {
        EXPECT_TRUE(scene.prepare(0.0, camera, materials, frame));
        EXPECT_TRUE(scene.status(plume).lit);
        EXPECT_TRUE(scene.status(cloud).lit);
        const Cloud& c = *scene.findCloud(cloud);
        VolumeField field(materials);
        field.addMedium(denseMedium(cloudVoxels(c), DenseFilter::Trilinear, double(kMaxExtinction)));
        const LitVolumeDesc lit{.lights = {light}, .gas = {.albedo = 1.0f}};
        double minT = 1.0, hiT = 0.0, sumT = 0.0;
        std::size_t n = 0;
        for (const Splat& sp : frame.splats()) {
            const glm::dvec3 f = litFactor(field, glm::dvec3(sp.center), glm::dvec3(camera.eye()), lit);
            minT = std::min(minT, f.x);
            hiT = std::max(hiT, f.x);
            sumT += f.x;
            const glm::vec3 got = unpack(sp.color);
            for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], double(base[a]) * f[a], kTolerance) << "splat at " << sp.center.x << "," << sp.center.y << "," << sp.center.z;
            ++n;
        }
        EXPECT_EQ(n, 64u);
        if (maxT) *maxT = hiT;
        if (meanT) *meanT = n ? sumT / double(n) : 0.0;
        return minT;
    }
};

std::vector<float> slopedDensity(const Cloud& c) {
    const glm::ivec3 n = c.dims();
    std::vector<float> f(c.density().size());
    for (int z = 0, i = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x, ++i)
                f[std::size_t(i)] = (x == 0 && z == 0) ? 0.05f : 0.12f + 0.05f * float(x) + 0.06f * float(y) + 0.03f * float(z);
    return f;
}

} // namespace

// A slanted sun: every ray from the plume to it crosses lattice planes on all
// three axes inside the cloud (a cubic per cell), and the column under the
// threshold is a hole. Without the cloud's shadow every splat would be the
// base colour (T = 1): the test asserts the cloud takes at least half the light.
TEST(VolumeShadows, PlumeUnderACloudIsDarkerByTheCloudsTransmittance) {
    const glm::vec3 cloudAt{-4.0f, 20.0f, -4.0f};
    PlumeUnderCloud s({-1.5f, 4.0f, -1.5f}, cloudAt, slopedDensity(makeCloud(cloudAt)));
    const Light sun = Light::directional({0.25f, -1.0f, 0.15f});
    ASSERT_TRUE(s.scene.addLight(sun));
    double maxT = 0.0, meanT = 0.0;
    const double minT = s.check(sun, &maxT, &meanT);
    EXPECT_LT(minT, 0.5);
    // The same case integrated outside the project: tools/validate/cloud_shadow.py.
    std::printf("reference T: min %.9f, max %.9f, mean %.9f\n", minT, maxT, meanT);
    // The cloud not casting: the plume sees the sun unattenuated.
    s.scene.options(s.cloud).lighting.castsShadow = false;
    ASSERT_TRUE(s.scene.prepare(0.1, s.camera, s.materials, s.frame));
    for (const Splat& sp : s.frame.splats())
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(unpack(sp.color)[a], s.base[a], kTolerance);
}

// The plume straddles the cloud's bottom: half its splats start their trace
// inside the cloud's field, mid-cell (the first piece is partial), the others
// below it (the first piece starts at the padding cell's face).
TEST(VolumeShadows, PlumeInsideTheCloudTracesFromMidCell) {
    const glm::vec3 cloudAt{-4.0f, 20.0f, -4.0f};
    PlumeUnderCloud s({-1.3f, 18.6f, -1.7f}, cloudAt, slopedDensity(makeCloud(cloudAt)));
    const Light sun = Light::directional({-0.3f, -1.0f, 0.2f});
    ASSERT_TRUE(s.scene.addLight(sun));
    EXPECT_LT(s.check(sun), 0.7);
}

// A point light above the cloud: each splat's ray converges on the light, so
// the rays differ in direction, and the trace stops at the light, not at the
// field's far side.
TEST(VolumeShadows, PointLightAboveTheCloudShadowsAlongConvergingRays) {
    const glm::vec3 cloudAt{-4.0f, 20.0f, -4.0f};
    PlumeUnderCloud s({-1.5f, 4.0f, -1.5f}, cloudAt, slopedDensity(makeCloud(cloudAt)));
    // Intensity so that the irradiance at the plume (~26 units below) is about 1.
    const Light bulb = Light::point({1.0f, 30.0f, 0.5f}, glm::vec3(1.0f), 26.0f * 26.0f);
    ASSERT_TRUE(s.scene.addLight(bulb));
    EXPECT_LT(s.check(bulb), 0.5);
}
