// splatfx/shapes.hpp: coarse grids shaped by hand: soft boxes, spheres,
// cylinders and cones voxelized onto a lattice, and the paper's flame shape.
//
// King et al. 1999, sec. 2: the grid carries only the gross shape (opacity
// per voxel); the detail comes from the textures. These helpers give that
// gross shape without writing a loop over cells: voxelizeShapes fills a
// lattice with the strongest of a list of soft-edged shapes, scaled by an
// overall opacity and faded along an axis that also sets the colour
// coordinate; flameOpacity is the flame used by the fire presets.
// It does not animate, texture or render: see effect.hpp and presets.hpp.
// Shapes are given in lattice cells (cell (x, y, z) is the point x, y, z),
// not in world units; the grid's spacing and transform place them.
//
//   auto grid = splatfx::voxelizeShapes({splatfx::Shape::sphere({3, 3, 3}, 2.5f)},
//                                       {.dims = {7, 7, 7}, .opacity = 0.6f});
//   if (!grid) return fail(grid.error());
//
// Threading: plain values and pure functions; safe from any thread.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "splatfx/grid.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

enum class ShapeType {
    Box,    // axis-aligned, between two corner cells (both included)
    Sphere, // around a centre cell
    Cone,   // along a segment, radius varying linearly from one end to the other (equal radii: a cylinder)
};

// One soft-edged shape, in lattice cells.
struct Shape {
    ShapeType type = ShapeType::Box; // default Box
    glm::vec3 from{0.0f};            // Box: min corner cell; Sphere: centre; Cone: axis start; default (0, 0, 0)
    glm::vec3 to{0.0f};              // Box: max corner cell; Cone: axis end; Sphere: unused; default (0, 0, 0)
    float radiusFrom = 1.0f;         // Sphere: radius; Cone: radius at `from`; cells, >= 0; default 1
    float radiusTo = 1.0f;           // Cone: radius at `to`; cells, >= 0; default 1
    float opacity = 1.0f;            // weight well inside the shape, [0, 1]; default 1
    float softCells = 0.75f;         // width of the ramp across the surface, cells, > 0; default 0.75

    static Shape box(glm::vec3 minCell, glm::vec3 maxCell);
    static Shape sphere(glm::vec3 centreCell, float radiusCells);
    static Shape cylinder(glm::vec3 fromCell, glm::vec3 toCell, float radiusCells);
    static Shape cone(glm::vec3 fromCell, glm::vec3 toCell, float radiusFromCells, float radiusToCells);

    // Signed distance to the surface at a cell, in cells, positive inside.
    // Boxes, cylinders and cones reach half a cell beyond their end cells, so
    // a box from (0,0,0) to (2,2,2) covers exactly those 27 cells. A cone
    // whose ends coincide covers nothing (-1e9).
    float insideCells(glm::vec3 cell) const;
    // opacity * clamp(insideCells / softCells + 0.5, 0, 1): half weight on
    // the surface, full weight softCells / 2 inside it.
    float weight(glm::vec3 cell) const;
};

struct VoxelizeDesc {
    glm::ivec3 dims{7, 20, 5};   // lattice cells, each >= 1, at most kMaxVoxels in all; default the paper's 7x20x5
    glm::vec3 spacing{1.0f};     // grid-local units between cells, each > 0; default 1
    float opacity = 0.5f;        // multiplies every shape's weight, [0, 1]; default 0.5
    glm::vec3 fadeAxis{0, 1, 0}; // direction (any length > 0) of the fade and the colour coordinate; default +y
    float fadeTo = 1.0f;         // opacity factor at the far end of fadeAxis (1 at the near end), [0, 1]; default 1 (no fade)
};

// Each cell takes the strongest shape covering it (every cell weight 1 when
// `shapes` is empty), times desc.opacity, times a linear fade from 1 to
// fadeTo along fadeAxis over the lattice; cells left at 0 are not stored.
// Each voxel's colour coordinate is its position along fadeAxis over the
// lattice, in [0, 1]. The grid's transform is the identity.
// On failure (a field out of range or not finite; the message names it) or
// when no cell ends above 0, returns an error; that one reads "the shapes
// cover no cell of the lattice (dims) at non-zero opacity".
Result<Grid> voxelizeShapes(const std::vector<Shape>& shapes, const VoxelizeDesc& desc = {});

// The fire presets' flame (King et al. 1999, Fig. 1): dense at the base and
// along the vertical axis, narrowing to a quarter of the width and thinning
// to 40 % at the top of a dims lattice. topHeight (> 0) is where, as a
// fraction of the lattice height, the flame ends (1: the full lattice;
// fireToSmoke puts it above its smoke split). Returns [0, 1]; cells outside
// the flame return 0. Callers scale it by the opacity they want.
float flameOpacity(glm::ivec3 cell, glm::ivec3 dims, float topHeight = 1.0f);

} // namespace splatfx
