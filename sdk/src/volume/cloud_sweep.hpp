// Private to the SDK: the sun's transmittance through a cloud's grid by a
// plane sweep (clouds.cpp, cloud.cpp).
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace splatfx::detail {

// Transmittance toward the sun at every grid point (x fastest), through the
// extinction scale * field (optical depth per cell length, natural log units): a plane sweep along the sun's main axis, one plane per step,
// each point attenuated from the point one step toward the sun (bilinear in
// the previous plane, trapezoid rule on the extinction). Light entering from
// outside the grid is unattenuated: a point on a face toward the sun has
// T = 1. `towardSun` is in grid axes, non-zero. Exact for a uniform field
// with the sun along an axis or a diagonal (every step lands on grid
// points); first order in the cell size otherwise (the bilinear lookup
// smears where rays switch from one exit face to another). O(points).
void sweepSunTransmittance(glm::ivec3 dims, const std::vector<float>& field, double scale, glm::dvec3 towardSun, std::vector<float>& trans);

} // namespace splatfx::detail
