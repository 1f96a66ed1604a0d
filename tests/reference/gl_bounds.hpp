// Error bounds for comparing the GL renderer with the splat-exact reference
// (shared by tests/reference and tests/stability).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "splatfx/materials.hpp"

namespace splatfx::test {

// Largest |bilinear(stored window) - exact window| over the support, in units
// of F(0), for layer 0 as the GPU holds it (RGBA8: each texel rounded to
// 1/255), plus the GPU's fixed-point filter weights (llvmpipe: 8 fractional
// bits, so up to 1/256 of the largest step between neighbouring texels, per axis).
inline double windowErrorBound(const Materials& mat, std::uint32_t layerIndex = 0) {
    const int n = mat.layerSize();
    const std::vector<float>& layer = mat.layer(layerIndex);
    auto texel = [&](int x, int y) {
        x = std::clamp(x, 0, n - 1), y = std::clamp(y, 0, n - 1);
        return std::round(double(layer[(size_t(y) * n + x) * 4 + 3]) * 255.0) / 255.0;
    };
    double step = 0.0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x + 1 < n; ++x) step = std::max({step, std::abs(texel(x + 1, y) - texel(x, y)), std::abs(texel(y, x + 1) - texel(y, x))});
    const Footprint& fp = mat.footprint();
    const double R = fp.radius(), F0 = fp.exact(0.0);
    double worst = 0.0;
    const int samples = 8 * n;
    for (int j = 0; j < samples; ++j)
        for (int i = 0; i < samples; ++i) {
            const double u = (i + 0.5) / samples * 2.0 - 1.0, v = (j + 0.5) / samples * 2.0 - 1.0;
            const double fx = (0.5 + 0.5 * u) * n - 0.5, fy = (0.5 - 0.5 * v) * n - 0.5;
            const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
            const double ax = fx - x0, ay = fy - y0;
            const double bil =
                (texel(x0, y0) * (1 - ax) + texel(x0 + 1, y0) * ax) * (1 - ay) + (texel(x0, y0 + 1) * (1 - ax) + texel(x0 + 1, y0 + 1) * ax) * ay;
            const double r = R * std::sqrt(u * u + v * v);
            worst = std::max(worst, std::abs(bil - (r < R ? fp.exact(r) / F0 : 0.0)));
        }
    return worst + 2.0 * step / 256.0;
}

// |GPU sample - double bilinear sample of the same float layer|: RGBA8
// storage (half a step of 1/255) plus fixed-point filter weights (as above).
// What ReferenceWindow::Stored leaves between the two.
inline double storedErrorBound(const Materials& mat, std::uint32_t layerIndex) {
    const int n = mat.layerSize();
    const std::vector<float>& layer = mat.layer(layerIndex);
    double step = 0.0;
    auto a = [&](int x, int y) { return double(layer[(size_t(y) * n + x) * 4 + 3]); };
    for (int y = 0; y < n; ++y)
        for (int x = 0; x + 1 < n; ++x) step = std::max({step, std::abs(a(x + 1, y) - a(x, y)), std::abs(a(y, x + 1) - a(y, x))});
    return 0.5 / 255.0 + 2.0 * (step + 1.0 / 255.0) / 256.0;
}

} // namespace splatfx::test
