// Helpers shared by the lit ground fog tests (ground_fog_light_test.cpp,
// ground_fog_light_hard_cases_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/volume.hpp"

namespace ground_fog_test {

// A flat layer: terrain at `bottom`, fog top at `top` everywhere.
inline splatfx::GroundFogDesc slab(glm::ivec2 dims, float spacing, float bottom, float top) {
    splatfx::GroundFogDesc d;
    d.dims = dims;
    d.spacingWorld = spacing;
    d.terrainHeight.assign(std::size_t(dims.x) * std::size_t(dims.y), bottom);
    d.fogTop.assign(d.terrainHeight.size(), top);
    return d;
}

// A white directional sun travelling along `travel`, the layer's extinction per world unit.
inline splatfx::GroundFogLighting sunAlong(glm::vec3 travel, float extinction) {
    splatfx::GroundFogLighting L;
    L.sun = splatfx::Light::directional(travel);
    L.extinctionPerWorld = extinction;
    return L;
}

// Whether the terrain of `d` hides a light toward u (unit) from p: the light
// is below the horizon (u.y < 0; the ground goes on past the grid), or the ray
// p + t u, t >= 0, passes below the terrain's triangulation (cell (i, j) split
// along (i, j)-(i+1, j+1) when i + j is even, else along (i+1, j)-(i, j+1)) by
// more than 1e-7 of the scene's size somewhere. Brute force: the ray clipped to
// every triangle's footprint, the terrain linear on it (independent of the
// SDK's walk along the ray).
inline bool terrainHides(const splatfx::GroundFogDesc& d, glm::dvec3 p, glm::dvec3 u) {
    if (u.y < 0.0) return true;
    const double s = double(d.spacingWorld);
    double scale = 1.0 + s;
    for (float h : d.terrainHeight) scale = std::max(scale, 1.0 + std::abs(double(h)) + s);
    const double eps = 1e-7 * scale;
    auto vertex = [&](int i, int j) {
        return glm::dvec3(double(d.originWorld.x) + double(i) * s, double(d.terrainHeight[std::size_t(i) + std::size_t(d.dims.x) * std::size_t(j)]),
                          double(d.originWorld.z) + double(j) * s);
    };
    for (int j = 0; j + 1 < d.dims.y; ++j)
        for (int i = 0; i + 1 < d.dims.x; ++i) {
            const glm::dvec3 c00 = vertex(i, j), c10 = vertex(i + 1, j), c01 = vertex(i, j + 1), c11 = vertex(i + 1, j + 1);
            const bool even = ((i + j) & 1) == 0;
            const glm::dvec3 tris[2][3] = {{c00, c10, even ? c11 : c01}, {even ? c00 : c10, c11, c01}};
            for (const auto& tri : tris) {
                // The ray's footprint inside the triangle: three half-planes, each linear in t.
                const double area = (tri[1].x - tri[0].x) * (tri[2].z - tri[0].z) - (tri[2].x - tri[0].x) * (tri[1].z - tri[0].z);
                double lo = 0.0, hi = 1e7;
                for (int e = 0; e < 3 && lo <= hi; ++e) {
                    const glm::dvec3 a = tri[e], b = tri[(e + 1) % 3];
                    auto side = [&](double x, double z) { return ((b.x - a.x) * (z - a.z) - (b.z - a.z) * (x - a.x)) * (area > 0.0 ? 1.0 : -1.0); };
                    const double c0 = side(p.x, p.z), c1 = side(p.x + u.x, p.z + u.z) - c0;
                    if (c1 == 0.0) {
                        if (c0 < 0.0) hi = lo - 1.0;
                    } else if (c1 > 0.0) {
                        lo = std::max(lo, -c0 / c1);
                    } else {
                        hi = std::min(hi, -c0 / c1);
                    }
                }
                if (!(hi >= lo)) continue;
                for (double t : {lo, hi}) {
                    // The terrain under p + t u: the triangle's plane.
                    const glm::dvec3 q = p + t * u;
                    const glm::dvec3 n = glm::cross(tri[1] - tri[0], tri[2] - tri[0]);
                    const double h = tri[0].y - (n.x * (q.x - tri[0].x) + n.z * (q.z - tri[0].z)) / n.y;
                    if (q.y - h < -eps) return true;
                }
            }
        }
    return false;
}

// The reference's transmittance from p toward the sun (travel: its
// direction of travel) and its error estimate: integrateGroundFogRay through
// the layer, 0 where the terrain hides the sun (terrainHides).
inline std::pair<double, double> referenceT(const splatfx::GroundFogDesc& d, float extinction, glm::vec3 p, glm::vec3 travel) {
    const glm::dvec3 toSun = -glm::normalize(glm::dvec3(travel));
    if (terrainHides(d, glm::dvec3(p), toSun)) return {0.0, 0.0};
    const splatfx::TransferFunction tf = *splatfx::makeGroundFogTransfer(glm::vec3(1.0f), extinction);
    splatfx::GroundFogRayStats st;
    splatfx::integrateGroundFogRay(d, tf, glm::dvec3(p), toSun, 0.0, 1e4, 1e-11, 20, &st);
    EXPECT_TRUE(st.converged);
    return {st.transmittance, st.errorEstimate};
}

} // namespace ground_fog_test
