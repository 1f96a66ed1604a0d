// splatfx/grid.hpp: the coarse voxel grid an effect is modelled on.
//
// King et al. 1999, sec. 2: "We allow for sparse grids by describing the
// volume as a set of grid points." A Grid is a list of voxels on a regular
// lattice (spacing may differ per axis) plus a world transform. Opacity says
// how much material a voxel holds; the colour coordinate indexes a colour
// table; texture and phase pick the textured splat drawn for it.
// It does not render, animate or own GPU memory: see splats.hpp, dynamics.
//
//   auto grid = splatfx::Grid::box({7, 20, 5});          // the paper's fire grid
//   if (!grid) return fail(grid.error());
//   grid->transform = glm::translate(glm::mat4(1), {0, 0, -3});
//
// Threading: a plain value; one writer at a time.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/result.hpp"

namespace splatfx {

struct Voxel {
    glm::ivec3 cell{0};        // lattice position, in cells
    float opacity = 1.0f;      // material present, [0, 1]; opacity of a ray through the centre of one cubic voxel
    float colorCoord = 0.0f;   // [0, 1] index into the colour table (fire: normalized height, sec. 2 step 4)
    std::uint32_t texture = 0; // texture index within the effect's texture set
    float phase = 0.0f;        // [0, 1) progress towards the next texture (used for cross-fades)
    glm::vec3 stretch{0.0f};   // kernel elongation: stretched by 1 + |stretch| along stretch's direction (e.g. the flow)
};

// Largest voxel count a builder accepts; beyond it the request is almost
// certainly a unit mistake, and the allocation would not fit a frame budget.
inline constexpr std::uint64_t kMaxVoxels = 1u << 24;

class Grid {
public:
    std::vector<Voxel> voxels;
    glm::vec3 spacing{1.0f};   // distance between lattice points along x, y, z, in grid-local units
    glm::mat4 transform{1.0f}; // grid-local to world
    glm::ivec3 dims{0};        // extent of the lattice the builders filled (0 for hand-made lists)

    // Builders. Each fills every cell whose centre lies inside the shape, with
    // opacity 1, colour coordinate = normalized height, texture 0, phase 0.
    // The lattice is centred on x and z and starts at y = 0 (a fire's base).
    // On failure (non-positive or absurd size) the message names the argument.
    static Result<Grid> box(glm::ivec3 dims, glm::vec3 spacing = glm::vec3(1.0f));
    static Result<Grid> sphere(float radiusCells, glm::vec3 spacing = glm::vec3(1.0f));
    static Result<Grid> cylinder(float radiusCells, int heightCells, glm::vec3 spacing = glm::vec3(1.0f));
    // Apex at the top: radius shrinks linearly from radiusCells at y = 0 to 0.
    static Result<Grid> cone(float radiusCells, int heightCells, glm::vec3 spacing = glm::vec3(1.0f));
    // x fastest, then y, then z. Voxels with opacity 0 are left out (sparse).
    // Fails on a size mismatch or an opacity that is NaN, infinite, negative or above 1.
    static Result<Grid> fromDense(glm::ivec3 dims, const std::vector<float>& opacity, glm::vec3 spacing = glm::vec3(1.0f));

    // Position of a lattice point in grid-local and world coordinates.
    glm::vec3 localPosition(glm::ivec3 cell) const;
    glm::vec3 worldPosition(glm::ivec3 cell) const { return glm::vec3(transform * glm::vec4(localPosition(cell), 1.0f)); }

    // Checks every voxel: finite values, opacity and colour coordinate in
    // [0, 1], finite stretch, positive finite spacing. The message names the
    // first bad voxel and field. Splat building never fails: it clamps.
    Status validate() const;

    // Sets each voxel's colour coordinate to its height normalized over the
    // grid's y range: the paper's cheap temperature for fire (sec. 2, step 4).
    void colorByHeight();
};

} // namespace splatfx
