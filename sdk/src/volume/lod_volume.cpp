// The LOD volume: octree error (sec. 2.2, 2.4), per-frame refinement (eq. 1),
// volumetric morphing (sec. 3, eqs. 6-8), back-to-front emission with
// frustum culling (4.2), the zero-opacity test (4.1) and volumetric clipping
// at the near plane (4.3). Roettger & Ertl 2002.
#include "splatfx/volume.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace splatfx {
namespace {

constexpr int kMaxRootLevel = 12;
constexpr float kMorphSteps = 254.0f; // e' in 8 bits: code 0 = not refined, 1..255 = refined with e' = (code-1)/254

int autoRootLevel(glm::ivec3 dims) {
    const int m = std::max(1, std::min({dims.x, dims.y, dims.z}) - 1);
    int n = 0;
    while (n < kMaxRootLevel && (2 << n) <= m) ++n;
    return std::max(1, n);
}

glm::ivec3 rootsFor(glm::ivec3 dims, int n) {
    const int s = 1 << n;
    return {std::max(1, (dims.x - 1 + s - 1) / s), std::max(1, (dims.y - 1 + s - 1) / s), std::max(1, (dims.z - 1 + s - 1) / s)};
}

bool finiteVec(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

float det3(const Tetrahedron& t) {
    const glm::vec3 a = t.position[1] - t.position[0], b = t.position[2] - t.position[0], c = t.position[3] - t.position[0];
    return glm::dot(a, glm::cross(b, c));
}

// Zero volume (to float precision, relative to the tetrahedron's size) or not.
bool degenerate(const Tetrahedron& t) {
    float l2 = 0.0f;
    for (int i = 1; i < 4; ++i) l2 = std::max(l2, glm::dot(t.position[std::size_t(i)] - t.position[0], t.position[std::size_t(i)] - t.position[0]));
    const float v = std::fabs(det3(t));
    // A float determinant of vectors of length L carries ~1e-7 L^3 of rounding;
    // ten times that is treated as zero volume.
    return !(v > 1e-6f * l2 * std::sqrt(l2));
}

void orient(Tetrahedron& t) {
    if (det3(t) < 0.0f) {
        std::swap(t.position[2], t.position[3]);
        std::swap(t.scalar[2], t.scalar[3]);
        std::swap(t.lengthScale[2], t.lengthScale[3]);
    }
}

// Where the eye is, for ordering: a point (perspective) or a direction toward it (orthographic).
struct Viewer {
    glm::vec3 eye{0.0f};
    glm::vec3 towardEye{0.0f}; // orthographic: -forward
    bool perspective = true;
    // > 0: the eye is on the side of the plane (through p0, normal n) that n points to.
    float side(glm::vec3 n, glm::vec3 p0) const { return perspective ? glm::dot(n, eye - p0) : glm::dot(n, towardEye); }
};

// Back-to-front order of a few convex pieces meeting face to face (MPVO,
// Williams 1992 [48]): a piece whose free vertex lies on the eye's side of a
// shared face is in front of the other one.
void orderPieces(Tetrahedron* t, int count, const Viewer& v) {
    if (count < 2) return;
    bool behind[3][3] = {}; // behind[i][j]: i must be drawn before j
    for (int i = 0; i < count; ++i)
        for (int j = i + 1; j < count; ++j) {
            int shared[3], ns = 0, freeI = -1;
            for (int a = 0; a < 4; ++a) {
                bool found = false;
                for (int b = 0; b < 4; ++b)
                    if (t[i].position[std::size_t(a)] == t[j].position[std::size_t(b)]) found = true;
                if (found && ns < 3) shared[ns++] = a;
                else if (!found) freeI = a;
            }
            if (ns != 3 || freeI < 0) continue;
            const glm::vec3 p0 = t[i].position[std::size_t(shared[0])];
            const glm::vec3 n = glm::cross(t[i].position[std::size_t(shared[1])] - p0, t[i].position[std::size_t(shared[2])] - p0);
            const float freeSide = glm::dot(n, t[i].position[std::size_t(freeI)] - p0);
            const float eyeSide = v.side(n, p0);
            if (freeSide * eyeSide > 0.0f) behind[j][i] = true; // i is on the eye's side: i in front
            else behind[i][j] = true;
        }
    Tetrahedron sorted[3];
    bool placed[3] = {};
    for (int k = 0; k < count; ++k) {
        int pick = -1;
        for (int i = 0; i < count && pick < 0; ++i) {
            if (placed[i]) continue;
            bool free = true;
            for (int j = 0; j < count; ++j)
                if (!placed[j] && behind[j][i]) free = false;
            if (free) pick = i;
        }
        if (pick < 0) // a cycle cannot occur for pieces of one convex cell; keep input order if float says otherwise
            for (int i = 0; i < count && pick < 0; ++i)
                if (!placed[i]) pick = i;
        placed[pick] = true;
        sorted[k] = t[pick];
    }
    for (int k = 0; k < count; ++k) t[k] = sorted[k];
}

Tetrahedron lerpVertex(const Tetrahedron& t, int i, int o, float di, float dOut, Tetrahedron& dst, int slot) {
    const float f = di / (di - dOut); // in [0, 1): di >= 0 > dOut
    dst.position[std::size_t(slot)] = t.position[std::size_t(i)] + f * (t.position[std::size_t(o)] - t.position[std::size_t(i)]);
    dst.scalar[std::size_t(slot)] = t.scalar[std::size_t(i)] + f * (t.scalar[std::size_t(o)] - t.scalar[std::size_t(i)]);
    dst.lengthScale[std::size_t(slot)] = t.lengthScale[std::size_t(i)] + f * (t.lengthScale[std::size_t(o)] - t.lengthScale[std::size_t(i)]);
    return dst;
}

void copyVertex(const Tetrahedron& t, int i, Tetrahedron& dst, int slot) {
    dst.position[std::size_t(slot)] = t.position[std::size_t(i)];
    dst.scalar[std::size_t(slot)] = t.scalar[std::size_t(i)];
    dst.lengthScale[std::size_t(slot)] = t.lengthScale[std::size_t(i)];
}

} // namespace

// ---------------------------------------------------------------------------
// Clipping (sec. 4.3)
// ---------------------------------------------------------------------------

int clipTetrahedron(const Tetrahedron& tet, glm::vec3 normal, float offset, std::vector<Tetrahedron>& out) {
    float d[4];
    int inside[4], outside[4], ni = 0, no = 0;
    for (int i = 0; i < 4; ++i) {
        d[i] = glm::dot(normal, tet.position[std::size_t(i)]) - offset;
        if (!std::isfinite(d[i])) return 0;
        // On the plane counts as visible: a vertex on the plane needs no cut.
        if (d[i] >= 0.0f) inside[ni++] = i;
        else outside[no++] = i;
    }
    Tetrahedron pieces[3];
    int count = 0;
    if (no == 0) {
        pieces[count++] = tet;
    } else if (no == 3) {
        // The tip at the one visible vertex.
        Tetrahedron& t = pieces[count++];
        copyVertex(tet, inside[0], t, 0);
        for (int k = 0; k < 3; ++k) lerpVertex(tet, inside[0], outside[k], d[inside[0]], d[outside[k]], t, k + 1);
    } else if (no == 1 || no == 2) {
        // A prism: triangles a (slots 0-2) and b (slots 3-5), edges a_k - b_k.
        Tetrahedron prism; // use two Tetrahedra as six vertex slots
        Tetrahedron prism2;
        auto setSlot = [&](int slot, auto&& fill) {
            Tetrahedron& dst = slot < 4 ? prism : prism2;
            fill(dst, slot < 4 ? slot : slot - 4);
        };
        if (no == 1) {
            for (int k = 0; k < 3; ++k) {
                setSlot(k, [&](Tetrahedron& dst, int s) { copyVertex(tet, inside[k], dst, s); });
                setSlot(k + 3, [&](Tetrahedron& dst, int s) { lerpVertex(tet, inside[k], outside[0], d[inside[k]], d[outside[0]], dst, s); });
            }
        } else {
            // a = (i0, cut(i0,o0), cut(i0,o1)), b = (i1, cut(i1,o0), cut(i1,o1)).
            for (int k = 0; k < 2; ++k) {
                const int base = 3 * k, iv = inside[k];
                setSlot(base, [&](Tetrahedron& dst, int s) { copyVertex(tet, iv, dst, s); });
                for (int l = 0; l < 2; ++l)
                    setSlot(base + 1 + l, [&](Tetrahedron& dst, int s) { lerpVertex(tet, iv, outside[l], d[iv], d[outside[l]], dst, s); });
            }
        }
        auto getSlot = [&](int slot, Tetrahedron& dst, int s) { copyVertex(slot < 4 ? prism : prism2, slot < 4 ? slot : slot - 4, dst, s); };
        // The staircase split (a0 a1 a2 b0), (a1 a2 b0 b1), (a2 b0 b1 b2): valid for a convex prism.
        static constexpr int kSplit[3][4] = {{0, 1, 2, 3}, {1, 2, 3, 4}, {2, 3, 4, 5}};
        for (const auto& s : kSplit) {
            Tetrahedron& t = pieces[count++];
            for (int v = 0; v < 4; ++v) getSlot(s[v], t, v);
        }
    }
    int appended = 0;
    for (int k = 0; k < count; ++k) {
        if (degenerate(pieces[k])) continue;
        orient(pieces[k]);
        out.push_back(pieces[k]);
        ++appended;
    }
    return appended;
}

// ---------------------------------------------------------------------------
// Construction (sec. 2.1, 2.2, 2.4)
// ---------------------------------------------------------------------------

std::size_t LodVolume::bytesFor(glm::ivec3 dims, bool hasLengthScale, int rootLevel) {
    const int n = rootLevel > 0 ? rootLevel : autoRootLevel(dims);
    const glm::ivec3 r = rootsFor(dims, n);
    const double px = double(r.x) * double(1 << n) + 1, py = double(r.y) * double(1 << n) + 1, pz = double(r.z) * double(1 << n) + 1;
    double bytes = px * py * pz * (hasLengthScale ? 2.0 : 1.0);
    for (int l = 1; l <= n; ++l) {
        const double s = double(1 << (n - l));
        bytes += 5.0 * (double(r.x) * s) * (double(r.y) * s) * (double(r.z) * s); // Delta 2 + e' 1 + range 2
    }
    return bytes > 1.8e19 ? std::size_t(-1) : std::size_t(bytes);
}

Result<LodVolume> LodVolume::create(const ScalarVolume& field, const LodVolumeDesc& desc) {
    const glm::ivec3 d = field.dims;
    if (d.x < 2 || d.y < 2 || d.z < 2)
        return makeError("ScalarVolume.dims must be at least 2 along every axis (got " + std::to_string(d.x) + "x" + std::to_string(d.y) + "x" +
                         std::to_string(d.z) + ")");
    const double count = double(d.x) * double(d.y) * double(d.z);
    if (double(field.scalar.size()) != count)
        return makeError("ScalarVolume.scalar has " + std::to_string(field.scalar.size()) + " values; dims ask for " +
                         std::to_string(std::uint64_t(count)));
    if (!field.lengthScale.empty() && field.lengthScale.size() != field.scalar.size())
        return makeError("ScalarVolume.lengthScale must be empty or the size of ScalarVolume.scalar");
    if (!finiteVec(desc.originWorld)) return makeError("LodVolumeDesc.originWorld must be finite");
    if (!std::isfinite(desc.spacingWorld) || !(desc.spacingWorld > 0.0f)) return makeError("LodVolumeDesc.spacingWorld must be finite and > 0");
    // Eq. 4 holds for C > sqrt(3) (the paper's condition).
    if (!std::isfinite(desc.minAccuracyC) || !(double(desc.minAccuracyC) > std::sqrt(3.0)))
        return makeError("LodVolumeDesc.minAccuracyC must be finite and > sqrt(3) (eq. 4)");
    if (desc.rootLevel < 0 || desc.rootLevel > kMaxRootLevel)
        return makeError("LodVolumeDesc.rootLevel must be 0 (auto) or in [1, " + std::to_string(kMaxRootLevel) + "]");
    if (!std::isfinite(desc.padValue) || desc.padValue < 0.0f || desc.padValue > 1.0f) return makeError("LodVolumeDesc.padValue must be in [0, 1]");
    const std::size_t need = bytesFor(d, !field.lengthScale.empty(), desc.rootLevel);
    if (need > desc.memoryBudgetBytes)
        return makeError("LodVolume: a " + std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z) + " field needs " +
                         std::to_string(need) + " bytes, above LodVolumeDesc.memoryBudgetBytes = " + std::to_string(desc.memoryBudgetBytes));

    for (std::size_t i = 0; i < field.scalar.size(); ++i) {
        const float v = field.scalar[i];
        if (!std::isfinite(v) || v < 0.0f || v > 1.0f)
            return makeError("ScalarVolume.scalar[" + std::to_string(i) + "] must be finite and in [0, 1]");
    }
    for (std::size_t i = 0; i < field.lengthScale.size(); ++i) {
        const float v = field.lengthScale[i];
        if (!std::isfinite(v) || v < 0.0f || v > 1.0f)
            return makeError("ScalarVolume.lengthScale[" + std::to_string(i) + "] must be finite and in [0, 1]");
    }
    LodVolume v;
    v.mRootLevel = desc.rootLevel > 0 ? desc.rootLevel : autoRootLevel(d);
    v.mRoots = rootsFor(d, v.mRootLevel);
    v.mDims = v.mRoots * (1 << v.mRootLevel) + 1;
    v.mOrigin = desc.originWorld;
    v.mSpacing = desc.spacingWorld;
    v.mC = desc.minAccuracyC;
    v.mKMax = double(desc.minAccuracyC) / (2.0 * double(desc.minAccuracyC) - 0.5 * std::sqrt(3.0)); // eq. 4
    v.mDeltaMode = desc.delta;
    const std::size_t points = std::size_t(v.mDims.x) * std::size_t(v.mDims.y) * std::size_t(v.mDims.z);
    auto q8 = [](float x) { return std::uint8_t(std::lround(x * 255.0f)); };
    v.mScalar.assign(points, q8(desc.padValue));
    if (!field.lengthScale.empty()) v.mLength.assign(points, q8(desc.padValue));
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                const std::size_t src = std::size_t(x) + std::size_t(d.x) * (std::size_t(y) + std::size_t(d.y) * std::size_t(z));
                const std::size_t dst = v.pointIndex({x, y, z});
                v.mScalar[dst] = q8(field.scalar[src]);
                if (!v.mLength.empty()) v.mLength[dst] = q8(field.lengthScale[src]);
            }
    v.build();
    return v;
}

unsigned LodVolume::centreTetCorners(glm::ivec3 node) {
    unsigned mask = 0;
    for (unsigned c = 0; c < 8; ++c) {
        const int parity = (node.x + node.y + node.z + int(c & 1) + int((c >> 1) & 1) + int((c >> 2) & 1)) & 1;
        if (parity == 0) mask |= 1u << c;
    }
    return mask;
}

float LodVolume::scalarAt(glm::ivec3 p) const { return float(mScalar[pointIndex(p)]) / 255.0f; }
float LodVolume::lengthScaleAt(glm::ivec3 p) const { return mLength.empty() ? 1.0f : float(mLength[pointIndex(p)]) / 255.0f; }

namespace {

// The 19 non-corner lattice points of a node (3x3x3 lattice, index a + 3b + 9c)
// and what each one's coarse value interpolates (sec. 2.2, 3): edge midpoints
// the two edge ends, face centres the two corners on the face's diagonal
// (the even-parity ones, which differ between alternating neighbours) and the
// centre the four corners of the centre tetrahedron.
struct LatticeRule {
    int index = 0;
    int kind = 0;                 // 1 edge, 2 face, 3 centre
    int axis = 0;                 // edge: its direction; face: its normal
    int coarse[4] = {0, 0, 0, 0}; // lattice indices of the coarse ends (2 or 4 used)
    int coarseCount = 0;
};

int lat(int a, int b, int c) { return a + 3 * b + 9 * c; }
int cornerLat(unsigned c) { return lat(2 * int(c & 1), 2 * int((c >> 1) & 1), 2 * int((c >> 2) & 1)); }

// Rules for a node whose centre tetrahedron uses the corners in `evenMask`.
void latticeRules(unsigned evenMask, LatticeRule (&rules)[19]) {
    int k = 0;
    for (int c = 0; c < 3; ++c)
        for (int b = 0; b < 3; ++b)
            for (int a = 0; a < 3; ++a) {
                const int ones = (a == 1) + (b == 1) + (c == 1);
                if (ones == 0) continue;
                LatticeRule r;
                r.index = lat(a, b, c);
                r.kind = ones;
                const int p[3] = {a, b, c};
                if (ones == 1) {
                    r.axis = a == 1 ? 0 : (b == 1 ? 1 : 2);
                    int lo[3] = {a, b, c}, hi[3] = {a, b, c};
                    lo[r.axis] = 0;
                    hi[r.axis] = 2;
                    r.coarse[0] = lat(lo[0], lo[1], lo[2]);
                    r.coarse[1] = lat(hi[0], hi[1], hi[2]);
                    r.coarseCount = 2;
                } else if (ones == 2) {
                    r.axis = a != 1 ? 0 : (b != 1 ? 1 : 2);
                    for (unsigned cc = 0; cc < 8; ++cc) {
                        const int cp[3] = {2 * int(cc & 1), 2 * int((cc >> 1) & 1), 2 * int((cc >> 2) & 1)};
                        if (cp[r.axis] != p[r.axis] || !(evenMask & (1u << cc))) continue;
                        r.coarse[r.coarseCount++] = cornerLat(cc);
                    }
                } else {
                    for (unsigned cc = 0; cc < 8; ++cc)
                        if (evenMask & (1u << cc)) r.coarse[r.coarseCount++] = cornerLat(cc);
                }
                rules[k++] = r;
            }
}

} // namespace

void LodVolume::build() {
    mLevels.assign(std::size_t(mRootLevel) + 1, Level{});
    for (int l = 1; l <= mRootLevel; ++l) {
        Level& lv = mLevels[std::size_t(l)];
        lv.nodes = mRoots * (1 << (mRootLevel - l));
        const std::size_t count = std::size_t(lv.nodes.x) * std::size_t(lv.nodes.y) * std::size_t(lv.nodes.z);
        lv.delta.assign(count, 0);
        lv.morph.assign(count, 0);
        lv.rangeLo.assign(count, 0);
        lv.rangeHi.assign(count, 0);
    }
    for (int l = 1; l <= mRootLevel; ++l) {
        Level& lv = mLevels[std::size_t(l)];
        for (int z = 0; z < lv.nodes.z; ++z)
            for (int y = 0; y < lv.nodes.y; ++y)
                for (int x = 0; x < lv.nodes.x; ++x) {
                    const glm::ivec3 node{x, y, z};
                    const std::size_t idx = nodeIndex(l, node);
                    const double local = localDeltaAt(l, node);
                    // 16-bit linear mapping of Delta in [0, 1] (scalars are in [0, 1], so deviations are),
                    // rounded up so the stored value never understates the error.
                    std::uint32_t q = std::uint32_t(std::ceil(local * 65535.0));
                    std::uint8_t lo = 255, hi = 0;
                    if (l == 1) {
                        const glm::ivec3 base = node * 2;
                        for (int c = 0; c < 27; ++c) {
                            const std::uint8_t s = mScalar[pointIndex(base + glm::ivec3(c % 3, (c / 3) % 3, c / 9))];
                            lo = std::min(lo, s);
                            hi = std::max(hi, s);
                        }
                    } else {
                        const Level& ch = mLevels[std::size_t(l - 1)];
                        for (int c = 0; c < 8; ++c) {
                            const glm::ivec3 cn = node * 2 + glm::ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
                            const std::size_t ci = nodeIndex(l - 1, cn);
                            // Eq. 5, on the quantized values so the dequantized ones obey it exactly.
                            q = std::max(q, std::uint32_t(std::ceil(mKMax * double(ch.delta[ci]))));
                            lo = std::min(lo, ch.rangeLo[ci]);
                            hi = std::max(hi, ch.rangeHi[ci]);
                        }
                    }
                    lv.delta[idx] = std::uint16_t(std::min<std::uint32_t>(q, 65535));
                    lv.rangeLo[idx] = lo;
                    lv.rangeHi[idx] = hi;
                }
    }
}

double LodVolume::localDeltaAt(int level, glm::ivec3 node) const {
    const int h = 1 << (level - 1);
    const glm::ivec3 base = node * (2 * h);
    LatticeRule rules[19];
    latticeRules(centreTetCorners(node), rules);
    double best = 0.0;
    for (int channel = 0; channel < (mLength.empty() ? 1 : 2); ++channel) {
        const std::vector<std::uint8_t>& f = channel == 0 ? mScalar : mLength;
        double v[27];
        for (int c = 0; c < 27; ++c) v[c] = double(f[pointIndex(base + h * glm::ivec3(c % 3, (c / 3) % 3, c / 9))]) / 255.0;
        double maxDev = 0.0, sum = 0.0;
        for (const LatticeRule& r : rules) {
            double coarse = 0.0;
            for (int k = 0; k < r.coarseCount; ++k) coarse += v[r.coarse[k]];
            coarse /= double(r.coarseCount);
            const double dev = std::fabs(v[r.index] - coarse);
            maxDev = std::max(maxDev, dev);
            sum += dev;
        }
        best = std::max(best, mDeltaMode == DeltaMode::Max ? maxDev : sum / 19.0);
    }
    return best;
}

double LodVolume::deltaAt(int level, glm::ivec3 node) const { return double(mLevels[std::size_t(level)].delta[nodeIndex(level, node)]) / 65535.0; }

double LodVolume::errorMetric(int level, glm::ivec3 node, glm::vec3 eye, float detailC) const {
    const double size = double(1 << level) * double(mSpacing);
    const glm::dvec3 centre = glm::dvec3(mOrigin) + (glm::dvec3(node) + 0.5) * size;
    const double d = glm::length(glm::dvec3(eye) - centre);
    const double delta = deltaAt(level, node);
    const double num = size * double(mC) * std::max(double(detailC) * delta, 1.0); // eq. 1
    return d > 0.0 ? num / d : std::numeric_limits<double>::infinity();
}

std::size_t LodVolume::memoryBytes() const {
    std::size_t b = mScalar.size() + mLength.size();
    for (const Level& l : mLevels) b += l.delta.size() * 2 + l.morph.size() + l.rangeLo.size() + l.rangeHi.size();
    return b;
}

std::uint64_t LodVolume::fullResolutionTets() const {
    return 5ull * std::uint64_t(mDims.x - 1) * std::uint64_t(mDims.y - 1) * std::uint64_t(mDims.z - 1);
}

// ---------------------------------------------------------------------------
// Per-frame update (sec. 2.2, 3, 4)
// ---------------------------------------------------------------------------

struct LodTraversal {
    const LodVolume& vol;
    const LodRefineDesc& desc;
    const TransferFunction* transfer;
    LodFrame& out;
    Viewer viewer;
    glm::vec4 planes[6];
    glm::vec3 nearNormal{0.0f};
    float nearOffset = 0.0f;
    LatticeRule rules[2][19]; // by centre-tetrahedron parity of the node

    float morphWeight(int level, glm::ivec3 n) const {
        const LodVolume::Level& lv = vol.mLevels[std::size_t(level)];
        if (n.x < 0 || n.y < 0 || n.z < 0 || n.x >= lv.nodes.x || n.y >= lv.nodes.y || n.z >= lv.nodes.z) return 2.0f; // outside: no vote
        const std::uint8_t code = lv.morph[vol.nodeIndex(level, n)];
        if (code == 0) return 0.0f; // not refined (or not reached): the vertex is a T-vertex there (sec. 2.3)
        return desc.morph ? float(code - 1) / kMorphSteps : 1.0f;
    }

    // w of eq. 7: the minimum over the same-level nodes that share the vertex.
    float sharedWeight(int level, glm::ivec3 node, const LatticeRule& r) const {
        const int p[3] = {r.index % 3, (r.index / 3) % 3, r.index / 9};
        if (r.kind == 3) return morphWeight(level, node);
        float w = 2.0f;
        if (r.kind == 2) {
            glm::ivec3 a = node, b = node;
            a[r.axis] += p[r.axis] / 2 - 1;
            b[r.axis] += p[r.axis] / 2;
            w = std::min(morphWeight(level, a), morphWeight(level, b));
        } else {
            const int u = (r.axis + 1) % 3, v = (r.axis + 2) % 3;
            for (int du = 0; du < 2; ++du)
                for (int dv = 0; dv < 2; ++dv) {
                    glm::ivec3 m = node;
                    m[u] += p[u] / 2 - 1 + du;
                    m[v] += p[v] / 2 - 1 + dv;
                    w = std::min(w, morphWeight(level, m));
                }
        }
        return std::min(w, 1.0f);
    }

    glm::vec3 worldOf(glm::ivec3 gridPoint) const { return vol.mOrigin + glm::vec3(gridPoint) * vol.mSpacing; }

    // 0 outside, 1 intersecting, 2 fully inside the frustum.
    int classify(glm::vec3 lo, glm::vec3 hi) const {
        bool inside = true;
        for (const glm::vec4& p : planes) {
            const glm::vec3 n(p);
            const glm::vec3 far(n.x >= 0 ? hi.x : lo.x, n.y >= 0 ? hi.y : lo.y, n.z >= 0 ? hi.z : lo.z);
            const glm::vec3 near(n.x >= 0 ? lo.x : hi.x, n.y >= 0 ? lo.y : hi.y, n.z >= 0 ? lo.z : hi.z);
            const float slack = 1e-5f * (std::fabs(p.w) + glm::length(n) * glm::length(hi - lo));
            if (glm::dot(n, far) + p.w < -slack) return 0;
            if (glm::dot(n, near) + p.w < slack) inside = false;
        }
        return inside ? 2 : 1;
    }

    void node(int level, glm::ivec3 n, const float (&cs)[8], const float (&cm)[8], bool fullyInside) {
        const int size = 1 << level;
        const glm::ivec3 base = n * size;
        if (desc.frustumCull && !fullyInside) {
            const int c = classify(worldOf(base), worldOf(base + size));
            if (c == 0) {
                ++out.stats.nodesCulled;
                return;
            }
            fullyInside = c == 2;
        }
        const bool refined = level >= 1 && vol.mLevels[std::size_t(level)].morph[vol.nodeIndex(level, n)] != 0;
        if (desc.zeroOpacityTest && level >= 1) {
            // Every value in the subtree is a convex combination of this node's
            // (morphed) corners and its raw grid points (eq. 8), so this range bounds it.
            const LodVolume::Level& lv = vol.mLevels[std::size_t(level)];
            float lo = float(lv.rangeLo[vol.nodeIndex(level, n)]) / 255.0f, hi = float(lv.rangeHi[vol.nodeIndex(level, n)]) / 255.0f;
            for (int c = 0; c < 8; ++c) {
                lo = std::min(lo, cs[c]);
                hi = std::max(hi, cs[c]);
            }
            if (transfer->zeroOpacity(lo, hi)) {
                ++out.stats.nodesTransparent;
                return;
            }
        }
        if (!refined) {
            leaf(level, n, cs, cm);
            return;
        }
        // Lattice values of the refined node: corners as given, the 19 others by eq. 8
        // (with the weights the right way round: w = 0 is the coarse value, so a new vertex does not pop).
        const LatticeRule(&rl)[19] = rules[(n.x + n.y + n.z) & 1];
        float vs[27], vm[27];
        for (unsigned c = 0; c < 8; ++c) {
            vs[cornerLat(c)] = cs[c];
            vm[cornerLat(c)] = cm[c];
        }
        const int h = size / 2;
        for (const LatticeRule& r : rl) {
            const glm::ivec3 g = base + h * glm::ivec3(r.index % 3, (r.index / 3) % 3, r.index / 9);
            const float w = sharedWeight(level, n, r);
            float coarseS, coarseM;
            if (r.coarseCount == 2) {
                coarseS = 0.5f * (vs[r.coarse[0]] + vs[r.coarse[1]]);
                coarseM = 0.5f * (vm[r.coarse[0]] + vm[r.coarse[1]]);
            } else {
                coarseS = 0.25f * ((vs[r.coarse[0]] + vs[r.coarse[1]]) + (vs[r.coarse[2]] + vs[r.coarse[3]]));
                coarseM = 0.25f * ((vm[r.coarse[0]] + vm[r.coarse[1]]) + (vm[r.coarse[2]] + vm[r.coarse[3]]));
            }
            vs[r.index] = (1.0f - w) * coarseS + w * vol.scalarAt(g);
            vm[r.index] = (1.0f - w) * coarseM + w * vol.lengthScaleAt(g);
        }
        // Children back to front: per axis the half away from the eye first (a BSP
        // order over the three mid-planes, so it is a visibility order, sec. 4).
        int nearBit[3];
        const glm::vec3 mid = worldOf(base + h);
        for (int a = 0; a < 3; ++a) nearBit[a] = viewer.perspective ? (viewer.eye[a] >= mid[a] ? 1 : 0) : (viewer.towardEye[a] > 0.0f ? 1 : 0);
        for (int i = 0; i < 8; ++i) {
            const int bx = (i & 4) ? nearBit[0] : 1 - nearBit[0];
            const int by = (i & 2) ? nearBit[1] : 1 - nearBit[1];
            const int bz = (i & 1) ? nearBit[2] : 1 - nearBit[2];
            float ccs[8], ccm[8];
            for (unsigned c = 0; c < 8; ++c) {
                const int li = lat(bx + int(c & 1), by + int((c >> 1) & 1), bz + int((c >> 2) & 1));
                ccs[c] = vs[li];
                ccm[c] = vm[li];
            }
            node(level - 1, n * 2 + glm::ivec3(bx, by, bz), ccs, ccm, fullyInside);
        }
    }

    void leaf(int level, glm::ivec3 n, const float (&cs)[8], const float (&cm)[8]) {
        const int size = 1 << level;
        const glm::ivec3 base = n * size;
        glm::vec3 p[8];
        for (unsigned c = 0; c < 8; ++c) p[c] = worldOf(base + size * glm::ivec3(int(c & 1), int((c >> 1) & 1), int((c >> 2) & 1)));
        const unsigned even = LodVolume::centreTetCorners(n);
        auto make = [&](const unsigned(&idx)[4]) {
            Tetrahedron t;
            for (int v = 0; v < 4; ++v) {
                t.position[std::size_t(v)] = p[idx[v]];
                t.scalar[std::size_t(v)] = cs[idx[v]];
                t.lengthScale[std::size_t(v)] = cm[idx[v]];
            }
            orient(t);
            return t;
        };
        // Corner tetrahedra at the odd corners; each meets the centre one across the
        // plane through its corner's three neighbours (MPVO order within the cube).
        Tetrahedron back[4], front[4];
        int nb = 0, nf = 0;
        unsigned centreIdx[4];
        int ci = 0;
        for (unsigned c = 0; c < 8; ++c) {
            if (even & (1u << c)) {
                centreIdx[ci++] = c;
                continue;
            }
            const unsigned idx[4] = {c, c ^ 1u, c ^ 2u, c ^ 4u};
            const glm::vec3 nrm = glm::cross(p[c ^ 2u] - p[c ^ 1u], p[c ^ 4u] - p[c ^ 1u]);
            const float cornerSide = glm::dot(nrm, p[c] - p[c ^ 1u]);
            if (cornerSide * viewer.side(nrm, p[c ^ 1u]) > 0.0f) front[nf++] = make(idx);
            else back[nb++] = make(idx);
        }
        for (int i = 0; i < nb; ++i) emit(back[i]);
        emit(make(centreIdx));
        for (int i = 0; i < nf; ++i) emit(front[i]);
    }

    void emit(const Tetrahedron& t) {
        if (desc.zeroOpacityTest) {
            const float lo = std::min({t.scalar[0], t.scalar[1], t.scalar[2], t.scalar[3]});
            const float hi = std::max({t.scalar[0], t.scalar[1], t.scalar[2], t.scalar[3]});
            if (transfer->zeroOpacity(lo, hi)) {
                ++out.stats.tetsTransparent;
                return;
            }
        }
        if (desc.clipNear) {
            bool cut = false;
            for (const glm::vec3& q : t.position)
                if (glm::dot(nearNormal, q) - nearOffset < 0.0f) cut = true;
            if (cut) {
                ++out.stats.clippedInput;
                const std::size_t first = out.tets.size();
                const int added = clipTetrahedron(t, nearNormal, nearOffset, out.tets);
                if (added > 1) {
                    out.stats.clippedExtra += std::uint64_t(added - 1);
                    orderPieces(&out.tets[first], added, viewer);
                }
                return;
            }
        }
        out.tets.push_back(t);
    }
};

Status LodVolume::update(const Camera& camera, const LodRefineDesc& refine, const TransferFunction* transfer, LodFrame& out) {
    out.tets.clear();
    out.rgb.clear();
    out.stats = LodFrameStats{};
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(camera.view[c][r]) || !std::isfinite(camera.proj[c][r]))
                return makeError("LodVolume::update: camera.view and camera.proj must be finite");
    if (!std::isfinite(refine.detailC) || refine.detailC < 0.0f) return makeError("LodRefineDesc.detailC must be finite and >= 0");
    if (refine.zeroOpacityTest && transfer == nullptr)
        return makeError("LodVolume::update: LodRefineDesc.zeroOpacityTest needs a transfer function (got null)");
    const glm::vec3 eye = camera.eye();
    if (!finiteVec(eye)) return makeError("LodVolume::update: camera.view is not invertible");

    // Pass 1 (sec. 2.2, 3): top-down refinement by eq. 1, e' of eq. 6 kept in 8 bits.
    for (const auto& w : mMorphWritten) mLevels[std::size_t(w.first)].morph[w.second] = 0;
    mMorphWritten.clear();
    std::vector<std::pair<int, glm::ivec3>> stack;
    for (int z = 0; z < mRoots.z; ++z)
        for (int y = 0; y < mRoots.y; ++y)
            for (int x = 0; x < mRoots.x; ++x) stack.push_back({mRootLevel, {x, y, z}});
    while (!stack.empty()) {
        const auto [level, n] = stack.back();
        stack.pop_back();
        const double e = errorMetric(level, n, eye, refine.detailC);
        if (!(e > 1.0)) continue;
        const double ePrime = std::min(std::max(e - 1.0, 0.0), 1.0);
        const std::size_t idx = nodeIndex(level, n);
        mLevels[std::size_t(level)].morph[idx] = std::uint8_t(1 + std::lround(ePrime * double(kMorphSteps)));
        mMorphWritten.push_back({level, idx});
        ++out.stats.nodesRefined;
        if (level >= 2)
            for (int c = 0; c < 8; ++c) stack.push_back({level - 1, n * 2 + glm::ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1)});
    }

    // Pass 2 (sec. 3, 4): morph, cull, test, clip and emit back to front.
    LodTraversal t{*this, refine, transfer, out, {}, {}, {}, 0.0f, {}};
    t.viewer.perspective = camera.perspective();
    t.viewer.eye = eye;
    t.viewer.towardEye = -camera.forward();
    const glm::mat4 m = camera.proj * camera.view;
    for (int i = 0; i < 3; ++i) {
        const glm::vec4 row(m[0][i], m[1][i], m[2][i], m[3][i]);
        const glm::vec4 w(m[0][3], m[1][3], m[2][3], m[3][3]);
        t.planes[2 * i] = w + row;
        t.planes[2 * i + 1] = w - row;
    }
    t.nearNormal = camera.forward();
    t.nearOffset = glm::dot(t.nearNormal, eye) + camera.nearPlane();
    latticeRules(centreTetCorners({0, 0, 0}), t.rules[0]);
    latticeRules(centreTetCorners({1, 0, 0}), t.rules[1]);

    // Roots back to front too: they are cells of one coarser grid, so a BSP over it orders them.
    auto rootOrder = [&](int level, glm::ivec3 lo, glm::ivec3 hi, auto&& self) -> void {
        // Recursive halving of the root block along its longest axis, far half first.
        const glm::ivec3 ext = hi - lo;
        if (ext.x * ext.y * ext.z == 1) {
            const int size = 1 << level;
            float cs[8], cm[8];
            for (unsigned c = 0; c < 8; ++c) {
                const glm::ivec3 g = lo * size + size * glm::ivec3(int(c & 1), int((c >> 1) & 1), int((c >> 2) & 1));
                cs[c] = scalarAt(g);
                cm[c] = lengthScaleAt(g);
            }
            t.node(level, lo, cs, cm, false);
            return;
        }
        const int a = (ext.x >= ext.y && ext.x >= ext.z) ? 0 : (ext.y >= ext.z ? 1 : 2);
        const int split = lo[a] + ext[a] / 2;
        glm::ivec3 hiA = hi, loB = lo;
        hiA[a] = split;
        loB[a] = split;
        const float plane = mOrigin[a] + float(split * (1 << level)) * mSpacing;
        const bool eyeHigh = t.viewer.perspective ? eye[a] >= plane : t.viewer.towardEye[a] > 0.0f;
        if (eyeHigh) {
            self(level, lo, hiA, self);
            self(level, loB, hi, self);
        } else {
            self(level, loB, hi, self);
            self(level, lo, hiA, self);
        }
    };
    rootOrder(mRootLevel, glm::ivec3(0), mRoots, rootOrder);
    out.stats.emitted = out.tets.size();
    out.stats.fullResolution = fullResolutionTets();
    return {};
}

} // namespace splatfx
