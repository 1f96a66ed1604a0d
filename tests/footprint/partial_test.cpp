// The kernel's partial line integral (issue 15): exactBefore against closed
// forms, and the pre-integrated table against the exact fraction.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/footprint.hpp"

using splatfx::Footprint;
using splatfx::FootprintDesc;
using splatfx::Kernel;

namespace {

// Polynomial in t, coefficients lowest first.
using Poly = std::vector<double>;
Poly mul(const Poly& a, const Poly& b) {
    Poly c(a.size() + b.size() - 1, 0.0);
    for (size_t i = 0; i < a.size(); ++i)
        for (size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
    return c;
}
Poly add(Poly a, const Poly& b) {
    if (b.size() > a.size()) a.resize(b.size(), 0.0);
    for (size_t i = 0; i < b.size(); ++i) a[i] += b[i];
    return a;
}
// Antiderivative evaluated at t.
double antiderivative(const Poly& p, double t) {
    double s = 0.0;
    for (size_t i = p.size(); i-- > 0;) s = s * t + p[i] / double(i + 1);
    return s * t;
}

// The Crawfis-Max kernel along the ray at offset r as a polynomial in t:
// (1 - x)^3 (1 + a x + b x^2), x = (r^2 + t^2) / R^2 (footprint.cpp's form,
// with its published coefficients; docs/architecture.md).
Poly crawfisMaxAlongRay(double r) {
    const double R = 1.6, a = -1.5, b = 1.06103515625;
    const Poly x = {r * r / (R * R), 0.0, 1.0 / (R * R)};
    const Poly oneMinus = {1.0 - x[0], 0.0, -x[2]};
    Poly cube = mul(mul(oneMinus, oneMinus), oneMinus);
    const Poly quad = add(add(Poly{1.0}, mul(Poly{a}, x)), mul(Poly{b}, mul(x, x)));
    return mul(cube, quad);
}

std::vector<FootprintDesc> kernels() { return {FootprintDesc{.kernel = Kernel::CrawfisMax}, FootprintDesc{.kernel = Kernel::Gaussian}}; }

} // namespace

TEST(PartialIntegral, LimitsAndSymmetry) {
    for (const FootprintDesc& d : kernels()) {
        const Footprint fp(d);
        const double R = fp.radius(), F0 = fp.exact(0.0);
        for (double r = 0.0; r < R; r += R / 37.0) {
            const double half = std::sqrt(R * R - r * r);
            // s -> -inf: nothing in front; s -> +inf: the whole line integral, exactly.
            EXPECT_EQ(fp.exactBefore(r, -half), 0.0);
            EXPECT_EQ(fp.exactBefore(r, -1e30), 0.0);
            EXPECT_EQ(fp.exactBefore(r, std::numeric_limits<double>::infinity()), fp.exact(r));
            EXPECT_EQ(fp.exactBefore(r, half), fp.exact(r));
            // s = 0: the kernel is even in s. Both halves use the same mirrored
            // nodes, so they agree to rounding (1e-13 of F(0), ~500 ulps of sums).
            EXPECT_NEAR(fp.exactBefore(r, 0.0), 0.5 * fp.exact(r), 1e-13 * F0) << "r " << r;
            EXPECT_NEAR(fp.exactFractionBefore(r, 0.0), 0.5, 1e-12) << "r " << r;
            // Odd symmetry of the front part: F(r, s) + F(r, -s) = F(r).
            for (double s = 0.05; s < half; s += 0.1) EXPECT_NEAR(fp.exactBefore(r, s) + fp.exactBefore(r, -s), fp.exact(r), 1e-12 * F0);
        }
        // Outside the support, and bad input.
        EXPECT_EQ(fp.exactBefore(R * 1.01, 0.0), 0.0);
        EXPECT_EQ(fp.exactBefore(std::nan(""), 0.0), 0.0);
        EXPECT_EQ(fp.exactBefore(0.3, std::nan("")), 0.0);
        EXPECT_EQ(fp.fractionBefore(0.3f, std::nanf("")), 0.0f);
        EXPECT_EQ(fp.exactFractionBefore(2.0 * R, 0.1), 1.0);
        EXPECT_EQ(fp.exactFractionBefore(2.0 * R, -0.1), 0.0);
    }
}

TEST(PartialIntegral, MonotoneInDepth) {
    for (const FootprintDesc& d : kernels()) {
        const Footprint fp(d);
        const double R = fp.radius();
        for (double r = 0.0; r < R; r += R / 11.0) {
            double last = 0.0;
            for (double s = -R; s <= R; s += R / 97.0) {
                const double v = fp.exactBefore(r, s);
                EXPECT_GE(v, last - 1e-15) << "r " << r << " s " << s;
                last = v;
            }
        }
    }
}

// Truncated Gaussian: along the chord the kernel is exp(-r^2/2 sigma^2) exp(-t^2/2 sigma^2),
// so the fraction in front of s is (erf(s k) + erf(c k)) / (2 erf(c k)), k = 1/(sigma sqrt 2), c the half chord.
TEST(PartialIntegral, GaussianMatchesErf) {
    const FootprintDesc d{.kernel = Kernel::Gaussian, .gaussianSigma = 0.7f, .gaussianRadius = 2.0f};
    const Footprint fp(d);
    const double sigma = d.gaussianSigma, R = fp.radius(), k = 1.0 / (sigma * std::sqrt(2.0));
    for (double r = 0.0; r < R; r += 0.07) {
        const double c = std::sqrt(R * R - r * r);
        for (double s = -c; s <= c; s += c / 23.0) {
            const double closed = (std::erf(s * k) + std::erf(c * k)) / (2.0 * std::erf(c * k));
            // 5-point Gauss-Legendre on <= 64 panels of a Gaussian: error far below 1e-10.
            EXPECT_NEAR(fp.exactBefore(r, s) / fp.exact(r), closed, 1e-10) << "r " << r << " s " << s;
            EXPECT_NEAR(fp.exactFractionBefore(r, s), closed, 1e-10) << "r " << r << " s " << s;
        }
    }
}

// Crawfis-Max: the kernel along a ray is a degree-10 polynomial in t, integrated in closed form.
TEST(PartialIntegral, CrawfisMaxMatchesPolynomial) {
    const Footprint fp({.kernel = Kernel::CrawfisMax});
    const double R = fp.radius();
    for (double r = 0.0; r < R; r += 0.053) {
        const double c = std::sqrt(R * R - r * r);
        const Poly p = crawfisMaxAlongRay(r);
        const double total = antiderivative(p, c) - antiderivative(p, -c);
        for (double s = -c; s <= c; s += c / 19.0) {
            const double closed = (antiderivative(p, s) - antiderivative(p, -c)) / total;
            // The rule is exact for degree 9 per panel and the integrand has degree 10:
            // the residual is ~1e-13; 1e-10 leaves room for the rim rows' cancellation.
            EXPECT_NEAR(fp.exactBefore(r, s) / fp.exact(r), closed, 1e-10) << "r " << r << " s " << s;
        }
    }
}

// The table against the exact fraction. Bilinear interpolation errs by at
// most (dx^2 |P_xx| + dy^2 |P_yy|) / 8 on a cell; the second derivatives are
// measured on the exact function here (in the table's coordinates: chord
// fraction sigma and r), plus float rounding of the entries.
TEST(PartialIntegral, TableMatchesExact) {
    for (const FootprintDesc& base : kernels())
        for (int size : {8, 32, 128}) {
            FootprintDesc d = base;
            d.partialRadialSize = size;
            d.partialDepthSize = size;
            const Footprint fp(d);
            const double R = fp.radius();
            auto P = [&](double r, double sigma) {
                const double c = std::sqrt(std::max(R * R - r * r, 0.0));
                return fp.exactFractionBefore(r, sigma * c);
            };
            const double dr = R / (size - 1), ds = 2.0 / (size - 1), h = 1e-3;
            double pss = 0.0, prr = 0.0;
            for (double r = h; r < R * (1.0 - 1e-3) - h; r += R / 97.0)
                for (double s = -1.0 + h; s < 1.0 - h; s += 0.013) {
                    pss = std::max(pss, std::abs(P(r, s + h) - 2.0 * P(r, s) + P(r, s - h)) / (h * h));
                    prr = std::max(prr, std::abs(P(r + h, s) - 2.0 * P(r, s) + P(r - h, s)) / (h * h));
                }
            const double bound = (ds * ds * pss + dr * dr * prr) / 8.0 + 1e-6;
            double worst = 0.0;
            for (double r = 0.0; r < R * (1.0 - 1e-3); r += R / 151.0)
                for (double s = -1.0; s <= 1.0; s += 1.0 / 79.0) {
                    const double c = std::sqrt(R * R - r * r);
                    worst = std::max(worst, std::abs(double(fp.fractionBefore(float(r), float(s * c))) - P(r, s)));
                }
            EXPECT_LE(worst, bound) << "size " << size;
            // A user-facing scale: at the default-ish size the cut is within 1 % of the kernel's weight.
            if (size >= 32) { EXPECT_LT(worst, 0.01) << "size " << size; }
        }
}

TEST(PartialIntegral, GlslNamesAndConstants) {
    const Footprint fp({.partialRadialSize = 16, .partialDepthSize = 40});
    EXPECT_EQ(fp.partialRows(), 16);
    EXPECT_EQ(fp.partialCols(), 40);
    EXPECT_EQ(fp.partialTable().size(), size_t(16 * 40));
    const std::string g = splatfx::partialGlsl(fp, 5);
    EXPECT_NE(g.find("layout(binding = 5) uniform sampler2D splatfx_partial_table;"), std::string::npos);
    EXPECT_NE(g.find("float splatfx_partial_before(float r, float s)"), std::string::npos);
    // Sizes out of range are clamped, never a crash.
    const Footprint tiny({.partialRadialSize = 0, .partialDepthSize = -5});
    EXPECT_EQ(tiny.partialRows(), 2);
    EXPECT_EQ(tiny.partialCols(), 2);
    EXPECT_GE(tiny.fractionBefore(0.1f, 0.0f), 0.0f);
}
