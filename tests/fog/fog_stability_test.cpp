// Hard cases of the fog integrals (issue 14, item 6), one named test each.
#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

#include "splatfx/fog.hpp"

namespace splatfx {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

Fog make(FogDesc d) {
    auto f = Fog::create(std::move(d));
    EXPECT_TRUE(f.ok()) << f.error();
    return std::move(*f);
}

TEST(FogStability, CosineWaveNumberToZero) {
    // Integral of 0.5 cos(k x + phi) over x in [0, L]: for small k the textbook
    // (sin(kL + phi) - sin(phi)) / k cancels; the sinc form must not. Reference: that
    // textbook form in long double where its cancellation costs < 1e-19 / k relative
    // (k >= 1e-5), else the Taylor series L cos(phi) - k L^2 sin(phi) / 2 - k^2 L^3 cos(phi) / 6,
    // whose truncation is below k^3 L^4 / 24 < 5e-12 ... 4e-16 for k <= 1e-6.
    const double L = 10.0, phi = 0.7;
    for (double k : {0.3, 1e-2, 3e-3, 1e-3, 1e-4, 1e-5, 1e-6, 1e-9, 1e-12, 1e-300, 0.0}) {
        FogDesc d;
        d.terms.push_back(FogTerm::constant(0.5));
        d.terms.push_back(FogTerm::cosine(0.5, k, {1, 0, 0}, phi));
        const Fog fog = make(d);
        double cosPart;
        if (k >= 1e-5) {
            const long double kl = k;
            cosPart = double((std::sin(kl * L + (long double)phi) - std::sin((long double)phi)) / kl);
        } else {
            cosPart = L * std::cos(phi) - k * L * L * std::sin(phi) / 2 - k * k * L * L * L * std::cos(phi) / 6;
        }
        const double expected = 0.5 * L + 0.5 * cosPart;
        EXPECT_NEAR(fog.opticalDepth({0, 0, 0}, {L, 0, 0}, 0.0), expected, 2e-15 * expected) << "k = " << k;
    }
}

TEST(FogStability, SegmentPerpendicularToTheCosineDirection) {
    // Lambda(x) is constant along the segment (beta = 0 exactly, and 1e-17 off it).
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    d.terms.push_back(FogTerm::cosine(0.6, 3.0, {0, 1, 0}, 0.0));
    const Fog fog = make(d);
    const double y = 0.4;
    const double expected = 5.0 * (1.0 + 0.6 * std::cos(3.0 * y));
    EXPECT_NEAR(fog.opticalDepth({0, y, 0}, {3, y, 4}, 0.0), expected, 1e-14);
    EXPECT_NEAR(fog.opticalDepth({0, y, 0}, {3, y + 1e-17, 4}, 0.0), expected, 1e-14);
}

TEST(FogStability, SegmentParallelToALineEquipotential) {
    // |e_perp| = 0 exactly, then 1e-12: the closed form must be continuous (no 1/|e_perp|).
    FogDesc d;
    d.terms.push_back(FogTerm::line(1.0, {0, 0, 0}, {0, 1, 0}, 0.5, 2.0));
    const Fog fog = make(d);
    const double r2 = 0.3 * 0.3 + 0.4 * 0.4;
    const double expected = 7.0 / (0.5 + 2.0 * r2);
    EXPECT_NEAR(fog.opticalDepth({0.3, -2, 0.4}, {0.3, 5, 0.4}, 0.0), expected, 1e-14);
    const double nearly = fog.opticalDepth({0.3, -2, 0.4}, {0.3 + 7e-12, 5, 0.4}, 0.0);
    EXPECT_NEAR(nearly, expected, 1e-10); // the density changes by ~1e-11 over the segment
    // And a polynomial axis the segment does not move along (dU = 0).
    FogDesc p;
    p.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.8, -1, 0, 0, 1}, 2.0));
    const Fog pf = make(p);
    // x = 7: u = 3.5 wraps to -0.5 in the reference cell; P(-0.5) = 0.8 + 0.5 + 0.0625.
    EXPECT_NEAR(pf.opticalDepth({7, -5, 0}, {7, 5, 2}, 0.0), std::sqrt(104.0) * 1.3625, 1e-13);
}

TEST(FogStability, CameraAtAnEquipotentialCentre) {
    // r -> 0: the camera exactly at a point's centre, on a line, inside a sphere.
    FogDesc d;
    d.terms.push_back(FogTerm::point(1.0, {1, 2, 3}, 0.25, 4.0));
    const Fog fp = make(d);
    // From the centre along any direction: integral_0^L ds / (c + d s^2) = atan(L sqrt(d/c)) / sqrt(c d).
    const double L = 3.0, expected = std::atan(L * std::sqrt(4.0 / 0.25)) / std::sqrt(0.25 * 4.0);
    EXPECT_NEAR(fp.opticalDepth({1, 2, 3}, glm::dvec3(1, 2, 3) + L * glm::normalize(glm::dvec3(1, -1, 2)), 0.0), expected, 1e-14);
    EXPECT_NEAR(fp.density({1, 2, 3}, 0.0), 4.0, 1e-15);
    FogDesc l;
    l.terms.push_back(FogTerm::line(1.0, {0, 0, 0}, {0, 0, 1}, 0.25, 4.0));
    EXPECT_NEAR(make(l).opticalDepth({0, 0, 2}, {L, 0, 2}, 0.0), expected, 1e-14);
    FogDesc s;
    s.terms.push_back(FogTerm::sphere(1.0, {0, 0, 0}, 1.0, 0.25, 4.0));
    const Fog fs = make(s);
    // From the centre: 1 / c over the radius, then the shifted atan outside.
    const double q = integrateFogNumerically(fs, {0, 0, 0}, {0, 0, 3}, 0.0, 1e-12).value;
    EXPECT_NEAR(fs.opticalDepth({0, 0, 0}, {0, 0, 3}, 0.0), q, 1e-11);
    EXPECT_TRUE(std::isfinite(fs.opticalDepth({0, 0, 0}, {0, 0, 0}, 0.0)));
}

TEST(FogStability, RayOneHundredThousandUnitsLong) {
    // Fig. 6's fog along a 1e5-unit ray, against the quadrature (~1.5e6 pieces).
    const Fog fog = make(paperFig6Fog());
    const glm::dvec3 o{0.3, 0.2, -0.1}, p = o + 1e5 * glm::normalize(glm::dvec3(0.8, 0.05, 0.6));
    const double tol = 1e-6; // absolute on an optical depth of ~1e5: 1e-11 relative
    const FogQuadrature q = integrateFogNumerically(fog, o, p, 0.0, tol);
    ASSERT_TRUE(q.converged);
    EXPECT_NEAR(fog.opticalDepth(o, p, 0.0), q.value, tol + 1e-12 * q.value);
    EXPECT_EQ(fog.transmittance(o, p, 0.0), 0.0); // exp(-1e5) underflows to 0, not NaN
}

TEST(FogStability, FarFromTheOrigin) {
    // T = (1e6, 1e6, 1e6) is an exact period of Fig. 6's fog (x: 40, y: 2, z: 4 divide 1e6), so
    // the optical depth of a 1-unit segment must not change when it is moved there. A float
    // Gamma(P) - Gamma(O) would lose everything (phases ~2e7 rad); relative to o in double the
    // only loss is the phase of the reference, |w| |T| eps ~ 2e7 * 1.1e-16 = 2.4e-9 rad.
    const Fog fog = make(paperFig6Fog());
    const glm::dvec3 T{1e6, 1e6, 1e6};
    const glm::dvec3 o{0.3, 0.7, -0.2}, p{0.9, 1.1, 0.4};
    const double near = fog.opticalDepth(o, p, 0.0);
    const double far = fog.opticalDepth(o + T, p + T, 0.0);
    EXPECT_NEAR(far, near, 1.0 * 1.0 * 2.4e-9 * 4); // |segment| * sum|amp| * phase error, x4 for the four phase sums
    // Equipotentials and polynomials far away: moved with their object, nothing changes.
    FogDesc d;
    d.terms.push_back(FogTerm::point(1.0, T, 1.0, 1.0));
    d.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.8, -1, 0, 0, 1}, 2.0, FogCellMode::ZeroOutside, T.x));
    FogDesc d0;
    d0.terms.push_back(FogTerm::point(1.0, {0, 0, 0}, 1.0, 1.0));
    d0.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.8, -1, 0, 0, 1}, 2.0, FogCellMode::ZeroOutside, 0.0));
    EXPECT_NEAR(make(d).opticalDepth(o + T, p + T, 0.0), make(d0).opticalDepth(o, p, 0.0), 1e-9);
}

TEST(FogStability, RayCrossingTenThousandPolynomialCells) {
    // 1D periodic polynomial, cell [-1, 1] (C = 1): from x = 0.3 to 0.3 + 2e4 is exactly 1e4
    // periods, so tau = 1e4 * integral over one cell, along the axis or along a slanted ray.
    FogDesc d;
    d.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.8, -1, 0, 0, 1}, 1.0));
    const Fog fog = make(d);
    const double cell = 2 * 0.8 + 2.0 / 5.0; // integral_{-1}^{1} 0.8 - u + u^4 du
    EXPECT_NEAR(fog.opticalDepth({0.3, 0, 0}, {20000.3, 0, 0}, 0.0), 1e4 * cell, 1e-12 * 1e4 * cell);
    const glm::dvec3 o{0.3, 1, 2}, p{20000.3, 5000, -7000};
    const double slant = glm::length(p - o) / 2e4; // ds / dx
    EXPECT_NEAR(fog.opticalDepth(o, p, 0.0), 1e4 * cell * slant, 1e-11 * 1e4 * cell * slant);
    // 1e12 cells: O(1) and still exact to rounding.
    EXPECT_NEAR(fog.opticalDepth({0.3, 0, 0}, {0.3 + 2e12, 0, 0}, 0.0), 1e12 * cell, 1e-9 * 1e12 * cell);
    // A three-variable periodic polynomial on a slanted ray through ~1e4 cells: the cell walk,
    // against the quadrature.
    FogTerm t;
    t.kind = FogTermKind::Polynomial;
    t.cellHalfSize = {1.0, 1.5, 2.0};
    t.monomials = {{2.0, 0, 0, 0}, {-0.5, 2, 1, 0}, {0.3, 1, 1, 1}, {0.2, 0, 0, 4}};
    FogDesc d3;
    d3.terms.push_back(t);
    const Fog f3 = make(d3);
    const glm::dvec3 o3{0.1, 0.2, 0.3}, p3{12000.0, 3000.0, -2500.0};
    const FogQuadrature q = integrateFogNumerically(f3, o3, p3, 0.0, 1e-6);
    ASSERT_TRUE(q.converged);
    EXPECT_NEAR(f3.opticalDepth(o3, p3, 0.0), q.value, 1e-6 + 1e-12 * q.value);
}

TEST(FogStability, HugeDensitiesUnderflowToZeroTransmittance) {
    for (double c : {1e3, 1e100, 1e300, std::numeric_limits<double>::max()}) {
        FogDesc d;
        d.terms.push_back(FogTerm::constant(c));
        d.terms.push_back(FogTerm::point(c, {0, 0, 0}, 1.0, 1.0));
        const Fog fog = make(d);
        const double tau = fog.opticalDepth({-1e5, 0, 0}, {1e5, 0, 0}, 0.0);
        EXPECT_FALSE(std::isnan(tau)) << c;
        EXPECT_GT(tau, 0.0);
        const double f = fog.transmittance({-1e5, 0, 0}, {1e5, 0, 0}, 0.0);
        EXPECT_EQ(f, 0.0) << c;
    }
}

TEST(FogStability, ZeroTermsIsClearAir) {
    const Fog fog = make(FogDesc{});
    EXPECT_TRUE(fog.empty());
    EXPECT_EQ(fog.density({1, 2, 3}, 0.0), 0.0);
    EXPECT_EQ(fog.opticalDepth({0, 0, 0}, {1e9, 0, 0}, 5.0), 0.0);
    EXPECT_EQ(fog.transmittance({0, 0, 0}, {1e9, 0, 0}, 5.0), 1.0);
    EXPECT_EQ(integrateFogNumerically(fog, {0, 0, 0}, {1, 0, 0}, 0.0).value, 0.0);
}

TEST(FogStability, NonFiniteInputsAreFullyFogged) {
    const Fog fog = make(paperFig6Fog());
    for (glm::dvec3 bad : {glm::dvec3(kNaN, 0, 0), glm::dvec3(0, kInf, 0), glm::dvec3(0, 0, -kInf)}) {
        EXPECT_EQ(fog.opticalDepth({0, 0, 0}, bad, 0.0), kInf);
        EXPECT_EQ(fog.opticalDepth(bad, {0, 0, 0}, 0.0), kInf);
        EXPECT_EQ(fog.transmittance({0, 0, 0}, bad, 0.0), 0.0);
        EXPECT_TRUE(std::isnan(fog.density(bad, 0.0)));
    }
    EXPECT_EQ(fog.transmittance({0, 0, 0}, {1, 0, 0}, kNaN), 0.0);
    const glm::dvec3 c = fog.apply({0, 0, 0}, {kNaN, 0, 0}, 0.0, {0, 0, 0});
    EXPECT_EQ(c, fog.desc().colour); // invalid depth: the fog colour, never NaN
}

TEST(FogStability, ZeroLengthSegment) {
    const Fog fog = make(paperFig8Fog());
    EXPECT_EQ(fog.opticalDepth({15, 2, 15}, {15, 2, 15}, 0.0), 0.0);
    EXPECT_EQ(fog.transmittance({15, 2, 15}, {15, 2, 15}, 0.0), 1.0);
}

// ---- More edges (issue 24, item 3) ----------------------------------------------

// Adaptive quadrature of the density (the fog's own reference, validated
// against closed forms in fog_test.cpp) along [o, p].
double quadrature(const Fog& fog, glm::dvec3 o, glm::dvec3 p, double t = 0.0) {
    const FogQuadrature q = integrateFogNumerically(fog, o, p, t, 1e-11);
    EXPECT_TRUE(q.converged);
    return q.value;
}

TEST(FogStability, CosineOfAMillionCyclesPerUnitAveragesOut) {
    // k = 10^6 over L = 10: the cosine's integral is (sin(kL + phi) - sin(phi)) / k,
    // at most 2e-6; in long double the argument 10^7 keeps 1e-12 of the phase.
    const double L = 10.0, phi = 0.3, k = 1e6;
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.5));
    d.terms.push_back(FogTerm::cosine(0.5, k, {1, 0, 0}, phi));
    const Fog fog = make(d);
    const long double kl = k;
    const double expected = 0.5 * L + 0.5 * double((std::sin(kl * L + (long double)phi) - std::sin((long double)phi)) / kl);
    // The closed form's phase k x in double: 10^7 x 2^-53 = 1e-9 rad, over k: 1e-15 absolute.
    EXPECT_NEAR(fog.opticalDepth({0, 0, 0}, {L, 0, 0}, 0.0), expected, 1e-12);
}

TEST(FogStability, WindAfterAMillionSecondsSlidesTheFogExactly) {
    // Wind moves every term: the fog at t over [o, p] is the calm fog over [o - w t, p - w t].
    // After 10^6 s the displacement is 3 x 10^5: phases reduced in double keep 1e-10 rad.
    FogDesc windy;
    windy.terms.push_back(FogTerm::constant(0.4));
    windy.terms.push_back(FogTerm::cosine(0.3, 2.0, {1, 0, 0}, 0.1));
    windy.wind = FogWind::constant({0.3, 0.0, 0.0});
    FogDesc calm = windy;
    calm.wind = {};
    const Fog a = make(windy), b = make(calm);
    const double t = 1e6;
    const glm::dvec3 o(1.0, 0.5, 2.0), p(7.5, 1.0, -3.0), w(0.3 * t, 0.0, 0.0);
    EXPECT_NEAR(a.opticalDepth(o, p, t), b.opticalDepth(o - w, p - w, t), 1e-9);
}

TEST(FogStability, ZeroOutsidePolynomialRayStartingExactlyOnItsCellFace) {
    // The ray starts on the face x = centre + halfSize (where the cell's polynomial
    // ends) and runs back through the cell: the piece boundaries coincide with the end.
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.1));
    d.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.5, 0.0, -0.25, 0.0, 0.1}, 1.5, FogCellMode::ZeroOutside));
    const Fog fog = make(d);
    const glm::dvec3 face(1.5, 0.2, 0.0);
    for (glm::dvec3 to : {glm::dvec3(-4.0, 0.2, 0.0), glm::dvec3(1.5, 3.0, 1.0), glm::dvec3(3.0, 0.2, 0.0)})
        EXPECT_NEAR(fog.opticalDepth(face, to, 0.0), quadrature(fog, face, to), 1e-9) << to.x << " " << to.y;
}

TEST(FogStability, RayTangentToASpherePotential) {
    // The sphere potential is constant inside and falls outside: a ray touching the
    // sphere at one point (the regimes meet there) integrates as the quadrature does.
    FogDesc d;
    d.terms.push_back(FogTerm::sphere(1.0, {0.0, 0.0, 0.0}, 2.0, 1.0, 0.5));
    const Fog fog = make(d);
    const glm::dvec3 o(-10.0, 2.0, 0.0), p(10.0, 2.0, 0.0); // tangent at (0, 2, 0)
    EXPECT_NEAR(fog.opticalDepth(o, p, 0.0), quadrature(fog, o, p), 1e-9);
    const glm::dvec3 o2(-10.0, 2.0 - 1e-12, 0.0), p2(10.0, 2.0 - 1e-12, 0.0); // a hair inside: continuous
    EXPECT_NEAR(fog.opticalDepth(o2, p2, 0.0), fog.opticalDepth(o, p, 0.0), 1e-9);
}

TEST(FogStability, RayThroughALineEquipotentialsAxis) {
    // r = 0 where the ray crosses the line: the integrand peaks at 1 / c there.
    FogDesc d;
    d.terms.push_back(FogTerm::line(1.0, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 0.01, 4.0));
    const Fog fog = make(d);
    const glm::dvec3 o(-5.0, 1.0, 0.0), p(5.0, -2.0, 0.0);
    // Closed form: the ray's distance to the axis is |x| (z = 0), x = -5 + 10 s:
    // integral of 1 / (c + d x^2) over x, times |p - o| / 10.
    const double c = 0.01, dd = 4.0, scale = glm::length(p - o) / 10.0;
    const double exact = scale * (2.0 / std::sqrt(c * dd)) * std::atan(5.0 * std::sqrt(dd / c));
    EXPECT_NEAR(fog.opticalDepth(o, p, 0.0), exact, 1e-12 * exact);
}

TEST(FogStability, PotentialWithZeroFalloffIsAConstant) {
    // d = 0: 1 / (c + 0 r^2) = 1 / c everywhere, including at the centre.
    FogDesc d;
    d.terms.push_back(FogTerm::point(0.5, {1.0, 1.0, 1.0}, 2.0, 0.0));
    const Fog fog = make(d);
    const glm::dvec3 o(1.0, 1.0, 1.0), p(4.0, 5.0, 1.0);
    EXPECT_NEAR(fog.opticalDepth(o, p, 0.0), 0.5 * 5.0 / 2.0, 1e-15);
}

TEST(FogStability, CosineProductOfOppositeDirectionsHasAZeroFrequencyPart) {
    // cos(k x) cos(-k x + phi): the difference frequency is 2k, the sum frequency 0
    // (the sinc at 0): the product's constant part cos(phi) / 2 must integrate as L cos(phi) / 2.
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    d.terms.push_back(FogTerm::cosineProduct(0.5, 1.7, {1, 0, 0}, 0.0, 1.7, {-1, 0, 0}, 0.4));
    const Fog fog = make(d);
    const glm::dvec3 o(0.0, 0.0, 0.0), p(9.0, 0.0, 0.0);
    EXPECT_NEAR(fog.opticalDepth(o, p, 0.0), quadrature(fog, o, p), 1e-9);
}

TEST(FogStability, FarCutOffExactlyAtTheSegmentsEnd) {
    // A point exactly at farDistanceWorld is not beyond it (transmittance exp(-depth));
    // one ulp further is (0).
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.1));
    d.farDistanceWorld = 10.0;
    const Fog fog = make(d);
    EXPECT_NEAR(fog.transmittance({0, 0, 0}, {10.0, 0, 0}, 0.0), std::exp(-1.0), 1e-15);
    EXPECT_EQ(fog.transmittance({0, 0, 0}, {std::nextafter(10.0, 11.0), 0, 0}, 0.0), 0.0);
}

TEST(FogStability, PolynomialCellsOfAMillionthAlongAThousandUnits) {
    // 10^9 cells crossed: counted in O(1), whole cells at the cell integral. The
    // reference: the mean over a cell times the length, off by at most the two
    // partial cells (2 x 2h x max |P| = 4e-6 x 1.35).
    const double h = 1e-6, L = 1000.0;
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    d.terms.push_back(FogTerm::polynomial1D(1.0, 0, {0.2, 0.0, 1.0}, h)); // P(u) = 0.2 + u^2, mean 0.2 + 1/3
    const Fog fog = make(d);
    const double got = fog.opticalDepth({0.3, 0, 0}, {0.3 + L, 0, 0}, 0.0);
    EXPECT_NEAR(got, L * (1.0 + 0.2 + 1.0 / 3.0), 4e-6 * 1.35 + 1e-9 * L);
}

} // namespace
} // namespace splatfx
