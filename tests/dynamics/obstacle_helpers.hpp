// Helpers shared by the solver-obstacle tests (obstacle_test.cpp, obstacle_stability_test.cpp,
// obstacle_hard_cases_test.cpp).
#pragma once

#include <cmath>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/solver.hpp"

namespace obstacle_test {

// A box obstacle covering the lattice cells lo..hi (inclusive) of `s`; with the solver's transform the
// identity, grid-local is world.
inline splatfx::Obstacle boxOverCells(const splatfx::FluidSolver& s, glm::ivec3 lo, glm::ivec3 hi, splatfx::Slip slip = splatfx::Slip::Free,
                                      splatfx::Motion motion = {}) {
    const glm::vec3 centre = 0.5f * (s.localPosition(lo) + s.localPosition(hi));
    const glm::vec3 size = glm::vec3(hi - lo + 1) * s.desc().spacing;
    return {.desc = {.shape = splatfx::ObstacleShape::Box, .size = size, .transform = glm::translate(glm::mat4(1.0f), centre), .slip = slip},
            .motion = std::move(motion)};
}

// Every density finite and non-negative, every temperature and the top speed finite.
inline bool allFinite(const splatfx::FluidSolver& s) {
    for (float v : s.density())
        if (!std::isfinite(v) || v < 0.0f) return false;
    for (float v : s.temperature())
        if (!std::isfinite(v)) return false;
    return std::isfinite(s.maxSpeed());
}

} // namespace obstacle_test
