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

// Per-node frustum culling of a LOD cloud (Roettger & Ertl sec. 4.2;
// issue 24 item 4): nodes outside the frustum emit no tetrahedra, and what is
// in view is unchanged. The culled list is the full list less tetrahedra that
// each lie wholly behind one frustum plane, in the same order, so every pixel
// ray integrates the same pieces: the reference image in view is the same to
// the bit.
TEST(Clouds, FrustumCullingDropsOnlyNodesOutOfView) {
    CloudDesc d;
    d.dims = {33, 33, 17};
    auto field = makeCloudVolume(d);
    ASSERT_TRUE(field);
    auto vol = LodVolume::create(*field, {});
    ASSERT_TRUE(vol) << vol.error();
    auto tf = makeCloudTransfer({});
    ASSERT_TRUE(tf);
    // Above the deck (z up), looking down on a corner of it: most nodes are beside the view.
    const Camera cam = Camera::lookAt({22, 22, 40}, {26, 26, 8}, {0, 1, 0}, glm::radians(30.0f), {48, 36}, 0.1f, 200.0f);
    LodRefineDesc on;
    on.detailC = 50.0f;
    LodRefineDesc off = on;
    off.frustumCull = false;
    LodFrame culled, all;
    ASSERT_TRUE(vol->update(cam, on, &*tf, culled));
    ASSERT_TRUE(vol->update(cam, off, &*tf, all));
    EXPECT_GT(culled.stats.nodesCulled, 0u);
    EXPECT_EQ(all.stats.nodesCulled, 0u);
    EXPECT_LT(culled.tets.size() * 2, all.tets.size()) << "most of the deck is out of this view";
    const glm::mat4 vp = cam.proj * cam.view;
    auto behindOnePlane = [&](const Tetrahedron& t) {
        for (int i = 0; i < 3; ++i)
            for (float sign : {-1.0f, 1.0f}) {
                const glm::vec4 pl = glm::vec4(vp[0][3], vp[1][3], vp[2][3], vp[3][3]) + sign * glm::vec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
                bool every = true;
                for (const glm::vec3& p : t.position) every = every && glm::dot(glm::vec3(pl), p) + pl.w < 0.0f;
                if (every) return true;
            }
        return false;
    };
    std::size_t k = 0;
    for (const Tetrahedron& t : all.tets) {
        if (k < culled.tets.size() && culled.tets[k].position == t.position && culled.tets[k].scalar == t.scalar) {
            ++k;
            continue;
        }
        ASSERT_TRUE(behindOnePlane(t)) << "a dropped tetrahedron reaches into the view";
    }
    ASSERT_EQ(k, culled.tets.size()) << "the kept tetrahedra are a subsequence of the full list";
    // The reference image in view: every pixel centre's ray through both lists.
    const glm::mat4 inv = glm::inverse(vp);
    const glm::dvec3 eye(cam.eye());
    int cloudy = 0;
    for (int y = 0; y < 36; ++y)
        for (int x = 0; x < 48; ++x) {
            const glm::vec4 f = inv * glm::vec4((x + 0.5f) / 48.0f * 2 - 1, (y + 0.5f) / 36.0f * 2 - 1, 1.0f, 1.0f);
            const glm::dvec3 dir = glm::normalize(glm::dvec3(glm::vec3(f) / f.w) - eye);
            const glm::dvec4 a = integrateRay(culled.tets, *tf, eye, dir, 0.0, 1e4);
            const glm::dvec4 b = integrateRay(all.tets, *tf, eye, dir, 0.0, 1e4);
            cloudy += b.a > 1e-3;
            ASSERT_EQ(a, b) << "pixel " << x << "," << y;
        }
    EXPECT_GT(cloudy, 48 * 36 / 10) << "the view should hold cloud for this test to mean anything";
}
