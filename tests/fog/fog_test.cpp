// The fog model (Biri et al. 2002): every term's closed-form integral against
// the adaptive quadrature, wind and time, validation messages, the paper's fogs.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "splatfx/fog.hpp"

namespace splatfx {
namespace {

constexpr double kPi = std::numbers::pi;

Fog make(FogDesc d) {
    auto f = Fog::create(std::move(d));
    EXPECT_TRUE(f.ok()) << f.error();
    return std::move(*f);
}

// The closed form against the quadrature on seeded random segments. The
// quadrature is asked for tolerance `tol` on each segment; its K15-G7
// estimate is conservative, so the two agree to tol plus the closed form's
// own rounding (a few hundred ulps of the optical depth, 1e-13 relative).
void expectMatchesQuadrature(const Fog& fog, double extent, double tSec = 0.0, int segments = 24, double tol = 1e-9) {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> u(-extent, extent);
    for (int i = 0; i < segments; ++i) {
        const glm::dvec3 o{u(rng), u(rng), u(rng)}, p{u(rng), u(rng), u(rng)};
        const double closed = fog.opticalDepth(o, p, tSec);
        const FogQuadrature q = integrateFogNumerically(fog, o, p, tSec, tol);
        ASSERT_TRUE(q.converged) << "segment " << i;
        EXPECT_NEAR(closed, q.value, tol + 1e-13 * std::abs(q.value))
            << "segment " << i << " from (" << o.x << ", " << o.y << ", " << o.z << ") to (" << p.x << ", " << p.y << ", " << p.z << ")";
    }
}

TEST(FogQuadrature, IntegratesADegreeNinePolynomialExactly) {
    // u^9 + u^8 on a segment inside a zero-outside cell: the exact integral is known by hand.
    FogDesc d;
    FogTerm t = FogTerm::polynomial1D(1.0, 0, {0, 0, 0, 0, 0, 0, 0, 0, 1, 1}, 2.0, FogCellMode::ZeroOutside);
    d.terms.push_back(FogTerm::constant(1.0)); // keeps the sum positive for u in [-1, 0]
    d.terms.push_back(t);
    const Fog fog = make(d);
    // x from -1 to 1.5 (u = x / 2 from -0.5 to 0.75): 2.5 + 2 * [u^10/10 + u^9/9]
    auto F = [](double u) { return std::pow(u, 10) / 10 + std::pow(u, 9) / 9; };
    const double exact = 2.5 + 2.0 * (F(0.75) - F(-0.5));
    const FogQuadrature q = integrateFogNumerically(fog, {-1, 0, 0}, {1.5, 0, 0}, 0.0, 1e-12);
    EXPECT_NEAR(q.value, exact, 1e-12);
    EXPECT_NEAR(fog.opticalDepth({-1, 0, 0}, {1.5, 0, 0}, 0.0), exact, 1e-13);
}

TEST(FogTerms, ConstantIsLengthTimesWeight) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.3));
    const Fog fog = make(d);
    EXPECT_NEAR(fog.opticalDepth({1, 2, 3}, {4, 6, 3}, 0.0), 0.3 * 5.0, 1e-15);
    EXPECT_NEAR(fog.transmittance({1, 2, 3}, {4, 6, 3}, 0.0), std::exp(-1.5), 1e-15);
}

TEST(FogTerms, CosineOnAnAxisAndOnAnyDirection) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(2.0));
    d.terms.push_back(FogTerm::cosine(0.7, 3.0, {0, 1, 0}, 0.4));
    d.terms.push_back(FogTerm::cosine(-0.5, 1.7, {1, -2, 0.5}, -1.0));
    expectMatchesQuadrature(make(d), 6.0);
}

TEST(FogTerms, CosineProductIsFigureSixStyle) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    d.terms.push_back(FogTerm::cosineProduct(0.9, kPi, {1, 0, 0}, 0.3, kPi / 2, {0, 0, 1}, -0.2));
    const Fog fog = make(d);
    expectMatchesQuadrature(fog, 5.0);
    // Point values: the product, not the sum.
    const glm::dvec3 x{0.3, 1.0, -0.8};
    EXPECT_NEAR(fog.density(x, 0.0), 1.0 + 0.9 * std::cos(kPi * 0.3 + 0.3) * std::cos(kPi / 2 * -0.8 - 0.2), 1e-14);
}

TEST(FogTerms, PeriodicPolynomialIn1DCrossingCells) {
    FogDesc d;
    d.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.8, -1, 0, 0, 1}, 1.5));
    const Fog fog = make(d);
    expectMatchesQuadrature(fog, 8.0); // segments up to ~28 long: several cells each
    // Wraps: density at x and x + 2C agree.
    EXPECT_NEAR(fog.density({0.4, 0, 0}, 0), fog.density({0.4 + 3.0 * 7, 5, -2}, 0), 1e-12);
    EXPECT_NEAR(fog.density({0.6, 0, 0}, 0), 0.8 - 0.4 + std::pow(0.4, 4), 1e-14);
}

TEST(FogTerms, ZeroOutsidePolynomial) {
    FogDesc d;
    d.terms.push_back(FogTerm::polynomial1D(0.5, 1, {1, 0, -1}, 2.0, FogCellMode::ZeroOutside, 1.0));
    const Fog fog = make(d);
    expectMatchesQuadrature(fog, 5.0);
    EXPECT_EQ(fog.density({0, 3.5, 0}, 0), 0.0);
    // Through the whole slab y in [-1, 3]: 0.5 * 2 * integral_{-1}^{1} (1 - u^2) du = 0.5 * 2 * 4/3.
    EXPECT_NEAR(fog.opticalDepth({0, -10, 0}, {0, 10, 0}, 0), 0.5 * 2.0 * 4.0 / 3.0, 1e-14);
}

FogTerm polynomial2D(FogCellMode mode) {
    FogTerm t;
    t.kind = FogTermKind::Polynomial;
    t.cellMode = mode;
    t.cellHalfSize = {1.2, 1.0, 0.8};
    t.cellCentre = {0.3, 0, -0.2};
    // 2 - u^2 v + 0.5 v^3 - u w^4 + 0.3 u^2 v^2 w  (three variables, total degree 5)
    t.monomials = {{2.0, 0, 0, 0}, {-1.0, 2, 1, 0}, {0.5, 0, 3, 0}, {-1.0, 1, 0, 4}, {0.3, 2, 2, 1}};
    return t;
}

TEST(FogTerms, PeriodicPolynomialInThreeVariables) {
    FogDesc d;
    d.terms.push_back(polynomial2D(FogCellMode::Periodic));
    expectMatchesQuadrature(make(d), 6.0);
}

TEST(FogTerms, ZeroOutsidePolynomialInThreeVariables) {
    FogDesc d;
    d.terms.push_back(polynomial2D(FogCellMode::ZeroOutside));
    expectMatchesQuadrature(make(d), 3.0);
}

TEST(FogTerms, PointEquipotential) {
    FogDesc d;
    d.terms.push_back(FogTerm::point(0.8, {0.5, -0.3, 1.0}, 0.5, 2.0));
    d.terms.push_back(FogTerm::point(0.3, {-2, 1, 0}, 1.0, 0.1));
    expectMatchesQuadrature(make(d), 5.0);
}

TEST(FogTerms, LineEquipotential) {
    FogDesc d;
    d.terms.push_back(FogTerm::line(0.6, {0.5, 0, 1}, {1, 2, 0.3}, 0.4, 1.5));
    expectMatchesQuadrature(make(d), 5.0);
}

TEST(FogTerms, SphereEquipotentialBothRegimes) {
    // kappa = c/d + h^2 - R^2 > 0 everywhere (small ball) and <= 0 for rays through a big ball.
    FogDesc d;
    d.terms.push_back(FogTerm::sphere(0.5, {0.2, 0.1, -0.3}, 0.5, 1.0, 1.0));
    d.terms.push_back(FogTerm::sphere(0.4, {-1, 1, 0.5}, 3.0, 0.2, 4.0));
    expectMatchesQuadrature(make(d), 6.0);
    const Fog fog = make(d);
    // Inside the big ball (away from the small one) the second term is flat at 0.4 / c.
    EXPECT_NEAR(fog.density({-1.5, 1.5, 0.0}, 0) - fog.density({-1.0, 0.5, 1.5}, 0),
                0.5 / (1.0 + std::pow(glm::length(glm::dvec3(-1.7, 1.4, 0.3)), 2) - 0.25) -
                    0.5 / (1.0 + std::pow(glm::length(glm::dvec3(-1.2, 0.4, 1.8)), 2) - 0.25),
                1e-14);
}

TEST(FogTerms, EveryKindTogether) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.2));
    d.terms.push_back(FogTerm::cosine(0.4, 2.0, {0.3, 1, 0}, 0.1));
    d.terms.push_back(FogTerm::cosineProduct(0.3, 1.0, {1, 0, 0}, 0.0, 2.0, {0, 0, 1}, 0.5));
    d.terms.push_back(FogTerm::polynomial1D(0.5, 2, {0.8, -1, 0, 0, 1}, 2.0));
    d.terms.push_back(polynomial2D(FogCellMode::ZeroOutside));
    d.terms.push_back(FogTerm::point(0.2, {1, 1, 1}, 1.0, 1.0));
    d.terms.push_back(FogTerm::line(0.2, {0, 0, 0}, {0, 1, 0}, 1.0, 0.5));
    d.terms.push_back(FogTerm::sphere(0.2, {-1, 0, 1}, 1.0, 0.5, 1.0));
    d.wind = FogWind::ramp(0.0, {0.5, 0, 0}, 4.0, {0, 0, -1});
    const Fog fog = make(d);
    expectMatchesQuadrature(fog, 6.0, 0.0, 12);
    expectMatchesQuadrature(fog, 6.0, 2.5, 12);
}

TEST(FogWindTest, DisplacementIsTheExactIntegralOfVelocity) {
    const glm::dvec3 v{2.0, 0.0, -1.0};
    const FogWind c = FogWind::constant(v);
    EXPECT_EQ(c.displacement(0.0), glm::dvec3(0.0));
    EXPECT_NEAR(glm::length(c.displacement(3.5) - 3.5 * v), 0.0, 1e-14);
    EXPECT_NEAR(glm::length(c.displacement(-2.0) + 2.0 * v), 0.0, 1e-14);
    // Ramp from 0 at t = 0 to v at t = 2: D(1) = v / 4, D(2) = v, then constant v: D(3) = 2 v.
    const FogWind r = FogWind::ramp(0.0, glm::dvec3(0.0), 2.0, v);
    EXPECT_NEAR(glm::length(r.displacement(1.0) - 0.25 * v), 0.0, 1e-14);
    EXPECT_NEAR(glm::length(r.displacement(2.0) - v), 0.0, 1e-14);
    EXPECT_NEAR(glm::length(r.displacement(3.0) - 2.0 * v), 0.0, 1e-14);
    // Keyframes starting after 0: velocity held before the first key.
    const FogWind k{{{1.0, {1, 0, 0}}, {3.0, {3, 0, 0}}, {4.0, {0, 0, 0}}}};
    // integral_0^5 = 1 (held) + 4 (ramp 1 -> 3 over 2 s) + 1.5 (3 -> 0 over 1 s) + 0 = 6.5
    EXPECT_NEAR(k.displacement(5.0).x, 6.5, 1e-14);
    EXPECT_NEAR(k.velocity(2.0).x, 2.0, 1e-15);
}

TEST(FogWindTest, WindSlidesEveryTerm) {
    // Every term moves by D(t): tau(o, p, t) = tau(o - D, p - D, 0), for cosines (phases),
    // polynomials (integration limits inside the reference cell, Fig. 5) and equipotential centres.
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    d.terms.push_back(FogTerm::cosine(0.3, 2.0, {1, 1, 0}, 0.2));
    d.terms.push_back(FogTerm::polynomial1D(0.5, 0, {0.8, -1, 0, 0, 1}, 1.0));
    d.terms.push_back(FogTerm::point(0.4, {0, 1, 0}, 1.0, 2.0));
    d.terms.push_back(FogTerm::sphere(0.4, {2, 1, 0}, 1.0, 1.0, 2.0));
    d.wind = FogWind::ramp(0.0, {1.0, 0.2, 0.0}, 10.0, {-0.5, 0.0, 0.7});
    const Fog fog = make(d);
    for (double t : {0.7, 4.0, 13.0}) {
        const glm::dvec3 D = fog.windDisplacement(t);
        ASSERT_GT(glm::length(D), 0.5);
        const glm::dvec3 o{-3, 0.5, 0.2}, p{4, 1.5, -0.5};
        EXPECT_NEAR(fog.opticalDepth(o, p, t), fog.opticalDepth(o - D, p - D, 0.0), 1e-12) << "t = " << t;
        EXPECT_NEAR(fog.density(p, t), fog.density(p - D, 0.0), 1e-13);
    }
}

TEST(FogWindTest, WindFactorZeroKeepsATermStill) {
    FogDesc d;
    FogTerm still = FogTerm::point(1.0, {0, 0, 0}, 1.0, 1.0);
    still.windFactor = 0.0;
    d.terms.push_back(still);
    d.wind = FogWind::constant({3, 0, 0});
    const Fog fog = make(d);
    EXPECT_EQ(fog.density({0.5, 0, 0}, 7.0), fog.density({0.5, 0, 0}, 0.0));
}

TEST(FogTime, WeightAndPhaseCurves) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    FogTerm c = FogTerm::cosine(0.5, 1.0, {1, 0, 0});
    c.weightOverTime.keys = {{0.0, 0.2}, {2.0, 0.6}};
    c.phaseOverTime.keys = {{0.0, 0.0}, {2.0, kPi}};
    d.terms.push_back(c);
    const Fog fog = make(d);
    // At t = 1: weight 0.4, phase pi / 2: 1 + 0.4 cos(x + pi/2).
    EXPECT_NEAR(fog.density({0.3, 0, 0}, 1.0), 1.0 + 0.4 * std::cos(0.3 + kPi / 2), 1e-14);
    // Held after the last key.
    EXPECT_NEAR(fog.density({0.3, 0, 0}, 9.0), 1.0 + 0.6 * std::cos(0.3 + kPi), 1e-14);
}

TEST(FogTime, WaveScaleOwnMotionAndPotentialParameters) {
    // Sec. 5: "modifications of coefficients k will shrink or expand the function"; potentials'
    // c, d and positions may change too.
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    FogTerm c = FogTerm::cosine(0.5, 1.0, {1, 0, 0});
    c.waveScaleOverTime.keys = {{0.0, 1.0}, {1.0, 3.0}};
    d.terms.push_back(c);
    FogTerm p = FogTerm::point(0.8, {0, 0, 0}, 1.0, 1.0);
    p.motion = FogWind::constant({0, 2, 0});
    p.cOverTime.keys = {{0.0, 1.0}, {2.0, 2.0}};
    p.dOverTime.keys = {{0.0, 1.0}, {2.0, 0.5}};
    d.terms.push_back(p);
    const Fog fog = make(d);
    // t = 0.5: k = 2; the point is at (0, 1, 0) with c = 1.25, d = 0.875.
    const glm::dvec3 x{0.3, 1.4, 0.2};
    const double r2 = 0.3 * 0.3 + 0.4 * 0.4 + 0.2 * 0.2;
    EXPECT_NEAR(fog.density(x, 0.5), 1.0 + 0.5 * std::cos(2.0 * 0.3) + 0.8 / (1.25 + 0.875 * r2), 1e-14);
    // The integrals follow: closed form against quadrature at that time.
    const glm::dvec3 o{-2, 0.5, 0.1}, q{3, 1.5, -0.4};
    const FogQuadrature num = integrateFogNumerically(fog, o, q, 0.5, 1e-11);
    EXPECT_NEAR(fog.opticalDepth(o, q, 0.5), num.value, 1e-11 + 1e-13 * num.value);
    FogDesc bad = d;
    bad.terms[2].cOverTime.keys = {{0.0, 1.0}, {2.0, 0.0}};
    auto f = Fog::create(bad);
    ASSERT_FALSE(f.ok());
    EXPECT_NE(f.error().find("terms[2].cOverTime.keys[1] value must be > 0"), std::string::npos) << f.error();
}

TEST(FogTime, PolynomialBlendIsLinearInTheCoefficients) {
    // Sec. 5: interpolating the coefficients of two shapes; the integral is linear in them.
    FogTerm t = FogTerm::polynomial1D(1.0, 0, {0.8, -1, 0, 0, 1}, 2.0);
    FogTerm b = FogTerm::polynomial1D(1.0, 0, {1.0, 0, -0.5}, 2.0);
    t.monomialsB = b.monomials;
    t.blendOverTime.keys = {{0.0, 0.0}, {4.0, 1.0}};
    FogDesc d;
    d.terms.push_back(t);
    const Fog fog = make(d);
    FogDesc da, db;
    da.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.8, -1, 0, 0, 1}, 2.0));
    db.terms.push_back(b);
    const Fog fa = make(da), fb = make(db);
    const glm::dvec3 o{-7, 0, 0}, p{9.3, 1, 2};
    EXPECT_NEAR(fog.opticalDepth(o, p, 1.0), 0.75 * fa.opticalDepth(o, p, 0) + 0.25 * fb.opticalDepth(o, p, 0), 1e-12);
    EXPECT_NEAR(fog.opticalDepth(o, p, 8.0), fb.opticalDepth(o, p, 0), 1e-12);
}

TEST(FogValidation, CosineRuleViolationNamesTheTerm) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    d.terms.push_back(FogTerm::cosine(0.5, 1.0, {1, 0, 0}));
    d.terms.push_back(FogTerm::cosine(-0.7, 2.0, {0, 1, 0}));
    auto f = Fog::create(d);
    ASSERT_FALSE(f.ok());
    EXPECT_NE(f.error().find("negative"), std::string::npos) << f.error();
    EXPECT_NE(f.error().find("terms[2] (cosine"), std::string::npos) << f.error();
}

TEST(FogValidation, PolynomialMinimumNamesWhere) {
    FogDesc d;
    d.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.1, 0, -1}, 3.0)); // 0.1 - u^2: -0.9 at u = +-1
    auto f = Fog::create(d);
    ASSERT_FALSE(f.ok());
    EXPECT_NE(f.error().find("terms[0] (polynomial"), std::string::npos) << f.error();
    EXPECT_NE(f.error().find("minimum -0.9"), std::string::npos) << f.error();
    // A constant that covers the dip makes it valid.
    d.terms.push_back(FogTerm::constant(0.9));
    EXPECT_TRUE(Fog::create(d).ok());
}

TEST(FogValidation, NegativeAtSomeTimeOnly) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    FogTerm c = FogTerm::cosine(0.5, 1.0, {1, 0, 0});
    c.weightOverTime.keys = {{0.0, 0.5}, {3.0, 1.5}};
    d.terms.push_back(c);
    auto f = Fog::create(d);
    ASSERT_FALSE(f.ok());
    EXPECT_NE(f.error().find("t = 3 s"), std::string::npos) << f.error();
}

TEST(FogValidation, BadFieldsAreNamed) {
    auto expectError = [](FogDesc d, const std::string& part) {
        auto f = Fog::create(std::move(d));
        ASSERT_FALSE(f.ok());
        EXPECT_NE(f.error().find(part), std::string::npos) << f.error();
    };
    FogDesc d;
    d.terms.push_back(FogTerm::point(1.0, {0, 0, 0}, 0.0, 1.0));
    expectError(d, "terms[0].c must be > 0");
    d.terms[0] = FogTerm::point(1.0, {0, 0, 0}, 1.0, -1.0);
    expectError(d, "terms[0].d must be finite and >= 0");
    d.terms[0] = FogTerm::cosine(std::nan(""), 1.0, {1, 0, 0});
    expectError(d, "terms[0].weight must be finite");
    d.terms[0] = FogTerm::polynomial1D(1.0, 0, {1, 0, 1}, 0.0);
    expectError(d, "terms[0].cellHalfSize must be finite and > 0");
    d.terms[0] = FogTerm::polynomial1D(1.0, 0, std::vector<double>(12, 0.1), 1.0);
    expectError(d, "above the maximum 9");
    d.terms[0] = FogTerm::line(1.0, {0, 0, 0}, {0, 0, 0}, 1.0, 1.0);
    expectError(d, "terms[0].axis must be a finite non-zero vector");
    d.terms[0] = FogTerm::constant(1.0);
    d.terms[0].weightOverTime.keys = {{1.0, 1.0}, {0.0, 1.0}};
    expectError(d, "terms[0].weightOverTime.keys must be sorted");
    d.terms[0] = FogTerm::constant(1.0);
    d.wind.keys = {{0.0, {std::numeric_limits<double>::infinity(), 0, 0}}};
    expectError(d, "FogDesc.wind.keys[0] must be finite");
    d.wind = {};
    d.farDistanceWorld = -1.0;
    expectError(d, "FogDesc.farDistanceWorld");
}

TEST(FogValidation, TheShaderTheTermsGenerateIsBudgetedNotTheirCount) {
    // 64 degree-9 polynomials on X: ~110 KB of generated GLSL (docs/fog.md,
    // "What a fog's shader costs": 35 s of compile here), over the 32 KiB default.
    FogDesc d;
    d.terms.push_back(FogTerm::constant(2.0));
    for (int i = 0; i < 64; ++i) d.terms.push_back(FogTerm::polynomial1D(0.01, 0, std::vector<double>(10, 0.1), 1.0 + 0.01 * i));
    auto f = Fog::create(d);
    ASSERT_FALSE(f.ok());
    EXPECT_NE(f.error().find("FogDesc.terms: the shader of its 65 terms needs "), std::string::npos) << f.error();
    EXPECT_NE(f.error().find("over FogDesc.shaderBudgetBytes = 32768"), std::string::npos) << f.error();
    // Raised knowingly, the same fog is made, and its measure is what was refused.
    d.shaderBudgetBytes = 1ull << 20;
    auto raised = Fog::create(d);
    ASSERT_TRUE(raised.ok()) << raised.error();
    EXPECT_GT(fogGlsl(*raised)->termBytes, 32768u);
    // 256 point potentials are one loop: their count costs no generated code.
    FogDesc points;
    for (int i = 0; i < 256; ++i) points.terms.push_back(FogTerm::point(0.01, {double(i), 0.0, 0.0}, 1.0, 1.0));
    auto p = Fog::create(points);
    ASSERT_TRUE(p.ok()) << p.error();
    EXPECT_LT(fogGlsl(*p)->termBytes, 2048u);
}

TEST(FogPaper, Figure6FormulaAndValidity) {
    const Fog fog = make(paperFig6Fog());
    auto K = [](double x, double y, double z) {
        return 1 + 0.5 * std::cos(5 * kPi * y) + 0.2 * std::cos(7 * kPi * (y + 0.1 * x)) + 0.2 * std::cos(5 * kPi * (y - 0.05 * x)) +
               0.1 * std::cos(kPi * x) * std::cos(kPi * z / 2);
    };
    for (glm::dvec3 x : {glm::dvec3(0.1, 0.2, 0.3), glm::dvec3(-3.7, 1.25, 8.0), glm::dvec3(12.0, -0.4, -2.2)})
        EXPECT_NEAR(fog.density(x, 0.0), K(x.x, x.y, x.z), 1e-13);
    expectMatchesQuadrature(fog, 3.0, 0.0, 8);
}

TEST(FogPaper, Figure7PolynomialsOnXAndZ) {
    const Fog fog = make(paperFig7Fog(10.0));
    auto P = [](double u) { return 0.8 - u + std::pow(u, 4); };
    EXPECT_NEAR(fog.density({3.0, 7.0, -4.0}, 0.0), P(0.3) + P(-0.4), 1e-14);
    expectMatchesQuadrature(fog, 40.0, 0.0, 8);
}

TEST(FogPaper, Figure8PointsAroundTrees) {
    const Fog fog = make(paperFig8Fog());
    EXPECT_GT(fog.density({15, 2, 15}, 0), 0.5);
    double far = 0.02; // 100 units above: the constant plus four faint tails
    for (double x : {-15.0, 15.0})
        for (double z : {-15.0, 15.0}) far += 0.5 / (1.0 + 0.05 * (x * x + 98.0 * 98.0 + z * z));
    EXPECT_NEAR(fog.density({0, 100, 0}, 0), far, 1e-15);
    expectMatchesQuadrature(fog, 30.0, 0.0, 8);
}

TEST(FogApply, BlendsWithTheFogColourAndCutsOffFar) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.1));
    d.colour = {1.0, 0.5, 0.0};
    d.farDistanceWorld = 50.0;
    const Fog fog = make(d);
    const glm::dvec3 c = fog.apply({0, 0, 0}, {10, 0, 0}, 0.0, {0.0, 0.0, 1.0});
    const double f = std::exp(-1.0);
    EXPECT_NEAR(c.x, 1.0 - f, 1e-15);
    EXPECT_NEAR(c.y, 0.5 * (1.0 - f), 1e-15);
    EXPECT_NEAR(c.z, f, 1e-15);
    EXPECT_EQ(fog.transmittance({0, 0, 0}, {50.5, 0, 0}, 0.0), 0.0); // sec. 4.2: beyond the threshold, all fog
}

} // namespace
} // namespace splatfx
