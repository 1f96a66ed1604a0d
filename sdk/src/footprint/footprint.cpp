#include "splatfx/footprint.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace splatfx {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Crawfis-Max criterion (Crawfis & Max 1993): a radially symmetric kernel of
// support 1.6 whose sum over the unit lattice is as flat as possible. Form:
// (1 - x)^3 (1 + a x + b x^2), x = r^2 / R^2; a, b minimise the peak-to-peak
// ripple of the lattice sum (0.57 %; a plain (1 - x)^3 gives 13 %).
constexpr double kCmRadius = 1.6;
constexpr double kCmA = -1.5;
constexpr double kCmB = 1.06103515625;

double rawKernel(const FootprintDesc& d, double r) {
    if (d.kernel == Kernel::CrawfisMax) {
        const double x = r * r / (kCmRadius * kCmRadius);
        if (x >= 1.0) return 0.0;
        const double t = 1.0 - x;
        return t * t * t * (1.0 + kCmA * x + kCmB * x * x);
    }
    if (r >= d.gaussianRadius) return 0.0;
    return std::exp(-r * r / (2.0 * double(d.gaussianSigma) * d.gaussianSigma));
}

// Composite Gauss-Legendre (5 points) over n panels of [a, b].
template <class F>
double integrate(F f, double a, double b, int panels) {
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

} // namespace

void buildPartialTable(const Footprint& fp, double R, int rows, int cols, std::vector<float>& out); // partial.cpp

Footprint::Footprint(const FootprintDesc& desc) : mDesc(desc) {
    assert(desc.tableSize >= 2 && "FootprintDesc::tableSize must be at least 2");
    assert(desc.gaussianSigma > 0.0f && desc.gaussianRadius > 0.0f);
    mRadius = desc.kernel == Kernel::CrawfisMax ? float(kCmRadius) : desc.gaussianRadius;
    mRadiusExact = desc.kernel == Kernel::CrawfisMax ? kCmRadius : double(desc.gaussianRadius);
    // Normalize the 3D kernel to unit integral: 4 pi * integral r^2 h(r) dr = 1.
    const double volume = 4.0 * kPi * integrate([&](double r) { return r * r * rawKernel(mDesc, r); }, 0.0, mRadius, 64);
    mNorm = 1.0 / volume;
    mTable.resize(size_t(desc.tableSize));
    for (int i = 0; i < desc.tableSize; ++i) {
        const double r = double(mRadius) * i / (desc.tableSize - 1);
        mTable[size_t(i)] = float(exact(r));
    }
    mInvCentre = mTable[0] > 0.0f ? 1.0f / mTable[0] : 0.0f;
    mPartialRows = std::clamp(desc.partialRadialSize, 2, 1024);
    mPartialCols = std::clamp(desc.partialDepthSize, 2, 1024);
    buildPartialTable(*this, mRadiusExact, mPartialRows, mPartialCols, mPartial);
}

double Footprint::kernel(double r) const { return mNorm * rawKernel(mDesc, std::abs(r)); }

double Footprint::exact(double r) const {
    r = std::abs(r);
    if (r >= mRadius) return 0.0;
    // The chord through the support sphere is finite; the kernel is smooth
    // inside it, so a fixed composite rule converges to double precision.
    const double halfChord = std::sqrt(double(mRadius) * mRadius - r * r);
    return 2.0 * integrate([&](double s) { return kernel(std::sqrt(r * r + s * s)); }, 0.0, halfChord, 32);
}

float Footprint::table(float r) const {
    r = std::abs(r);
    if (!(r < mRadius)) return 0.0f; // also catches NaN
    const float f = r / mRadius * float(mTable.size() - 1);
    const size_t i = size_t(f);
    const float t = f - float(i);
    return mTable[i] + (mTable[std::min(i + 1, mTable.size() - 1)] - mTable[i]) * t;
}

std::vector<float> Footprint::image(int size) const {
    std::vector<float> img(size_t(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const float u = ((x + 0.5f) / size * 2.0f - 1.0f) * mRadius;
            const float v = ((y + 0.5f) / size * 2.0f - 1.0f) * mRadius;
            img[size_t(y) * size + x] = weight(std::sqrt(u * u + v * v));
        }
    return img;
}

} // namespace splatfx
