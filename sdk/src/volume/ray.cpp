// The finest-level tetrahedral field and the reference ray integral through it.
#include "splatfx/volume.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace splatfx {
namespace {

// Piecewise-linear value in a unit cell split in five tetrahedra (Fig. 1).
// `v` holds the 8 corner values (bit 0 x, bit 1 y, bit 2 z); `odd` is the
// cell's parity. `where` picks the tetrahedron, `u` is where it is evaluated
// (the same point, or an end of a ray piece inside the same tetrahedron).
double cellValue(const double (&v)[8], bool odd, glm::dvec3 where, glm::dvec3 u) {
    // Flipping x maps the odd decomposition onto the even one.
    auto val = [&](unsigned c) { return v[odd ? (c ^ 1u) : c]; };
    if (odd) {
        where.x = 1.0 - where.x;
        u.x = 1.0 - u.x;
    }
    // Even decomposition: corner tetrahedra at the odd corners 1, 2, 4, 7, each the
    // set within L1 distance 1 of its corner; the centre one on 0, 3, 5, 6.
    static constexpr unsigned kOdd[4] = {1u, 2u, 4u, 7u};
    for (unsigned q : kOdd) {
        const glm::dvec3 qc(double(q & 1u), double((q >> 1) & 1u), double((q >> 2) & 1u));
        const glm::dvec3 dw = glm::abs(where - qc);
        if (dw.x + dw.y + dw.z <= 1.0) {
            const glm::dvec3 du = glm::abs(u - qc); // linear inside this tetrahedron
            return val(q) + (val(q ^ 1u) - val(q)) * du.x + (val(q ^ 2u) - val(q)) * du.y + (val(q ^ 4u) - val(q)) * du.z;
        }
    }
    const double lb = 0.5 * (u.x + u.y - u.z), lc = 0.5 * (u.x - u.y + u.z), ld = 0.5 * (-u.x + u.y + u.z);
    return (1.0 - lb - lc - ld) * val(0) + lb * val(3) + lc * val(5) + ld * val(6);
}

} // namespace

glm::dvec2 LodVolume::sampleFinest(glm::dvec3 pw) const {
    if (!std::isfinite(pw.x) || !std::isfinite(pw.y) || !std::isfinite(pw.z)) return glm::dvec2(0.0);
    glm::dvec3 g = (pw - glm::dvec3(mOrigin)) / double(mSpacing);
    const glm::dvec3 hi = glm::dvec3(mDims - 1);
    g = glm::clamp(g, glm::dvec3(0.0), hi);
    const glm::ivec3 cell = glm::min(glm::ivec3(glm::floor(g)), mDims - 2);
    const glm::dvec3 u = g - glm::dvec3(cell);
    double s[8], m[8];
    for (unsigned c = 0; c < 8; ++c) {
        const glm::ivec3 p = cell + glm::ivec3(int(c & 1u), int((c >> 1) & 1u), int((c >> 2) & 1u));
        s[c] = double(scalarAt(p));
        m[c] = double(lengthScaleAt(p));
    }
    const bool odd = ((cell.x + cell.y + cell.z) & 1) != 0;
    return {cellValue(s, odd, u, u), cellValue(m, odd, u, u)};
}

glm::dvec4 LodVolume::integrateRay(const TransferFunction& transfer, glm::dvec3 origin, glm::dvec3 dir, double tNear, double tFar) const {
    const double speed = glm::length(dir); // world length per unit t
    if (!(speed > 0.0) || !std::isfinite(speed) || std::isnan(tNear) || std::isnan(tFar)) return glm::dvec4(0.0);
    if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z)) return glm::dvec4(0.0);
    // Grid space: one unit per cell.
    const glm::dvec3 o = (origin - glm::dvec3(mOrigin)) / double(mSpacing);
    const glm::dvec3 d = dir / double(mSpacing);
    const glm::dvec3 hi = glm::dvec3(mDims - 1);
    double t0 = std::max(tNear, -1e300), t1 = std::min(tFar, 1e300);
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
            if (o[a] < 0.0 || o[a] > hi[a]) return glm::dvec4(0.0);
            continue;
        }
        double ta = (0.0 - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (!(t1 > t0)) return glm::dvec4(0.0);

    // Cell walk (Amanatides & Woo): cell of the first point, then axis crossings.
    const glm::dvec3 start = o + d * t0;
    glm::ivec3 cell = glm::clamp(glm::ivec3(glm::floor(start)), glm::ivec3(0), mDims - 2);
    glm::ivec3 step(0);
    glm::dvec3 tNext(std::numeric_limits<double>::infinity());
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 0.0) {
            step[a] = 1;
            tNext[a] = (double(cell[a] + 1) - o[a]) / d[a];
        } else if (d[a] < 0.0) {
            step[a] = -1;
            tNext[a] = (double(cell[a]) - o[a]) / d[a];
        }
    }
    glm::dvec3 color(0.0);
    double T = 1.0;
    double t = t0;
    while (t < t1 && T > 1e-18) {
        const int a = (tNext.x <= tNext.y && tNext.x <= tNext.z) ? 0 : (tNext.y <= tNext.z ? 1 : 2);
        const double tExit = std::min(tNext[a], t1);
        if (tExit > t) {
            double s[8], m[8];
            double lo = 1.0, hiS = 0.0;
            for (unsigned c = 0; c < 8; ++c) {
                const glm::ivec3 p = cell + glm::ivec3(int(c & 1u), int((c >> 1) & 1u), int((c >> 2) & 1u));
                s[c] = double(scalarAt(p));
                m[c] = double(lengthScaleAt(p));
                lo = std::min(lo, s[c]);
                hiS = std::max(hiS, s[c]);
            }
            if (!transfer.zeroOpacity(lo, hiS)) {
                const bool odd = ((cell.x + cell.y + cell.z) & 1) != 0;
                const glm::dvec3 base(cell);
                // Breaks where the ray crosses the planes between corner and centre tetrahedra.
                double cuts[6];
                int nc = 0;
                cuts[nc++] = t;
                static constexpr unsigned kOdd[4] = {1u, 2u, 4u, 7u};
                for (unsigned q : kOdd) {
                    // Plane sum_a |u_a - q_a| = 1 in the decomposition's frame (x flipped for odd cells).
                    double f0 = 0.0, f1 = 0.0;
                    for (int ax = 0; ax < 3; ++ax) {
                        double u0 = o[ax] - base[ax], u1 = d[ax];
                        if (odd && ax == 0) {
                            u0 = 1.0 - u0;
                            u1 = -u1;
                        }
                        const bool qa = ((q >> ax) & 1u) != 0;
                        f0 += qa ? 1.0 - u0 : u0;
                        f1 += qa ? -u1 : u1;
                    }
                    if (f1 != 0.0) {
                        const double tc = (1.0 - f0) / f1;
                        if (tc > t && tc < tExit) cuts[nc++] = tc;
                    }
                }
                cuts[nc++] = tExit;
                for (int i = 1; i < nc; ++i) // insertion sort of at most 6
                    for (int j = i; j > 0 && cuts[j] < cuts[j - 1]; --j) std::swap(cuts[j], cuts[j - 1]);
                for (int i = 0; i + 1 < nc && T > 1e-18; ++i) {
                    const double ta = cuts[i], tb = cuts[i + 1];
                    if (!(tb > ta)) continue;
                    const glm::dvec3 ua = o + d * ta - base, ub = o + d * tb - base, um = o + d * (0.5 * (ta + tb)) - base;
                    const glm::dvec3 ca = glm::clamp(ua, 0.0, 1.0), cb = glm::clamp(ub, 0.0, 1.0), cm = glm::clamp(um, 0.0, 1.0);
                    const glm::dvec4 seg = integrateSegment(transfer, cellValue(s, odd, cm, ca), cellValue(s, odd, cm, cb), (tb - ta) * speed,
                                                            cellValue(m, odd, cm, ca), cellValue(m, odd, cm, cb));
                    color += T * glm::dvec3(seg);
                    T *= 1.0 - seg.a;
                }
            }
        }
        t = tExit;
        if (tNext[a] >= t1) break;
        cell[a] += step[a];
        if (cell[a] < 0 || cell[a] > mDims[a] - 2) break;
        tNext[a] += double(step[a]) / d[a];
    }
    return glm::dvec4(color, 1.0 - T);
}

} // namespace splatfx

namespace splatfx {

glm::dvec4 integrateRay(const std::vector<Tetrahedron>& tets, const TransferFunction& transfer, glm::dvec3 o, glm::dvec3 d, double tNear,
                        double tFar) {
    const double speed = glm::length(d);
    if (!(speed > 0.0) || !std::isfinite(speed) || std::isnan(tNear) || std::isnan(tFar)) return glm::dvec4(0.0);
    if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.z)) return glm::dvec4(0.0);
    struct Piece {
        double t0, t1;
        std::size_t tet;
    };
    std::vector<Piece> pieces;
    static constexpr int kFaces[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};
    for (std::size_t i = 0; i < tets.size(); ++i) {
        const Tetrahedron& t = tets[i];
        double lo = tNear, hi = tFar;
        for (const auto& f : kFaces) {
            const glm::dvec3 a(t.position[std::size_t(f[0])]), b(t.position[std::size_t(f[1])]), c(t.position[std::size_t(f[2])]),
                q(t.position[std::size_t(f[3])]);
            glm::dvec3 n = glm::cross(b - a, c - a);
            if (glm::dot(n, q - a) < 0.0) n = -n; // inward
            const double num = glm::dot(n, o - a), den = glm::dot(n, d);
            if (den == 0.0) {
                if (num < 0.0) hi = lo - 1.0;
                continue;
            }
            const double tc = -num / den;
            if (den > 0.0) lo = std::max(lo, tc);
            else hi = std::min(hi, tc);
        }
        if (hi > lo) pieces.push_back({lo, hi, i});
    }
    std::sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) { return a.t0 < b.t0; });
    glm::dvec3 color(0.0);
    double T = 1.0, reached = tNear;
    for (const Piece& p : pieces) {
        const double t0 = std::max(p.t0, reached); // shared faces: each stretch of the ray once
        if (!(p.t1 > t0)) continue;
        const Tetrahedron& t = tets[p.tet];
        // Barycentric coordinates of the two ends (double).
        const glm::dvec3 p0(t.position[0]);
        const glm::dmat3 m(glm::dvec3(t.position[1]) - p0, glm::dvec3(t.position[2]) - p0, glm::dvec3(t.position[3]) - p0);
        const glm::dmat3 inv = glm::inverse(m);
        auto at = [&](double tt, const std::array<float, 4>& v) {
            const glm::dvec3 l = inv * (o + d * tt - p0);
            return (1.0 - l.x - l.y - l.z) * v[0] + l.x * v[1] + l.y * v[2] + l.z * v[3];
        };
        const glm::dvec4 seg =
            integrateSegment(transfer, at(t0, t.scalar), at(p.t1, t.scalar), (p.t1 - t0) * speed, at(t0, t.lengthScale), at(p.t1, t.lengthScale));
        color += T * glm::dvec3(seg);
        T *= 1.0 - seg.a;
        reached = p.t1;
        if (T < 1e-18) break;
    }
    return glm::dvec4(color, 1.0 - T);
}

} // namespace splatfx
