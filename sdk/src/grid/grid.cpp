#include "splatfx/grid.hpp"

#include <cmath>
#include <string>

#include "grid/number_text.hpp"

namespace splatfx {
namespace {

using grid_detail::str;

Status checkSpacing(glm::vec3 spacing) {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(spacing[a]) || spacing[a] <= 0.0f)
            return makeError("grid spacing." + std::string(1, "xyz"[a]) + " must be a positive finite number, got " + str(spacing[a]));
    return {};
}

Status checkCount(const char* what, glm::ivec3 dims) {
    for (int a = 0; a < 3; ++a)
        if (dims[a] <= 0) return makeError(std::string(what) + "." + "xyz"[a] + " must be at least 1, got " + std::to_string(dims[a]));
    const std::uint64_t n = std::uint64_t(dims.x) * std::uint64_t(dims.y) * std::uint64_t(dims.z);
    if (n > kMaxVoxels)
        return makeError(std::string(what) + " asks for " + std::to_string(n) + " voxels; the limit is " + std::to_string(kMaxVoxels) +
                         " (splatfx grids are meant to be coarse)");
    return {};
}

// Fills every lattice point of dims whose centre passes inside(x, y, z),
// with x and z measured from the lattice centre and y from its base.
template <class Inside>
Result<Grid> fill(glm::ivec3 dims, glm::vec3 spacing, const char* what, Inside inside) {
    if (Status s = checkSpacing(spacing); !s) return makeError(s.error());
    if (Status s = checkCount(what, dims); !s) return makeError(s.error());
    Grid g;
    g.dims = dims;
    g.spacing = spacing;
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x) {
                const float cx = x - 0.5f * (dims.x - 1), cz = z - 0.5f * (dims.z - 1);
                if (!inside(cx, float(y), cz)) continue;
                Voxel v;
                v.cell = {x, y, z};
                g.voxels.push_back(v);
            }
    g.colorByHeight();
    return g;
}

Status checkRadius(const char* what, float r) {
    if (!std::isfinite(r) || r <= 0.0f) return makeError(std::string(what) + " must be a positive finite number, got " + str(r));
    if (r > 4096.0f) return makeError(std::string(what) + " of " + str(r) + " cells is beyond the voxel limit");
    return {};
}

} // namespace

glm::vec3 Grid::localPosition(glm::ivec3 cell) const {
    // Centred on x and z so transforms rotate an effect about its axis.
    const glm::vec3 half = glm::vec3(glm::max(dims - 1, glm::ivec3(0))) * 0.5f;
    return (glm::vec3(cell) - glm::vec3(half.x, 0.0f, half.z)) * spacing;
}

Result<Grid> Grid::box(glm::ivec3 dims, glm::vec3 spacing) {
    return fill(dims, spacing, "box dims", [](float, float, float) { return true; });
}

Result<Grid> Grid::sphere(float r, glm::vec3 spacing) {
    if (Status s = checkRadius("sphere radiusCells", r); !s) return makeError(s.error());
    const int n = 2 * int(std::floor(r)) + 1;
    return fill({n, n, n}, spacing, "sphere", [r, n](float x, float y, float z) {
        const float cy = y - 0.5f * (n - 1);
        return x * x + cy * cy + z * z <= r * r;
    });
}

Result<Grid> Grid::cylinder(float r, int h, glm::vec3 spacing) {
    if (Status s = checkRadius("cylinder radiusCells", r); !s) return makeError(s.error());
    const int n = 2 * int(std::floor(r)) + 1;
    return fill({n, h, n}, spacing, "cylinder", [r](float x, float, float z) { return x * x + z * z <= r * r; });
}

Result<Grid> Grid::cone(float r, int h, glm::vec3 spacing) {
    if (Status s = checkRadius("cone radiusCells", r); !s) return makeError(s.error());
    const int n = 2 * int(std::floor(r)) + 1;
    return fill({n, h, n}, spacing, "cone", [r, h](float x, float y, float z) {
        // Radius at this height; the top layer keeps at least its centre voxel.
        const float ry = std::max(r * (1.0f - y / float(std::max(h, 1))), 0.5f);
        return x * x + z * z <= ry * ry;
    });
}

Result<Grid> Grid::fromDense(glm::ivec3 dims, const std::vector<float>& opacity, glm::vec3 spacing) {
    if (Status s = checkSpacing(spacing); !s) return makeError(s.error());
    if (Status s = checkCount("fromDense dims", dims); !s) return makeError(s.error());
    const size_t n = size_t(dims.x) * dims.y * dims.z;
    if (opacity.size() != n)
        return makeError("fromDense: opacity has " + std::to_string(opacity.size()) + " values but dims " + std::to_string(dims.x) + "x" +
                         std::to_string(dims.y) + "x" + std::to_string(dims.z) + " need " + std::to_string(n));
    Grid g;
    g.dims = dims;
    g.spacing = spacing;
    size_t i = 0;
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x, ++i) {
                const float o = opacity[i];
                if (!std::isfinite(o) || o < 0.0f || o > 1.0f)
                    return makeError("fromDense: opacity[" + std::to_string(i) + "] (cell " + std::to_string(x) + "," + std::to_string(y) + "," +
                                     std::to_string(z) + ") is " + str(o) + "; opacities must be finite and in [0, 1]");
                if (o == 0.0f) continue;
                Voxel v;
                v.cell = {x, y, z};
                v.opacity = o;
                g.voxels.push_back(v);
            }
    if (g.voxels.empty()) return makeError("fromDense: every opacity is 0; the grid would be empty (nothing to draw)");
    g.colorByHeight();
    return g;
}

Status Grid::validate() const {
    if (Status s = checkSpacing(spacing); !s) return s;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(transform[c][r])) return makeError("grid transform has a non-finite entry");
    if (voxels.size() > kMaxVoxels)
        return makeError("grid holds " + std::to_string(voxels.size()) + " voxels; the limit is " + std::to_string(kMaxVoxels));
    for (size_t i = 0; i < voxels.size(); ++i) {
        const Voxel& v = voxels[i];
        const std::string at = "voxel " + std::to_string(i) + ": ";
        if (!std::isfinite(v.opacity) || v.opacity < 0.0f || v.opacity > 1.0f)
            return makeError(at + "opacity is " + str(v.opacity) + "; expected a finite value in [0, 1]");
        if (!std::isfinite(v.colorCoord) || v.colorCoord < 0.0f || v.colorCoord > 1.0f)
            return makeError(at + "colorCoord is " + str(v.colorCoord) + "; expected a finite value in [0, 1]");
        if (!std::isfinite(v.phase)) return makeError(at + "phase is not finite");
        if (!std::isfinite(v.stretch.x) || !std::isfinite(v.stretch.y) || !std::isfinite(v.stretch.z)) return makeError(at + "stretch is not finite");
    }
    return {};
}

void Grid::colorByHeight() {
    if (voxels.empty()) return;
    int lo = voxels[0].cell.y, hi = lo;
    for (const Voxel& v : voxels) {
        lo = std::min(lo, v.cell.y);
        hi = std::max(hi, v.cell.y);
    }
    const float span = float(std::max(hi - lo, 1));
    for (Voxel& v : voxels) v.colorCoord = float(v.cell.y - lo) / span;
}

} // namespace splatfx
