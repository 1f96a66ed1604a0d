#include "splatfx/splats.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace splatfx {
namespace {

// Largest optical depth (log2 units) a voxel may have: opacity 1 - 2^-24,
// i.e. opaque at 8-bit and half precision, yet exp2(-24 * 0) stays exact at
// the footprint's zero edge (an infinite depth would give inf * 0 = NaN).
constexpr float kMaxTau = 24.0f;

float smoothstep(float a, float b, float x) {
    if (!(b > a)) return x >= b ? 1.0f : 0.0f;
    const float t = std::clamp((x - a) / (b - a), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

// Symmetric square root of a 2x2 symmetric positive definite matrix.
void sqrt2x2(float a, float b, float c, float out[3]) { // [[a b][b c]]
    const float s = std::sqrt(std::max(a * c - b * b, 0.0f));
    const float t = std::sqrt(std::max(a + c + 2.0f * s, 1e-30f));
    out[0] = (a + s) / t;
    out[1] = b / t;
    out[2] = (c + s) / t;
}

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::uint32_t orderedBits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

} // namespace

void SplatBuilder::begin(const Camera& camera) {
    mCamera = camera;
    mSplats.clear();
    mStats = {};
}

void SplatBuilder::add(const Grid& grid, const Materials& materials, const SplatStyle& style) {
    mStats.voxelsIn += grid.voxels.size();
    const Camera& cam = mCamera;
    const glm::vec3 eye = cam.eye(), fwd = cam.forward(), camUp = cam.up(), camRight = cam.right();
    const bool persp = cam.perspective();
    const float nearZ = cam.nearPlane();
    const float R = materials.footprint().radius();

    // Frustum planes (Gribb & Hartmann) for conservative sphere culling.
    const glm::mat4 vp = cam.proj * cam.view;
    glm::vec4 planes[6];
    for (int i = 0; i < 3; ++i) {
        const glm::vec4 row(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
        const glm::vec4 w(vp[0][3], vp[1][3], vp[2][3], vp[3][3]);
        planes[2 * i] = w + row;
        planes[2 * i + 1] = w - row;
    }
    for (auto& p : planes) p /= std::max(glm::length(glm::vec3(p)), 1e-30f);

    const bool hasSet = style.textured && style.textureSet < materials.setCount();
    const Materials::SetRange range = hasSet ? materials.set(style.textureSet) : Materials::SetRange{0, 1, false, 1.0f};
    const bool hasTable = style.colorTable < materials.colorTableCount();
    const glm::mat3 rot(grid.transform);
    const float opacityScale = std::isfinite(style.opacityScale) ? std::max(style.opacityScale, 0.0f) : 0.0f;

    for (const Voxel& v : grid.voxels) {
        // Kernel shape: grid rotation/scale, lattice spacing, then the voxel's stretch.
        glm::mat3 m = rot * glm::mat3(glm::vec3(grid.spacing.x, 0, 0), glm::vec3(0, grid.spacing.y, 0), glm::vec3(0, 0, grid.spacing.z));
        const float stretchLen = glm::length(v.stretch);
        if (stretchLen > 0.0f && std::isfinite(stretchLen)) {
            const glm::vec3 s = v.stretch / stretchLen;
            m = m * (glm::mat3(1.0f) + stretchLen * glm::outerProduct(s, s));
        }
        const float det = glm::determinant(m);
        const glm::vec3 c = glm::vec3(grid.transform * glm::vec4(grid.localPosition(v.cell), 1.0f));
        if (!std::isfinite(v.opacity) || !std::isfinite(v.colorCoord) || !std::isfinite(v.phase) || !finite3(c) ||
            !std::isfinite(det) || std::abs(det) < 1e-12f) {
            ++mStats.rejected;
            continue;
        }
        const float opacity = std::clamp(v.opacity * opacityScale, 0.0f, 1.0f);
        const glm::vec3 toC = c - eye;
        const float viewZ = glm::dot(toC, fwd);
        // Conservative world extent of the footprint: R times the kernel's largest axis.
        const float extent = R * std::sqrt(glm::dot(m[0], m[0]) + glm::dot(m[1], m[1]) + glm::dot(m[2], m[2]));
        bool outside = opacity <= 0.0f;
        if (mDesc.frustumCull)
            for (const auto& p : planes) outside = outside || glm::dot(glm::vec3(p), c) + p.w < -extent;
        const float fade = smoothstep(nearZ + mDesc.nearFadeStart * extent, nearZ + mDesc.nearFadeEnd * extent, viewZ);
        if (outside || fade <= 0.0f) {
            ++mStats.culled;
            continue;
        }

        // Screen-plane basis at the splat: perpendicular to the ray through
        // its centre, "up" as close to the camera's up as possible so
        // textures stay upright (flames rise on screen).
        const float dist = glm::length(toC);
        const glm::vec3 d = persp ? (dist > 1e-20f ? toC / dist : fwd) : fwd;
        glm::vec3 e1 = glm::cross(d, camUp);
        const float e1Len = glm::length(e1);
        e1 = e1Len > 1e-6f ? e1 / e1Len : camRight;
        const glm::vec3 e2 = glm::normalize(glm::cross(e1, d));

        // Line integral of h(|M^-1 x|) along d at plane offset q: F(|.|_Q) / |M^-1 d|,
        // with Q the quadratic form of the distance in kernel space.
        const glm::mat3 mi = glm::inverse(m);
        const glm::vec3 a1 = mi * e1, a2 = mi * e2, b = mi * d;
        const float bLen = glm::length(b);
        const glm::vec3 bh = b / bLen;
        const float q00 = glm::dot(a1, a1) - glm::dot(a1, bh) * glm::dot(a1, bh);
        const float q01 = glm::dot(a1, a2) - glm::dot(a1, bh) * glm::dot(a2, bh);
        const float q11 = glm::dot(a2, a2) - glm::dot(a2, bh) * glm::dot(a2, bh);
        // Q^-1 maps the unit disc onto the ellipse; its square root gives the axes.
        const float qDet = std::max(q00 * q11 - q01 * q01, 1e-30f);
        float s[3];
        sqrt2x2(q11 / qDet, -q01 / qDet, q00 / qDet, s);

        Splat sp;
        sp.center = c;
        sp.axisU = R * (s[0] * e1 + s[1] * e2);
        sp.axisV = R * (s[1] * e1 + s[2] * e2);
        if (!finite3(sp.axisU) || !finite3(sp.axisV)) {
            ++mStats.rejected;
            continue;
        }
        const float tableAlpha = hasTable ? std::clamp(materials.colorTable(style.colorTable).sample(v.colorCoord).a, 0.0f, 1.0f) : 1.0f;
        const float alpha = opacity * tableAlpha;
        // Optical depth through the centre, relative to an isotropic voxel of
        // equal volume: the chord along d (1 / |M^-1 d|) over det(M)^(1/3).
        const float tau = alpha >= 1.0f ? kMaxTau : std::min(-std::log2(1.0f - alpha), kMaxTau);
        const float chord = (1.0f / bLen) / std::cbrt(std::abs(det));
        sp.density = tau * std::min(chord, 64.0f) * fade * range.gain;
        sp.colorCoord = std::clamp(v.colorCoord, 0.0f, 1.0f);
        sp.colorRow = hasTable ? float(style.colorTable) : 0.0f;
        sp.layer = float(range.first + v.texture % range.count);
        sp.nextLayer = float(range.first + (v.texture + 1) % range.count);
        sp.blend = style.crossfade ? std::clamp(v.phase - std::floor(v.phase), 0.0f, 1.0f) : 0.0f;
        sp.depth = persp ? dist : viewZ;
        mSplats.push_back(sp);
    }
}

void SplatBuilder::sort(SortMode mode) { sortBackToFront(mSplats, mode, mDesc.buckets); }

void sortBackToFront(std::vector<Splat>& splats, SortMode mode, std::uint32_t buckets) {
    if (mode == SortMode::None || splats.size() < 2) return;
    const size_t n = splats.size();
    // Keys ascending = depth descending: back to front.
    thread_local std::vector<std::uint32_t> keys, keys2;
    thread_local std::vector<Splat> tmp;
    keys.resize(n);
    keys2.resize(n);
    tmp.resize(n);
    if (mode == SortMode::Exact) {
        for (size_t i = 0; i < n; ++i) keys[i] = ~orderedBits(splats[i].depth);
    } else {
        float lo = splats[0].depth, hi = lo;
        for (const Splat& s : splats) lo = std::min(lo, s.depth), hi = std::max(hi, s.depth);
        const float scale = hi > lo ? float(std::max(buckets, 1u)) / (hi - lo) : 0.0f;
        const std::uint32_t last = std::max(buckets, 1u) - 1;
        for (size_t i = 0; i < n; ++i)
            keys[i] = last - std::min(last, std::uint32_t((splats[i].depth - lo) * scale));
    }
    // LSD radix sort, 8 bits per pass on indices; skip passes where all digits agree.
    thread_local std::vector<std::uint32_t> idx, idx2;
    idx.resize(n);
    idx2.resize(n);
    for (size_t i = 0; i < n; ++i) idx[i] = std::uint32_t(i);
    for (int shift = 0; shift < 32; shift += 8) {
        size_t count[257] = {};
        for (size_t i = 0; i < n; ++i) ++count[((keys[i] >> shift) & 255u) + 1];
        if (count[((keys[0] >> shift) & 255u) + 1] == n) continue;
        for (int b = 0; b < 256; ++b) count[b + 1] += count[b];
        for (size_t i = 0; i < n; ++i) {
            const size_t dst = count[(keys[i] >> shift) & 255u]++;
            keys2[dst] = keys[i];
            idx2[dst] = idx[i];
        }
        keys.swap(keys2);
        idx.swap(idx2);
    }
    for (size_t i = 0; i < n; ++i) tmp[i] = splats[idx[i]];
    splats.swap(tmp);
}

} // namespace splatfx
