#include <algorithm>
#include <cmath>
#include <random>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/splats.hpp"

using namespace splatfx;

namespace {

Materials plainMaterials() {
    Materials m{Footprint{}};
    m.addTextureSet(TextureSet::turbulence({.count = 4, .size = 16}));
    m.addColorTable(ColorTable::constant({1, 1, 1, 1}));
    return m;
}

// Line integral of the anisotropic kernel h(|M^-1 (x - c)|) along direction d
// through point p, by brute-force quadrature in double.
double lineIntegral(const Footprint& fp, const glm::dmat3& mi, glm::dvec3 c, glm::dvec3 p, glm::dvec3 d) {
    const int n = 20000;
    const double L = 40.0, h = 2.0 * L / n;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 x = p + (-L + (i + 0.5) * h) * d;
        sum += fp.kernel(glm::length(mi * (x - c)));
    }
    return sum * h;
}

} // namespace

TEST(SplatBuilder, SortsBackToFrontForRandomSplatsAndCameras) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const Materials m = plainMaterials();
    for (int trial = 0; trial < 20; ++trial) {
        Grid g;
        g.dims = {1, 1, 1};
        for (int i = 0; i < 500; ++i) {
            Voxel v;
            v.cell = {int(u(rng) * 20), int(u(rng) * 20), int(u(rng) * 20)};
            v.opacity = 0.5f;
            g.voxels.push_back(v);
        }
        const glm::vec3 eye(u(rng) * 60, u(rng) * 60, u(rng) * 60);
        SplatBuilder b({.frustumCull = false});
        b.begin(Camera::lookAt(eye, {0, 0, 0}, {0, 1, 0}, 1.2f, {64, 64}, 0.01f, 500.0f));
        b.add(g, m);
        b.sort();
        const auto& s = b.splats();
        ASSERT_GT(s.size(), 0u);
        for (size_t i = 0; i < s.size(); ++i) {
            EXPECT_NEAR(s[i].depth, glm::length(s[i].center - eye), 1e-4f * s[i].depth);
            if (i) { EXPECT_GE(s[i - 1].depth, s[i].depth) << "trial " << trial << " at " << i; }
        }
    }
}

TEST(SplatBuilder, RadixSortIsStableAndMatchesStdStableSort) {
    std::mt19937 rng(7);
    std::vector<Splat> s(5000);
    for (size_t i = 0; i < s.size(); ++i) {
        s[i].depth = float(rng() % 300) * 0.25f; // many ties
        s[i].layer = float(i);                   // original position, to check stability
    }
    auto expected = s;
    std::stable_sort(expected.begin(), expected.end(), [](const Splat& a, const Splat& b) { return a.depth > b.depth; });
    sortBackToFront(s, SortMode::Exact);
    for (size_t i = 0; i < s.size(); ++i) {
        EXPECT_EQ(s[i].depth, expected[i].depth);
        EXPECT_EQ(s[i].layer, expected[i].layer);
    }
}

TEST(SplatBuilder, BucketedSortOrdersBuckets) {
    std::mt19937 rng(9);
    std::vector<Splat> s(2000);
    for (auto& sp : s) sp.depth = float(rng() % 10000) / 100.0f;
    sortBackToFront(s, SortMode::Bucketed, 10);
    // Within 10 buckets over [0, 100): order may break only inside a 10-unit bucket.
    for (size_t i = 1; i < s.size(); ++i) EXPECT_GE(s[i - 1].depth, s[i].depth - 10.0f);
}

TEST(SplatBuilder, EllipseMatchesTheExactLineIntegralOfAnAnisotropicKernel) {
    // Non-cubic spacing, a rotated grid and a stretch along a diagonal: the
    // splat's ellipse mapping must reproduce the kernel's true line integral.
    const Materials m = plainMaterials();
    const Footprint& fp = m.footprint();
    Grid g;
    g.spacing = {0.7f, 1.9f, 1.1f};
    g.transform = glm::rotate(glm::mat4(1.0f), 0.6f, glm::normalize(glm::vec3(1, 2, 0.5f)));
    Voxel v;
    v.stretch = {0.8f, 0.3f, -0.5f};
    g.voxels.push_back(v);
    const glm::vec3 eye(3.0f, 4.0f, 12.0f);
    SplatBuilder b;
    b.begin(Camera::lookAt(eye, {0, 0, 0}, {0, 1, 0}, 1.0f, {64, 64}));
    b.add(g, m);
    ASSERT_EQ(b.splats().size(), 1u);
    const Splat& s = b.splats()[0];

    glm::dmat3 M = glm::dmat3(glm::mat3(g.transform)) * glm::dmat3(glm::dvec3(0.7, 0, 0), glm::dvec3(0, 1.9, 0), glm::dvec3(0, 0, 1.1));
    const glm::dvec3 st(0.8, 0.3, -0.5);
    const double sl = glm::length(st);
    M = M * (glm::dmat3(1.0) + sl * glm::outerProduct(st / sl, st / sl));
    const glm::dmat3 mi = glm::inverse(M);
    const glm::dvec3 c(s.center), d = glm::normalize(c - glm::dvec3(eye));
    const double bLen = glm::length(mi * d);
    const double R = fp.radius();
    for (double uu : {0.0, 0.3, -0.55, 0.8})
        for (double vv : {0.0, 0.45, -0.7}) {
            if (uu * uu + vv * vv >= 1.0) continue;
            const glm::dvec3 p = c + uu * glm::dvec3(s.axisU) + vv * glm::dvec3(s.axisV);
            const double expected = lineIntegral(fp, mi, c, p, d);
            const double predicted = fp.exact(R * std::sqrt(uu * uu + vv * vv)) / bLen;
            // Float axes (relative error ~1e-6) and the 20000-panel quadrature
            // (error ~1e-7 of the peak) bound the mismatch well below 1e-4 of the peak.
            EXPECT_NEAR(predicted, expected, 1e-4 * fp.exact(0.0) / bLen) << "u " << uu << " v " << vv;
        }
}

TEST(SplatBuilder, CubicVoxelFacingTheCameraIsACircleOfTheKernelRadius) {
    const Materials m = plainMaterials();
    Grid g;
    g.spacing = glm::vec3(2.0f);
    g.voxels.push_back(Voxel{});
    SplatBuilder b;
    b.begin(Camera::lookAt({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 1.0f, {64, 64}));
    b.add(g, m);
    ASSERT_EQ(b.splats().size(), 1u);
    const Splat& s = b.splats()[0];
    const float r = 2.0f * m.footprint().radius();
    EXPECT_NEAR(glm::length(s.axisU), r, 1e-4f * r);
    EXPECT_NEAR(glm::length(s.axisV), r, 1e-4f * r);
    EXPECT_NEAR(glm::dot(s.axisU, s.axisV), 0.0f, 1e-4f * r * r);
    // Texture "up" is the camera's up: flames rise on screen.
    EXPECT_GT(s.axisV.y, 0.999f * r);
    // Opacity 1 is clamped to the largest finite optical depth, not infinity.
    EXPECT_TRUE(std::isfinite(s.density));
}

TEST(SplatBuilder, NearPlaneFadesInsteadOfPopping) {
    const Materials m = plainMaterials();
    Grid g;
    Voxel v;
    v.opacity = 0.5f; // optical depth 1 (log2 units)
    g.voxels.push_back(v);
    float last = 0.0f;
    const float dz = 0.05f;
    // The fade is a smoothstep (slope at most 1.5) over (end - start) * extent,
    // extent = R * sqrt(3) for a unit cube; the density may change per step by
    // at most tau * 1.5 * dz / ((end - start) * extent). tau: textured sets carry a gain.
    const SplatBuilderDesc desc{.nearFade = true};
    const float tau = 1.0f * m.set(0).gain;
    const float maxJump = tau * 1.5f * dz / ((desc.nearFadeEnd - desc.nearFadeStart) * m.footprint().radius() * std::sqrt(3.0f));
    // Walk the camera towards the voxel: density must fall smoothly to zero.
    for (float z = 6.0f; z > 0.0f; z -= dz) {
        SplatBuilder b(desc);
        b.begin(Camera::lookAt({0, 0, z}, {0, 0, -1}, {0, 1, 0}, 1.0f, {64, 64}, 0.1f));
        b.add(g, m);
        const float d = b.splats().empty() ? 0.0f : b.splats()[0].density;
        if (z < 5.9f) { EXPECT_LE(std::abs(d - last), maxJump * 1.001f) << "jump at z " << z; }
        last = d;
    }
    EXPECT_EQ(last, 0.0f);
}

TEST(SplatBuilder, ClampsOpacityAndDropsNonFiniteVoxels) {
    const Materials m = plainMaterials();
    Grid g;
    Voxel ok, nan, big;
    nan.cell = {1, 0, 0};
    nan.opacity = std::nanf("");
    big.cell = {2, 0, 0};
    big.opacity = 7.0f;
    g.voxels = {ok, nan, big};
    SplatBuilder b;
    b.begin(Camera::lookAt({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 1.0f, {64, 64}));
    b.add(g, m);
    EXPECT_EQ(b.stats().rejected, 1u);
    ASSERT_EQ(b.splats().size(), 2u);
    EXPECT_EQ(b.splats()[0].density, b.splats()[1].density); // 7 clamped to 1, like the first
}

TEST(SplatBuilder, ThreadsGiveTheSameSplatsAsOneThread) {
    const Materials m = plainMaterials();
    Grid g = *Grid::box({40, 40, 40}, glm::vec3(0.25f));
    for (size_t i = 0; i < g.voxels.size(); i += 7) g.voxels[i].opacity = 0.0f;                // some culled
    for (size_t i = 3; i < g.voxels.size(); i += 11) g.voxels[i].stretch = {0.0f, 0.5f, 0.0f}; // some stretched
    g.voxels[5].opacity = std::nanf("");                                                       // one rejected
    const Camera cam = Camera::lookAt({2, 6, 14}, {0, 4, 0}, {0, 1, 0}, 0.9f, {320, 240});
    auto build = [&](unsigned threads) {
        SplatBuilder b({.threads = threads});
        b.begin(cam);
        b.add(g, m);
        b.sort();
        return std::pair(b.splats(), b.stats());
    };
    const auto [one, oneStats] = build(1);
    for (unsigned t : {2u, 3u, 8u}) {
        const auto [many, manyStats] = build(t);
        ASSERT_EQ(many.size(), one.size()) << t << " threads";
        EXPECT_EQ(std::memcmp(many.data(), one.data(), one.size() * sizeof(Splat)), 0) << t << " threads";
        EXPECT_EQ(manyStats.culled, oneStats.culled);
        EXPECT_EQ(manyStats.rejected, oneStats.rejected);
    }
    EXPECT_EQ(oneStats.rejected, 1u);
}

// The builder computes geometry many voxels at a time (a SIMD loop); each
// splat must still be exactly what that voxel gives on its own, for a batch
// size that does not divide the grid, anisotropic and stretched kernels, and
// a rotated grid.
TEST(SplatBuilder, BatchedGeometryMatchesOneVoxelAtATime) {
    const Materials m = plainMaterials();
    Grid g = *Grid::box({7, 9, 11}, glm::vec3(0.3f, 0.5f, 0.4f));
    g.transform = glm::rotate(glm::translate(glm::mat4(1.0f), {0.5f, -1.0f, 0.2f}), 0.6f, glm::normalize(glm::vec3(1, 2, 0.5f)));
    for (size_t i = 0; i < g.voxels.size(); i += 5) g.voxels[i].stretch = {0.2f, 0.7f, 0.0f};
    for (size_t i = 0; i < g.voxels.size(); ++i) g.voxels[i].colorCoord = float(i % 13) / 13.0f;
    const Camera cam = Camera::lookAt({3, 4, 12}, {0, 1, 0}, {0, 1, 0}, 0.9f, {320, 240});
    SplatBuilder all;
    all.begin(cam);
    all.add(g, m);
    ASSERT_EQ(all.splats().size(), g.voxels.size());
    Grid single = g;
    for (size_t i = 0; i < g.voxels.size(); ++i) {
        single.voxels = {g.voxels[i]};
        SplatBuilder one;
        one.begin(cam);
        one.add(single, m);
        ASSERT_EQ(one.splats().size(), 1u);
        const Splat& a = all.splats()[i];
        const Splat& b = one.splats()[0];
        const float tol = 1e-5f;
        EXPECT_LT(glm::length(a.center - b.center), tol) << i;
        EXPECT_LT(glm::length(a.axisU - b.axisU), tol) << i;
        EXPECT_LT(glm::length(a.axisV - b.axisV), tol) << i;
        EXPECT_NEAR(a.density, b.density, tol * b.density) << i;
        EXPECT_NEAR(a.depth, b.depth, tol * b.depth) << i;
        EXPECT_EQ(a.color, b.color) << i;
        EXPECT_EQ(a.layer, b.layer) << i;
    }
}

// A voxel's texture index wraps around its set (any 32-bit index, any set
// size), and the cross-fade partner is the next texture, wrapping at the end.
TEST(SplatBuilder, TextureIndexWrapsAroundItsSet) {
    Materials m{Footprint{}};
    m.addTextureSet(TextureSet::turbulence({.count = 2, .size = 16}));
    const std::uint32_t set = m.addTextureSet(TextureSet::turbulence({.count = 7, .size = 16}));
    const Materials::SetRange range = m.set(set);
    ASSERT_EQ(range.count, 7u);
    Grid g;
    const std::uint32_t textures[] = {0u, 6u, 7u, 13u, 12345678u, 0x7fffffffu, 0xfffffffeu, 0xffffffffu};
    for (std::uint32_t t : textures) {
        Voxel v;
        v.cell = {int(g.voxels.size()), 0, 0};
        v.texture = t;
        g.voxels.push_back(v);
    }
    g.dims = {int(g.voxels.size()), 1, 1};
    SplatBuilder b;
    b.begin(Camera::lookAt({0, 0, 20}, {0, 0, 0}, {0, 1, 0}, 1.0f, {64, 64}));
    b.add(g, m, {.textureSet = set});
    ASSERT_EQ(b.splats().size(), g.voxels.size());
    for (size_t i = 0; i < g.voxels.size(); ++i) {
        const std::uint32_t index = textures[i] % 7u;
        EXPECT_EQ(b.splats()[i].layer, range.first + index) << textures[i];
        EXPECT_EQ(b.splats()[i].nextLayer, range.first + (index + 1) % 7u) << textures[i];
    }
}

// The depth cut's along-ray scale (issue 15): splatRayScale must give the
// world length of one kernel unit along the centre ray, 1 / |M^-1 d|, for an
// anisotropic, rotated, stretched kernel, and the spacing for a cubic one.
TEST(SplatBuilder, RayScaleIsTheKernelsLengthAlongTheRay) {
    const Materials m = plainMaterials();
    const float R = m.footprint().radius();
    for (int stretched = 0; stretched < 2; ++stretched) {
        Grid g;
        g.spacing = {0.7f, 1.9f, 1.1f};
        g.transform = glm::rotate(glm::mat4(1.0f), 0.6f, glm::normalize(glm::vec3(1, 2, 0.5f)));
        Voxel v;
        if (stretched) v.stretch = {0.8f, 0.3f, -0.5f};
        g.voxels.push_back(v);
        const glm::vec3 eye(3.0f, 4.0f, 12.0f);
        SplatBuilder b;
        b.begin(Camera::lookAt(eye, {0, 0, 0}, {0, 1, 0}, 1.0f, {64, 64}));
        b.add(g, m);
        ASSERT_EQ(b.splats().size(), 1u);
        const Splat& s = b.splats()[0];
        glm::dmat3 M = glm::dmat3(glm::mat3(g.transform)) * glm::dmat3(glm::dvec3(0.7, 0, 0), glm::dvec3(0, 1.9, 0), glm::dvec3(0, 0, 1.1));
        if (stretched) {
            const glm::dvec3 st(0.8, 0.3, -0.5);
            const double sl = glm::length(st);
            M = M * (glm::dmat3(1.0) + sl * glm::outerProduct(st / sl, st / sl));
        }
        const glm::dvec3 d = glm::normalize(glm::dvec3(s.center) - glm::dvec3(eye));
        const double expected = 1.0 / glm::length(glm::inverse(M) * d);
        // The code stores rho in 1/32 steps of log2: at most 2^(1/64) - 1 = 1.09 % off.
        EXPECT_NEAR(splatRayScale(s, R), expected, 0.011 * expected) << "stretched " << stretched;
        EXPECT_NE(s.color >> 24, 255u); // anisotropic: a code is stored
    }
    // Cubic spacing: exactly the spacing, code 255.
    Grid g;
    g.spacing = glm::vec3(0.8f);
    g.voxels.push_back(Voxel{});
    SplatBuilder b;
    b.begin(Camera::lookAt({2, 1, 9}, {0, 0, 0}, {0, 1, 0}, 1.0f, {64, 64}));
    b.add(g, m);
    ASSERT_EQ(b.splats().size(), 1u);
    EXPECT_EQ(b.splats()[0].color >> 24, 255u);
    EXPECT_NEAR(splatRayScale(b.splats()[0], R), 0.8f, 1e-5f);
    // Codes round-trip; bad input is clamped, never NaN.
    for (float rho : {0.2f, 0.5f, 1.0f, 1.7f, 9.0f}) EXPECT_NEAR(rayScaleRho(rayScaleCode(rho)), rho, 0.011f * rho);
    EXPECT_EQ(rayScaleCode(std::nanf("")), 0);
    EXPECT_GT(rayScaleRho(rayScaleCode(1e9f)), 10.0f);
}

// SplatVariation (issue 25): each option changes only what it says, the
// same way on every build of the same cells and seed.
namespace {
std::vector<Splat> buildVaried(const Grid& g, const Materials& m, const Camera& cam, const SplatVariation& v) {
    SplatBuilder b;
    b.begin(cam);
    b.add(g, m, {.textureSet = 0, .colorTable = 0, .variation = v});
    return b.splats(); // grid order: splat i is voxel i
}
} // namespace

TEST(SplatVariation, RotationAndMirrorTurnOnlyTheTexture) {
    const Materials m = plainMaterials();
    Grid g = *Grid::box({5, 6, 4}, glm::vec3(0.5f, 0.4f, 0.7f)); // non-cubic: anisotropic ellipses
    const Camera cam = Camera::lookAt({3, 4, 6}, {0, 1, 0}, {0, 1, 0}, glm::radians(50.0f), {320, 240}, 0.1f, 100.0f);
    const std::vector<Splat> plain = buildVaried(g, m, cam, {});
    const std::vector<Splat> turned = buildVaried(g, m, cam, {.rotationRad = 3.14159265f, .mirror = true, .seed = 7});
    ASSERT_EQ(plain.size(), turned.size());
    int mirrored = 0, turnedFar = 0;
    for (std::size_t i = 0; i < plain.size(); ++i) {
        const Splat &a = plain[i], &b = turned[i];
        EXPECT_EQ(a.center, b.center);
        EXPECT_EQ(a.density, b.density);
        EXPECT_EQ(a.layer, b.layer);
        // The footprint is F(|(u, v)|) over the ellipse: the same ellipse iff
        // U U^T + V V^T is unchanged (an orthogonal change of (u, v) keeps it).
        const glm::mat3 qa = glm::outerProduct(a.axisU, a.axisU) + glm::outerProduct(a.axisV, a.axisV);
        const glm::mat3 qb = glm::outerProduct(b.axisU, b.axisU) + glm::outerProduct(b.axisV, b.axisV);
        const float scale = glm::length(a.axisU) * glm::length(a.axisU);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(qa[r][c], qb[r][c], 1e-5f * scale); // float rounding of a 2x2 rotation
        mirrored += glm::dot(glm::cross(a.axisU, a.axisV), glm::cross(b.axisU, b.axisV)) < 0.0f;
        turnedFar += glm::dot(glm::normalize(a.axisV), glm::normalize(b.axisV)) < 0.0f;
    }
    // About half mirrored and half turned by more than 90 degrees (120 voxels: 3 sigma is +-16).
    EXPECT_NEAR(mirrored, 60, 17);
    EXPECT_NEAR(turnedFar, 60, 17);
    EXPECT_EQ(buildVaried(g, m, cam, {.rotationRad = 3.14159265f, .mirror = true, .seed = 7})[5].axisU, turned[5].axisU); // deterministic
}

TEST(SplatVariation, JitterStaysInTheCellAndScaleKeepsTheMaterial) {
    const Materials m = plainMaterials();
    Grid g = *Grid::box({6, 6, 6}, glm::vec3(0.5f));
    const Camera cam = Camera::lookAt({0, 1.5f, 9}, {0, 1.5f, 0}, {0, 1, 0}, glm::radians(50.0f), {320, 240}, 0.1f, 100.0f);
    const std::vector<Splat> plain = buildVaried(g, m, cam, {});
    const std::vector<Splat> moved = buildVaried(g, m, cam, {.jitter = 0.5f, .seed = 3});
    const std::vector<Splat> sized = buildVaried(g, m, cam, {.scaleLog2 = 0.5f, .seed = 3});
    ASSERT_EQ(plain.size(), moved.size());
    float largest = 0.0f;
    for (std::size_t i = 0; i < plain.size(); ++i) {
        const glm::vec3 d = moved[i].center - plain[i].center;
        largest = std::max({largest, std::abs(d.x), std::abs(d.y), std::abs(d.z)});
        EXPECT_LE(std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}), 0.25f + 1e-5f); // half a cell of 0.5
        const float s = glm::length(sized[i].axisU) / glm::length(plain[i].axisU);
        EXPECT_GE(s, std::exp2(-0.5f) * (1.0f - 1e-5f));
        EXPECT_LE(s, std::exp2(0.5f) * (1.0f + 1e-5f));
        // Material = density x ellipse area: kept (float rounding).
        EXPECT_NEAR(sized[i].density * s * s, plain[i].density, 1e-5f * plain[i].density);
    }
    EXPECT_GT(largest, 0.2f); // 216 voxels x 3 axes: some offset reaches past 0.2 of the 0.25
    const std::vector<Splat> other = buildVaried(g, m, cam, {.jitter = 0.5f, .seed = 4});
    EXPECT_NE(other[0].center, moved[0].center); // the seed matters
}

TEST(SplatVariation, OutOfRangeFieldsAreNamed) {
    EXPECT_EQ(checkSplatVariation({.jitter = 1.2f}), "variation.jitter must be in [0, 1], got 1.200000");
    EXPECT_EQ(checkSplatVariation({.rotationRad = -1.0f}, "style."), "style.rotationRad must be in [0, 3.14159], got -1.000000");
    EXPECT_EQ(checkSplatVariation({.scaleLog2 = std::nanf("")}), "variation.scaleLog2 must be in [0, 1], got nan");
    EXPECT_EQ(checkSplatVariation(SplatVariation::recommended(1)), "");
}

TEST(SplatVariation, PlainFootprintsStayOnTheLattice) {
    // Fig. 1a's traditional splats: no stamp to hide, and the lattice reconstructs the field best.
    const Materials m = plainMaterials();
    Grid g = *Grid::box({4, 4, 4}, glm::vec3(0.5f));
    const Camera cam = Camera::lookAt({0, 1, 6}, {0, 1, 0}, {0, 1, 0}, glm::radians(50.0f), {320, 240}, 0.1f, 100.0f);
    SplatBuilder a, b;
    a.begin(cam);
    b.begin(cam);
    a.add(g, m, {.textured = false});
    b.add(g, m, {.textured = false, .variation = SplatVariation::recommended(9)});
    ASSERT_EQ(a.splats().size(), b.splats().size());
    for (std::size_t i = 0; i < a.splats().size(); ++i) {
        EXPECT_EQ(a.splats()[i].center, b.splats()[i].center);
        EXPECT_EQ(a.splats()[i].axisU, b.splats()[i].axisU);
    }
}
