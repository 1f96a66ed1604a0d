// Reference quadrature of the fog density along a segment: adaptive
// Gauss-Kronrod 7/15 on breakpoints that no feature can hide between. It
// uses only point evaluations of the density, never the closed forms, so the
// tests can hold each closed form against it.
#include <algorithm>
#include <cmath>
#include <vector>

#include "fog/frozen.hpp"

namespace splatfx {

namespace {

// Kronrod 15-point nodes (positive half) and weights, with the embedded
// 7-point Gauss weights at the odd nodes (Kronrod 1965; the QUADPACK values).
constexpr double kXgk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851, 0.864864423359769072789712788640926,
                            0.741531185599394439863864773280788, 0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                            0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
constexpr double kWgk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204, 0.104790010322250183839876322541518,
                            0.140653259715525918745189590510238, 0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                            0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kWg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780, 0.381830050505118944950369775488975,
                           0.417959183673469387755102040816327};

struct Segment {
    double a, b;
    int depth;
};

} // namespace

FogQuadrature integrateFogNumerically(const Fog& fog, glm::dvec3 o, glm::dvec3 p, double tSec, double absTolerance, long maxEvaluations) {
    FogQuadrature q;
    const double L = glm::length(p - o);
    if (!(L > 0.0) || fog.empty()) {
        q.converged = std::isfinite(L);
        return q;
    }
    const glm::dvec3 e = (p - o) / L;
    const fogdetail::Frozen fr = fogdetail::freeze(fog.desc(), tSec, o);
    auto f = [&](double s) {
        ++q.evaluations;
        return fogdetail::evaluate(fr, s * e);
    };

    // Breakpoints: a spacing below a quarter of the shortest cosine period and
    // below the smallest polynomial cell along the ray; every crossing of a
    // polynomial cell boundary (the periodic copies are discontinuous there);
    // the closest approach to each equipotential and a geometric ladder of
    // points around it at its width sqrt(c/d), plus a sphere's entry and exit.
    std::vector<double> bp{0.0, L};
    double spacing = L;
    for (const auto& w : fr.waves) {
        const double k = glm::length(w.w);
        if (k > 0.0) spacing = std::min(spacing, 1.5707963267948966 / k);
    }
    for (const auto& poly : fr.polys) {
        for (int a = 0; a < 3; ++a) {
            if (!poly.used[a] || e[a] == 0.0) continue;
            spacing = std::min(spacing, poly.halfSize[a] / std::abs(e[a]));
            const double u0 = poly.uRef[a], u1 = poly.uRef[a] + L * e[a] / poly.halfSize[a];
            const double lo = std::min(u0, u1), hi = std::max(u0, u1);
            const double first = 2.0 * std::ceil((lo - 1.0) * 0.5) + 1.0;
            for (double b = first; b <= hi && bp.size() < 4'000'000; b += 2.0) bp.push_back((b - u0) * poly.halfSize[a] / e[a]);
        }
    }
    for (const auto& pot : fr.pots) {
        glm::dvec3 dir = e, v = -pot.qRel;
        if (pot.kind == FogTermKind::Line) {
            dir = e - glm::dot(e, pot.axis) * pot.axis;
            v = v - glm::dot(v, pot.axis) * pot.axis;
        }
        const double m2 = glm::dot(dir, dir);
        if (m2 == 0.0 || pot.d == 0.0) continue;
        const double s0 = -glm::dot(v, dir) / m2;
        const double width = std::sqrt(pot.c / pot.d) / std::sqrt(m2);
        bp.push_back(s0);
        for (double k = 0.25; k < 1e7; k *= 2.0) {
            bp.push_back(s0 - k * width);
            bp.push_back(s0 + k * width);
        }
        if (pot.kind == FogTermKind::Sphere) {
            const glm::dvec3 hv = v + s0 * e;
            const double h2 = glm::dot(hv, hv);
            if (pot.radius2 > h2) {
                bp.push_back(s0 - std::sqrt(pot.radius2 - h2));
                bp.push_back(s0 + std::sqrt(pot.radius2 - h2));
            }
        }
    }
    const long uniform = long(std::min(2e6, std::ceil(L / spacing)));
    for (long i = 1; i < uniform; ++i) bp.push_back(L * double(i) / double(uniform));
    bp.erase(std::remove_if(bp.begin(), bp.end(), [L](double s) { return !(s >= 0.0 && s <= L); }), bp.end());
    std::sort(bp.begin(), bp.end());
    bp.erase(std::unique(bp.begin(), bp.end()), bp.end());

    std::vector<Segment> stack;
    for (size_t i = 0; i + 1 < bp.size(); ++i) stack.push_back({bp[i], bp[i + 1], 0});
    q.converged = true;
    while (!stack.empty()) {
        const Segment s = stack.back();
        stack.pop_back();
        const double c = 0.5 * (s.a + s.b), h = 0.5 * (s.b - s.a);
        if (h <= 0.0) continue;
        double fc = f(c);
        double kron = kWgk[7] * fc, gauss = kWg[3] * fc;
        for (int j = 0; j < 7; ++j) {
            const double f1 = f(c - h * kXgk[j]), f2 = f(c + h * kXgk[j]);
            kron += kWgk[j] * (f1 + f2);
            if (j % 2 == 1) gauss += kWg[j / 2] * (f1 + f2);
        }
        kron *= h;
        gauss *= h;
        const double err = std::abs(kron - gauss);
        // Each piece gets a share of the tolerance in proportion to its length.
        const double allowed = absTolerance * (2.0 * h / L);
        if (err <= allowed || err <= 1e-15 * std::abs(kron) || s.depth >= 60 || q.evaluations > maxEvaluations) {
            if (err > allowed && err > 1e-15 * std::abs(kron)) q.converged = false;
            q.value += kron;
            q.errorEstimate += err;
            continue;
        }
        stack.push_back({s.a, c, s.depth + 1});
        stack.push_back({c, s.b, s.depth + 1});
    }
    // Biri et al.'s eq. 9 as printed (FogPotentialForm::Segment) is no density: its
    // depth is weight / (c + d r^2) with r the distance from the segment to the object,
    // found here by search (the squared distance along the segment is convex: a sampled
    // bracket, then golden sections), not by segmentDistance2's closed vertex.
    for (const auto& pot : fr.pots) {
        if (!pot.segment) continue;
        auto r2At = [&](double s) {
            glm::dvec3 v = s * e - pot.qRel;
            if (pot.kind == FogTermKind::Line) v -= glm::dot(v, pot.axis) * pot.axis;
            const double r2 = glm::dot(v, v);
            return pot.kind == FogTermKind::Sphere ? std::max(0.0, r2 - pot.radius2) : r2;
        };
        constexpr int kSamples = 64;
        int best = 0;
        for (int i = 1; i <= kSamples; ++i)
            if (r2At(L * i / kSamples) < r2At(L * best / kSamples)) best = i;
        double a = L * std::max(best - 1, 0) / kSamples, b = L * std::min(best + 1, kSamples) / kSamples;
        const double g = 0.5 * (std::sqrt(5.0) - 1.0);
        for (int it = 0; it < 200 && b - a > 1e-15 * L; ++it) {
            const double x1 = b - g * (b - a), x2 = a + g * (b - a);
            if (r2At(x1) <= r2At(x2)) b = x2;
            else a = x1;
        }
        const double r2 = std::min({r2At(0.5 * (a + b)), r2At(0.0), r2At(L)});
        q.value += pot.weight / (pot.c + pot.d * r2);
    }
    return q;
}

} // namespace splatfx
