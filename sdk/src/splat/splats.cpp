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
    const float inv = 1.0f / std::sqrt(std::max(a + c + 2.0f * s, 1e-30f));
    out[0] = (a + s) * inv;
    out[1] = b * inv;
    out[2] = (c + s) * inv;
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
    const ColorTable* table = hasTable ? &materials.colorTable(style.colorTable) : nullptr;

    // The kernel's shape: grid rotation/scale times lattice spacing, then the
    // voxel's stretch. Without a stretch it is the same for every voxel, so
    // its inverse, determinant and extent are computed once per grid.
    struct Shape {
        glm::mat3 sigma, sigmaInv; // M M^T and its inverse
        float cbrtDet = 1.0f, extent = 0.0f;
        bool ok = false;
        Shape() = default;
        explicit Shape(const glm::mat3& m, float R) {
            const float det = glm::determinant(m);
            ok = std::isfinite(det) && std::abs(det) >= 1e-12f;
            if (!ok) return;
            sigma = m * glm::transpose(m);
            const glm::mat3 mi = glm::inverse(m);
            sigmaInv = glm::transpose(mi) * mi;
            cbrtDet = std::cbrt(std::abs(det));
            // Conservative world extent of the footprint: R times the kernel's largest axis.
            extent = R * std::sqrt(sigma[0][0] + sigma[1][1] + sigma[2][2]);
        }
    };
    const glm::mat3 gridShape = rot * glm::mat3(glm::vec3(grid.spacing.x, 0, 0), glm::vec3(0, grid.spacing.y, 0), glm::vec3(0, 0, grid.spacing.z));
    const Shape plain(gridShape, R);
    const glm::vec3 half = glm::vec3(glm::max(grid.dims - 1, glm::ivec3(0))) * 0.5f;
    const glm::vec3 halfXZ(half.x, 0.0f, half.z);

    // Colour-table entry, read inline: its alpha scales the voxel's opacity,
    // its colour goes into the splat (8 bits per channel).
    const std::vector<glm::vec4>* entries = table ? &table->entries : nullptr;
    const float lastEntry = entries ? float(entries->size() - 1) : 0.0f;
    auto tableAt = [&](float t) {
        if (!entries) return glm::vec4(1.0f);
        const float f = std::clamp(t, 0.0f, 1.0f) * lastEntry;
        const size_t i = std::min(size_t(f), entries->size() - 2);
        return glm::clamp(glm::mix((*entries)[i], (*entries)[i + 1], f - float(i)), glm::vec4(0.0f), glm::vec4(1.0f));
    };

    // Written in place (no push_back in the loop); trimmed at the end.
    const std::size_t first = mSplats.size();
    mSplats.resize(first + grid.voxels.size());
    Splat* out = mSplats.data() + first;
    for (const Voxel& v : grid.voxels) {
        const float stretch2 = glm::dot(v.stretch, v.stretch);
        const Shape* shapePtr = &plain;
        Shape stretchedShape;
        if (stretch2 > 0.0f) {
            const float stretchLen = std::sqrt(stretch2);
            const glm::vec3 sd = v.stretch / stretchLen;
            stretchedShape = Shape(gridShape * (glm::mat3(1.0f) + stretchLen * glm::outerProduct(sd, sd)), R);
            stretchedShape.ok = stretchedShape.ok && std::isfinite(stretchLen);
            shapePtr = &stretchedShape;
        }
        const Shape& shape = *shapePtr;
        const glm::vec3 c = glm::vec3(grid.transform * glm::vec4((glm::vec3(v.cell) - halfXZ) * grid.spacing, 1.0f));
        if (!std::isfinite(v.opacity) || !std::isfinite(v.colorCoord) || !std::isfinite(v.phase) || !finite3(c) || !shape.ok ||
            !std::isfinite(stretch2)) {
            ++mStats.rejected;
            continue;
        }
        const float opacity = std::clamp(v.opacity * opacityScale, 0.0f, 1.0f);
        const glm::vec3 toC = c - eye;
        const float viewZ = glm::dot(toC, fwd);
        const float extent = shape.extent;
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
        const glm::vec3 e2 = glm::cross(e1, d); // unit: e1 and d are orthonormal

        // Line integral of h(|M^-1 x|) along d at plane offset q: F(|q|_Q) / |M^-1 d|.
        // Q is the Schur complement of Sigma^-1 = (M M^T)^-1 in the frame
        // (e1, e2, d), so Q^-1 is simply the (e1, e2) block of Sigma: the
        // ellipse's axes are the square root of that 2x2 block.
        const glm::vec3 se1 = shape.sigma * e1, se2 = shape.sigma * e2;
        float sq[3];
        sqrt2x2(glm::dot(e1, se1), glm::dot(e2, se1), glm::dot(e2, se2), sq);
        const float bLen = std::sqrt(glm::dot(d, shape.sigmaInv * d));

        Splat& sp = *out;
        sp.center = c;
        sp.axisU = R * (sq[0] * e1 + sq[1] * e2);
        sp.axisV = R * (sq[1] * e1 + sq[2] * e2);
        if (!finite3(sp.axisU) || !finite3(sp.axisV)) {
            ++mStats.rejected;
            continue;
        }
        const glm::vec4 entry = tableAt(v.colorCoord);
        const float alpha = opacity * entry.a;
        // Optical depth through the centre, relative to an isotropic voxel of
        // equal volume: the chord along d (1 / |M^-1 d|) over det(M)^(1/3).
        // log1p: 1.0f - alpha rounds to 1 for alpha < 6e-8, which would lose the voxel entirely.
        const float tau = alpha >= 1.0f ? kMaxTau : std::min(-std::log1p(-alpha) * 1.44269504f, kMaxTau);
        const float chord = (1.0f / bLen) / shape.cbrtDet;
        sp.density = tau * std::min(chord, 64.0f) * fade * range.gain;
        sp.colorCoord = std::clamp(v.colorCoord, 0.0f, 1.0f);
        sp.colorRow = hasTable ? float(style.colorTable) : 0.0f;
        const std::uint32_t index = v.texture % range.count; // one division per voxel, not two
        sp.layer = std::uint16_t(range.first + index);
        sp.nextLayer = std::uint16_t(range.first + (index + 1 == range.count ? 0 : index + 1));
        sp.color = std::uint32_t(entry.r * 255.0f + 0.5f) | std::uint32_t(entry.g * 255.0f + 0.5f) << 8 |
                   std::uint32_t(entry.b * 255.0f + 0.5f) << 16 | 0xff000000u;
        sp.blend = style.crossfade ? std::clamp(v.phase - std::floor(v.phase), 0.0f, 1.0f) : 0.0f;
        sp.depth = persp ? dist : viewZ;
        ++out;
    }
    mSplats.resize(std::size_t(out - mSplats.data()));
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
