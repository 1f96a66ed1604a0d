// The extinction field the lights see, and exact optical depth along segments (the shadow-tracing reference).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/lighting.hpp"

namespace splatfx {
namespace {

// As the splat builder (sdk/src/splat/splats.cpp, kMaxTau): opacity 1 is 24
// log2 units of depth, opaque at 8 bits and in half precision.
constexpr float kMaxTau = 24.0f;

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

struct Fnv {
    std::uint64_t h = 1469598103934665603ull;
    void bytes(const void* p, std::size_t n) {
        const auto* c = static_cast<const unsigned char*>(p);
        for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
    }
};

// Parameter range [s0, s1] of a + s d (s in [lo, hi]) inside the box [0, top]; false if none.
bool clipToBox(glm::vec3 a, glm::vec3 d, glm::vec3 top, float& s0, float& s1) {
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0f) {
            if (a[k] < 0.0f || a[k] > top[k]) return false;
            continue;
        }
        float t0 = (0.0f - a[k]) / d[k], t1 = (top[k] - a[k]) / d[k];
        if (t0 > t1) std::swap(t0, t1);
        s0 = std::max(s0, t0);
        s1 = std::min(s1, t1);
    }
    return s0 < s1;
}

} // namespace

Result<DensityField> DensityField::fromGrid(const Grid& grid, const DensityFieldDesc& desc) {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(grid.spacing[a]) || grid.spacing[a] <= 0.0f)
            return makeError(std::string("grid.spacing.") + "xyz"[a] + " must be a positive finite number");
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(grid.transform[c][r])) return makeError("grid.transform must be finite");
    const glm::mat3 shape =
        glm::mat3(grid.transform) * glm::mat3(glm::vec3(grid.spacing.x, 0, 0), glm::vec3(0, grid.spacing.y, 0), glm::vec3(0, 0, grid.spacing.z));
    const double det = std::abs(double(glm::determinant(shape)));
    if (!(det > 1e-30) || !std::isfinite(det)) return makeError("grid.transform with grid.spacing gives voxels of zero or non-finite volume");
    if (!std::isfinite(desc.opacityScale) || desc.opacityScale < 0.0f) return makeError("DensityFieldDesc.opacityScale must be a finite number >= 0");

    DensityField f;
    f.mVoxelSize = float(std::cbrt(det));
    f.mInvVoxelSize = 1.0f / f.mVoxelSize;

    auto usable = [](const Voxel& v) { return std::isfinite(v.opacity) && std::isfinite(v.colorCoord) && v.opacity > 0.0f; };
    glm::ivec3 lo(std::numeric_limits<int>::max()), hi(std::numeric_limits<int>::min());
    bool any = false;
    for (const Voxel& v : grid.voxels) {
        if (!usable(v)) continue;
        lo = glm::min(lo, v.cell);
        hi = glm::max(hi, v.cell);
        any = true;
    }
    if (any && desc.opacityScale > 0.0f) {
        // One zero cell of padding each side: the trilinear field falls to
        // zero one cell beyond the outermost voxels, as a splat's kernel does.
        const glm::i64vec3 n = glm::i64vec3(hi) - glm::i64vec3(lo) + glm::i64vec3(3);
        const std::uint64_t count = std::uint64_t(n.x) * std::uint64_t(n.y) * std::uint64_t(n.z);
        if (count > kMaxVoxels)
            return makeError("grid: the voxels' cells span " + std::to_string(n.x - 2) + "x" + std::to_string(n.y - 2) + "x" +
                             std::to_string(n.z - 2) + " cells, more than the " + std::to_string(kMaxVoxels) + "-cell limit of a density field");
        f.mDims = glm::ivec3(n);
        f.mOrigin = glm::vec3(lo - 1);
        f.mValues.assign(std::size_t(count), 0.0f);
        for (const Voxel& v : grid.voxels) {
            if (!usable(v)) continue;
            float alpha = std::clamp(v.opacity * desc.opacityScale, 0.0f, 1.0f);
            if (desc.colorTable && desc.colorTable->entries.size() >= 2) alpha *= std::clamp(desc.colorTable->sample(v.colorCoord).a, 0.0f, 1.0f);
            const float tau = alpha >= 1.0f ? kMaxTau : std::min(float(-std::log1p(-double(alpha)) / std::log(2.0)), kMaxTau);
            const glm::ivec3 c = v.cell - lo + 1;
            f.mValues[std::size_t(c.x) + std::size_t(n.x) * (std::size_t(c.y) + std::size_t(n.y) * std::size_t(c.z))] += tau;
        }
        // Lattice coordinate c of a world point: c = (T^-1 world) / spacing + halfXZ (Grid::localPosition inverted).
        const glm::vec3 half = glm::vec3(glm::max(grid.dims - 1, glm::ivec3(0))) * 0.5f;
        const glm::vec3 halfXZ(half.x, 0.0f, half.z);
        f.mWorldToLattice =
            glm::translate(glm::mat4(1.0f), halfXZ - f.mOrigin) * glm::scale(glm::mat4(1.0f), 1.0f / grid.spacing) * glm::inverse(grid.transform);
        const glm::mat4 toWorld = glm::inverse(f.mWorldToLattice);
        f.mBoundsMin = glm::vec3(std::numeric_limits<float>::max());
        f.mBoundsMax = glm::vec3(-std::numeric_limits<float>::max());
        for (int k = 0; k < 8; ++k) {
            const glm::vec3 corner((k & 1) ? float(n.x - 1) : 0.0f, (k & 2) ? float(n.y - 1) : 0.0f, (k & 4) ? float(n.z - 1) : 0.0f);
            const glm::vec3 w(toWorld * glm::vec4(corner, 1.0f));
            f.mBoundsMin = glm::min(f.mBoundsMin, w);
            f.mBoundsMax = glm::max(f.mBoundsMax, w);
        }
        if (!finite3(f.mBoundsMin) || !finite3(f.mBoundsMax)) return makeError("grid: the field's world bounds are not finite");
    }
    Fnv h;
    h.bytes(f.mValues.data(), f.mValues.size() * sizeof(float));
    h.bytes(&f.mDims, sizeof(f.mDims));
    h.bytes(&f.mWorldToLattice, sizeof(f.mWorldToLattice));
    h.bytes(&f.mVoxelSize, sizeof(f.mVoxelSize));
    f.mFingerprint = h.h;
    return f;
}

float DensityField::lattice(glm::vec3 c) const {
    const glm::vec3 top = glm::vec3(mDims - 1);
    if (!(c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f && c.x <= top.x && c.y <= top.y && c.z <= top.z)) return 0.0f;
    const glm::ivec3 i = glm::min(glm::ivec3(glm::floor(c)), mDims - 2);
    const glm::vec3 t = c - glm::vec3(i);
    const std::size_t sx = 1, sy = std::size_t(mDims.x), sz = sy * std::size_t(mDims.y);
    const float* p = mValues.data() + std::size_t(i.x) + sy * std::size_t(i.y) + sz * std::size_t(i.z);
    const float c00 = p[0] + (p[sx] - p[0]) * t.x, c10 = p[sy] + (p[sy + sx] - p[sy]) * t.x;
    const float c01 = p[sz] + (p[sz + sx] - p[sz]) * t.x, c11 = p[sz + sy] + (p[sz + sy + sx] - p[sz + sy]) * t.x;
    const float c0 = c00 + (c10 - c00) * t.y, c1 = c01 + (c11 - c01) * t.y;
    return c0 + (c1 - c0) * t.z;
}

float DensityField::at(glm::vec3 world) const {
    if (mValues.empty() || !finite3(world)) return 0.0f;
    return lattice(glm::vec3(mWorldToLattice * glm::vec4(world, 1.0f))) * mInvVoxelSize;
}

float DensityField::opticalDepth(glm::vec3 fromWorld, glm::vec3 toWorld) const {
    if (mValues.empty() || !finite3(fromWorld) || !finite3(toWorld)) return 0.0f;
    const float len = glm::length(toWorld - fromWorld);
    if (!(len > 0.0f) || !std::isfinite(len)) return 0.0f;
    const glm::vec3 a(mWorldToLattice * glm::vec4(fromWorld, 1.0f));
    const glm::vec3 d = glm::vec3(mWorldToLattice * glm::vec4(toWorld, 1.0f)) - a;
    float s0 = 0.0f, s1 = 1.0f;
    if (!clipToBox(a, d, glm::vec3(mDims - 1), s0, s1)) return 0.0f;
    // Next lattice-plane crossing along each axis (a 3D DDA). Between two
    // consecutive crossings the segment stays in one cell, where the
    // trilinear field is a cubic in s: Simpson's rule is exact there.
    float next[3], step[3];
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0f) {
            next[k] = std::numeric_limits<float>::infinity();
            step[k] = 0.0f;
            continue;
        }
        const float start = a[k] + s0 * d[k];
        const float plane = d[k] > 0.0f ? std::floor(start) + 1.0f : std::ceil(start) - 1.0f;
        next[k] = (plane - a[k]) / d[k];
        step[k] = 1.0f / std::abs(d[k]);
    }
    auto f = [&](float s) { return lattice(a + s * d); };
    double sum = 0.0;
    float s = s0, fs = f(s0);
    // At most one piece per plane crossed, plus rounding slack.
    const int maxPieces = 2 * (mDims.x + mDims.y + mDims.z) + 8;
    for (int piece = 0; piece < maxPieces && s < s1; ++piece) {
        float e = std::min({next[0], next[1], next[2], s1});
        for (int k = 0; k < 3; ++k)
            while (next[k] <= e) next[k] += step[k]; // every axis crossed at e (edges, corners) moves on
        if (!(e > s)) continue;
        const float fe = f(e);
        sum += double(e - s) / 6.0 * (double(fs) + 4.0 * double(f(0.5f * (s + e))) + double(fe));
        s = e;
        fs = fe;
    }
    return float(sum * double(len) * double(mInvVoxelSize));
}

float DensityField::opticalDepthToLight(glm::vec3 world, const Light& light) const {
    if (mValues.empty()) return 0.0f;
    if (light.type == LightType::Directional) {
        const float n = glm::length(light.direction);
        if (!(n > 0.0f) || !std::isfinite(n)) return 0.0f;
        // Far enough towards the light to leave the field; the clip trims it.
        const float reach = glm::length(glm::max(glm::abs(world - mBoundsMin), glm::abs(world - mBoundsMax))) + mVoxelSize;
        return opticalDepth(world, world - light.direction / n * reach);
    }
    return opticalDepth(world, light.position);
}

float ShadowTracer::transmittance(std::size_t light, glm::vec3 world) const {
    if (light >= mLights.size()) return 1.0f;
    return std::exp2(-mField->opticalDepthToLight(world, mLights[light]));
}

} // namespace splatfx
