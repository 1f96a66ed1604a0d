// Ground fog (sec. 6) as vertical prisms of three tetrahedra: volume, dropped
// zero-height prisms, back-to-front order along rays, near-plane clipping, bad input.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/volume.hpp"
#include "volume_test_util.hpp"

using namespace splatfx;

namespace {

// Valleys: a wavy terrain, the fog top flat at `top`.
GroundFogDesc valleys(glm::ivec2 dims, float top) {
    GroundFogDesc d;
    d.dims = dims;
    d.originWorld = {-10.0f, 0.0f, -10.0f};
    d.spacingWorld = 20.0f / float(dims.x - 1);
    for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) {
            const float x = float(i) / float(dims.x - 1), z = float(j) / float(dims.y - 1);
            d.terrainHeight.push_back(2.0f * std::sin(6.0f * x) * std::cos(5.0f * z) + 0.5f * x);
            d.fogTop.push_back(top);
        }
    return d;
}

// Closed form: the fog volume over each triangle of the alternating
// triangulation is its area times the mean thickness at its corners.
double exactVolume(const GroundFogDesc& d) {
    auto h = [&](int i, int j) {
        const std::size_t k = std::size_t(i) + std::size_t(d.dims.x) * std::size_t(j);
        return std::max(double(d.fogTop[k]) - double(d.terrainHeight[k]), 0.0);
    };
    const double area = 0.5 * double(d.spacingWorld) * double(d.spacingWorld);
    double v = 0.0;
    for (int j = 0; j + 1 < d.dims.y; ++j)
        for (int i = 0; i + 1 < d.dims.x; ++i) {
            if (((i + j) & 1) == 0)
                v += area / 3.0 * (h(i, j) + h(i + 1, j) + h(i + 1, j + 1)) + area / 3.0 * (h(i, j) + h(i + 1, j + 1) + h(i, j + 1));
            else v += area / 3.0 * (h(i, j) + h(i + 1, j) + h(i, j + 1)) + area / 3.0 * (h(i + 1, j) + h(i + 1, j + 1) + h(i, j + 1));
        }
    return v;
}

Camera farCamera() { return Camera::lookAt({-30.0f, 25.0f, -24.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.1f, 500.0f); }

} // namespace

// The emitted tetrahedra tile the fog exactly: their volumes add up to the
// closed form, all positively oriented, the scalar `density` at the terrain and 0 at the top.
TEST(GroundFog, TetrahedraTileTheFogVolume) {
    const GroundFogDesc d = valleys({17, 13}, 0.8f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    LodFrame f;
    ASSERT_TRUE(fog->update(farCamera(), f));
    EXPECT_EQ(f.stats.clippedInput, 0u);
    double v = 0.0;
    for (const Tetrahedron& t : f.tets) {
        const double tv = voltest::tetVolume(t);
        EXPECT_GT(tv, 0.0);
        v += tv;
        for (int k = 0; k < 4; ++k) EXPECT_TRUE(t.scalar[std::size_t(k)] == 0.0f || t.scalar[std::size_t(k)] == d.density);
    }
    const double exact = exactVolume(d);
    ASSERT_GT(exact, 1.0);
    // Float positions (~2^-24 relative of coordinates <= 12) over ~2000 tetrahedra.
    EXPECT_NEAR(v, exact, 1e-4 * exact);
}

// Prisms with no fog at any corner are dropped: fog at one interior point only
// leaves the triangles around it (6 or 4 with alternating diagonals), 3 tetrahedra each at most.
TEST(GroundFog, ZeroHeightPrismsAreDropped) {
    GroundFogDesc d = valleys({9, 9}, -100.0f);
    const std::size_t k = 4 + 9 * 4; // point (4, 4)
    d.fogTop[k] = d.terrainHeight[k] + 1.0f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    // The triangles with (4, 4) as a corner, counted from the alternating rule directly.
    int incident = 0;
    for (int j = 3; j <= 4; ++j)
        for (int i = 3; i <= 4; ++i) {
            const bool even = ((i + j) & 1) == 0;
            const glm::ivec2 tri[2][3] = {{{i, j}, {i + 1, j}, {i + 1, j + 1}}, {{i, j}, {i + 1, j + 1}, {i, j + 1}}};
            const glm::ivec2 triOdd[2][3] = {{{i, j}, {i + 1, j}, {i, j + 1}}, {{i + 1, j}, {i + 1, j + 1}, {i, j + 1}}};
            for (int t = 0; t < 2; ++t)
                for (int c = 0; c < 3; ++c)
                    if ((even ? tri[t][c] : triOdd[t][c]) == glm::ivec2(4, 4)) ++incident;
        }
    EXPECT_EQ(fog->prismCount(), std::uint64_t(incident));
    LodFrame f;
    ASSERT_TRUE(fog->update(farCamera(), f));
    EXPECT_EQ(f.stats.fullResolution, 3u * std::uint64_t(incident));
    EXPECT_GT(f.tets.size(), 0u);
    EXPECT_LE(f.tets.size(), 3u * std::size_t(incident)); // the zero-volume pieces at the fog's edge are dropped too
}

// Along any ray from the eye a tetrahedron later in the list is never behind
// an earlier one (the BSP over the grid and MPVO inside the prisms), from
// outside the fog and from inside it (with near-plane clipping).
TEST(GroundFog, BackToFrontAlongRaysOutsideAndInside) {
    const GroundFogDesc d = valleys({17, 13}, 0.8f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    const Camera inside = Camera::lookAt({0.5f, 0.6f, 0.3f}, {8.0f, 0.2f, 3.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.3f, 500.0f);
    const Camera cams[2] = {farCamera(), inside};
    for (int ci = 0; ci < 2; ++ci) {
        const Camera& cam = cams[ci];
        LodFrame f;
        ASSERT_TRUE(fog->update(cam, f));
        std::mt19937 rng(3);
        std::uniform_real_distribution<double> u(-0.45, 0.45);
        int crossings = 0;
        for (int r = 0; r < 300; ++r) {
            const glm::dvec3 dir = glm::normalize(glm::dvec3(cam.forward()) + u(rng) * glm::dvec3(cam.right()) + u(rng) * glm::dvec3(cam.up()));
            double lastIn = 1e300;
            for (const Tetrahedron& t : f.tets) {
                const glm::dvec2 iv = voltest::rayInterval(t, glm::dvec3(cam.eye()), dir);
                if (!(iv.y - iv.x > 1e-6) || iv.y <= 0.0) continue;
                ++crossings;
                EXPECT_LE(iv.x, lastIn + 1e-5) << "ray " << r;
                lastIn = std::min(lastIn, iv.x);
            }
        }
        EXPECT_GT(crossings, 100);
        if (ci == 1) { EXPECT_GT(f.stats.clippedInput, 0u) << "the eye is inside the fog: the near plane cuts it"; }
    }
}

TEST(GroundFog, BadInputIsAnError) {
    GroundFogDesc d = valleys({5, 5}, 1.0f);
    d.fogTop.pop_back();
    auto a = GroundFog::create(d);
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("fogTop"), std::string::npos);
    d = valleys({5, 5}, 1.0f);
    d.terrainHeight[3] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(GroundFog::create(d));
    d = valleys({5, 5}, 1.0f);
    d.dims = {1, 25};
    EXPECT_FALSE(GroundFog::create(d));
    EXPECT_FALSE(makeGroundFogTransfer({1, 1, 1}, -1.0f));
}

// The sort-free emissive model (GroundFogDesc::sortFree) emits the
// same tetrahedra as the sorted layer, in another order, from outside and
// from inside the fog (near-plane clipping included).
TEST(GroundFog, SortFreeEmitsTheSameTetrahedraInGridOrder) {
    GroundFogDesc d = valleys({17, 13}, 0.8f);
    GroundFogDesc free = d;
    free.sortFree = true;
    auto sorted = GroundFog::create(d);
    auto unsorted = GroundFog::create(free);
    ASSERT_TRUE(sorted && unsorted);
    const Camera inside = Camera::lookAt({0.5f, 0.6f, 0.3f}, {8.0f, 0.2f, 3.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.3f, 500.0f);
    for (const Camera& cam : {farCamera(), inside}) {
        LodFrame a, b;
        ASSERT_TRUE(sorted->update(cam, a));
        ASSERT_TRUE(unsorted->update(cam, b));
        ASSERT_EQ(a.tets.size(), b.tets.size());
        EXPECT_EQ(a.stats.clippedInput, b.stats.clippedInput);
        auto key = [](const Tetrahedron& t) {
            std::array<float, 28> k{};
            std::size_t i = 0;
            for (const glm::vec3& p : t.position) k[i++] = p.x, k[i++] = p.y, k[i++] = p.z;
            for (float s : t.scalar) k[i++] = s;
            for (float m : t.lengthScale) k[i++] = m;
            return k;
        };
        std::vector<std::array<float, 28>> ka, kb;
        for (const Tetrahedron& t : a.tets) ka.push_back(key(t));
        for (const Tetrahedron& t : b.tets) kb.push_back(key(t));
        const bool sameOrder = ka == kb;
        EXPECT_FALSE(sameOrder) << "grid order should differ from back to front for this view";
        std::sort(ka.begin(), ka.end());
        std::sort(kb.begin(), kb.end());
        EXPECT_EQ(ka, kb) << "the same tetrahedra, only reordered";
    }
}
