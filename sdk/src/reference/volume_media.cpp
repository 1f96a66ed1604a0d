// Continuous media for the volume-exact reference (see reference.hpp): dense
// voxels read at full resolution, and a procedural gas's own density.
#include <algorithm>
#include <cmath>

#include "reference_common.hpp"
#include "splatfx/reference.hpp"

namespace splatfx {
namespace {
constexpr double kLn2 = 0.69314718055994530942;
constexpr double kMaxTau = 24.0; // the splat builder's cap on a voxel's log2 optical depth (splats.cpp)

// Appends origin + t dir's crossings of the planes coordinate = first + k * step
// (k integer) along each axis, for t in (t0, t1).
void planeCrossings(glm::dvec3 origin, glm::dvec3 dir, double t0, double t1, glm::dvec3 first, double step, std::vector<double>& out) {
    for (int a = 0; a < 3; ++a) {
        if (dir[a] == 0.0) continue;
        const double p0 = origin[a] + t0 * dir[a], p1 = origin[a] + t1 * dir[a];
        const double lo = std::min(p0, p1), hi = std::max(p0, p1);
        for (double k = std::ceil((lo - first[a]) / step); first[a] + k * step <= hi; k += 1.0) {
            const double t = (first[a] + k * step - origin[a]) / dir[a];
            if (t > t0 && t < t1) out.push_back(t);
        }
    }
}
} // namespace

ContinuousMedium denseMedium(std::shared_ptr<const DenseVoxels> voxels, DenseFilter filter, double extinctionPerValue,
                             std::function<glm::dvec3(glm::dvec3)> color) {
    ContinuousMedium m;
    const DenseVoxels& v = *voxels;
    const double s = v.voxelSize;
    // Nearest: voxel i covers [i - 1/2, i + 1/2] voxels about its centre; trilinear
    // support reaches the next centre outside the array (where the value is 0).
    const double reach = filter == DenseFilter::Nearest ? 0.5 : 1.0;
    m.boxMin = v.origin - reach * s;
    m.boxMax = v.origin + (glm::dvec3(v.dims - 1) + reach) * s;
    m.featureSize = s;
    const glm::dvec3 first = filter == DenseFilter::Nearest ? v.origin - 0.5 * s : v.origin;
    m.breaks = [first, s](glm::dvec3 o, glm::dvec3 d, double t0, double t1, std::vector<double>& out) {
        planeCrossings(o, d, t0, t1, first, s, out);
    };
    m.sample = [voxels, filter, extinctionPerValue, color](glm::dvec3 p) {
        const DenseVoxels& g = *voxels;
        const glm::dvec3 u = (p - g.origin) / g.voxelSize; // in voxel units, centres on integers
        auto at = [&g](int x, int y, int z) -> double {
            if (x < 0 || y < 0 || z < 0 || x >= g.dims.x || y >= g.dims.y || z >= g.dims.z) return 0.0;
            return double(g.values[(std::size_t(z) * std::size_t(g.dims.y) + std::size_t(y)) * std::size_t(g.dims.x) + std::size_t(x)]);
        };
        double value = 0.0;
        if (filter == DenseFilter::Nearest) {
            value = at(int(std::floor(u.x + 0.5)), int(std::floor(u.y + 0.5)), int(std::floor(u.z + 0.5)));
        } else {
            const glm::dvec3 f = glm::floor(u), w = u - f;
            const int x = int(f.x), y = int(f.y), z = int(f.z);
            for (int c = 0; c < 8; ++c) {
                const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
                const double wt = (dx ? w.x : 1.0 - w.x) * (dy ? w.y : 1.0 - w.y) * (dz ? w.z : 1.0 - w.z);
                if (wt > 0.0) value += wt * at(x + dx, y + dy, z + dz);
            }
        }
        ContinuousMedium::Sample out;
        out.extinction = extinctionPerValue * value;
        out.color = color ? color(p) : glm::dvec3(1.0);
        return out;
    };
    return m;
}

ContinuousMedium proceduralGasMedium(const ProceduralGasDesc& gas, const Grid& lattice, double timeSec, const Materials& materials,
                                     const GasMediumDesc& desc) {
    ContinuousMedium m;
    const glm::dvec3 sp(lattice.spacing);
    const double cell = desc.cellLength > 0.0 ? desc.cellLength : std::cbrt(sp.x * sp.y * sp.z);
    const glm::dmat4 toWorld(lattice.transform);
    // The cells' extent in grid-local space, then its world bounding box.
    const glm::dvec3 lo = glm::dvec3(lattice.localPosition({0, 0, 0})) - 0.5 * sp;
    const glm::dvec3 hi = glm::dvec3(lattice.localPosition(lattice.dims - 1)) + 0.5 * sp;
    m.boxMin = glm::dvec3(1e300);
    m.boxMax = glm::dvec3(-1e300);
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        const glm::dvec3 w = glm::dvec3(toWorld * glm::dvec4(corner, 1.0));
        m.boxMin = glm::min(m.boxMin, w);
        m.boxMax = glm::max(m.boxMax, w);
    }
    // Turbulence's finest octave has 2^(octaves-1) * frequency cycles per unit.
    m.featureSize = std::min({sp.x, sp.y, sp.z, 1.0 / (double(gas.turbulence.frequency) * std::ldexp(1.0, gas.turbulence.octaves - 1))});
    const glm::dmat4 toLocal = glm::inverse(toWorld);
    const bool hasTable = desc.style.colorTable < materials.colorTableCount();
    const double opacityScale = std::isfinite(desc.style.opacityScale) ? std::max(double(desc.style.opacityScale), 0.0) : 0.0;
    const double rowLow = desc.rowLow, rowHigh = desc.rowHigh == desc.rowLow && desc.rowLow == 0.0 ? double(lattice.dims.y - 1) : desc.rowHigh;
    const double span = std::max(rowHigh - rowLow, 1.0);
    const glm::dvec3 lo3 = lo, hi3 = hi;
    const Materials* mat = &materials;
    const std::uint32_t table = desc.style.colorTable;
    const double threshold = desc.threshold;
    m.sample = [=](glm::dvec3 p) {
        ContinuousMedium::Sample out;
        const glm::dvec3 local = glm::dvec3(toLocal * glm::dvec4(p, 1.0));
        if (glm::any(glm::lessThan(local, lo3)) || glm::any(glm::greaterThan(local, hi3))) return out; // a rotated lattice's box is wider
        const double d = double(proceduralGasDensity(gas, glm::vec3(p), timeSec));
        if (!(d > threshold)) return out;
        const double coord = std::clamp((local.y / sp.y - rowLow) / span, 0.0, 1.0);
        const double tableAlpha = hasTable ? std::clamp(double(mat->colorTable(table).sample(float(coord)).a), 0.0, 1.0) : 1.0;
        const double alpha = std::clamp(d * opacityScale, 0.0, 1.0) * tableAlpha;
        if (!(alpha > 0.0)) return out;
        const double tau2 = alpha >= 1.0 ? kMaxTau : std::min(-std::log1p(-alpha) / kLn2, kMaxTau);
        out.extinction = kLn2 * tau2 / cell;
        const std::uint32_t row = hasTable ? table : 0u;
        out.color = row < mat->colorTableCount() ? reference::rowColor(mat->colorRow(row), coord) : glm::dvec3(1.0);
        return out;
    };
    return m;
}

} // namespace splatfx
