// More hard cases of volumes as light (docs/STABILITY.md, "Volumes as
// light"): splats all at one point, an occlusion grid of one bin, a light in
// the surface's own plane, emitters that emit nothing, a fire too dense to
// let any light out. Each test is named after what would go wrong.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/emitted_light.hpp"
#include "splatfx/reference.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// A round splat of world support radius a at c, its plane facing p, plain
// footprint (layer 0), colour row `row` (as emitted_light_test.cpp's).
Splat facing(glm::vec3 c, glm::vec3 p, float a, float density, std::uint32_t row) {
    const glm::vec3 w = glm::normalize(p - c);
    const glm::vec3 helper = std::abs(w.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 u = glm::normalize(glm::cross(helper, w)), v = glm::cross(w, u);
    Splat s;
    s.center = c;
    s.density = density;
    s.axisU = u * a;
    s.axisV = v * a;
    s.colorRow = float(row);
    s.colorCoord = 0.5f;
    s.depth = glm::length(p - c);
    return s;
}

struct Plain {
    Materials m{Footprint{}};
    std::uint32_t row = m.addColorTable(ColorTable::constant({1.0f, 0.5f, 0.25f, 1.0f}));
};

// The mean alpha the fit takes over a plain splat's quad: its 16 x 16
// samples of the stored layer-0 window (emitted_light.cpp's emission()),
// here in double.
double meanAlpha(const Materials& m, double density) {
    const int n = m.layerSize(), stride = std::max(1, n / 16);
    double sum = 0.0;
    int count = 0;
    for (int y = stride / 2; y < n; y += stride)
        for (int x = stride / 2; x < n; x += stride, ++count)
            sum += -std::expm1(-std::log(2.0) * density * double(m.layer(0)[(std::size_t(y) * n + x) * 4 + 3]));
    return sum / count;
}

} // namespace

TEST(EmittedLightHardCases, SplatsAllAtOnePointFitOneLightNotSeveralCoincidentOnes) {
    // Six identical splats at one point, four lights asked: the slices along
    // the principal axis (there is none: zero covariance) split them into
    // four clusters with one centre, which k-means never separates: four
    // lights at the same place, taking four of the frame's eight slots for
    // what one light gives exactly. One light: at the point, radius 0, six
    // times one splat's intensity (a float sum of six equal terms: within
    // 6 ulps). Two such points give two lights.
    Plain p;
    const glm::vec3 c(0.3f, 0.4f, -2.0f), eye(0.0f);
    const Splat one = facing(c, eye, 0.1f, 1.5f, p.row);
    auto single = fitEmittedLights(std::vector<Splat>{one}, p.m, {.enabled = true, .occlusion = false});
    ASSERT_TRUE(single && single->size() == 1u);
    const glm::vec3 I1 = (*single)[0].intensity;
    auto six = fitEmittedLights(std::vector<Splat>(6, one), p.m, {.enabled = true, .lights = 4, .occlusion = false});
    ASSERT_TRUE(six) << six.error();
    ASSERT_EQ(six->size(), 1u) << "coincident splats are one light";
    EXPECT_EQ((*six)[0].position, c);
    EXPECT_EQ((*six)[0].radius, 0.0f);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR((*six)[0].intensity[k], 6.0f * I1[k], 6.0f * I1[k] * 6.0f * 0x1p-24f);

    std::vector<Splat> two(3, one);
    const Splat other = facing(c + glm::vec3(1.0f, 0.0f, 0.0f), eye, 0.1f, 1.5f, p.row);
    two.insert(two.end(), 3, other);
    auto pair = fitEmittedLights(two, p.m, {.enabled = true, .lights = 4, .occlusion = false});
    ASSERT_TRUE(pair) << pair.error();
    ASSERT_EQ(pair->size(), 2u);
    for (const EmittedLight& l : *pair) {
        EXPECT_TRUE(l.position == one.center || l.position == other.center);
        EXPECT_EQ(l.radius, 0.0f);
        EXPECT_NEAR(l.intensity.x, 3.0f * I1.x, 3.0f * I1.x * 3.0f * 0x1p-24f * 4.0f); // 3 terms; the two splats' areas differ by ulps (their axes)
    }
}

TEST(EmittedLightHardCases, SplatsAtOnePointShareOneOcclusionBinInClosedForm) {
    // All splats at one point make an occlusion grid of one bin (the extent
    // is one bin wide on every axis), whose face is the bin's side squared,
    // the mean |U x V|. Each splat sees half of the others' optical area
    // ahead along every axis direction: N splats of mean alpha A escape
    // exp2(-0.5 (N - 1) 4 |U x V| (-log2(1 - A)) / |U x V|) = (1 - A)^(2 (N - 1)),
    // the same for all six directions. Float: the optical depth is a sum of
    // N terms and a division (N + 3 ulps of tau), exp2 a few more: 16 ulps
    // of tau ln 2 relative, and the shares' power-weighted mean (N ulps).
    Plain p;
    const float density = 0.8f;
    const Splat one = facing({0.3f, 0.4f, -2.0f}, glm::vec3(0.0f), 0.1f, density, p.row);
    for (int N : {1, 2, 5}) {
        auto lights = fitEmittedLights(std::vector<Splat>(std::size_t(N), one), p.m, {.enabled = true, .occlusion = true});
        ASSERT_TRUE(lights && lights->size() == 1u);
        const double A = meanAlpha(p.m, density);
        const double want = std::pow(1.0 - A, 2.0 * (N - 1));
        const double tau = -2.0 * (N - 1) * std::log2(1.0 - A);
        const double tol = want * (tau * std::log(2.0) * (N + 16) + N) * 0x1p-24 + 1e-30;
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR((*lights)[0].escapePlus[a], want, tol) << N << " splats, axis " << a;
            EXPECT_NEAR((*lights)[0].escapeMinus[a], want, tol) << N << " splats, axis " << a;
        }
    }
}

TEST(EmittedLightHardCases, ALightInTheSurfacesPlaneOrBehindItGivesNothingAndNeverNegative) {
    // A light exactly in the surface's tangent plane (cos theta = 0), and
    // one turned 10^-6 rad behind it: the fitted light gives exactly 0, never
    // a negative or NaN irradiance. The exact irradiance of the splat in the
    // plane is not 0 (half its disc is above the horizon) but at most its
    // largest cosine, a / d, times I / d^2 (every ray's cosine is <= a / d),
    // plus the reference's error estimate: the point law's error at grazing
    // light is that small.
    Plain p;
    const glm::vec3 point(0.0f), normal(0.0f, 1.0f, 0.0f);
    const float a = 0.05f, d = 2.0f;
    for (double behind : {0.0, 1e-6}) {
        const glm::vec3 c(0.0f, float(-d * std::sin(behind)), float(-d * std::cos(behind)));
        const std::vector<Splat> splats{facing(c, point, a, 1.5f, p.row)};
        auto lights = fitEmittedLights(splats, p.m, {.enabled = true, .occlusion = false});
        ASSERT_TRUE(lights && lights->size() == 1u);
        const glm::vec3 e = emittedIrradiance(*lights, point, normal);
        EXPECT_EQ(e, glm::vec3(0.0f)) << "behind " << behind;
        auto exact = emittedIrradianceExact(splats, p.m, glm::dvec3(point), glm::dvec3(normal), {.faceSize = 128});
        ASSERT_TRUE(exact) << exact.error();
        const double I = (*lights)[0].intensity.x;
        EXPECT_GE(exact->irradiance.x, 0.0);
        EXPECT_LE(exact->irradiance.x, I / (d * d) * (a / d) * 1.01 + exact->errorEstimate) << "1 % for the fit's own intensity quadrature";
    }
}

TEST(EmittedLightHardCases, EmittersThatEmitNothingGiveNoLightAndChangeNoOtherLight) {
    // Zero-opacity splats (density 0: no alpha, no colour) and a scale of 0
    // emit nothing: no light and no grid node other than 0, not an error and
    // not a light of intensity 0 taking a slot. Zero-opacity splats among
    // emitting ones (anywhere, here far away) leave the lights bit for bit
    // as without them: they neither move the centroid nor occlude.
    Plain p;
    const glm::vec3 eye(0.0f);
    std::vector<Splat> fire;
    for (int i = 0; i < 4; ++i) fire.push_back(facing({0.1f * float(i), 0.2f, -2.0f}, eye, 0.1f, 1.2f, p.row));
    Splat dead = facing({0.1f, 0.2f, -2.05f}, eye, 0.1f, 0.0f, p.row);
    auto none = fitEmittedLights(std::vector<Splat>(3, dead), p.m, {.enabled = true, .lights = 2});
    ASSERT_TRUE(none) << none.error();
    EXPECT_TRUE(none->empty());
    auto scaled0 = fitEmittedLights(fire, p.m, {.enabled = true, .lights = 2, .scale = 0.0f});
    ASSERT_TRUE(scaled0) << scaled0.error();
    EXPECT_TRUE(scaled0->empty()) << "a light of intensity 0 must not take a slot";
    auto grid0 = fitEmittedGrid(fire, p.m, {.enabled = true, .mode = EmittedLightMode::Grid, .scale = 0.0f});
    ASSERT_TRUE(grid0) << grid0.error();
    for (const auto& node : grid0->nodes)
        for (const glm::vec3& v : node) EXPECT_EQ(v, glm::vec3(0.0f));
    EXPECT_EQ(emittedIrradiance(*grid0, glm::vec3(5.0f), {0, 1, 0}), glm::vec3(0.0f));

    auto clean = fitEmittedLights(fire, p.m, {.enabled = true, .lights = 2});
    std::vector<Splat> mixed = fire;
    mixed.insert(mixed.begin() + 1, dead);
    dead.center = glm::vec3(40.0f, 0.0f, -3.0f);
    mixed.push_back(dead);
    auto withDead = fitEmittedLights(mixed, p.m, {.enabled = true, .lights = 2});
    ASSERT_TRUE(clean && withDead);
    EXPECT_TRUE(test::sameLights(*withDead, *clean));
}

TEST(EmittedLightHardCases, AFireTooDenseToLetLightOutGivesFiniteZeroNotNaN) {
    // 125 opaque splats (density 10^3: each sample's alpha rounds to 1, the
    // mean clamped just below 1, an optical depth of about 20 each) packed in
    // a 5^3 block: the inner splats' escape underflows to exactly 0 (exp2 of
    // minus hundreds). Every light and node stays finite, every escape share
    // in [0, 1], the lights' intensity is the splats' (occlusion scales the
    // escape, not the intensity: the same as with occlusion off, bit for bit),
    // and the irradiance beside the block is finite and >= 0.
    Plain p;
    std::vector<Splat> block;
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 5; ++x) block.push_back(facing(glm::vec3(x, y, z) * 0.1f + glm::vec3(0.0f, 0.0f, -3.0f), glm::vec3(0.0f), 0.1f, 1e3f, p.row));
    auto on = fitEmittedLights(block, p.m, {.enabled = true, .lights = 3, .occlusion = true});
    auto off = fitEmittedLights(block, p.m, {.enabled = true, .lights = 3, .occlusion = false});
    ASSERT_TRUE(on && off);
    ASSERT_FALSE(on->empty());
    glm::vec3 sumOn(0.0f), sumOff(0.0f);
    for (const EmittedLight& l : *on) {
        for (int a = 0; a < 3; ++a) {
            EXPECT_TRUE(l.escapePlus[a] >= 0.0f && l.escapePlus[a] <= 1.0f);
            EXPECT_TRUE(l.escapeMinus[a] >= 0.0f && l.escapeMinus[a] <= 1.0f);
        }
        EXPECT_TRUE(std::isfinite(l.radius) && std::isfinite(l.position.x + l.position.y + l.position.z));
        sumOn += l.intensity;
    }
    for (const EmittedLight& l : *off) sumOff += l.intensity;
    // Clustered differently (the weights carry the escape), so summed in another order: 125 terms, 125 ulps.
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(sumOn[a], sumOff[a], sumOff[a] * 125.0f * 0x1p-24f);
    const glm::vec3 e = emittedIrradiance(*on, {0.2f, 0.2f, -2.0f}, {0.0f, 0.0f, -1.0f});
    EXPECT_TRUE(std::isfinite(e.x) && e.x >= 0.0f && e.x < emittedIrradiance(*off, {0.2f, 0.2f, -2.0f}, {0.0f, 0.0f, -1.0f}).x);
    auto grid = fitEmittedGrid(block, p.m, {.enabled = true, .mode = EmittedLightMode::Grid, .occlusion = true});
    ASSERT_TRUE(grid) << grid.error();
    for (const auto& node : grid->nodes)
        for (const glm::vec3& v : node) EXPECT_TRUE(std::isfinite(v.x) && v.x >= 0.0f);
}
