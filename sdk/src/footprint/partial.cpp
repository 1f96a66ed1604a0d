// The kernel's partial line integral and its pre-integrated table (issue 15):
// the part of a voxel's optical depth in front of a surface or behind the
// near plane along a pixel ray (Ebert & Parent 1990, the volume broken into
// sections at the surfaces' depths; King et al. 1999 for pre-integration).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "splatfx/footprint.hpp"

#include "glsl/glsl_files.hpp"

namespace splatfx {
namespace {

// 5-point Gauss-Legendre on n panels of [a, b] (as footprint.cpp's rule).
template <class F>
double gauss(F f, double a, double b, int panels) {
    static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
    static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};
    double sum = 0.0;
    const double h = (b - a) / panels;
    for (int p = 0; p < panels; ++p) {
        const double m = a + (p + 0.5) * h;
        for (int i = 0; i < 5; ++i) sum += w[i] * f(m + 0.5 * h * x[i]);
    }
    return sum * 0.5 * h;
}

// The last table row and the r >= R limit: a ray grazing the support. The
// fraction's shape over sigma converges as the chord vanishes, so it is
// evaluated just inside the rim, where the double-precision kernel is still
// far from underflow ((1 - x)^3 ~ 1e-17 for Crawfis-Max).
constexpr double kRimInset = 1e-6;

std::string num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    std::string s(buf);
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0"; // a GLSL float literal
    return s;
}

} // namespace

double Footprint::chordIntegral(double r, double from, double to) const {
    if (!(to > from)) return 0.0;
    // Panels in proportion to the covered share of the chord, as exact() uses 32 on a half chord.
    const double half = std::sqrt(std::max(mRadiusExact * mRadiusExact - r * r, 0.0));
    const int panels = std::clamp(int(std::ceil(32.0 * (to - from) / std::max(half, 1e-300))), 1, 64);
    return gauss([&](double s) { return kernel(std::sqrt(r * r + s * s)); }, from, to, panels);
}

double Footprint::exactBefore(double r, double s) const {
    if (std::isnan(r) || std::isnan(s)) return 0.0;
    r = std::abs(r);
    if (r >= mRadiusExact) return 0.0;
    const double half = std::sqrt(mRadiusExact * mRadiusExact - r * r);
    if (s <= -half) return 0.0;
    if (s >= half) return exact(r); // the whole chord: the same rule as exact(), so s -> inf is exactly F(r)
    return chordIntegral(r, -half, s);
}

// Fraction in chord coordinates: integral over tau in [-1, sigma] of
// h(sqrt(r^2 + c^2 tau^2)), c the half chord, over the same on [-1, 1]
// (the factor c cancels, which keeps the rim row well defined).
double Footprint::rowFraction(double r, double sigma) const {
    const double R = mRadiusExact;
    r = std::min(std::abs(r), R * (1.0 - kRimInset));
    sigma = std::clamp(sigma, -1.0, 1.0);
    const double c = std::sqrt(R * R - r * r);
    auto f = [&](double tau) { return kernel(std::sqrt(r * r + c * c * tau * tau)); };
    const double total = 2.0 * gauss(f, 0.0, 1.0, 32);
    if (!(total > 0.0)) return sigma >= 0.0 ? 1.0 : 0.0;
    const double part = sigma <= 0.0 ? total * 0.5 - gauss(f, sigma, 0.0, std::max(1, int(std::ceil(32.0 * -sigma))))
                                     : total * 0.5 + gauss(f, 0.0, sigma, std::max(1, int(std::ceil(32.0 * sigma))));
    return std::clamp(part / total, 0.0, 1.0);
}

double Footprint::exactFractionBefore(double r, double s) const {
    if (std::isnan(r) || std::isnan(s)) return 0.0;
    r = std::abs(r);
    const double R = mRadiusExact;
    if (r >= R) return s > 0.0 ? 1.0 : s < 0.0 ? 0.0 : 0.5; // vanishing chord: a step at the closest point
    const double half = std::sqrt(R * R - r * r);
    if (s <= -half) return 0.0;
    if (s >= half) return 1.0;
    return rowFraction(r, s / half);
}

float Footprint::fractionBefore(float r, float s) const {
    if (std::isnan(r) || std::isnan(s)) return 0.0f;
    r = std::abs(r);
    const float R = mRadius;
    // As partialGlsl(): the chord coordinate, a step where the chord vanishes.
    const float half = std::sqrt(std::max(R * R - r * r, 0.0f));
    const float sigma = std::clamp(s / std::max(half, 1e-6f), -1.0f, 1.0f);
    const float fx = (sigma * 0.5f + 0.5f) * float(mPartialCols - 1);
    const float fy = std::min(r / R, 1.0f) * float(mPartialRows - 1);
    const int x0 = std::min(int(fx), mPartialCols - 2), y0 = std::min(int(fy), mPartialRows - 2);
    const float ax = fx - float(x0), ay = fy - float(y0);
    auto at = [&](int x, int y) { return mPartial[size_t(y) * size_t(mPartialCols) + size_t(x)]; };
    const float lo = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * ax;
    const float hi = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * ax;
    return lo + (hi - lo) * ay;
}

// Called from the constructor once the kernel is normalized.
// R: the support radius in double (Footprint::radius() is a float, and 1.6f
// is above 1.6: a chord from it would overshoot the support at the rim).
void buildPartialTable(const Footprint& fp, double R, int rows, int cols, std::vector<float>& out);

void buildPartialTable(const Footprint& fp, double R, int rows, int cols, std::vector<float>& out) {
    out.assign(size_t(rows) * size_t(cols), 0.0f);
    for (int i = 0; i < rows; ++i) {
        const double r = std::min(R * i / (rows - 1), R * (1.0 - kRimInset));
        const double c = std::sqrt(R * R - r * r);
        auto f = [&](double tau) { return fp.kernel(std::sqrt(r * r + c * c * tau * tau)); };
        // Cumulative over the columns: two panels per interval (the
        // Crawfis-Max integrand is a degree-10 polynomial in tau, which a
        // 5-point rule on two panels integrates to ~1e-12 relative).
        std::vector<double> cum(size_t(cols), 0.0);
        for (int j = 1; j < cols; ++j) {
            const double a = -1.0 + 2.0 * (j - 1) / (cols - 1), b = -1.0 + 2.0 * j / (cols - 1);
            cum[size_t(j)] = cum[size_t(j - 1)] + gauss(f, a, b, 2);
        }
        const double total = cum.back();
        for (int j = 0; j < cols; ++j) out[size_t(i) * cols + j] = total > 0.0 ? float(cum[size_t(j)] / total) : (j * 2 >= cols - 1 ? 1.0f : 0.0f);
        out[size_t(i) * cols + cols - 1] = 1.0f;
    }
}

std::string partialGlsl(const Footprint& fp, int binding) {
    // partial.glsl (render/gl/glsl) with this footprint's constants in place of its names.
    const int rows = fp.partialRows(), cols = fp.partialCols();
    const std::string b = std::to_string(binding), r = num(double(fp.radius())), rf = r;
    const std::string xs = num(double(cols - 1) / cols), xb = num(0.5 / cols), ys = num(double(rows - 1) / rows), yb = num(0.5 / rows);
    return glsl::substitute(std::string(glsl::file("partial.glsl")), {{"SPLATFX_PARTIAL_BINDING", b},
                                                                      {"SPLATFX_PARTIAL_RADIUS", r},
                                                                      {"SPLATFX_PARTIAL_RADIUS_F", rf},
                                                                      {"SPLATFX_PARTIAL_X_SCALE", xs},
                                                                      {"SPLATFX_PARTIAL_X_BIAS", xb},
                                                                      {"SPLATFX_PARTIAL_Y_SCALE", ys},
                                                                      {"SPLATFX_PARTIAL_Y_BIAS", yb}});
}

} // namespace splatfx
