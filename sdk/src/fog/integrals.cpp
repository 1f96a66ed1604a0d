// Closed-form line integrals of every fog term (Biri et al. 2002, eq. 8),
// computed relative to a reference point. docs/fog.md derives each one and
// says which numerical hazard each branch avoids.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "fog/frozen.hpp"

namespace splatfx::fogdetail {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// 5-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree <= 9,
// hence for any polynomial term restricted to a line inside one cell.
constexpr double kGaussX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
constexpr double kGaussW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};

double reduceAngle(double a) { return a - kTwoPi * std::nearbyint(a / kTwoPi); }

// sin(z) / z without the 0/0 at z = 0 (the k -> 0 and parallel-segment cases).
double sinc(double z) {
    if (std::abs(z) < 1e-4) return 1.0 - z * z / 6.0; // next term z^4/120 < 1e-18
    return std::sin(z) / z;
}

double wrapCell(double u) { return u - 2.0 * std::floor((u + 1.0) * 0.5); }
double cellIndex(double u) { return std::floor((u + 1.0) * 0.5); }

// Integral of 1 / (c + d |v + s e|^2) over s in [0, L] for a unit-speed or
// slower direction e (|e| <= 1): the point (e unit) and the line (components
// perpendicular to the axis). Closed form with one atan2, written so that no
// branch divides by |e| -> 0 (segment parallel to the line), by d -> 0, or
// subtracts two nearly equal atans (segment far from the centre).
double inverseQuadratic(glm::dvec3 v, glm::dvec3 e, double L, double c, double d) {
    if (d == 0.0) return L / c;
    const double m = glm::length(e);
    if (m == 0.0) return L / (c + d * glm::dot(v, v));
    const glm::dvec3 eh = e / m;
    const double sigma0 = -glm::dot(v, eh); // closest approach along the path, in distance units
    const glm::dvec3 hv = v + sigma0 * eh;
    const double den = c + d * glm::dot(hv, hv);
    const double A = std::sqrt(den / d);
    const double Lp = m * L;
    const double x0 = -sigma0 / A;
    const double x1 = (Lp - sigma0) / A;
    // atan(x1) - atan(x0) = atan2(x1 - x0, 1 + x0 x1), in (0, pi) for x1 > x0.
    const double diff = std::atan2(Lp / A, 1.0 + x0 * x1);
    return diff * (A / den) / m;
}

// Integral of 1 / (d (u^2 + kappa)) over u in [ua, ub] (ua < ub).
// kappa > 0: atan form. kappa <= 0: only called with ua, ub of one sign and
// u^2 + kappa > 0 on the interval (outside a sphere's ball); written in
// z = 1/u as atanh(b z) / b, b = sqrt(-kappa), smooth as b -> 0.
double inverseShifted(double ua, double ub, double kappa, double d) {
    if (ub <= ua) return 0.0;
    if (kappa > 0.0) {
        const double a = std::sqrt(kappa);
        const double x0 = ua / a, x1 = ub / a;
        return std::atan2((ub - ua) / a, 1.0 + x0 * x1) / (d * a);
    }
    auto F = [kappa](double z) {
        const double y = -kappa * z * z; // in [0, 1)
        if (y < 1e-8) return z * (1.0 + y / 3.0);
        const double r = std::sqrt(y);
        return z * std::atanh(r) / r;
    };
    return (F(1.0 / ua) - F(1.0 / ub)) / d;
}

double integrateSphere(const Potential& p, glm::dvec3 v, glm::dvec3 e, double L) {
    if (p.d == 0.0) return L / p.c;
    const double s0 = -glm::dot(v, e);
    const glm::dvec3 hv = v + s0 * e;
    const double h2 = glm::dot(hv, hv);
    // Missing the ball: 1 / (c + d ((s - s0)^2 + h2 - R^2)) with kappa > 0.
    if (p.radius2 <= h2) return inverseShifted(-s0, L - s0, p.c / p.d + (h2 - p.radius2), p.d);
    const double w = std::sqrt(p.radius2 - h2);
    const double kappa = p.c / p.d - w * w; // may be <= 0: log form outside the ball
    const double inA = std::max(0.0, s0 - w), inB = std::min(L, s0 + w);
    double total = 0.0;
    if (inB > inA) total += (inB - inA) / p.c;
    // Outside pieces, in u = s - s0: before the ball u in [-s0, min(L, s0 - w) - s0], after it [max(0, s0 + w) - s0, L - s0].
    const double beforeEnd = std::min(L, s0 - w);
    if (beforeEnd > 0.0) total += inverseShifted(-s0, beforeEnd - s0, kappa, p.d);
    const double afterStart = std::max(0.0, s0 + w);
    if (afterStart < L) total += inverseShifted(afterStart - s0, L - s0, kappa, p.d);
    return total;
}

struct PolyWalk {
    const Poly& p;
    glm::dvec3 U0, dU;
    double L;

    // Gauss-Legendre over lambda in [la, lb], in the cell of the midpoint.
    double piece(double la, double lb) const {
        if (lb <= la) return 0.0;
        const double mid = 0.5 * (la + lb), half = 0.5 * (lb - la);
        glm::dvec3 shift(0.0);
        if (p.mode == FogCellMode::Periodic)
            for (int a = 0; a < 3; ++a)
                if (p.used[a]) shift[a] = 2.0 * cellIndex(U0[a] + mid * dU[a]);
        double sum = 0.0;
        for (int j = 0; j < 5; ++j) {
            const double l = mid + half * kGaussX[j];
            sum += kGaussW[j] * evalPoly(p, U0 + l * dU - shift);
        }
        return sum * half * L;
    }
};

double integratePoly(const Poly& p, glm::dvec3 oRel, glm::dvec3 pRel, double L) {
    const glm::dvec3 U0 = p.uRef + oRel / p.halfSize;
    const glm::dvec3 dU = (pRel - oRel) / p.halfSize;
    const PolyWalk walk{p, U0, dU, L};
    if (p.usedCount == 0) return L * evalPoly(p, glm::dvec3(0.0));

    if (p.mode == FogCellMode::ZeroOutside) {
        double la = 0.0, lb = 1.0;
        for (int a = 0; a < 3; ++a) {
            if (!p.used[a]) continue;
            if (dU[a] == 0.0) {
                if (std::abs(U0[a]) > 1.0) return 0.0;
                continue;
            }
            double l0 = (-1.0 - U0[a]) / dU[a], l1 = (1.0 - U0[a]) / dU[a];
            if (l0 > l1) std::swap(l0, l1);
            la = std::max(la, l0);
            lb = std::min(lb, l1);
        }
        return walk.piece(la, lb);
    }

    // Periodic: which used axes cross cell boundaries?
    int moving[3], nMoving = 0;
    bool othersFixed = true;
    for (int a = 0; a < 3; ++a) {
        if (!p.used[a]) continue;
        if (cellIndex(U0[a]) != cellIndex(U0[a] + dU[a])) moving[nMoving++] = a;
        else if (dU[a] != 0.0) othersFixed = false;
    }
    if (nMoving == 0) return walk.piece(0.0, 1.0);

    if (nMoving == 1 && othersFixed) {
        // One axis varies (a 1D polynomial, or an axis-aligned ray through a
        // multi-variable one): whole cells all integrate to the same value,
        // so count them. O(1) however many cells the ray crosses.
        const int a = moving[0];
        const double n0 = cellIndex(U0[a]), n1 = cellIndex(U0[a] + dU[a]);
        const double dir = dU[a] > 0.0 ? 1.0 : -1.0;
        const double b1 = 2.0 * n0 + dir, bk = 2.0 * n1 - dir;
        const double l1 = std::clamp((b1 - U0[a]) / dU[a], 0.0, 1.0);
        const double lk = std::clamp((bk - U0[a]) / dU[a], 0.0, 1.0);
        const double whole = std::abs(n1 - n0) - 1.0;
        double total = walk.piece(0.0, l1) + walk.piece(lk, 1.0);
        if (whole > 0.0) {
            glm::dvec3 u(0.0);
            for (int b = 0; b < 3; ++b)
                if (p.used[b] && b != a) u[b] = wrapCell(U0[b]);
            double cell = 0.0; // integral over u_a in [-1, 1], other coordinates fixed
            for (int j = 0; j < 5; ++j) {
                u[a] = kGaussX[j];
                cell += kGaussW[j] * evalPoly(p, u);
            }
            total += whole * cell * (L / std::abs(dU[a]));
        }
        return total;
    }

    // General direction through a multi-variable periodic polynomial: the
    // pieces differ from cell to cell, so walk them (cost O(cells crossed)).
    double nextIndex[3], step[3];
    double next[3];
    int axes[3], nAxes = 0;
    for (int a = 0; a < 3; ++a) {
        if (!p.used[a] || dU[a] == 0.0) continue;
        axes[nAxes++] = a;
        const double dir = dU[a] > 0.0 ? 1.0 : -1.0;
        nextIndex[a] = 2.0 * cellIndex(U0[a]) + dir; // boundary coordinate
        step[a] = 2.0 * dir;
        next[a] = (nextIndex[a] - U0[a]) / dU[a];
    }
    double total = 0.0, lam = 0.0;
    long count = 0;
    while (lam < 1.0) {
        double ln = 1.0;
        for (int i = 0; i < nAxes; ++i) ln = std::min(ln, next[axes[i]]);
        total += walk.piece(lam, ln);
        lam = ln;
        for (int i = 0; i < nAxes; ++i) {
            const int a = axes[i];
            while (next[a] <= lam) {
                nextIndex[a] += step[a];
                next[a] = (nextIndex[a] - U0[a]) / dU[a];
            }
        }
        if (++count >= kMaxCellsPerRay && lam < 1.0) {
            // Beyond the cap: the remainder at the cell's mean density
            // (docs/fog.md: exact on average for directions that fill the cell).
            double mean = 0.0;
            const int nu = p.used[0] ? 5 : 1, nv = p.used[1] ? 5 : 1, nw = p.used[2] ? 5 : 1;
            for (int i = 0; i < nu; ++i)
                for (int j = 0; j < nv; ++j)
                    for (int k = 0; k < nw; ++k) {
                        const double wgt = (nu > 1 ? kGaussW[i] / 2 : 1.0) * (nv > 1 ? kGaussW[j] / 2 : 1.0) * (nw > 1 ? kGaussW[k] / 2 : 1.0);
                        mean += wgt * evalPoly(p, {nu > 1 ? kGaussX[i] : 0.0, nv > 1 ? kGaussX[j] : 0.0, nw > 1 ? kGaussX[k] : 0.0});
                    }
            total += (1.0 - lam) * L * mean;
            break;
        }
    }
    return total;
}

double evalPotential(const Potential& p, glm::dvec3 x) {
    if (p.segment) return 0.0; // a depth of the whole segment, not a density (integrate adds it)
    const glm::dvec3 v = x - p.qRel;
    double r2 = glm::dot(v, v);
    if (p.kind == FogTermKind::Line) {
        const double along = glm::dot(v, p.axis);
        const glm::dvec3 perp = v - along * p.axis;
        r2 = glm::dot(perp, perp);
    } else if (p.kind == FogTermKind::Sphere) {
        r2 = std::max(0.0, r2 - p.radius2);
    }
    return p.weight / (p.c + p.d * r2);
}

} // namespace

double segmentDistance2(const Potential& p, glm::dvec3 oRel, glm::dvec3 e, double L) {
    glm::dvec3 v = oRel - p.qRel, dir = e;
    if (p.kind == FogTermKind::Line) {
        v -= glm::dot(v, p.axis) * p.axis;
        dir -= glm::dot(dir, p.axis) * p.axis;
    }
    // |v + s dir|^2 is convex in s: its minimum over [0, L] is the clamped vertex.
    const double m2 = glm::dot(dir, dir);
    const double s = m2 > 0.0 ? std::clamp(-glm::dot(v, dir) / m2, 0.0, L) : 0.0;
    const glm::dvec3 h = v + s * dir;
    const double r2 = glm::dot(h, h);
    return p.kind == FogTermKind::Sphere ? std::max(0.0, r2 - p.radius2) : r2;
}

double evalPoly(const Poly& p, glm::dvec3 u) {
    double pw[3][kFogMaxDegree + 1];
    for (int a = 0; a < 3; ++a) {
        pw[a][0] = 1.0;
        for (int n = 1; n <= kFogMaxDegree; ++n) pw[a][n] = pw[a][n - 1] * u[a];
    }
    double s = 0.0;
    for (const FogMonomial& m : p.mono) s += m.coeff * pw[0][m.px] * pw[1][m.py] * pw[2][m.pz];
    return s;
}

Frozen freeze(const FogDesc& desc, double tSec, glm::dvec3 ref) {
    Frozen fr;
    const glm::dvec3 D = desc.wind.displacement(tSec);
    for (const FogTerm& term : desc.terms) {
        const double w = term.weightOverTime.at(tSec, term.weight);
        const glm::dvec3 Dt = term.windFactor * D + term.motion.displacement(tSec);
        const double waveScale = term.waveScaleOverTime.at(tSec, 1.0);
        switch (term.kind) {
        case FogTermKind::Constant: fr.constant += w; break;
        case FogTermKind::Cosine: {
            const double phase = term.phaseOverTime.at(tSec, term.phase);
            const glm::dvec3 wave = waveScale * term.wave;
            fr.waves.push_back({wave, reduceAngle(glm::dot(wave, ref - Dt) + phase), w});
            break;
        }
        case FogTermKind::CosineProduct: {
            // cos a cos b = (cos(a + b) + cos(a - b)) / 2
            const glm::dvec3 w1 = waveScale * term.wave, w2 = waveScale * term.wave2;
            const double a1 = reduceAngle(glm::dot(w1, ref - Dt) + term.phaseOverTime.at(tSec, term.phase));
            const double a2 = reduceAngle(glm::dot(w2, ref - Dt) + term.phase2);
            fr.waves.push_back({w1 + w2, reduceAngle(a1 + a2), 0.5 * w});
            fr.waves.push_back({w1 - w2, reduceAngle(a1 - a2), 0.5 * w});
            break;
        }
        case FogTermKind::Polynomial: {
            Poly p;
            p.mode = term.cellMode;
            p.halfSize = term.cellHalfSize;
            const double s = term.monomialsB.empty() ? 0.0 : term.blendOverTime.at(tSec, 0.0);
            // One fixed exponent set (A's order, then B's new ones) so the structure, hence the
            // generated GLSL, does not change with time. A few monomials: a linear search.
            p.mono.reserve(term.monomials.size() + term.monomialsB.size());
            auto add = [&p](const FogMonomial& m, double scale) {
                for (FogMonomial& q : p.mono)
                    if (q.px == m.px && q.py == m.py && q.pz == m.pz) {
                        q.coeff += scale * m.coeff;
                        return;
                    }
                p.mono.push_back({scale * m.coeff, m.px, m.py, m.pz});
                if (m.px > 0) p.used[0] = true;
                if (m.py > 0) p.used[1] = true;
                if (m.pz > 0) p.used[2] = true;
            };
            for (const FogMonomial& m : term.monomials) add(m, w * (1.0 - s));
            for (const FogMonomial& m : term.monomialsB) add(m, w * s);
            for (int a = 0; a < 3; ++a)
                if (p.used[a]) {
                    ++p.usedCount;
                    p.usedAxis = a;
                }
            p.uRef = (ref - term.cellCentre - Dt) / term.cellHalfSize;
            if (p.mode == FogCellMode::Periodic)
                for (int a = 0; a < 3; ++a)
                    if (p.used[a]) p.uRef[a] = wrapCell(p.uRef[a]);
            fr.polys.push_back(std::move(p));
            break;
        }
        case FogTermKind::Point:
        case FogTermKind::Line:
        case FogTermKind::Sphere:
            fr.pots.push_back({term.kind, term.centre + Dt - ref, term.axis, term.radius * term.radius, term.cOverTime.at(tSec, term.c),
                               term.dOverTime.at(tSec, term.d), w, term.form == FogPotentialForm::Segment});
            break;
        }
    }
    return fr;
}

double evaluate(const Frozen& f, glm::dvec3 x) {
    double k = f.constant;
    for (const Wave& w : f.waves) k += w.amp * std::cos(glm::dot(w.w, x) + w.alpha);
    for (const Poly& p : f.polys) {
        glm::dvec3 u = p.uRef + x / p.halfSize;
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
            if (!p.used[a]) continue;
            if (p.mode == FogCellMode::Periodic) u[a] = wrapCell(u[a]);
            else if (std::abs(u[a]) > 1.0) inside = false;
        }
        if (inside) k += evalPoly(p, u);
    }
    for (const Potential& p : f.pots) k += evalPotential(p, x);
    return k;
}

double integrate(const Frozen& f, glm::dvec3 oRel, glm::dvec3 pRel) {
    const glm::dvec3 seg = pRel - oRel;
    const double L = glm::length(seg);
    if (L == 0.0) return 0.0;
    const glm::dvec3 e = seg / L;
    double total = f.constant * L;
    // cos(a + b s) over [0, L] = L cos(a + b L / 2) sinc(b L / 2); the midpoint phase
    // is taken from the midpoint itself, so far-away segments lose nothing.
    for (const Wave& w : f.waves) {
        const double midPhase = glm::dot(w.w, 0.5 * (oRel + pRel)) + w.alpha;
        total += w.amp * L * std::cos(midPhase) * sinc(0.5 * glm::dot(w.w, seg));
    }
    for (const Poly& p : f.polys) total += integratePoly(p, oRel, pRel, L);
    for (const Potential& p : f.pots) {
        if (p.segment) {
            total += p.weight / (p.c + p.d * segmentDistance2(p, oRel, e, L));
            continue;
        }
        const glm::dvec3 v = oRel - p.qRel;
        double I = 0.0;
        if (p.kind == FogTermKind::Point) I = inverseQuadratic(v, e, L, p.c, p.d);
        else if (p.kind == FogTermKind::Line) I = inverseQuadratic(v - glm::dot(v, p.axis) * p.axis, e - glm::dot(e, p.axis) * p.axis, L, p.c, p.d);
        else I = integrateSphere(p, v, e, L);
        total += p.weight * I;
    }
    return total;
}

} // namespace splatfx::fogdetail
