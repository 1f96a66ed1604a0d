#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/lighting.hpp"

using splatfx::HgLobe;
using splatfx::PhaseFunction;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Composite Simpson with 400 panels. Callers split the range so that the
// integrand varies on the scale of each piece (geometric cuts towards a
// lobe's peak); Simpson's error is then ~(1/400)^4 ~ 4e-11 relative.
double integrate(const std::function<double(double)>& f, double a, double b) {
    constexpr int n = 400;
    const double h = (b - a) / n;
    double sum = f(a) + f(b);
    for (int i = 1; i < n; ++i) sum += f(a + i * h) * ((i & 1) ? 4.0 : 2.0);
    return sum * h / 3.0;
}

// Over the sphere: 2 pi times the integral over mu = cos theta. For g near 1
// the lobe is a spike of width (1 - g)^2 at mu = 1, so the range is split
// geometrically towards both ends, where adaptive Simpson then resolves it.
double sphereIntegral(const std::function<double(double)>& f) {
    double sum = 0.0;
    std::vector<double> cuts{-1.0};
    for (double e = 0.1; e > 1e-14; e *= 0.1) cuts.push_back(-1.0 + e);
    for (double e = 1e-14; e < 0.5; e *= 10.0) cuts.push_back(1.0 - e);
    cuts.push_back(1.0);
    std::sort(cuts.begin(), cuts.end());
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
        if (cuts[i + 1] > cuts[i]) sum += integrate(f, cuts[i], cuts[i + 1]);
    return 2.0 * kPi * sum;
}

} // namespace

// The float evaluation is within a few ulps relative (each of the few
// operations rounds once, then one float conversion): 1e-6 is ~16 ulps. The
// quadrature's own error is below 1e-9.
constexpr double kRel = 1e-6;

TEST(Phase, HenyeyGreensteinIntegratesToOneOverTheSphere) {
    // Through the float-cosine entry point for moderate g, where float mu
    // resolves the lobe (its width in 1 - mu, (1 - g)^2 / 2g, is >= 5e-3).
    for (float g : {-0.9f, -0.5f, 0.0f, 0.3f, 0.9f}) {
        const double I = sphereIntegral([g](double mu) { return double(PhaseFunction::henyeyGreenstein(g, float(mu))); });
        EXPECT_NEAR(I, 1.0, kRel) << "g = " << g;
    }
    // Through the direction entry point for every g up to +-0.999, over
    // theta (2 pi int p sin theta dtheta) with float unit vectors, as the
    // lighting calls it; theta is split geometrically towards 0 and pi.
    for (float g : {-0.999f, -0.99f, -0.5f, 0.0f, 0.5f, 0.99f, 0.999f}) {
        const HgLobe lobe[] = {{g, 1.0f}};
        const PhaseFunction p = *PhaseFunction::create(lobe);
        auto f = [&](double th) {
            const glm::vec3 a(0.0f, 0.0f, 1.0f), b(float(std::sin(th)), 0.0f, float(std::cos(th)));
            return double(p(a, b)) * std::sin(th);
        };
        std::vector<double> cuts{0.0, kPi};
        for (double e = 1e-7; e < 0.5; e *= 10.0) cuts.push_back(e), cuts.push_back(kPi - e);
        std::sort(cuts.begin(), cuts.end());
        double I = 0.0;
        for (std::size_t i = 0; i + 1 < cuts.size(); ++i) I += integrate(f, cuts[i], cuts[i + 1]);
        EXPECT_NEAR(2.0 * kPi * I, 1.0, kRel) << "g = " << g;
    }
}

TEST(Phase, HenyeyGreensteinMeanCosineIsG) {
    // A defining property of HG: <cos theta> = g.
    for (float g : {-0.7f, 0.0f, 0.5f, 0.95f}) {
        const double m = sphereIntegral([g](double mu) { return mu * double(PhaseFunction::henyeyGreenstein(g, float(mu))); });
        EXPECT_NEAR(m, g, kRel) << "g = " << g;
    }
}

TEST(Phase, WeightedSumIsNormalized) {
    const HgLobe lobes[] = {{0.8f, 7.0f}, {-0.4f, 3.0f}};
    auto p = PhaseFunction::create(lobes);
    ASSERT_TRUE(p) << p.error();
    EXPECT_FLOAT_EQ(p->lobe(0).weight, 0.7f);
    EXPECT_FLOAT_EQ(p->lobe(1).weight, 0.3f);
    const double I = sphereIntegral([&](double mu) { return double((*p)(float(mu))); });
    EXPECT_NEAR(I, 1.0, kRel);
    const double m = sphereIntegral([&](double mu) { return mu * double((*p)(float(mu))); });
    EXPECT_NEAR(m, 0.7 * 0.8 + 0.3 * -0.4, kRel);
}

TEST(Phase, ExtremeGIsFiniteAndMatchesTheClosedForm) {
    for (float g : {-0.999f, 0.999f}) {
        for (float mu : {-1.0f, -0.999999f, -0.5f, 0.0f, 0.5f, 0.999999f, 1.0f}) {
            const float p = PhaseFunction::henyeyGreenstein(g, mu);
            const long double G = g, M = mu;
            const long double ref = (1.0L - G * G) / (4.0L * 3.14159265358979323846L * std::pow(1.0L + G * G - 2.0L * G * M, 1.5L));
            ASSERT_TRUE(std::isfinite(p)) << "g " << g << " mu " << mu;
            EXPECT_NEAR(double(p), double(ref), kRel * double(ref)) << "g " << g << " mu " << mu;
        }
    }
    // The peak: (1 + g) / (4 pi (1 - g)^2), about 1.6e5 for g = 0.999.
    EXPECT_NEAR(PhaseFunction::henyeyGreenstein(0.999f, 1.0f), 1.999 / (4.0 * kPi * 1e-6), 1.999 / (4.0 * kPi * 1e-6) * 1e-3);
    EXPECT_TRUE(std::isfinite(PhaseFunction::henyeyGreenstein(0.5f, std::nanf(""))));
}

TEST(Phase, DefaultIsIsotropic) {
    const PhaseFunction p;
    for (float mu : {-1.0f, 0.0f, 0.7f, 1.0f}) EXPECT_FLOAT_EQ(p(mu), float(1.0 / (4.0 * kPi)));
}

TEST(Phase, BadLobesNameTheField) {
    const HgLobe one[] = {{1.0f, 1.0f}};
    auto a = PhaseFunction::create(one);
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("lobes[0].g must be in (-1, 1)"), std::string::npos) << a.error();
    const HgLobe neg[] = {{0.2f, 1.0f}, {0.1f, -1.0f}};
    auto b = PhaseFunction::create(neg);
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().find("lobes[1].weight"), std::string::npos) << b.error();
    auto c = PhaseFunction::create({});
    ASSERT_FALSE(c);
    EXPECT_NE(c.error().find("at least one"), std::string::npos);
    const HgLobe five[5] = {};
    auto d = PhaseFunction::create(five);
    ASSERT_FALSE(d);
    EXPECT_NE(d.error().find("at most 4"), std::string::npos) << d.error();
    const HgLobe zero[] = {{0.2f, 0.0f}};
    auto e = PhaseFunction::create(zero);
    ASSERT_FALSE(e);
    EXPECT_NE(e.error().find("weight must be positive"), std::string::npos) << e.error();
    const HgLobe nan[] = {{std::nanf(""), 1.0f}};
    EXPECT_FALSE(PhaseFunction::create(nan));
}
