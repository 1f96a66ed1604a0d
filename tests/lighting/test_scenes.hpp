// Grids shared by the lighting tests and the shadow benchmark.
#pragma once

#include <algorithm>
#include <cmath>

#include "splatfx/grid.hpp"
#include "splatfx/lighting.hpp"

namespace splatfx::test {

// A smooth Gaussian blob of opacity (peak `peak` at the centre), n^3 cells of `spacing`.
inline Grid gaussianBlob(int n, float spacing, float peak = 0.6f) {
    Grid g = *Grid::box({n, n, n}, glm::vec3(spacing));
    const float c = 0.5f * float(n - 1), sigma = 0.22f * float(n);
    for (Voxel& v : g.voxels) {
        const glm::vec3 d = glm::vec3(v.cell) - c;
        v.opacity = peak * std::exp(-glm::dot(d, d) / (2.0f * sigma * sigma));
    }
    return g;
}

// The paper's 1560-voxel effect size (12x26x5, as tools/bench/table1): a
// fire-shaped, smoothly varying opacity, densest low in the middle.
inline Grid effect1560(float spacing = 0.25f) {
    Grid g = *Grid::box({12, 26, 5}, glm::vec3(spacing));
    for (Voxel& v : g.voxels) {
        const float x = (float(v.cell.x) - 5.5f) / 6.0f, z = (float(v.cell.z) - 2.0f) / 2.5f, y = float(v.cell.y) / 25.0f;
        v.opacity = 0.7f * std::exp(-2.0f * (x * x + z * z)) * (1.0f - 0.8f * y);
    }
    return g;
}

// Largest difference between neighbouring table nodes along any axis (what
// GL's filter-weight precision scales).
inline float maxNeighbourStep(const ShadowTable& t) {
    const glm::ivec3 n = t.dims();
    const auto& d = t.data();
    float m = 0.0f;
    auto at = [&](int i, int j, int k) { return d[std::size_t(i + n.x * (j + n.y * k))]; };
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j)
            for (int i = 0; i < n.x; ++i) {
                if (i + 1 < n.x) m = std::max(m, std::abs(at(i + 1, j, k) - at(i, j, k)));
                if (j + 1 < n.y) m = std::max(m, std::abs(at(i, j + 1, k) - at(i, j, k)));
                if (k + 1 < n.z) m = std::max(m, std::abs(at(i, j, k + 1) - at(i, j, k)));
            }
    return m;
}

} // namespace splatfx::test
