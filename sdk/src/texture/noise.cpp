#include "noise.hpp"

#include <cmath>
#include <numeric>

namespace splatfx::detail {
namespace {

// splitmix64: a small, well-mixed generator so a seed fully determines the permutation.
std::uint64_t splitmix(std::uint64_t& s) {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// Gradient: one of the 32 edge midpoints of the 4D hypercube, picked by the hash.
double grad(std::uint8_t h, double x, double y, double z, double w) {
    const int axis = (h >> 3) & 3; // the zero component
    double a = 0, b = 0, c = 0;
    switch (axis) {
    case 0:
        a = y;
        b = z;
        c = w;
        break;
    case 1:
        a = x;
        b = z;
        c = w;
        break;
    case 2:
        a = x;
        b = y;
        c = w;
        break;
    default:
        a = x;
        b = y;
        c = z;
        break;
    }
    return ((h & 1) ? -a : a) + ((h & 2) ? -b : b) + ((h & 4) ? -c : c);
}

} // namespace

Noise4::Noise4(std::uint32_t seed) {
    std::array<std::uint8_t, 256> p{};
    std::iota(p.begin(), p.end(), 0);
    std::uint64_t s = seed;
    for (int i = 255; i > 0; --i) std::swap(p[size_t(i)], p[size_t(splitmix(s) % std::uint64_t(i + 1))]);
    for (int i = 0; i < 512; ++i) mPerm[size_t(i)] = p[size_t(i & 255)];
}

double Noise4::operator()(double x, double y, double z, double w) const {
    const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z), fw = std::floor(w);
    const int X = int(fx) & 255, Y = int(fy) & 255, Z = int(fz) & 255, W = int(fw) & 255;
    x -= fx;
    y -= fy;
    z -= fz;
    w -= fw;
    const double u = fade(x), v = fade(y), s = fade(z), t = fade(w);
    auto h = [&](int i, int j, int k, int l) { return mPerm[size_t(mPerm[size_t(mPerm[size_t(mPerm[size_t(X + i)] + Y + j)] + Z + k)] + W + l)]; };
    auto lerp = [](double a, double b, double f) { return a + (b - a) * f; };
    double acc[2];
    for (int l = 0; l < 2; ++l) {
        double zs[2];
        for (int k = 0; k < 2; ++k) {
            double ys[2];
            for (int j = 0; j < 2; ++j) ys[j] = lerp(grad(h(0, j, k, l), x, y - j, z - k, w - l), grad(h(1, j, k, l), x - 1, y - j, z - k, w - l), u);
            zs[k] = lerp(ys[0], ys[1], v);
        }
        acc[l] = lerp(zs[0], zs[1], s);
    }
    return lerp(acc[0], acc[1], t) * 0.5;
}

} // namespace splatfx::detail
