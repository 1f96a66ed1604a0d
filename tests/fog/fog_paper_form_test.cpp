// Biri et al.'s eq. 9 as printed (FogPotentialForm::Segment): the term adds
// weight / (c + d r^2) to the optical depth, r the distance between the
// segment OP and the object. Held against distances found without the closed
// vertex (dense sampling, the quadrature's search), and for the properties
// that make it a usable transmittance.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "splatfx/fog.hpp"

namespace splatfx {
namespace {

Fog make(FogDesc d) {
    auto f = Fog::create(std::move(d));
    EXPECT_TRUE(f.ok()) << f.error();
    return std::move(*f);
}

FogDesc alone(FogTerm t) {
    FogDesc d;
    d.terms.push_back(std::move(t));
    return d;
}

FogTerm segmentForm(FogTerm t) {
    t.form = FogPotentialForm::Segment;
    return t;
}

// The squared distance from the segment to the point q, by sampling n + 1
// points: the true minimum r^2 lies below the best sample by at most
// (L / n)^2 / 4 (|x(s) - q|^2 grows like (s - s*)^2 away from its minimum s*,
// and s* is within half a spacing of a sample).
double sampledDistance2(glm::dvec3 o, glm::dvec3 p, glm::dvec3 q, int n) {
    double best = 1e300;
    for (int i = 0; i <= n; ++i) {
        const glm::dvec3 x = o + (p - o) * (double(i) / n);
        best = std::min(best, glm::dot(x - q, x - q));
    }
    return best;
}

TEST(FogPaperForm, PointDepthIsTheValueAtTheSegmentsNearestPoint) {
    const glm::dvec3 q{1.0, 2.0, -3.0};
    const double w = 0.7, c = 0.5, d = 0.2;
    const Fog fog = make(alone(segmentForm(FogTerm::point(w, q, c, d))));
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    constexpr int kSamples = 20000;
    for (int i = 0; i < 40; ++i) {
        const glm::dvec3 o{u(rng), u(rng), u(rng)}, p{u(rng), u(rng), u(rng)};
        const double L = glm::length(p - o);
        const double r2 = sampledDistance2(o, p, q, kSamples);
        const double expected = w / (c + d * r2);
        // r^2 is off by at most (L / n)^2 / 4; the depth by w d / c^2 times that.
        const double tol = w * d / (c * c) * 0.25 * (L / kSamples) * (L / kSamples) + 1e-14;
        EXPECT_NEAR(fog.opticalDepth(o, p, 0.0), expected, tol) << "segment " << i;
    }
    // The three places the nearest point can be: the start, inside, the end.
    EXPECT_NEAR(fog.opticalDepth(q + glm::dvec3(0, 3, 0), q + glm::dvec3(0, 9, 0), 0.0), w / (c + d * 9.0), 1e-15);
    EXPECT_NEAR(fog.opticalDepth(q + glm::dvec3(-4, 2, 0), q + glm::dvec3(4, 2, 0), 0.0), w / (c + d * 4.0), 1e-15);
    EXPECT_NEAR(fog.opticalDepth(q + glm::dvec3(0, 0, 8), q + glm::dvec3(0, 0, 5), 0.0), w / (c + d * 25.0), 1e-15);
}

// Every kind, with density terms beside it, against the reference quadrature
// (which finds each segment term's distance by search, not by the closed
// vertex, and integrates the density terms numerically), on random segments.
TEST(FogPaperForm, EveryKindMatchesTheQuadratureBesideDensityTerms) {
    FogDesc desc;
    desc.terms.push_back(FogTerm::constant(0.02));
    desc.terms.push_back(FogTerm::cosine(0.01, 0.5, {1, 0, 0.3}));
    desc.terms.push_back(segmentForm(FogTerm::point(0.6, {2, 0, 1}, 0.5, 0.3)));
    desc.terms.push_back(segmentForm(FogTerm::line(0.4, {-1, 0, 2}, {0.3, 1, 0.1}, 1.0, 0.2)));
    desc.terms.push_back(segmentForm(FogTerm::sphere(0.5, {0, 3, -2}, 2.0, 0.8, 0.5)));
    desc.terms.push_back(FogTerm::point(0.3, {1, 1, 1}, 1.0, 1.0));
    const Fog fog = make(desc);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-8.0, 8.0);
    for (int i = 0; i < 30; ++i) {
        const glm::dvec3 o{u(rng), u(rng), u(rng)}, p{u(rng), u(rng), u(rng)};
        const FogQuadrature q = integrateFogNumerically(fog, o, p, 0.0, 1e-10);
        ASSERT_TRUE(q.converged);
        // The quadrature's own estimate, plus the golden search's distance to
        // the minimum (1e-15 L: r^2 off by ~(1e-15 L)^2, nothing here) and
        // rounding of a few ulps of each term.
        EXPECT_NEAR(fog.opticalDepth(o, p, 0.0), q.value, q.errorEstimate + 1e-10 + 1e-13 * std::abs(q.value)) << "segment " << i;
    }
}

// What makes it a transmittance: along one ray from the eye the depth never
// falls (the segment only reaches nearer the object), stops growing once the
// nearest point is passed, and its weight is a depth, not a per-length density
// (a path 1000 times longer past the nearest point adds nothing).
TEST(FogPaperForm, DepthGrowsOnlyAsThePathNearsTheObject) {
    const glm::dvec3 q{0.0, 1.0, 10.0};
    for (FogTerm t : {FogTerm::point(1.0, q, 0.5, 0.1), FogTerm::line(1.0, q, {1, 0, 0}, 0.5, 0.1), FogTerm::sphere(1.0, q, 3.0, 0.5, 0.1)}) {
        const Fog fog = make(alone(segmentForm(t)));
        const glm::dvec3 eye{0.0}, dir = glm::normalize(glm::dvec3(0.1, 0.05, 1.0));
        double last = 0.0;
        for (int i = 1; i <= 400; ++i) {
            const double depth = fog.opticalDepth(eye, eye + dir * (0.05 * i), 0.0);
            EXPECT_GE(depth, last) << "step " << i; // exact: a clamped nearest point only moves nearer
            last = depth;
        }
        // Past the nearest approach (s ~ 10) the segment's distance is fixed.
        EXPECT_EQ(fog.opticalDepth(eye, eye + dir * 20.0, 0.0), fog.opticalDepth(eye, eye + dir * 20000.0, 0.0));
        EXPECT_GT(fog.transmittance(eye, eye + dir * 20.0, 0.0), 0.0);
    }
}

TEST(FogPaperForm, ANegativeWeightIsRefusedWithTheFieldNamed) {
    FogDesc desc;
    desc.terms.push_back(FogTerm::constant(1.0));
    desc.terms.push_back(segmentForm(FogTerm::point(-0.1, {0, 0, 0}, 1.0, 1.0)));
    auto fog = Fog::create(desc);
    ASSERT_FALSE(fog.ok());
    EXPECT_NE(fog.error().find("terms[1].weight"), std::string::npos) << fog.error();
    EXPECT_NE(fog.error().find("Segment"), std::string::npos) << fog.error();
    // A density term of the same weight is fine beside the constant (it cannot take the density below 0).
    desc.terms[1].form = FogPotentialForm::Density;
    EXPECT_TRUE(Fog::create(desc).ok());
}

} // namespace
} // namespace splatfx
