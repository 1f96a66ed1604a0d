// Private to the SDK: the ground fog's lit vertices (ground_fog.cpp,
// ground_fog_light.cpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/lighting.hpp"

namespace splatfx::detail {

// The layer's field grid as the lighting reads it: terrain height and fog
// thickness at point (i, j) of the domain [0, nx-1] x [0, nz-1], stored with
// `stride` points per row (the desc's grid, or the LOD's padded one).
struct FogFieldView {
    int nx = 0, nz = 0, stride = 0;
    glm::dvec2 origin{0.0}; // world x, z of point (0, 0)
    double spacing = 1.0;
    const float* height = nullptr;
    const float* top = nullptr;       // fog top (full resolution), or null
    const float* thickness = nullptr; // thickness (LOD), or null
    double density = 1.0, depth = 0.0; // GroundFogDesc::density, densityDepthWorld
    double yLo = 0.0, yHi = 0.0;       // the layer's lowest terrain and highest top
    double hMax = 1e30;                // the highest terrain point, where known (terrainBlocks' walk ends above it)

    std::size_t at(int i, int j) const { return std::size_t(i) + std::size_t(stride) * std::size_t(j); }
    double h(int i, int j) const { return double(height[at(i, j)]); }
    double th(int i, int j) const {
        return thickness ? double(thickness[at(i, j)]) : std::max(double(top[at(i, j)]) - double(height[at(i, j)]), 0.0);
    }
};

// Integral of the fog's scalar (density at the terrain, 0 at the top) along
// p + t u, 0 <= t <= tMax (u unit), through the continuous layer. Double.
double fogScalarIntegral(const FogFieldView& f, glm::dvec3 p, glm::dvec3 u, std::vector<double>& scratch, double tMax = 1e30);
// The fog's scalar at a point of the same continuous layer (0 outside it).
double fogScalarAt(const FogFieldView& f, glm::dvec3 p);
// Whether the terrain stands between p and a light toward u (unit): the ray
// passes below the terrain's triangulation inside the grid, or the light is
// below the horizon (u.y < 0: the ground goes on past the grid). A ray along
// the surface is not blocked.
bool terrainBlocks(const FogFieldView& f, glm::dvec3 p, glm::dvec3 u, std::vector<double>& scratch);

// What update() needs to light each emitted vertex.
struct FogLitView {
    const FogFieldView* field = nullptr;
    const float* sunT = nullptr; // 2 per field point: terrain, top
    const PhaseFunction* phase = nullptr;
    glm::vec3 travel{0.0f, -1.0f, 0.0f}; // the sun's travel, unit
    glm::vec3 eye{0.0f}, back{0.0f};     // the camera's eye and -forward
    bool perspective = true;
    bool isotropic = true;
    float invPhaseMax = 1.0f;
    // s = T phase / max phase at a world vertex on the terrain (top = false) or the fog top.
    float scalarAt(glm::vec3 world, bool top) const;
};

} // namespace splatfx::detail
