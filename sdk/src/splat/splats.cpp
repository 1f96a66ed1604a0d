#include "splatfx/splats.hpp"

#include "splatfx/dynamics.hpp" // hashCell

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <thread>
#include <utility>
#include <vector>

namespace splatfx {
namespace {

// A table colour as the splat's 8-bit RGB (alpha byte 0xff): each channel clamped to [0, 1] and a
// NaN read as 0, so a bad colour-table entry is dark instead of undefined behaviour (a NaN or
// negative float converted to an unsigned int) or a channel over 1 carrying into the next byte.
std::uint32_t packTableColor(glm::vec4 c) {
    auto byte = [](float v) { return std::uint32_t((v > 0.0f ? std::min(v, 1.0f) : 0.0f) * 255.0f + 0.5f); };
    return byte(c.r) | byte(c.g) << 8 | byte(c.b) << 16 | 0xff000000u;
}

// Largest optical depth (log2 units) a voxel may have: opacity 1 - 2^-24,
// i.e. opaque at 8-bit and half precision, yet exp2(-24 * 0) stays exact at
// the footprint's zero edge (an infinite depth would give inf * 0 = NaN).
constexpr float kMaxTau = 24.0f;

float smoothstep(float a, float b, float x) {
    if (!(b > a)) return x >= b ? 1.0f : 0.0f;
    const float t = std::clamp((x - a) / (b - a), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::uint32_t orderedBits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

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

// x % d without a division (Lemire, Kaser & Kurz 2019), exact for every
// 32-bit x and d >= 1. The 64x32-bit high product is done in two 32x32 halves.
struct FastMod {
    std::uint32_t d;
    std::uint64_t m;
    explicit FastMod(std::uint32_t divisor) : d(std::max(divisor, 1u)), m(~std::uint64_t(0) / d + 1) {}
    std::uint32_t mod(std::uint32_t x) const {
        const std::uint64_t low = m * x; // the fraction x / d, in 64 bits
        return std::uint32_t(((low >> 32) * d + (((low & 0xffffffffu) * d) >> 32)) >> 32);
    }
};

// One voxel's SplatVariation draw: centre offset (cells), the texture's
// rotation (cos, sin; mirrored: the u axis negated) and size factor. Pure
// function of (cell, seed): stable over time, the same on every thread.
struct VariationDraw {
    float offset[3] = {0.0f, 0.0f, 0.0f};
    float cosA = 1.0f, sinA = 0.0f, mirror = 1.0f, scale = 1.0f;
};
constexpr std::uint32_t kVariationSalt = 0x1a771ceu; // apart from the texture dynamics' hashes of the same cells

// cos and sin of 4096 angles over [-pi, pi], cheaper than std::cos and
// std::sin per voxel; a 0.09 degree step is invisible in a texture.
struct TurnTable {
    static constexpr int kSize = 4096;
    float c[kSize + 1], s[kSize + 1];
    TurnTable() {
        for (int i = 0; i <= kSize; ++i) {
            const double a = (double(i) / kSize * 2.0 - 1.0) * 3.14159265358979323846;
            c[i] = float(std::cos(a)), s[i] = float(std::sin(a));
        }
    }
};
const TurnTable& turnTable() {
    static const TurnTable table; // built once, thread-safe
    return table;
}

VariationDraw drawVariation(const SplatVariation& var, glm::ivec3 cell) {
    VariationDraw d;
    std::uint32_t h = hashCell(cell, var.seed, kVariationSalt);
    auto next = [&h] { // a uniform in [-1, 1) per call
        h = hash32(h + 0x9e3779b9u);
        return 2.0f * hashUnit(h) - 1.0f;
    };
    const float jx = next(), jy = next(), jz = next(), angle = next(), flip = next(), size = next();
    if (var.jitter > 0.0f) d.offset[0] = var.jitter * jx, d.offset[1] = var.jitter * jy, d.offset[2] = var.jitter * jz;
    if (var.rotationRad > 0.0f) {
        const TurnTable& t = turnTable(); // nearest of the table's angles to rotationRad * angle, in [-pi, pi]
        const int i = std::clamp(int(std::lround((var.rotationRad * angle / 3.14159265f + 1.0f) * 0.5f * TurnTable::kSize)), 0, TurnTable::kSize);
        d.cosA = t.c[i], d.sinA = t.s[i];
    }
    if (var.mirror && flip < 0.0f) d.mirror = -1.0f;
    if (var.scaleLog2 > 0.0f) d.scale = std::exp2(var.scaleLog2 * size);
    return d;
}

SplatVariation sanitized(const SplatVariation& v) {
    assert(checkSplatVariation(v).empty() && "SplatBuilder::add: style.variation out of range (checkSplatVariation)");
    SplatVariation s = v;
    s.jitter = std::isfinite(v.jitter) ? std::clamp(v.jitter, 0.0f, SplatVariation::kMaxJitter) : 0.0f;
    s.rotationRad = std::isfinite(v.rotationRad) ? std::clamp(v.rotationRad, 0.0f, 3.14159265f) : 0.0f;
    s.scaleLog2 = std::isfinite(v.scaleLog2) ? std::clamp(v.scaleLog2, 0.0f, 1.0f) : 0.0f;
    return s;
}

// What a splat's geometry depends on besides its voxel and kernel shape.
struct Frame {
    glm::mat4 transform;
    glm::vec3 spacing, half;
    glm::vec3 eye, forward, up, right;
    float radius;
    bool perspective;
};

struct Geometry {
    glm::vec3 center{0.0f};
    float viewZ = 0.0f, dist = 0.0f;
    glm::vec3 axisU{0.0f}, axisV{0.0f};
    float chord = 0.0f; // optical-depth scale of the ray through the centre
};

// The view frustum's six planes from the view-projection matrix (Gribb &
// Hartmann), normalized so a plane's value at a point is its distance.
void frustumPlanes(const glm::mat4& vp, glm::vec4 (&planes)[6]) {
    for (int i = 0; i < 3; ++i) {
        const glm::vec4 row(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
        const glm::vec4 w(vp[0][3], vp[1][3], vp[2][3], vp[3][3]);
        planes[2 * i] = w + row;
        planes[2 * i + 1] = w - row;
    }
    for (auto& p : planes) p /= std::max(glm::length(glm::vec3(p)), 1e-30f);
}

constexpr int kBatch = 64;

// Geometry of kBatch voxels as structure of arrays, so computeGeometry's
// loop has no branches and vectorizes.
struct GeometryBatch {
    float cx[kBatch], cy[kBatch], cz[kBatch], viewZ[kBatch], dist[kBatch];
    float ux[kBatch], uy[kBatch], uz[kBatch], vx[kBatch], vy[kBatch], vz[kBatch], chord[kBatch];
    Geometry at(int i) const { return {{cx[i], cy[i], cz[i]}, viewZ[i], dist[i], {ux[i], uy[i], uz[i]}, {vx[i], vy[i], vz[i]}, chord[i]}; }
};

// The projected ellipse and centre chord of `count` voxels sharing one shape.
//
// Screen-plane basis at each splat: perpendicular to the ray d through its
// centre, "up" as close to the camera's up as possible so textures stay
// upright (flames rise on screen). The line integral of h(|M^-1 x|) along d
// at plane offset q is F(|q|_Q) / |M^-1 d|, where Q is the Schur complement
// of Sigma^-1 = (M M^T)^-1 in the frame (e1, e2, d); Q^-1 is simply the
// (e1, e2) block of Sigma, so the ellipse's axes are that 2x2 block's square
// root. Isotropic kernels see a circle of radius s and a chord of s.
// `offset` (3 floats per voxel, in cells; nullptr for none) moves each centre
// off its lattice point (SplatVariation::jitter).
template <bool Isotropic>
void computeGeometry(const Frame& f, const Shape& shape, const Voxel* voxels, int count, GeometryBatch& out, const float* offset = nullptr) {
    // Plain floats rather than glm vectors: GCC vectorizes the loop only
    // when no 3-vector aggregates are copied inside it (and, for the
    // selects, with -fno-trapping-math; see sdk/CMakeLists.txt).
    const glm::mat4& t = f.transform;
    const float t00 = t[0][0], t01 = t[0][1], t02 = t[0][2], t10 = t[1][0], t11 = t[1][1], t12 = t[1][2];
    const float t20 = t[2][0], t21 = t[2][1], t22 = t[2][2];
    const float ox = t[3][0] - f.eye.x, oy = t[3][1] - f.eye.y, oz = t[3][2] - f.eye.z; // grid origin from the eye
    const float ex = f.eye.x, ey = f.eye.y, ez = f.eye.z;
    const float sx = f.spacing.x, sy = f.spacing.y, sz = f.spacing.z, hx = f.half.x, hy = f.half.y, hz = f.half.z;
    const float fx = f.forward.x, fy = f.forward.y, fz = f.forward.z, ux = f.up.x, uy = f.up.y, uz = f.up.z;
    const float rx = f.right.x, ry = f.right.y, rz = f.right.z;
    const float perspW = f.perspective ? 1.0f : 0.0f;
    const float R = f.radius, isoAxis = f.radius * shape.s, isoChord = shape.s / shape.cbrtDet, invCbrtDet = 1.0f / shape.cbrtDet;
    const glm::mat3& S = shape.sigma;
    const glm::mat3& Si = shape.sigmaInv;
    const float s00 = S[0][0], s01 = S[0][1], s02 = S[0][2], s11 = S[1][1], s12 = S[1][2], s22 = S[2][2]; // symmetric
    const float i00 = Si[0][0], i01 = Si[0][1], i02 = Si[0][2], i11 = Si[1][1], i12 = Si[1][2], i22 = Si[2][2];
    // The cells first, into arrays: strided loads from the 40-byte voxels
    // would keep the loop below scalar.
    float cellX[kBatch], cellY[kBatch], cellZ[kBatch];
    for (int i = 0; i < count; ++i) {
        cellX[i] = float(voxels[i].cell.x);
        cellY[i] = float(voxels[i].cell.y);
        cellZ[i] = float(voxels[i].cell.z);
    }
    if (offset)
        for (int i = 0; i < count; ++i) {
            cellX[i] += offset[3 * i];
            cellY[i] += offset[3 * i + 1];
            cellZ[i] += offset[3 * i + 2];
        }
    for (int i = 0; i < count; ++i) {
        const float lx = (cellX[i] - hx) * sx, ly = (cellY[i] - hy) * sy, lz = (cellZ[i] - hz) * sz;
        // Eye-relative centre.
        const float cx = t00 * lx + t10 * ly + t20 * lz + ox, cy = t01 * lx + t11 * ly + t21 * lz + oy, cz = t02 * lx + t12 * ly + t22 * lz + oz;
        const float dist = std::sqrt(cx * cx + cy * cy + cz * cz);
        // Selections as arithmetic on 0/1 weights: vector selects, no branches.
        const float ray = dist > 1e-20f ? perspW : 0.0f;
        const float k = ray / (ray > 0.0f ? dist : 1.0f), kf = 1.0f - ray;
        const float dx = cx * k + fx * kf, dy = cy * k + fy * kf, dz = cz * k + fz * kf;
        // e1 = normalize(d x up), or the camera's right when d is parallel to up.
        float e1x = dy * uz - dz * uy, e1y = dz * ux - dx * uz, e1z = dx * uy - dy * ux;
        const float len = std::sqrt(e1x * e1x + e1y * e1y + e1z * e1z);
        const float ok = len > 1e-6f ? 1.0f : 0.0f;
        const float ke = ok / (ok > 0.0f ? len : 1.0f), kr = 1.0f - ok;
        e1x = e1x * ke + rx * kr, e1y = e1y * ke + ry * kr, e1z = e1z * ke + rz * kr;
        // e2 = e1 x d, unit since e1 and d are orthonormal.
        const float e2x = e1y * dz - e1z * dy, e2y = e1z * dx - e1x * dz, e2z = e1x * dy - e1y * dx;
        float q0 = isoAxis, q1 = 0.0f, q2 = isoAxis, chord = isoChord;
        if constexpr (!Isotropic) {
            const float a1 = s00 * e1x + s01 * e1y + s02 * e1z, b1 = s01 * e1x + s11 * e1y + s12 * e1z,
                        c1 = s02 * e1x + s12 * e1y + s22 * e1z; // Sigma e1
            const float a = e1x * a1 + e1y * b1 + e1z * c1, b = e2x * a1 + e2y * b1 + e2z * c1;
            const float a2 = s00 * e2x + s01 * e2y + s02 * e2z, b2 = s01 * e2x + s11 * e2y + s12 * e2z,
                        c2 = s02 * e2x + s12 * e2y + s22 * e2z; // Sigma e2
            const float c = e2x * a2 + e2y * b2 + e2z * c2;
            // Symmetric square root of [[a b][b c]], scaled to the footprint's radius.
            const float root = std::sqrt(std::max(a * c - b * b, 0.0f));
            const float inv = R / std::sqrt(std::max(a + c + 2.0f * root, 1e-30f));
            q0 = (a + root) * inv, q1 = b * inv, q2 = (c + root) * inv;
            const float id =
                (i00 * dx + i01 * dy + i02 * dz) * dx + (i01 * dx + i11 * dy + i12 * dz) * dy + (i02 * dx + i12 * dy + i22 * dz) * dz; // |M^-1 d|^2
            chord = invCbrtDet / std::sqrt(id);
        }
        out.cx[i] = cx + ex, out.cy[i] = cy + ey, out.cz[i] = cz + ez;
        out.viewZ[i] = cx * fx + cy * fy + cz * fz;
        out.dist[i] = dist;
        out.ux[i] = q0 * e1x + q1 * e2x, out.uy[i] = q0 * e1y + q1 * e2y, out.uz[i] = q0 * e1z + q1 * e2z;
        out.vx[i] = q1 * e1x + q2 * e2x, out.vy[i] = q1 * e1y + q2 * e2y, out.vz[i] = q1 * e1z + q2 * e2z;
        out.chord[i] = chord;
    }
}

} // namespace

std::uint8_t rayScaleCode(float rho) {
    if (rho == 1.0f) return 255;
    if (!(rho > 0.0f)) return 0; // also NaN
    const float c = std::clamp(std::round(32.0f * std::log2(rho)) + 127.0f, 0.0f, 254.0f);
    return c == 127.0f ? 255 : std::uint8_t(c);
}

float rayScaleRho(std::uint8_t code) { return code == 255 ? 1.0f : std::exp2((float(code) - 127.0f) / 32.0f); }

glm::vec3 splatColor(const Splat& sp) {
    const glm::vec3 c = glm::vec3(float(sp.color & 255u), float((sp.color >> 8) & 255u), float((sp.color >> 16) & 255u)) / 255.0f;
    return sp.colorCoord < 0.0f ? -sp.colorCoord * c : c;
}

float splatRayScale(const Splat& sp, float footprintRadius) {
    const float area = glm::length(glm::cross(sp.axisU, sp.axisV));
    if (!(area > 0.0f) || !(footprintRadius > 0.0f) || !std::isfinite(area)) return 0.0f;
    return rayScaleRho(std::uint8_t(sp.color >> 24)) * std::sqrt(area) / footprintRadius;
}

void SplatBuilder::begin(const Camera& camera) {
    mCamera = camera;
    mSplats.clear();
    mStats = {};
}

std::string checkSplatVariation(const SplatVariation& v, const std::string& field) {
    auto range = [&](const char* name, float x, float hi) {
        char bound[32];
        std::snprintf(bound, sizeof bound, "%g", double(hi));
        return x >= 0.0f && x <= hi ? std::string() : field + name + " must be in [0, " + bound + "], got " + std::to_string(x);
    };
    for (std::string e : {range("jitter", v.jitter, SplatVariation::kMaxJitter), range("rotationRad", v.rotationRad, 3.14159265f), range("scaleLog2", v.scaleLog2, 1.0f)})
        if (!e.empty()) return e;
    return {};
}

void SplatBuilder::add(const Grid& grid, const Materials& materials, const SplatStyle& style) {
    mStats.voxelsIn += grid.voxels.size();
    const Camera& cam = mCamera;
    const glm::vec3 eye = cam.eye(), fwd = cam.forward(), camUp = cam.up(), camRight = cam.right();
    const bool persp = cam.perspective();
    const float nearZ = cam.nearPlane();
    const float R = materials.footprint().radius();

    // Frustum planes (Gribb & Hartmann) for conservative sphere culling.
    glm::vec4 planes[6];
    frustumPlanes(cam.proj * cam.view, planes);

    const bool hasSet = style.textured && style.textureSet < materials.setCount();
    const Materials::SetRange range = hasSet ? materials.set(style.textureSet) : Materials::SetRange{0, 1, false, 1.0f};
    const bool hasTable = style.colorTable < materials.colorTableCount();
    const glm::mat3 rot(grid.transform);
    const float opacityScale = std::isfinite(style.opacityScale) ? std::max(style.opacityScale, 0.0f) : 0.0f;
    const ColorTable* table = hasTable ? &materials.colorTable(style.colorTable) : nullptr;

    const glm::mat3 gridShape = rot * glm::mat3(glm::vec3(grid.spacing.x, 0, 0), glm::vec3(0, grid.spacing.y, 0), glm::vec3(0, 0, grid.spacing.z));
    const Shape plain(gridShape, R);
    // Plain footprints have no stamp to hide and reconstruct the field best on
    // the lattice (Crawfis-Max: 0.57 % ripple): the variation is for textured splats.
    const SplatVariation variation = hasSet ? sanitized(style.variation) : SplatVariation{};
    const bool varied = variation.any();
    // Culling bound: a jittered centre moves by at most jitter * sqrt(3)
    // cells' largest axis, and a scaled splat reaches scale times as far.
    const float maxScale = std::exp2(variation.scaleLog2), jitterReach = variation.jitter * 1.7320508f * (R > 0.0f ? plain.extent / R : 0.0f);
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
            for (const auto& p : planes) inside = inside && glm::dot(glm::vec3(p), corner) + p.w >= -(plain.extent * maxScale + jitterReach);
        }
        cullEach = !inside;
    }

    // Everything the geometry of one splat depends on besides its voxel.
    const Frame frame{grid.transform, grid.spacing, halfXZ, eye, fwd, camUp, camRight, R, persp};

    auto build = [&](const Voxel* begin, const Voxel* end, Splat* out, SplatStats& stats) {
        // Local copies: the compiler cannot keep values read through
        // references in registers across the stores to *out (they might alias).
        const float nearZL = nearZ, fadeStart = mDesc.nearFadeStart, fadeEnd = mDesc.nearFadeEnd;
        const bool nearFade = mDesc.nearFade;
        const bool cull = cullEach, crossfade = style.crossfade, perspL = persp;
        const float colorRow = hasTable ? float(style.colorTable) : 0.0f, gain = range.gain, scaleL = opacityScale;
        const std::uint32_t setFirst = range.first;
        const FastMod setCount(range.count);
        bool haveEntry = false;
        float lastCoord = 0.0f, lastAlpha = -1.0f, lastTau = 0.0f;
        glm::vec4 entry(1.0f);
        std::uint32_t packedColor = 0xffffffffu;
        // Geometry is computed kBatch voxels at a time by a branch-free loop
        // the compiler vectorizes; the per-voxel rest below is scalar.
        GeometryBatch batch;
        VariationDraw draws[kBatch];
        float offsets[3 * kBatch];
        for (const Voxel* first = begin; first < end; first += kBatch) {
            const int count = int(std::min<std::ptrdiff_t>(kBatch, end - first));
            if (varied)
                for (int i = 0; i < count; ++i) {
                    draws[i] = drawVariation(variation, first[i].cell);
                    std::copy(draws[i].offset, draws[i].offset + 3, offsets + 3 * i);
                }
            const float* off = varied && variation.jitter > 0.0f ? offsets : nullptr;
            if (plain.ok) {
                if (plain.isotropic) computeGeometry<true>(frame, plain, first, count, batch, off);
                else computeGeometry<false>(frame, plain, first, count, batch, off);
            }
            for (int i = 0; i < count; ++i) {
                const Voxel& v = first[i];
                const float stretch2 = glm::dot(v.stretch, v.stretch);
                Geometry g;
                float extent = plain.extent;
                bool shapeOk = plain.ok;
                bool isoKernel = plain.isotropic;
                if (stretch2 > 0.0f) {
                    // A stretched kernel has its own shape: the same math, one voxel.
                    const float stretchLen = std::sqrt(stretch2);
                    const glm::vec3 sd = v.stretch / stretchLen;
                    const Shape shape(gridShape * (glm::mat3(1.0f) + stretchLen * glm::outerProduct(sd, sd)), R);
                    shapeOk = shape.ok && std::isfinite(stretchLen);
                    extent = shape.extent;
                    isoKernel = shape.isotropic;
                    if (shapeOk) {
                        GeometryBatch one;
                        if (shape.isotropic) computeGeometry<true>(frame, shape, &v, 1, one, off ? off + 3 * i : nullptr);
                        else computeGeometry<false>(frame, shape, &v, 1, one, off ? off + 3 * i : nullptr);
                        g = one.at(0);
                    }
                } else if (shapeOk) {
                    g = batch.at(i);
                }
                if (!std::isfinite(v.opacity) || !std::isfinite(v.colorCoord) || !std::isfinite(v.phase) || !shapeOk || !std::isfinite(stretch2) ||
                    !finite3(g.center)) {
                    ++stats.rejected;
                    continue;
                }
                const float opacity = std::clamp(v.opacity * scaleL, 0.0f, 1.0f);
                bool outside = opacity <= 0.0f;
                const float scale = varied ? draws[i].scale : 1.0f;
                if (cull)
                    for (const auto& p : planes) outside = outside || glm::dot(glm::vec3(p), g.center) + p.w < -extent * scale;
                const float fadeFrom = nearZL + fadeStart * extent, fadeTo = nearZL + fadeEnd * extent;
                const float fade = !nearFade || g.viewZ >= fadeTo ? 1.0f : smoothstep(fadeFrom, fadeTo, g.viewZ);
                if (outside || fade <= 0.0f) {
                    ++stats.culled;
                    continue;
                }
                if (!finite3(g.axisU) || !finite3(g.axisV)) {
                    ++stats.rejected;
                    continue;
                }
                Splat& sp = *out;
                sp.center = g.center;
                sp.axisU = g.axisU;
                sp.axisV = g.axisV;
                if (varied) {
                    // Turning or mirroring the (u, v) frame keeps the ellipse and
                    // |(u, v)|, so the footprint is unchanged: only the texture turns.
                    const VariationDraw& d = draws[i];
                    sp.axisU = d.mirror * d.scale * (d.cosA * g.axisU + d.sinA * g.axisV);
                    sp.axisV = d.scale * (d.cosA * g.axisV - d.sinA * g.axisU);
                }
                // Neighbouring voxels usually share a colour coordinate (one layer of
                // the lattice) and an opacity: reuse the last lookup and logarithm.
                if (!haveEntry || v.colorCoord != lastCoord) {
                    entry = tableAt(v.colorCoord);
                    packedColor = packTableColor(entry);
                    lastCoord = v.colorCoord;
                    haveEntry = true;
                }
                const float alpha = opacity * entry.a;
                // Optical depth through the centre: -log2(1 - alpha) times the
                // chord relative to an isotropic voxel of equal volume.
                // log2(1 - alpha) loses small alphas (1 - alpha rounds to 1 below 6e-8):
                // log1p below 2^-10, the cheaper log2 above, where it is exact to 1e-4 relative.
                if (alpha != lastAlpha) {
                    lastTau =
                        alpha >= 1.0f ? kMaxTau : std::min(alpha < 0x1p-10f ? -std::log1p(-alpha) * 1.44269504f : -std::log2(1.0f - alpha), kMaxTau);
                    lastAlpha = alpha;
                }
                // A splat scaled by s keeps its material: its optical depth falls by s^2 (area grows by s^2).
                sp.density = lastTau * std::min(g.chord, 64.0f) * fade * gain / (scale * scale);
                sp.colorCoord = std::clamp(v.colorCoord, 0.0f, 1.0f);
                sp.colorRow = colorRow;
                const std::uint32_t index = setCount.mod(v.texture);
                sp.layer = std::uint16_t(setFirst + index);
                sp.nextLayer = std::uint16_t(setFirst + (index + 1 == setCount.d ? 0 : index + 1));
                // The along-ray scale for the depth cut (splats.hpp, rayScaleCode):
                // chord = l / |det M|^(1/3), so rho = chord^(3/2); 1 (code 255) when isotropic.
                sp.color = isoKernel ? packedColor : (packedColor & 0x00ffffffu) | std::uint32_t(rayScaleCode(std::pow(g.chord, 1.5f))) << 24;
                sp.blend = crossfade ? std::clamp(v.phase - std::floor(v.phase), 0.0f, 1.0f) : 0.0f;
                sp.depth = perspL ? g.dist : g.viewZ;
                ++out;
            }
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
            ends[t] =
                build(grid.voxels.data() + (chunk(t) - first), grid.voxels.data() + (chunk(t + 1) - first), mSplats.data() + chunk(t), stats[t]);
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

void SplatBuilder::add(std::span<const Particle> particles, const Materials& materials, const ParticleStyle& pstyle) {
    mStats.voxelsIn += particles.size();
    const SplatStyle& style = pstyle.splat;
    const Camera& cam = mCamera;
    const bool persp = cam.perspective();
    const float R = materials.footprint().radius();
    glm::vec4 planes[6];
    frustumPlanes(cam.proj * cam.view, planes);
    const bool hasSet = style.textured && style.textureSet < materials.setCount();
    const Materials::SetRange range = hasSet ? materials.set(style.textureSet) : Materials::SetRange{0, 1, false, 1.0f};
    const bool hasTable = style.colorTable < materials.colorTableCount();
    const ColorTable* table = hasTable ? &materials.colorTable(style.colorTable) : nullptr;
    const float opacityScale = std::isfinite(style.opacityScale) ? std::max(style.opacityScale, 0.0f) : 0.0f;
    SplatVariation variation = hasSet ? sanitized(style.variation) : SplatVariation{};
    variation.jitter = 0.0f; // a particle's centre is its own, not a lattice point's
    const bool varied = variation.any();
    const float stretchPerSpeed = std::isfinite(pstyle.stretchPerSpeed) ? std::max(pstyle.stretchPerSpeed, 0.0f) : 0.0f;
    const float maxStretch = std::isfinite(pstyle.maxStretch) ? std::max(pstyle.maxStretch, 0.0f) : 0.0f;
    const FastMod setCount(range.count);
    const Voxel origin{}; // each particle is the lone lattice point of its own frame
    const glm::vec3 eye = cam.eye(), fwd = cam.forward(), camUp = cam.up(), camRight = cam.right();
    const float nearZ = cam.nearPlane();
    mSplats.reserve(mSplats.size() + particles.size());
    for (const Particle& p : particles) {
        const float size = p.sizeWorld;
        const float speed = glm::length(p.velocity);
        if (!finite3(p.position) || !(size > 0.0f) || !std::isfinite(size) || !std::isfinite(p.opacity) || !std::isfinite(p.colorCoord) ||
            !std::isfinite(p.phase) || !std::isfinite(speed)) {
            ++mStats.rejected;
            continue;
        }
        // The kernel of a voxel with spacing `size` and no rotation, stretched
        // along the velocity (the grid path's Voxel::stretch, in world units here).
        const float stretch = stretchPerSpeed > 0.0f && speed > 0.0f ? std::min(speed * stretchPerSpeed, maxStretch) : 0.0f;
        glm::mat3 m(size);
        if (stretch > 0.0f) {
            const glm::vec3 sd = p.velocity / speed;
            m = m * (glm::mat3(1.0f) + stretch * glm::outerProduct(sd, sd));
        }
        const Shape shape(m, R);
        if (!shape.ok) {
            ++mStats.rejected;
            continue;
        }
        const VariationDraw d = varied ? drawVariation(variation, glm::ivec3(int(p.id & 0x7fffffffu), int(p.id >> 31), 0x5a17)) : VariationDraw{};
        const float opacity = std::clamp(p.opacity * opacityScale, 0.0f, 1.0f);
        bool outside = opacity <= 0.0f;
        if (mDesc.frustumCull)
            for (const auto& pl : planes) outside = outside || glm::dot(glm::vec3(pl), p.position) + pl.w < -shape.extent * d.scale;
        if (outside) {
            ++mStats.culled;
            continue;
        }
        const Frame frame{glm::translate(glm::mat4(1.0f), p.position), glm::vec3(1.0f), glm::vec3(0.0f), eye, fwd, camUp, camRight, R, persp};
        GeometryBatch one;
        if (shape.isotropic) computeGeometry<true>(frame, shape, &origin, 1, one);
        else computeGeometry<false>(frame, shape, &origin, 1, one);
        const Geometry g = one.at(0);
        const float fadeFrom = nearZ + mDesc.nearFadeStart * shape.extent, fadeTo = nearZ + mDesc.nearFadeEnd * shape.extent;
        const float fade = !mDesc.nearFade || g.viewZ >= fadeTo ? 1.0f : smoothstep(fadeFrom, fadeTo, g.viewZ);
        if (fade <= 0.0f) {
            ++mStats.culled;
            continue;
        }
        if (!finite3(g.center) || !finite3(g.axisU) || !finite3(g.axisV)) {
            ++mStats.rejected;
            continue;
        }
        Splat sp;
        sp.center = g.center;
        sp.axisU = d.mirror * d.scale * (d.cosA * g.axisU + d.sinA * g.axisV);
        sp.axisV = d.scale * (d.cosA * g.axisV - d.sinA * g.axisU);
        glm::vec4 entry(1.0f);
        if (table) {
            const std::vector<glm::vec4>& e = table->entries;
            const float f = std::clamp(p.colorCoord, 0.0f, 1.0f) * float(e.size() - 1);
            const size_t i = std::min(size_t(f), e.size() - 2);
            entry = glm::clamp(glm::mix(e[i], e[i + 1], f - float(i)), glm::vec4(0.0f), glm::vec4(1.0f));
        }
        const std::uint32_t packed = packTableColor(entry);
        const float alpha = opacity * entry.a;
        // As add(Grid): -log2(1 - alpha), log1p for small alphas, capped at kMaxTau.
        const float tau = alpha >= 1.0f ? kMaxTau : std::min(alpha < 0x1p-10f ? -std::log1p(-alpha) * 1.44269504f : -std::log2(1.0f - alpha), kMaxTau);
        sp.density = tau * std::min(g.chord, 64.0f) * fade * range.gain / (d.scale * d.scale);
        sp.colorCoord = std::clamp(p.colorCoord, 0.0f, 1.0f);
        sp.colorRow = hasTable ? float(style.colorTable) : 0.0f;
        const std::uint32_t index = setCount.mod(p.texture);
        sp.layer = std::uint16_t(range.first + index);
        sp.nextLayer = std::uint16_t(range.first + (index + 1 == setCount.d ? 0 : index + 1));
        sp.color = shape.isotropic ? packed : (packed & 0x00ffffffu) | std::uint32_t(rayScaleCode(std::pow(g.chord, 1.5f))) << 24;
        sp.blend = style.crossfade ? std::clamp(p.phase - std::floor(p.phase), 0.0f, 1.0f) : 0.0f;
        sp.depth = persp ? g.dist : g.viewZ;
        mSplats.push_back(sp);
    }
}

void SplatBuilder::sort(SortMode mode) { sortBackToFront(mSplats, mScratch, mode, mDesc.buckets); }

void sortBackToFront(std::vector<Splat>& splats, SortMode mode, std::uint32_t buckets) {
    SortScratch scratch;
    sortBackToFront(splats, scratch, mode, buckets);
}

void sortBackToFront(std::vector<Splat>& splats, SortScratch& scratch, SortMode mode, std::uint32_t buckets) {
    if (mode == SortMode::None || splats.size() < 2) return;
    const size_t n = splats.size();
    // Keys ascending = depth descending: back to front.
    std::vector<std::uint32_t>& keys = scratch.keys;
    std::vector<std::uint32_t>& keys2 = scratch.keys2;
    std::vector<Splat>& tmp = scratch.splats;
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
        for (size_t i = 0; i < n; ++i) keys[i] = last - std::min(last, std::uint32_t((splats[i].depth - lo) * scale));
    }
    // LSD radix sort on indices, 8 bits per pass. The four digit histograms
    // come from one read of the keys; a pass whose digit is the same for every
    // key is skipped; the first pass that runs reads no index array.
    std::vector<std::uint32_t>& idx = scratch.index;
    std::vector<std::uint32_t>& idx2 = scratch.index2;
    idx.resize(n);
    idx2.resize(n);
    std::uint32_t count[4][256] = {};
    for (size_t i = 0; i < n; ++i) {
        const std::uint32_t k = keys[i];
        ++count[0][k & 255u];
        ++count[1][(k >> 8) & 255u];
        ++count[2][(k >> 16) & 255u];
        ++count[3][k >> 24];
    }
    bool sorted = false; // idx holds a permutation
    for (int pass = 0; pass < 4; ++pass) {
        const int shift = 8 * pass;
        std::uint32_t* offset = count[pass];
        if (offset[(keys[0] >> shift) & 255u] == n) continue;
        std::uint32_t sum = 0;
        for (std::uint32_t& c : count[pass]) sum += std::exchange(c, sum);
        for (size_t i = 0; i < n; ++i) {
            const std::uint32_t dst = offset[(keys[i] >> shift) & 255u]++;
            keys2[dst] = keys[i];
            idx2[dst] = sorted ? idx[i] : std::uint32_t(i);
        }
        keys.swap(keys2);
        idx.swap(idx2);
        sorted = true;
    }
    if (!sorted) return; // every key equal: already in (stable) order
    for (size_t i = 0; i < n; ++i) tmp[i] = splats[idx[i]];
    splats.swap(tmp);
}

} // namespace splatfx
