// Helpers shared by the lit ground fog tests (ground_fog_light_test.cpp,
// ground_fog_light_hard_cases_test.cpp).
#pragma once

#include <cstddef>

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

} // namespace ground_fog_test
