// Transfer function, the exact segment integral, and the pre-integration table
// (Roettger & Ertl 2002, sec. 4; Roettger, Kraus & Ertl 2000 [35]).
#include "splatfx/volume.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace splatfx {
namespace {

// The transfer function's linear piece that holds scalar s, as coefficients of
// value = a + b s (colour and extinction).
struct TfPiece {
    glm::dvec3 c0{0.0}, c1{0.0};
    double t0 = 0.0, t1 = 0.0;
};

TfPiece pieceAt(const std::vector<TransferPoint>& p, double s) {
    TfPiece out;
    if (std::isnan(s)) return out; // no material (and no search past the end: every comparison with NaN is false)
    if (p.size() == 1 || s <= double(p.front().scalar)) {
        // Constant below the first point (or everywhere for one point).
        const TransferPoint& q = (s <= double(p.front().scalar)) ? p.front() : p.back();
        out.c0 = glm::dvec3(q.color);
        out.t0 = double(q.extinctionPerWorld);
        return out;
    }
    if (s >= double(p.back().scalar)) {
        out.c0 = glm::dvec3(p.back().color);
        out.t0 = double(p.back().extinctionPerWorld);
        return out;
    }
    // First point strictly above s: right-continuous at steps (duplicate scalars).
    const auto it = std::upper_bound(p.begin(), p.end(), s, [](double v, const TransferPoint& q) { return v < double(q.scalar); });
    const TransferPoint& hi = *it;
    const TransferPoint& lo = *(it - 1);
    const double span = double(hi.scalar) - double(lo.scalar); // > 0: lo.scalar <= s < hi.scalar
    const double b = 1.0 / span;
    const glm::dvec3 dc = (glm::dvec3(hi.color) - glm::dvec3(lo.color)) * b;
    const double dt = (double(hi.extinctionPerWorld) - double(lo.extinctionPerWorld)) * b;
    out.c1 = dc;
    out.c0 = glm::dvec3(lo.color) - dc * double(lo.scalar);
    out.t1 = dt;
    out.t0 = double(lo.extinctionPerWorld) - dt * double(lo.scalar);
    return out;
}

double clampUnit(double v) { return std::min(1.0, std::max(0.0, v)); }

// 5-point Gauss-Legendre on [-1, 1].
constexpr double kGlX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
constexpr double kGlW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};

// Optical depth per unit step kept below this so exp() varies little inside a
// Gauss-Legendre step: the 5-point rule then errs ~ (1/4)^10 / 10! relative.
constexpr double kMaxStepDepth = 0.25;
// Transmittance below which the rest of a segment cannot change a double result.
constexpr double kMinTransmittance = 1e-18;

} // namespace

Result<TransferFunction> TransferFunction::create(std::vector<TransferPoint> points) {
    if (points.empty()) return makeError("TransferFunction: points must not be empty");
    for (std::size_t i = 0; i < points.size(); ++i) {
        const TransferPoint& q = points[i];
        const std::string at = "TransferFunction: points[" + std::to_string(i) + "]";
        if (!std::isfinite(q.scalar) || q.scalar < 0.0f || q.scalar > 1.0f) return makeError(at + ".scalar must be finite and in [0, 1]");
        if (!std::isfinite(q.color.x) || !std::isfinite(q.color.y) || !std::isfinite(q.color.z) || q.color.x < 0.0f || q.color.y < 0.0f ||
            q.color.z < 0.0f)
            return makeError(at + ".color must be finite and >= 0");
        if (!std::isfinite(q.extinctionPerWorld) || q.extinctionPerWorld < 0.0f) return makeError(at + ".extinctionPerWorld must be finite and >= 0");
        if (i > 0 && q.scalar < points[i - 1].scalar) return makeError(at + ".scalar must not be below the previous point's");
    }
    TransferFunction tf;
    tf.mPoints = std::move(points);
    return tf;
}

glm::dvec3 TransferFunction::color(double s) const {
    if (std::isnan(s)) return glm::dvec3(0.0); // no material
    const TfPiece p = pieceAt(mPoints, s);
    return p.c0 + p.c1 * s;
}

double TransferFunction::extinction(double s) const {
    if (std::isnan(s)) return 0.0; // no material
    const TfPiece p = pieceAt(mPoints, s);
    return std::max(0.0, p.t0 + p.t1 * s);
}

bool TransferFunction::zeroOpacity(double lo, double hi) const {
    if (!(lo <= hi)) std::swap(lo, hi);
    if (std::isnan(lo) || std::isnan(hi)) return false;
    // Piecewise linear: the maximum on [lo, hi] is at an end or a control point.
    if (extinction(lo) > 0.0 || extinction(hi) > 0.0) return false;
    for (const TransferPoint& q : mPoints)
        if (double(q.scalar) >= lo && double(q.scalar) <= hi && q.extinctionPerWorld > 0.0f) return false;
    return true;
}

namespace {

// The integral with its two accuracy knobs: the optical depth per Gauss-Legendre
// step and the transmittance at which the rest is dropped.
glm::dvec4 integrateSegmentWith(const TransferFunction& transfer, double sf, double sb, double length, double mf, double mb, double maxStepDepth,
                                double minTransmittance) {
    if (std::isnan(sf) || std::isnan(sb) || std::isnan(mf) || std::isnan(mb) || std::isnan(length) || !(length > 0.0)) return glm::dvec4(0.0);
    length = std::min(length, 1e30); // beyond this the transmittance is 0 in double for any extinction > 1e-28
    sf = clampUnit(sf);
    sb = clampUnit(sb);
    mf = std::max(0.0, std::min(mf, 1e30));
    mb = std::max(0.0, std::min(mb, 1e30));
    if (transfer.zeroOpacity(std::min(sf, sb), std::max(sf, sb)) || (mf == 0.0 && mb == 0.0)) return glm::dvec4(0.0);

    const std::vector<TransferPoint>& pts = transfer.points();
    // Breakpoints in u in [0, 1] where s(u) = sf + (sb - sf) u crosses a control point.
    double cuts[2 + 64];
    std::vector<double> many;
    double* u = cuts;
    int nu = 0;
    if (pts.size() + 2 > 64) {
        many.resize(pts.size() + 2);
        u = many.data();
    }
    u[nu++] = 0.0;
    if (sf != sb) {
        // The division by (sb - sf) happens only here; sf == sb has no interior cuts (the division limit).
        for (const TransferPoint& q : pts) {
            const double t = (double(q.scalar) - sf) / (sb - sf);
            if (t > 0.0 && t < 1.0) u[nu++] = t;
        }
    }
    u[nu++] = 1.0;
    std::sort(u, u + nu);

    glm::dvec3 color(0.0);
    double T = 1.0;
    for (int piece = 0; piece + 1 < nu && T > minTransmittance; ++piece) {
        const double ua = u[piece], ub = u[piece + 1];
        if (!(ub > ua)) continue;
        const double sMid = sf + (sb - sf) * (0.5 * (ua + ub));
        const TfPiece tp = pieceAt(pts, sMid);
        // Along u: scalar s(u), extinction tau(u) = t0 + t1 s(u) (>= 0 on the piece),
        // colour c(u), length scale m(u); k(u) = l tau(u) m(u) is quadratic in u.
        auto sAt = [&](double x) { return sf + (sb - sf) * x; };
        auto kAt = [&](double x) {
            const double tau = std::max(0.0, tp.t0 + tp.t1 * sAt(x));
            return length * tau * (mf + (mb - mf) * x);
        };
        auto cAt = [&](double x) { return tp.c0 + tp.c1 * sAt(x); };
        // Exact optical depth of a quadratic over [x0, x1] (Simpson is exact for it).
        auto depth = [&](double x0, double x1) { return (x1 - x0) / 6.0 * (kAt(x0) + 4.0 * kAt(0.5 * (x0 + x1)) + kAt(x1)); };
        // Bound of k on [x0, x1]: ends and the vertex of the quadratic.
        const double qa = length * (tp.t1 * (sb - sf)) * (mb - mf);                             // x^2
        const double qb = length * ((tp.t0 + tp.t1 * sf) * (mb - mf) + tp.t1 * (sb - sf) * mf); // x
        auto kMax = [&](double x0, double x1) {
            double m = std::max(kAt(x0), kAt(x1));
            if (qa != 0.0) {
                const double xv = -qb / (2.0 * qa);
                if (xv > x0 && xv < x1) m = std::max(m, kAt(xv));
            }
            return m;
        };
        double x = ua, h = ub - ua;
        while (x < ub && T > minTransmittance) {
            h = std::min(ub - x, 2.0 * h);
            const double km = kMax(x, x + h);
            if (km * h > maxStepDepth) h = maxStepDepth / km; // k's max cannot grow as h shrinks
            if (x + h <= x) {
                // The extinction is so large that the step underflows: the rest is opaque here.
                color += T * cAt(x);
                T = 0.0;
                break;
            }
            const double half = 0.5 * h, mid = x + half;
            glm::dvec3 acc(0.0);
            for (int g = 0; g < 5; ++g) {
                const double xg = mid + half * kGlX[g];
                acc += kGlW[g] * cAt(xg) * (kAt(xg) * std::exp(-depth(x, xg)));
            }
            color += T * half * acc;
            T *= std::exp(-depth(x, x + h));
            x += h;
        }
    }
    return glm::dvec4(color, 1.0 - T);
}

// For the float table: steps of optical depth 1 (the 5-point rule then errs
// ~1e-9 relative, below float's 6e-8) and a cut at transmittance 1e-9.
constexpr double kTableStepDepth = 1.0;
constexpr double kTableMinTransmittance = 1e-9;

} // namespace

glm::dvec4 integrateSegment(const TransferFunction& transfer, double sf, double sb, double length, double mf, double mb) {
    return integrateSegmentWith(transfer, sf, sb, length, mf, mb, kMaxStepDepth, kMinTransmittance);
}

Result<PreIntegrationTable> PreIntegrationTable::create(const TransferFunction& transfer, const PreIntegrationDesc& desc) {
    if (desc.scalarResolution < 2 || desc.scalarResolution > 1024) return makeError("PreIntegrationDesc.scalarResolution must be in [2, 1024]");
    if (desc.lengthResolution < 2 || desc.lengthResolution > 1024) return makeError("PreIntegrationDesc.lengthResolution must be in [2, 1024]");
    if (!std::isfinite(desc.maxLengthWorld) || !(desc.maxLengthWorld > 0.0f))
        return makeError("PreIntegrationDesc.maxLengthWorld must be finite and > 0");
    PreIntegrationTable t;
    const int n = desc.scalarResolution, m = desc.lengthResolution;
    t.mDims = {n, n, m};
    t.mMaxLength = desc.maxLengthWorld;
    t.mData.assign(std::size_t(n) * std::size_t(n) * std::size_t(m) * 4, 0.0f);
    for (int k = 1; k < m; ++k) { // k = 0: zero length, all zero
        const double l = double(k) / double(m - 1) * double(desc.maxLengthWorld);
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const glm::dvec4 v =
                    integrateSegmentWith(transfer, double(i) / (n - 1), double(j) / (n - 1), l, 1.0, 1.0, kTableStepDepth, kTableMinTransmittance);
                float* o = &t.mData[4 * (std::size_t(i) + std::size_t(n) * (std::size_t(j) + std::size_t(n) * std::size_t(k)))];
                o[0] = float(v.r);
                o[1] = float(v.g);
                o[2] = float(v.b);
                o[3] = float(v.a);
            }
    }
    return t;
}

glm::vec4 PreIntegrationTable::texel(int i, int j, int k) const {
    const float* o = &mData[4 * (std::size_t(i) + std::size_t(mDims.x) * (std::size_t(j) + std::size_t(mDims.y) * std::size_t(k)))];
    return {o[0], o[1], o[2], o[3]};
}

glm::vec4 PreIntegrationTable::lookupInRange(float sf, float sb, float l) const {
    auto axis = [](float v, int n, int& i0, float& f) {
        const float x = std::min(std::max(v, 0.0f), 1.0f) * float(n - 1);
        i0 = std::min(int(x), n - 2);
        f = x - float(i0);
    };
    int i, j, k;
    float fi, fj, fk;
    axis(sf, mDims.x, i, fi);
    axis(sb, mDims.y, j, fj);
    axis(l / mMaxLength, mDims.z, k, fk);
    glm::vec4 out(0.0f);
    for (int c = 0; c < 8; ++c) {
        const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
        const float w = (di ? fi : 1.0f - fi) * (dj ? fj : 1.0f - fj) * (dk ? fk : 1.0f - fk);
        if (w != 0.0f) out += w * texel(i + di, j + dj, k + dk);
    }
    return out;
}

glm::vec4 PreIntegrationTable::lookup(float sf, float sb, float l) const {
    if (!(l > 0.0f) || std::isnan(sf) || std::isnan(sb)) return glm::vec4(0.0f);
    if (l <= mMaxLength) return lookupInRange(sf, sb, l);
    // The scalar is linear along the segment, so each of N equal pieces is a
    // segment of its own: composite them front to back. N is capped at 2^16
    // (beyond 65536 maxLengthWorld the pieces are read at maxLengthWorld).
    const double pieces = std::min(65536.0, std::ceil(double(l) / double(mMaxLength)));
    const int count = int(pieces);
    const float pieceLength = std::min(mMaxLength, float(double(l) / pieces));
    glm::vec4 acc(0.0f);
    for (int p = 0; p < count && acc.a < 1.0f - 1e-7f; ++p) {
        const float a = sf + (sb - sf) * float(p) / float(count);
        const float b = sf + (sb - sf) * float(p + 1) / float(count);
        acc += (1.0f - acc.a) * lookupInRange(a, b, pieceLength);
    }
    return acc;
}

bool PreIntegrationTable::zeroOpacity(float lo, float hi) const {
    if (lo > hi) std::swap(lo, hi);
    const int n = mDims.x;
    const int i = std::max(0, std::min(n - 1, int(std::floor(std::min(std::max(lo, 0.0f), 1.0f) * float(n - 1)))));
    const int j = std::max(0, std::min(n - 1, int(std::ceil(std::min(std::max(hi, 0.0f), 1.0f) * float(n - 1)))));
    return texel(i, j, mDims.z - 1).a == 0.0f;
}

} // namespace splatfx
