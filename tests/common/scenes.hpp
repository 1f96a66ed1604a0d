// Small scenes shared by the core GL tests.
#pragma once

#include <cstdint>
#include <vector>

#include "splatfx/shapes.hpp"
#include "splatfx/splatfx.hpp"

namespace splatfx::test {

// The paper's 7x20x5 fire (Fig. 1) with a flame-shaped opacity and a seeded
// start texture per voxel, as the campfire sample sets it up.
inline Grid campfireGrid(std::uint32_t seed) {
    Grid g = *Grid::box({7, 20, 5}, glm::vec3(0.5f));
    for (Voxel& v : g.voxels) {
        v.opacity = 0.55f * flameOpacity(v.cell, g.dims);
        std::uint32_t x = std::uint32_t(v.cell.x * 73856093) ^ std::uint32_t(v.cell.y * 19349663) ^ std::uint32_t(v.cell.z * 83492791) ^ seed;
        x ^= x >> 13;
        x *= 0x5bd1e995u;
        x ^= x >> 15;
        v.texture = x;
    }
    return g;
}

inline Camera campfireCamera(glm::ivec2 size) { return Camera::lookAt({0.0f, 4.8f, 15.0f}, {0.0f, 4.6f, 0.0f}, {0, 1, 0}, 0.7853982f, size); }

// One voxel of opacity 0.6 at the origin, seen slightly off-axis at 64x48: the
// lone splat the GL-versus-reference bounds are derived for.
inline Grid loneVoxel() {
    Grid g;
    g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.6f});
    return g;
}
inline Camera loneSplatCamera() { return Camera::lookAt({0.4f, 0.3f, 5.0f}, {0, 0, 0}, {0, 1, 0}, 0.9f, {64, 48}); }

// That voxel as one untextured splat of a constant colour, and its materials.
struct LoneSplat {
    Materials mat{Footprint{}};
    Camera cam = loneSplatCamera();
    SplatBuilder builder;
    explicit LoneSplat(glm::vec4 colour = {0.9f, 0.6f, 0.3f, 1.0f}) {
        mat.addColorTable(ColorTable::constant(colour));
        builder.begin(cam);
        builder.add(loneVoxel(), mat, {.textured = false});
    }
    const std::vector<Splat>& splats() const { return builder.splats(); }
};

} // namespace splatfx::test
