#include "splatfx/splats.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <thread>
#include <vector>

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
        // Sigma = s^2 I (cubic spacing, rotation, uniform scale): every view
        // sees a circle of radius s and a chord of s, so the 2x2 square root
        // and |M^-1 d| are known without per-voxel work.
        bool isotropic = false;
        float s = 0.0f;
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
            const float s2 = (sigma[0][0] + sigma[1][1] + sigma[2][2]) / 3.0f;
            float offIso = 0.0f;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) offIso = std::max(offIso, std::abs(sigma[i][j] - (i == j ? s2 : 0.0f)));
            isotropic = offIso <= 1e-6f * s2;
            s = std::sqrt(s2);
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

    // One pass over a range of voxels, writing splats in place from `out`
    // (no push_back); returns the end of what it wrote. Reads only shared,
    // unchanging state, so ranges can run on several threads.
    // A lattice wholly inside the frustum needs no per-voxel plane tests: a
    // voxel is culled only when a whole plane's distance is below -extent, and
    // the lattice's corners bound that distance for every voxel inside it.
    // (A voxel outside its grid's dims is then merely not culled: harmless.)
    bool cullEach = mDesc.frustumCull;
    if (cullEach && plain.ok && glm::all(glm::greaterThan(grid.dims, glm::ivec3(0)))) {
        bool inside = true;
        for (int k = 0; k < 8 && inside; ++k) {
            const glm::ivec3 cell((k & 1) ? grid.dims.x - 1 : 0, (k & 2) ? grid.dims.y - 1 : 0, (k & 4) ? grid.dims.z - 1 : 0);
            const glm::vec3 corner = glm::vec3(grid.transform * glm::vec4((glm::vec3(cell) - halfXZ) * grid.spacing, 1.0f));
            for (const auto& p : planes) inside = inside && glm::dot(glm::vec3(p), corner) + p.w >= -plain.extent;
        }
        cullEach = !inside;
    }

    auto build = [&](const Voxel* begin, const Voxel* end, Splat* out, SplatStats& stats) {
        // Local copies: the compiler cannot keep values read through
        // references in registers across the stores to *out (they might alias).
        const glm::vec3 eyeL = eye, fwdL = fwd, camUpL = camUp, camRightL = camRight;
        const float nearZL = nearZ, fadeStart = mDesc.nearFadeStart, fadeEnd = mDesc.nearFadeEnd, RL = R;
        const bool cull = cullEach, crossfade = style.crossfade, perspL = persp;
        const float colorRow = hasTable ? float(style.colorTable) : 0.0f, gain = range.gain, scaleL = opacityScale;
        const std::uint32_t setFirst = range.first, setCount = range.count;
        const glm::mat4 transform = grid.transform;
        const glm::vec3 spacing = grid.spacing, halfL = halfXZ;
        bool haveEntry = false;
        float lastCoord = 0.0f, lastAlpha = -1.0f, lastTau = 0.0f;
        glm::vec4 entry(1.0f);
        std::uint32_t packedColor = 0xffffffffu;
        for (const Voxel* vp = begin; vp != end; ++vp) {
            const Voxel& v = *vp;
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
            const glm::vec3 c = glm::vec3(transform * glm::vec4((glm::vec3(v.cell) - halfL) * spacing, 1.0f));
            if (!std::isfinite(v.opacity) || !std::isfinite(v.colorCoord) || !std::isfinite(v.phase) || !finite3(c) || !shape.ok ||
                !std::isfinite(stretch2)) {
                ++stats.rejected;
                continue;
            }
            const float opacity = std::clamp(v.opacity * scaleL, 0.0f, 1.0f);
            const glm::vec3 toC = c - eyeL;
            const float viewZ = glm::dot(toC, fwdL);
            const float extent = shape.extent;
            bool outside = opacity <= 0.0f;
            if (cull)
                for (const auto& p : planes) outside = outside || glm::dot(glm::vec3(p), c) + p.w < -extent;
            const float fadeFrom = nearZL + fadeStart * extent, fadeTo = nearZL + fadeEnd * extent;
            const float fade = viewZ >= fadeTo ? 1.0f : smoothstep(fadeFrom, fadeTo, viewZ);
            if (outside || fade <= 0.0f) {
                ++stats.culled;
                continue;
            }

            // Screen-plane basis at the splat: perpendicular to the ray through
            // its centre, "up" as close to the camera's up as possible so
            // textures stay upright (flames rise on screen).
            const float dist = glm::length(toC);
            const glm::vec3 d = perspL ? (dist > 1e-20f ? toC * (1.0f / dist) : fwdL) : fwdL;
            glm::vec3 e1 = glm::cross(d, camUpL);
            const float e1Len = glm::length(e1);
            e1 = e1Len > 1e-6f ? e1 * (1.0f / e1Len) : camRightL;
            const glm::vec3 e2 = glm::cross(e1, d); // unit: e1 and d are orthonormal

            // Line integral of h(|M^-1 x|) along d at plane offset q: F(|q|_Q) / |M^-1 d|.
            // Q is the Schur complement of Sigma^-1 = (M M^T)^-1 in the frame
            // (e1, e2, d), so Q^-1 is simply the (e1, e2) block of Sigma: the
            // ellipse's axes are the square root of that 2x2 block.
            float sq[3] = {shape.s, 0.0f, shape.s};
            float bLen = 1.0f / shape.s;
            if (!shape.isotropic) {
                const glm::vec3 se1 = shape.sigma * e1, se2 = shape.sigma * e2;
                sqrt2x2(glm::dot(e1, se1), glm::dot(e2, se1), glm::dot(e2, se2), sq);
                bLen = std::sqrt(glm::dot(d, shape.sigmaInv * d));
            }

            Splat& sp = *out;
            sp.center = c;
            sp.axisU = RL * (sq[0] * e1 + sq[1] * e2);
            sp.axisV = RL * (sq[1] * e1 + sq[2] * e2);
            if (!finite3(sp.axisU) || !finite3(sp.axisV)) {
                ++stats.rejected;
                continue;
            }
            // Neighbouring voxels usually share a colour coordinate (one layer of
            // the lattice) and an opacity: reuse the last lookup and logarithm.
            if (!haveEntry || v.colorCoord != lastCoord) {
                entry = tableAt(v.colorCoord);
                packedColor = std::uint32_t(entry.r * 255.0f + 0.5f) | std::uint32_t(entry.g * 255.0f + 0.5f) << 8 |
                              std::uint32_t(entry.b * 255.0f + 0.5f) << 16 | 0xff000000u;
                lastCoord = v.colorCoord;
                haveEntry = true;
            }
            const float alpha = opacity * entry.a;
            // Optical depth through the centre, relative to an isotropic voxel of
            // equal volume: the chord along d (1 / |M^-1 d|) over det(M)^(1/3).
            // log2(1 - alpha) loses small alphas (1 - alpha rounds to 1 below 6e-8):
            // log1p below 2^-10, the cheaper log2 above, where it is exact to 1e-4 relative.
            if (alpha != lastAlpha) {
                lastTau = alpha >= 1.0f ? kMaxTau
                                        : std::min(alpha < 0x1p-10f ? -std::log1p(-alpha) * 1.44269504f : -std::log2(1.0f - alpha), kMaxTau);
                lastAlpha = alpha;
            }
            const float tau = lastTau;
            const float chord = (1.0f / bLen) / shape.cbrtDet;
            sp.density = tau * std::min(chord, 64.0f) * fade * gain;
            sp.colorCoord = std::clamp(v.colorCoord, 0.0f, 1.0f);
            sp.colorRow = colorRow;
            const std::uint32_t index = v.texture % setCount; // one division per voxel, not two
            sp.layer = std::uint16_t(setFirst + index);
            sp.nextLayer = std::uint16_t(setFirst + (index + 1 == setCount ? 0 : index + 1));
            sp.color = packedColor;
            sp.blend = crossfade ? std::clamp(v.phase - std::floor(v.phase), 0.0f, 1.0f) : 0.0f;
            sp.depth = perspL ? dist : viewZ;
            ++out;
        }
        return out;
    };

    const std::size_t first = mSplats.size(), n = grid.voxels.size();
    mSplats.resize(first + n);
    const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    const unsigned wanted = mDesc.threads == 0 ? hw : mDesc.threads;
    // Threads only pay off on large grids: below ~8k voxels a thread's start-up costs more than it saves.
    const unsigned threads = unsigned(std::clamp<std::size_t>(n / 8192, 1, std::max(1u, wanted)));
    if (threads <= 1) {
        Splat* out = build(grid.voxels.data(), grid.voxels.data() + n, mSplats.data() + first, mStats);
        mSplats.resize(std::size_t(out - mSplats.data()));
        return;
    }
    // Contiguous chunks keep the output in voxel order, so the result (and
    // the stable sort after it) is the same for any thread count.
    std::vector<SplatStats> stats(threads);
    std::vector<Splat*> ends(threads);
    std::vector<std::thread> pool;
    auto chunk = [&](unsigned t) { return first + n * t / threads; };
    for (unsigned t = 1; t < threads; ++t)
        pool.emplace_back([&, t] {
            ends[t] = build(grid.voxels.data() + (chunk(t) - first), grid.voxels.data() + (chunk(t + 1) - first),
                            mSplats.data() + chunk(t), stats[t]);
        });
    ends[0] = build(grid.voxels.data(), grid.voxels.data() + (chunk(1) - first), mSplats.data() + first, stats[0]);
    for (std::thread& th : pool) th.join();
    Splat* write = ends[0];
    for (unsigned t = 0; t < threads; ++t) {
        if (t > 0) {
            const Splat* from = mSplats.data() + chunk(t);
            write = std::copy(from, static_cast<const Splat*>(ends[t]), write);
        }
        mStats.rejected += stats[t].rejected;
        mStats.culled += stats[t].culled;
    }
    mSplats.resize(std::size_t(write - mSplats.data()));
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
