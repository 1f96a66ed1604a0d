// The continuous field of untextured splatting (see reference.hpp).
#include <algorithm>
#include <cmath>

#include "reference_common.hpp"
#include "splatfx/reference.hpp"

namespace splatfx {
namespace {
constexpr double kLn2 = 0.69314718055994530942;
// The splat builder's cap on a voxel's log2 optical depth (splats.cpp, kMaxTau).
constexpr double kMaxTau = 24.0;

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
} // namespace

VolumeField::VolumeField(const Materials& materials) : mMaterials(&materials), mCentreFootprint(materials.footprint().exact(0.0)) {
    // The last radius where the kernel is non-zero, by bisection to double precision: a chord
    // clipped there holds one polynomial piece of the kernel (see segmentOpticalDepth).
    const Footprint& fp = materials.footprint();
    double lo = 0.0, hi = double(fp.radius()) * (1.0 + 1e-6);
    for (int i = 0; i < 200 && hi - lo > 0.0; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        (fp.kernel(mid) > 0.0 ? lo : hi) = mid;
    }
    mSupportRadius = hi;
}

void VolumeField::add(const Grid& grid, const SplatStyle& style, std::span<const glm::vec3> voxelColors) {
    const Materials& mat = *mMaterials;
    const double R = mat.footprint().radius();
    const bool hasTable = style.colorTable < mat.colorTableCount();
    const double opacityScale = std::isfinite(style.opacityScale) ? std::max(double(style.opacityScale), 0.0) : 0.0;
    const glm::dmat3 rot(glm::dmat4(grid.transform));
    const glm::dmat3 space(glm::dvec3(grid.spacing.x, 0, 0), glm::dvec3(0, grid.spacing.y, 0), glm::dvec3(0, 0, grid.spacing.z));
    const bool override = voxelColors.size() == grid.voxels.size() && !voxelColors.empty();
    for (std::size_t vi = 0; vi < grid.voxels.size(); ++vi) {
        const Voxel& v = grid.voxels[vi];
        // The kernel matrix exactly as SplatBuilder::add forms it, in double.
        glm::dmat3 m = rot * space;
        const glm::dvec3 st(v.stretch);
        const double stretchLen = glm::length(st);
        if (stretchLen > 0.0 && std::isfinite(stretchLen)) {
            const glm::dvec3 s = st / stretchLen;
            m = m * (glm::dmat3(1.0) + stretchLen * glm::outerProduct(s, s));
        }
        const double det = glm::determinant(m);
        const glm::dvec3 c = glm::dvec3(glm::dmat4(grid.transform) * glm::dvec4(glm::dvec3(grid.localPosition(v.cell)), 1.0));
        if (!std::isfinite(v.opacity) || !std::isfinite(v.colorCoord) || !std::isfinite(v.phase) || !finite(c) || !std::isfinite(det) ||
            std::abs(det) < 1e-12) {
            ++mRejected;
            continue;
        }
        const double opacity = std::clamp(double(v.opacity) * opacityScale, 0.0, 1.0);
        const double tableAlpha = hasTable ? std::clamp(double(mat.colorTable(style.colorTable).sample(v.colorCoord).a), 0.0, 1.0) : 1.0;
        const double alpha = opacity * tableAlpha;
        if (!(alpha > 0.0)) continue;
        const double tau = alpha >= 1.0 ? kMaxTau : std::min(-std::log1p(-alpha) / kLn2, kMaxTau);
        VoxelKernel k;
        k.center = c;
        k.inverse = glm::inverse(m);
        k.scale = kLn2 * tau / (mCentreFootprint * std::cbrt(std::abs(det)));
        k.boundRadius = R * std::sqrt(glm::dot(m[0], m[0]) + glm::dot(m[1], m[1]) + glm::dot(m[2], m[2]));
        const std::uint32_t row = hasTable ? style.colorTable : 0u;
        k.color = row < mat.colorTableCount() ? reference::rowColor(mat.colorRow(row), std::clamp(double(v.colorCoord), 0.0, 1.0)) : glm::dvec3(1.0);
        if (override) k.color = glm::dvec3(voxelColors[vi]);
        mKernels.push_back(k);
    }
}

VolumeField::Sample VolumeField::evaluate(glm::dvec3 p) const {
    const Footprint& fp = mMaterials->footprint();
    Sample s;
    glm::dvec3 weighted(0.0);
    for (const VoxelKernel& k : mKernels) {
        const double r = glm::length(k.inverse * (p - k.center));
        const double e = k.scale * fp.kernel(r);
        s.extinction += e;
        weighted += e * k.color;
    }
    for (const ContinuousMedium& m : mMedia) {
        if (glm::any(glm::lessThan(p, m.boxMin)) || glm::any(glm::greaterThan(p, m.boxMax))) continue;
        const ContinuousMedium::Sample ms = m.sample(p);
        s.extinction += ms.extinction;
        weighted += ms.extinction * ms.color;
    }
    if (s.extinction > 0.0) s.color = weighted / s.extinction;
    return s;
}

double VolumeField::lineOpticalDepth(glm::dvec3 origin, glm::dvec3 dir) const {
    const Footprint& fp = mMaterials->footprint();
    const glm::dvec3 d = glm::normalize(dir);
    double tau = 0.0;
    for (const VoxelKernel& k : mKernels) {
        // In kernel space the line is y + s b; its integral is F(distance) / |b|.
        const glm::dvec3 y = k.inverse * (origin - k.center), b = k.inverse * d;
        const double bl = glm::length(b);
        const glm::dvec3 bh = b / bl;
        const double q2 = std::max(glm::dot(y, y) - glm::dot(y, bh) * glm::dot(y, bh), 0.0);
        tau += k.scale * fp.exact(std::sqrt(q2)) / bl;
    }
    return tau;
}

} // namespace splatfx
