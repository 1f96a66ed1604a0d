// Clouds (sec. 5): deterministic Perlin density, the light field's attenuation
// toward the sun, the transfer functions, and the zero-opacity test on air.
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/volume.hpp"

using namespace splatfx;

TEST(Clouds, DeterministicBySeedAndInRange) {
    CloudDesc d;
    d.dims = {33, 33, 17};
    auto a = makeCloudVolume(d), b = makeCloudVolume(d);
    ASSERT_TRUE(a && b) << a.error();
    EXPECT_EQ(a->scalar, b->scalar);
    EXPECT_EQ(a->lengthScale, b->lengthScale);
    d.seed = 2;
    auto c = makeCloudVolume(d);
    ASSERT_TRUE(c);
    EXPECT_NE(a->scalar, c->scalar);
    std::size_t cloudy = 0;
    for (std::size_t i = 0; i < a->scalar.size(); ++i) {
        EXPECT_GE(a->scalar[i], 0.0f);
        EXPECT_LE(a->scalar[i], 1.0f);
        EXPECT_GE(a->lengthScale[i], d.ambient - 1e-6f); // gamma = ambient + diffuse T, T in [0, 1]
        EXPECT_LE(a->lengthScale[i], d.ambient + d.diffuse + 1e-6f);
        cloudy += a->scalar[i] > 0.0f;
    }
    // Bottom and top layers are clear (cumulus profile), and there is cloud in between.
    for (int y = 0; y < 33; ++y)
        for (int x = 0; x < 33; ++x) {
            EXPECT_EQ(a->scalar[std::size_t(x + 33 * y)], 0.0f);
            EXPECT_EQ(a->scalar[std::size_t(x + 33 * (y + 33 * 16))], 0.0f);
        }
    EXPECT_GT(cloudy, a->scalar.size() / 50);
    EXPECT_LT(cloudy, a->scalar.size() / 2);
}

TEST(Clouds, LightIsAttenuatedThroughDensityTowardTheSun) {
    CloudDesc d;
    d.dims = {33, 33, 17};
    d.sunDirection = {0, 0, 1}; // straight down from +z: T at a point = exp(-k sum of density above it)
    auto v = makeCloudVolume(d);
    ASSERT_TRUE(v) << v.error();
    const int nx = 33, ny = 33, nz = 17;
    for (int y = 0; y < ny; y += 4)
        for (int x = 0; x < nx; x += 4) {
            double depth = 0.0;
            for (int z = nz - 1; z >= 0; --z) {
                const std::size_t i = std::size_t(x + nx * (y + ny * z));
                if (z < nz - 1) depth += 0.5 * (v->scalar[i] + v->scalar[i + std::size_t(nx * ny)]);
                // Trapezoid rule of the sweep, closed form for a vertical sun.
                const double gamma = d.ambient + d.diffuse * std::exp(-double(d.lightExtinctionPerCell) * depth);
                EXPECT_NEAR(v->lengthScale[i], gamma, 1e-5);
            }
        }
}

TEST(Clouds, TransferIsAnInverseRampWithZeroBelowTheThreshold) {
    CloudTransferDesc td;
    auto tf = makeCloudTransfer(td);
    ASSERT_TRUE(tf) << tf.error();
    EXPECT_EQ(tf->extinction(0.5 * td.threshold), 0.0);
    EXPECT_NEAR(tf->extinction(0.5), 0.5 * td.maxExtinctionPerWorld, 1e-6);
    EXPECT_NEAR(tf->extinction(1.0), td.maxExtinctionPerWorld, 1e-6);
    EXPECT_GT(tf->color(0.2).x, tf->color(0.9).x); // brighter where thinner
    auto bad = makeCloudTransfer({.threshold = 1.5f});
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("threshold"), std::string::npos);
}

TEST(Clouds, ZeroOpacityTestDiscardsThinAir) {
    CloudDesc d;
    d.dims = {33, 33, 17};
    auto field = makeCloudVolume(d);
    ASSERT_TRUE(field);
    auto vol = LodVolume::create(*field, {});
    ASSERT_TRUE(vol) << vol.error();
    auto tf = makeCloudTransfer({});
    ASSERT_TRUE(tf);
    const Camera cam = Camera::lookAt({-20, 16, 20}, {16, 16, 8}, {0, 0, 1}, glm::radians(60.0f), {64, 48});
    LodRefineDesc on;
    on.detailC = 50.0f;
    LodRefineDesc off = on;
    off.zeroOpacityTest = false;
    LodFrame a, b;
    ASSERT_TRUE(vol->update(cam, on, &*tf, a));
    ASSERT_TRUE(vol->update(cam, off, &*tf, b));
    EXPECT_LT(a.tets.size(), b.tets.size());
    EXPECT_GT(a.stats.nodesTransparent + a.stats.tetsTransparent, 0u);
    // Nothing visible was dropped: every dropped tetrahedron had zero extinction,
    // so a ray integrates the same through both lists. Checked on the kept ones:
    for (const Tetrahedron& t : a.tets) {
        float lo = 1, hi = 0;
        for (float s : t.scalar) {
            lo = std::min(lo, s);
            hi = std::max(hi, s);
        }
        EXPECT_FALSE(tf->zeroOpacity(lo, hi));
    }
}

TEST(Clouds, BadDescIsRejected) {
    CloudDesc d;
    d.octaves = 0;
    auto a = makeCloudVolume(d);
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("octaves"), std::string::npos);
    CloudDesc e;
    e.ambient = 0.8f;
    e.diffuse = 0.8f;
    auto b = makeCloudVolume(e);
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().find("ambient"), std::string::npos);
}
