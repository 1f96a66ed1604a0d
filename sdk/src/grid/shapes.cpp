#include "splatfx/shapes.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <string>

#include "grid/number_text.hpp"

namespace splatfx {
namespace {

using grid_detail::str;

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

Status checkUnit(const std::string& field, float v) {
    if (!(v >= 0.0f && v <= 1.0f)) return makeError(field + " must be in [0, 1], got " + str(v));
    return {};
}

Status checkShape(const Shape& s, std::size_t i) {
    const std::string at = "shapes[" + std::to_string(i) + "].";
    if (!finite(s.from) || !finite(s.to)) return makeError(at + "from/to must be finite");
    if (!(s.radiusFrom >= 0.0f && std::isfinite(s.radiusFrom))) return makeError(at + "radiusFrom must be finite and >= 0, got " + str(s.radiusFrom));
    if (!(s.radiusTo >= 0.0f && std::isfinite(s.radiusTo))) return makeError(at + "radiusTo must be finite and >= 0, got " + str(s.radiusTo));
    if (!(s.softCells > 0.0f && std::isfinite(s.softCells))) return makeError(at + "softCells must be finite and > 0, got " + str(s.softCells));
    return checkUnit(at + "opacity", s.opacity);
}

} // namespace

Shape Shape::box(glm::vec3 minCell, glm::vec3 maxCell) { return {.type = ShapeType::Box, .from = minCell, .to = maxCell}; }

Shape Shape::sphere(glm::vec3 centreCell, float radiusCells) {
    return {.type = ShapeType::Sphere, .from = centreCell, .radiusFrom = radiusCells, .radiusTo = radiusCells};
}

Shape Shape::cylinder(glm::vec3 fromCell, glm::vec3 toCell, float radiusCells) { return cone(fromCell, toCell, radiusCells, radiusCells); }

Shape Shape::cone(glm::vec3 fromCell, glm::vec3 toCell, float radiusFromCells, float radiusToCells) {
    return {.type = ShapeType::Cone, .from = fromCell, .to = toCell, .radiusFrom = radiusFromCells, .radiusTo = radiusToCells};
}

float Shape::insideCells(glm::vec3 p) const {
    switch (type) {
    case ShapeType::Box: {
        const glm::vec3 d = glm::min(p - (from - 0.5f), (to + 0.5f) - p);
        return std::min({d.x, d.y, d.z});
    }
    case ShapeType::Sphere: return radiusFrom - glm::length(p - from);
    case ShapeType::Cone: break;
    }
    const glm::vec3 ab = to - from;
    const float len2 = glm::dot(ab, ab);
    const float len = std::sqrt(len2);
    if (len < 1e-6f) return -1e9f;
    const float t = glm::dot(p - from, ab) / len2;
    const float tc = std::clamp(t, 0.0f, 1.0f);
    const float radial = glm::length(p - (from + tc * ab));
    const float along = std::min(t, 1.0f - t) * len + 0.5f; // caps include the end cells
    return std::min(glm::mix(radiusFrom, radiusTo, tc) + 0.5f - radial, along);
}

float Shape::weight(glm::vec3 p) const { return opacity * std::clamp(insideCells(p) / softCells + 0.5f, 0.0f, 1.0f); }

Result<Grid> voxelizeShapes(const std::vector<Shape>& shapes, const VoxelizeDesc& desc) {
    const glm::ivec3 dims = desc.dims;
    for (int a = 0; a < 3; ++a)
        if (dims[a] < 1) return makeError(std::string("VoxelizeDesc.dims.") + "xyz"[a] + " must be at least 1, got " + std::to_string(dims[a]));
    const std::uint64_t n = std::uint64_t(dims.x) * std::uint64_t(dims.y) * std::uint64_t(dims.z);
    if (n > kMaxVoxels) return makeError("VoxelizeDesc.dims asks for " + std::to_string(n) + " cells; the limit is " + std::to_string(kMaxVoxels));
    if (Status s = checkUnit("VoxelizeDesc.opacity", desc.opacity); !s) return makeError(s.error());
    if (Status s = checkUnit("VoxelizeDesc.fadeTo", desc.fadeTo); !s) return makeError(s.error());
    if (!finite(desc.fadeAxis) || glm::length(desc.fadeAxis) < 1e-6f) return makeError("VoxelizeDesc.fadeAxis must be finite and non-zero");
    for (std::size_t i = 0; i < shapes.size(); ++i)
        if (Status s = checkShape(shapes[i], i); !s) return makeError(s.error());

    // King et al. 1999, sec. 2: a coarse grid with opacities; the detail
    // comes from the textures. The fade runs over the lattice's extent along
    // the axis: from its lowest corner (factor 1) to its highest (fadeTo).
    const glm::vec3 axis = glm::normalize(desc.fadeAxis);
    float lo = 1e30f, hi = -1e30f;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p((corner & 1) ? dims.x - 1 : 0, (corner & 2) ? dims.y - 1 : 0, (corner & 4) ? dims.z - 1 : 0);
        lo = std::min(lo, glm::dot(p, axis)), hi = std::max(hi, glm::dot(p, axis));
    }
    const float span = std::max(hi - lo, 1e-6f);
    std::vector<float> dense(n, 0.0f);
    std::size_t i = 0;
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x, ++i) {
                const glm::vec3 p(x, y, z);
                float w = shapes.empty() ? 1.0f : 0.0f;
                for (const Shape& s : shapes) w = std::max(w, s.weight(p));
                const float t = (glm::dot(p, axis) - lo) / span;
                dense[i] = std::clamp(w * desc.opacity * glm::mix(1.0f, desc.fadeTo, t), 0.0f, 1.0f);
            }
    if (std::all_of(dense.begin(), dense.end(), [](float o) { return o <= 0.0f; }))
        return makeError("the shapes cover no cell of the lattice (dims) at non-zero opacity");
    Result<Grid> grid = Grid::fromDense(dims, dense, desc.spacing);
    if (!grid) return grid;
    for (Voxel& v : grid->voxels) v.colorCoord = std::clamp((glm::dot(glm::vec3(v.cell), axis) - lo) / span, 0.0f, 1.0f);
    return grid;
}

float flameOpacity(glm::ivec3 cell, glm::ivec3 dims, float topHeight) {
    assert(topHeight > 0.0f && "flameOpacity: topHeight must be > 0");
    const float h = cell.y / float(std::max(dims.y - 1, 1)) / topHeight;
    // Distance from the vertical axis, 1 at the lattice's side faces.
    const float rx = (cell.x - 0.5f * (dims.x - 1)) / (0.5f * dims.x);
    const float rz = (cell.z - 0.5f * (dims.z - 1)) / (0.5f * dims.z);
    const float r = std::sqrt(rx * rx + rz * rz);
    const float width = 1.0f - 0.75f * std::min(h, 1.0f);
    // A soft edge 0.35 wide, already 0.3 strong on the nominal width.
    const float edge = std::clamp((width - r) / 0.35f + 0.3f, 0.0f, 1.0f);
    return std::max(1.0f - 0.6f * h, 0.0f) * edge;
}

} // namespace splatfx
