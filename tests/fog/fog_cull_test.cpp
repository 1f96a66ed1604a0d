// Fog terms a view cannot see are dropped (issue 24 item 4): each term's
// bound over the frustum's box is a true bound on its optical depth, and the
// Scene's culled fog moves no pixel's transmittance by more than the stated
// depth; with no fog in view the frame has none (no fog pass).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "splatfx/scene.hpp"

namespace splatfx {
namespace {

// A segment of length <= maxLen inside [lo, hi], seeded.
struct Segment {
    glm::dvec3 a, b;
};
Segment randomSegment(std::mt19937& rng, glm::dvec3 lo, glm::dvec3 hi) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto point = [&] { return lo + (hi - lo) * glm::dvec3(u(rng), u(rng), u(rng)); };
    return {point(), point()};
}

TEST(FogCull, EachTermsBoundHoldsForSegmentsInTheBox) {
    // Segments inside the box: the closed-form depth of a one-term fog never exceeds the term's bound
    // (relative slack 1e-9 for the closed forms' double rounding).
    const glm::dvec3 lo(-10, 0, -30), hi(10, 8, -2);
    const double diag = glm::length(hi - lo);
    const std::vector<FogTerm> terms = {
        FogTerm::point(0.8, {30, 4, -10}, 1.0, 2.0),
        FogTerm::point(0.8, {0, 4, -10}, 1.0, 2.0),                                  // inside the box: the line bound
        FogTerm::sphere(0.5, {14, 2, -15}, 3.0, 0.5, 1.0),
        FogTerm::line(0.3, {0, 0, 20}, {1, 0, 0}, 1.0, 0.5),                          // parallel to x, 22 units away
        FogTerm::polynomial1D(1.0, 0, {1.0, 0.0, -1.0}, 2.0, FogCellMode::ZeroOutside, 13.0), // cell x in [11, 15]: outside
    };
    std::mt19937 rng(7);
    for (std::size_t k = 0; k < terms.size(); ++k) {
        FogDesc one;
        one.terms = {terms[k]};
        auto fog = Fog::create(one);
        ASSERT_TRUE(fog) << fog.error();
        const double bound = fog->termDepthBound(0, 0.0, lo, hi, diag);
        ASSERT_TRUE(std::isfinite(bound)) << k;
        double worst = 0.0;
        for (int i = 0; i < 4000; ++i) {
            const Segment s = randomSegment(rng, lo, hi);
            worst = std::max(worst, fog->opticalDepth(s.a, s.b, 0.0));
        }
        // Through the centre of a point inside the box the whole-line bound is nearly reached.
        const double through = fog->opticalDepth({-10, 4, -10}, {10, 4, -10}, 0.0);
        worst = std::max(worst, through);
        EXPECT_LE(worst, bound * (1.0 + 1e-9)) << "term " << k;
        if (k == 4) {
            EXPECT_EQ(bound, 0.0) << "a zero-outside cell clear of the box adds nothing";
        }
    }
    // Terms that fill space have no bound.
    FogDesc space;
    space.terms = {FogTerm::constant(0.1), FogTerm::cosine(0.05, 1.0, {1, 0, 0})};
    auto filled = Fog::create(space);
    ASSERT_TRUE(filled);
    EXPECT_TRUE(std::isinf(filled->termDepthBound(0, 0.0, lo, hi, diag)));
    EXPECT_TRUE(std::isinf(filled->termDepthBound(1, 0.0, lo, hi, diag)));
}

// A forest of potentials over a 2 km square with a light constant haze: the
// camera sees a few; the rest are dropped.
FogDesc forest() {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.005));
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1000.0, 1000.0);
    for (int i = 0; i < 60; ++i) d.terms.push_back(FogTerm::point(0.4, {u(rng), 3.0, u(rng)}, 1.0, 4.0));
    d.terms.push_back(FogTerm::point(0.4, {2.0, 3.0, -15.0}, 1.0, 4.0)); // in view
    d.terms.push_back(FogTerm::sphere(0.2, {-5.0, 1.0, -30.0}, 4.0, 1.0, 1.0)); // in view
    return d;
}

TEST(FogCull, DroppedTermsMoveNoPixelByMoreThanTheStatedDepth) {
    Scene scene;
    Materials mat{Footprint{}};
    Frame frame;
    const Camera cam = Camera::lookAt({0, 3, 0}, {0, 3, -10}, {0, 1, 0}, 0.9f, {64, 48}, 0.1f, 60.0f);
    auto full = Fog::create(forest());
    ASSERT_TRUE(full) << full.error();
    scene.setFog(*full);
    ASSERT_TRUE(scene.prepare(0.0, cam, mat, frame));
    const SceneCounters& c = scene.counters();
    EXPECT_GT(c.fogTermsSkipped, 40u) << "most of the forest is far out of view";
    EXPECT_GE(c.fogTermsDrawn, 3u) << "the haze and the two potentials in view";
    EXPECT_EQ(c.fogTermsDrawn + c.fogTermsSkipped, full->desc().terms.size());
    EXPECT_FALSE(c.fogSkipped);
    EXPECT_EQ(c.fogCullFallbacks, 0u);
    ASSERT_NE(frame.fog(), nullptr);
    ASSERT_EQ(frame.fog()->desc().terms.size(), c.fogTermsDrawn);
    // Every pixel's ray, from the eye to 16 depths out to the far plane: the culled fog's
    // transmittance differs from the full one's by at most 1 - exp(-maxSkippedDepth) (dropping terms
    // of total depth <= D scales f by exp(-D) at worst), plus double rounding. Fogged colours
    // (f C + (1 - f) C_fog, channels in [0, 1]) move by at most as much.
    const double bound = 1.0 - std::exp(-scene.fogCulling().maxSkippedDepth) + 1e-12;
    const glm::mat4 inv = glm::inverse(cam.proj * cam.view);
    const glm::dvec3 eye(cam.eye());
    double worst = 0.0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) {
            const glm::vec4 f = inv * glm::vec4((x + 0.5f) / 64.0f * 2 - 1, (y + 0.5f) / 48.0f * 2 - 1, 1.0f, 1.0f);
            const glm::dvec3 farPoint = glm::dvec3(glm::vec3(f) / f.w);
            for (int k = 1; k <= 16; ++k) {
                const glm::dvec3 p = eye + (farPoint - eye) * (k / 16.0);
                worst = std::max(worst, std::abs(full->transmittance(eye, p, 0.0) - frame.fog()->transmittance(eye, p, 0.0)));
            }
        }
    EXPECT_LE(worst, bound);
}

TEST(FogCull, NoFogInViewMeansNoFogInTheFrame) {
    Scene scene;
    Materials mat{Footprint{}};
    Frame frame;
    const Camera cam = Camera::lookAt({0, 3, 0}, {0, 3, -10}, {0, 1, 0}, 0.9f, {32, 32}, 0.1f, 60.0f);
    FogDesc d;
    d.terms = {FogTerm::point(0.4, {0, 3, 900}, 1.0, 4.0), FogTerm::sphere(0.3, {800, 0, 0}, 5.0, 1.0, 1.0)};
    scene.setFog(*Fog::create(d));
    ASSERT_TRUE(scene.prepare(0.0, cam, mat, frame));
    EXPECT_EQ(frame.fog(), nullptr) << "nothing to draw: the fog pass is skipped";
    EXPECT_TRUE(scene.counters().fogSkipped);
    EXPECT_EQ(scene.counters().fogTermsSkipped, 2u);
    // A far cut-off within the view fogs it whatever the terms: the fog stays.
    d.farDistanceWorld = 30.0;
    scene.setFog(*Fog::create(d));
    ASSERT_TRUE(scene.prepare(0.1, cam, mat, frame));
    EXPECT_NE(frame.fog(), nullptr);
    EXPECT_FALSE(scene.counters().fogSkipped);
    // Culling off: every term, always.
    d.farDistanceWorld = 0.0;
    scene.setFog(*Fog::create(d));
    const Status bad = scene.setFogCulling({.maxSkippedDepth = -1.0});
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(), "FogCullDesc.maxSkippedDepth must be finite and >= 0 (an optical depth; 0 drops only terms that add nothing), got -1.000000");
    EXPECT_EQ(scene.fogCulling().maxSkippedDepth, 1.0 / 512.0) << "the previous desc is kept";
    ASSERT_TRUE(scene.setFogCulling({.enabled = false}));
    ASSERT_TRUE(scene.prepare(0.2, cam, mat, frame));
    ASSERT_NE(frame.fog(), nullptr);
    EXPECT_EQ(frame.fog(), scene.fog());
    EXPECT_EQ(scene.counters().fogTermsDrawn, 2u);
}

} // namespace
} // namespace splatfx
