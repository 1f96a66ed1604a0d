// The fog model: curves, wind, terms, validation (Biri et al. 2002, sec. 3.2 and 5).
#include "splatfx/fog.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <string>

#include "fog/frozen.hpp"

namespace splatfx {

namespace {

const char* kindName(FogTermKind k) {
    switch (k) {
    case FogTermKind::Constant: return "constant";
    case FogTermKind::Cosine: return "cosine";
    case FogTermKind::CosineProduct: return "cosine product";
    case FogTermKind::Polynomial: return "polynomial";
    case FogTermKind::Point: return "point equipotential";
    case FogTermKind::Line: return "line equipotential";
    case FogTermKind::Sphere: return "sphere equipotential";
    }
    return "?";
}

std::string fmt(double v) {
    char b[64];
    std::snprintf(b, sizeof b, "%.6g", v);
    return b;
}
std::string fmt(glm::dvec3 v) {
    char b[128];
    std::snprintf(b, sizeof b, "(%.6g, %.6g, %.6g)", v.x, v.y, v.z);
    return b;
}

bool finite(double v) { return std::isfinite(v); }
bool finite(glm::dvec3 v) { return finite(v.x) && finite(v.y) && finite(v.z); }

Status checkCurve(const FogCurve& c, const std::string& name) {
    for (size_t i = 0; i < c.keys.size(); ++i) {
        if (!finite(c.keys[i].x) || !finite(c.keys[i].y)) return makeError(name + ".keys[" + std::to_string(i) + "] must be finite");
        if (i > 0 && c.keys[i].x < c.keys[i - 1].x)
            return makeError(name + ".keys must be sorted by time (keys[" + std::to_string(i) + "] at " + fmt(c.keys[i].x) + " s comes before " +
                             fmt(c.keys[i - 1].x) + " s)");
    }
    return {};
}

Status checkMonomials(const std::vector<FogMonomial>& ms, const std::string& name) {
    for (size_t i = 0; i < ms.size(); ++i) {
        const FogMonomial& m = ms[i];
        const std::string n = name + "[" + std::to_string(i) + "]";
        if (!finite(m.coeff)) return makeError(n + ".coeff must be finite");
        if (m.px < 0 || m.py < 0 || m.pz < 0) return makeError(n + " has a negative power");
        if (m.px + m.py + m.pz > kFogMaxDegree)
            return makeError(n + " has total degree " + std::to_string(m.px + m.py + m.pz) + ", above the maximum " + std::to_string(kFogMaxDegree));
    }
    return {};
}

Status checkTerm(FogTerm& t, const std::string& n) {
    if (!finite(t.weight)) return makeError(n + ".weight must be finite");
    if (!finite(t.windFactor)) return makeError(n + ".windFactor must be finite");
    if (Status s = checkCurve(t.weightOverTime, n + ".weightOverTime"); !s) return s;
    for (size_t i = 0; i < t.motion.keys.size(); ++i) {
        if (!finite(t.motion.keys[i].timeSec) || !finite(t.motion.keys[i].velocity))
            return makeError(n + ".motion.keys[" + std::to_string(i) + "] must be finite");
        if (i > 0 && t.motion.keys[i].timeSec < t.motion.keys[i - 1].timeSec) return makeError(n + ".motion.keys must be sorted by timeSec");
    }
    switch (t.kind) {
    case FogTermKind::Constant: break;
    case FogTermKind::CosineProduct:
        if (!finite(t.wave2)) return makeError(n + ".wave2 must be finite");
        if (!finite(t.phase2)) return makeError(n + ".phase2 must be finite");
        [[fallthrough]];
    case FogTermKind::Cosine:
        if (!finite(t.wave)) return makeError(n + ".wave must be finite");
        if (!finite(t.phase)) return makeError(n + ".phase must be finite");
        if (Status s = checkCurve(t.phaseOverTime, n + ".phaseOverTime"); !s) return s;
        if (Status s = checkCurve(t.waveScaleOverTime, n + ".waveScaleOverTime"); !s) return s;
        break;
    case FogTermKind::Polynomial:
        if (Status s = checkMonomials(t.monomials, n + ".monomials"); !s) return s;
        if (Status s = checkMonomials(t.monomialsB, n + ".monomialsB"); !s) return s;
        if (Status s = checkCurve(t.blendOverTime, n + ".blendOverTime"); !s) return s;
        for (size_t i = 0; i < t.blendOverTime.keys.size(); ++i)
            if (t.blendOverTime.keys[i].y < 0.0 || t.blendOverTime.keys[i].y > 1.0)
                return makeError(n + ".blendOverTime.keys[" + std::to_string(i) + "] value must be in [0, 1]");
        if (!finite(t.cellCentre)) return makeError(n + ".cellCentre must be finite");
        if (!finite(t.cellHalfSize) || t.cellHalfSize.x <= 0 || t.cellHalfSize.y <= 0 || t.cellHalfSize.z <= 0)
            return makeError(n + ".cellHalfSize must be finite and > 0 on every axis (got " + fmt(t.cellHalfSize) + ")");
        break;
    case FogTermKind::Line:
        if (!finite(t.axis) || glm::length(t.axis) < 1e-12) return makeError(n + ".axis must be a finite non-zero vector");
        t.axis = glm::normalize(t.axis);
        [[fallthrough]];
    case FogTermKind::Point:
    case FogTermKind::Sphere:
        if (!finite(t.centre)) return makeError(n + ".centre must be finite");
        if (!finite(t.c) || t.c <= 0.0)
            return makeError(n + ".c must be > 0 (the density 1 / (c + d r^2) is infinite at r = 0 otherwise; got " + fmt(t.c) + ")");
        if (!finite(t.d) || t.d < 0.0) return makeError(n + ".d must be finite and >= 0 (got " + fmt(t.d) + ")");
        if (!finite(t.radius) || t.radius < 0.0) return makeError(n + ".radius must be finite and >= 0");
        if (Status s = checkCurve(t.cOverTime, n + ".cOverTime"); !s) return s;
        if (Status s = checkCurve(t.dOverTime, n + ".dOverTime"); !s) return s;
        // Piecewise linear: positive at every key is positive everywhere.
        for (size_t i = 0; i < t.cOverTime.keys.size(); ++i)
            if (t.cOverTime.keys[i].y <= 0.0) return makeError(n + ".cOverTime.keys[" + std::to_string(i) + "] value must be > 0");
        for (size_t i = 0; i < t.dOverTime.keys.size(); ++i)
            if (t.dOverTime.keys[i].y < 0.0) return makeError(n + ".dOverTime.keys[" + std::to_string(i) + "] value must be >= 0");
        if (t.form != FogPotentialForm::Density && t.form != FogPotentialForm::Segment) return makeError(n + ".form is not a FogPotentialForm");
        if (t.form == FogPotentialForm::Segment) {
            // The segment form adds a depth that only grows as the path reaches nearer the
            // object; a negative weight would make the transmittance rise along the ray.
            if (t.weight < 0.0)
                return makeError(n + ".weight must be >= 0 with form Segment (Biri et al. eq. 9 adds a depth, not a density; got " +
                                 fmt(t.weight) + ")");
            for (size_t i = 0; i < t.weightOverTime.keys.size(); ++i)
                if (t.weightOverTime.keys[i].y < 0.0)
                    return makeError(n + ".weightOverTime.keys[" + std::to_string(i) + "] value must be >= 0 with form Segment");
        }
        break;
    }
    return {};
}

// Minimum of a polynomial over its reference cell [-1, 1]^used: a grid,
// then a shrinking pattern search from the best grid point. The grid is fine
// against the maximum degree (9), so a dip the grid misses is shallower
// than the derivative bound over one spacing, which the refinement recovers.
double polyMinimum(const fogdetail::Poly& p, glm::dvec3& where) {
    const int n = p.usedCount == 1 ? 2049 : p.usedCount == 2 ? 129 : 33;
    const int nu = p.used[0] ? n : 1, nv = p.used[1] ? n : 1, nw = p.used[2] ? n : 1;
    auto coord = [n](int i, int count) { return count == 1 ? 0.0 : -1.0 + 2.0 * i / (n - 1); };
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j)
            for (int k = 0; k < nw; ++k) {
                const glm::dvec3 u{coord(i, nu), coord(j, nv), coord(k, nw)};
                const double v = fogdetail::evalPoly(p, u);
                if (v < best) {
                    best = v;
                    where = u;
                }
            }
    double step = 2.0 / (n - 1);
    while (step > 1e-12) {
        bool moved = false;
        for (int a = 0; a < 3; ++a) {
            if (!p.used[a]) continue;
            for (double sgn : {-1.0, 1.0}) {
                glm::dvec3 u = where;
                u[a] = std::clamp(u[a] + sgn * step, -1.0, 1.0);
                const double v = fogdetail::evalPoly(p, u);
                if (v < best) {
                    best = v;
                    where = u;
                    moved = true;
                }
            }
        }
        if (!moved) step *= 0.5;
    }
    return best;
}

// Times at which the lower bound must be checked: every key of every curve
// (between keys, constants and -|cosine amplitudes| are linear / concave in
// t, so their sum is smallest at keys), plus interior points for terms
// whose bound is not concave between keys (a polynomial whose weight and
// blend both move, a negative potential whose weight and c both move).
std::vector<double> checkTimes(const FogDesc& d) {
    std::set<double> keys;
    for (const FogTerm& t : d.terms) {
        for (const auto& k : t.weightOverTime.keys) keys.insert(k.x);
        for (const auto& k : t.blendOverTime.keys) keys.insert(k.x);
        for (const auto& k : t.cOverTime.keys) keys.insert(k.x);
        for (const auto& k : t.dOverTime.keys) keys.insert(k.x);
    }
    if (keys.empty()) return {0.0};
    std::vector<double> out(keys.begin(), keys.end());
    const size_t n = out.size();
    for (size_t i = 0; i + 1 < n; ++i)
        for (int j = 1; j < 8; ++j) out.push_back(out[i] + (out[i + 1] - out[i]) * j / 8.0);
    return out;
}

Status checkNonNegative(const FogDesc& d) {
    for (double t : checkTimes(d)) {
        const fogdetail::Frozen fr = fogdetail::freeze(d, t, glm::dvec3(0.0));
        double positive = 0.0, total = 0.0;
        double worst = 0.0;
        std::string worstWhat;
        size_t polyIndex = 0;
        for (size_t i = 0; i < d.terms.size(); ++i) {
            const FogTerm& term = d.terms[i];
            const double w = term.weightOverTime.at(t, term.weight);
            double low = 0.0;
            std::string where;
            switch (term.kind) {
            case FogTermKind::Constant: low = w; break;
            case FogTermKind::Cosine:
            case FogTermKind::CosineProduct:
                low = -std::abs(w);
                where =
                    "where its cosine" + std::string(term.kind == FogTermKind::CosineProduct ? "s' product" : "") + " is " + (w > 0 ? "-1" : "+1");
                break;
            case FogTermKind::Polynomial: {
                const fogdetail::Poly& p = fr.polys[polyIndex++];
                glm::dvec3 u(0.0);
                low = polyMinimum(p, u);
                where = "at cell coordinates " + fmt(u) + " (world " + fmt(term.cellCentre + u * term.cellHalfSize) +
                        " at t = 0 without wind), minimum " + fmt(low);
                if (term.cellMode == FogCellMode::ZeroOutside) low = std::min(low, 0.0);
                break;
            }
            case FogTermKind::Point:
            case FogTermKind::Line:
            case FogTermKind::Sphere:
                const double c = term.cOverTime.at(t, term.c), dd = term.dOverTime.at(t, term.d);
                // A segment-form term is no density (and is >= 0): it holds nothing up.
                low = term.form == FogPotentialForm::Segment ? 0.0 : dd == 0.0 ? w / c : std::min(0.0, w / c);
                where = "at its centre " + fmt(term.centre) + ", value " + fmt(w / c);
                break;
            }
            total += low;
            if (low > 0.0) positive += low;
            if (low < worst) {
                worst = low;
                worstWhat = "terms[" + std::to_string(i) + "] (" + kindName(term.kind) + ", weight " + fmt(w) + ") " + where;
            }
        }
        const double scale = positive - worst;
        if (total < -1e-12 * std::max(scale, 1e-300))
            return makeError("fog density can go negative at t = " + fmt(t) + " s: the positive parts sum to at least " + fmt(positive) +
                             " but the terms can take away " + fmt(positive - total) +
                             " (Biri et al. sec. 3.2.1: c_0 >= sum |c_i|); the largest is " + worstWhat);
    }
    return {};
}

} // namespace

double FogCurve::at(double tSec, double base) const {
    if (keys.empty()) return base;
    if (tSec <= keys.front().x) return keys.front().y;
    if (tSec >= keys.back().x) return keys.back().y;
    const auto it = std::upper_bound(keys.begin(), keys.end(), tSec, [](double t, const glm::dvec2& k) { return t < k.x; });
    const glm::dvec2 b = *it, a = *(it - 1);
    const double span = b.x - a.x;
    return span > 0.0 ? a.y + (b.y - a.y) * ((tSec - a.x) / span) : b.y;
}

glm::dvec3 FogWind::velocity(double tSec) const {
    if (keys.empty()) return glm::dvec3(0.0);
    if (tSec <= keys.front().timeSec) return keys.front().velocity;
    if (tSec >= keys.back().timeSec) return keys.back().velocity;
    for (size_t i = 1; i < keys.size(); ++i)
        if (tSec < keys[i].timeSec) {
            const double span = keys[i].timeSec - keys[i - 1].timeSec;
            return keys[i - 1].velocity + (keys[i].velocity - keys[i - 1].velocity) * ((tSec - keys[i - 1].timeSec) / span);
        }
    return keys.back().velocity;
}

glm::dvec3 FogWind::displacement(double tSec) const {
    if (keys.empty()) return glm::dvec3(0.0);
    // A(t) = integral of v from the first key's time to t (v held before and after the keys);
    // D(t) = A(t) - A(0). Each linear piece integrates exactly to a quadratic.
    auto A = [this](double t) {
        const double t0 = keys.front().timeSec;
        if (t <= t0) return keys.front().velocity * (t - t0);
        glm::dvec3 sum(0.0);
        for (size_t i = 1; i < keys.size(); ++i) {
            const double a = keys[i - 1].timeSec, b = keys[i].timeSec;
            const glm::dvec3 va = keys[i - 1].velocity, vb = keys[i].velocity;
            if (t <= b) {
                const double tau = t - a, span = b - a;
                if (span > 0.0) sum += va * tau + (vb - va) * (tau * tau / (2.0 * span));
                return sum;
            }
            sum += 0.5 * (va + vb) * (b - a);
        }
        return sum + keys.back().velocity * (t - keys.back().timeSec);
    };
    return A(tSec) - A(0.0);
}

FogTerm FogTerm::constant(double weight) {
    FogTerm t;
    t.kind = FogTermKind::Constant;
    t.weight = weight;
    return t;
}

FogTerm FogTerm::cosine(double weight, double k, glm::dvec3 direction, double phase) {
    FogTerm t;
    t.kind = FogTermKind::Cosine;
    t.weight = weight;
    const double len = glm::length(direction);
    t.wave = len > 0.0 ? k * direction / len : glm::dvec3(0.0);
    t.phase = phase;
    return t;
}

FogTerm FogTerm::cosineProduct(double weight, double k1, glm::dvec3 dir1, double phase1, double k2, glm::dvec3 dir2, double phase2) {
    FogTerm t = cosine(weight, k1, dir1, phase1);
    t.kind = FogTermKind::CosineProduct;
    const double len = glm::length(dir2);
    t.wave2 = len > 0.0 ? k2 * dir2 / len : glm::dvec3(0.0);
    t.phase2 = phase2;
    return t;
}

FogTerm FogTerm::polynomial1D(double weight, int axis, std::vector<double> coeffs, double halfSize, FogCellMode mode, double centre) {
    FogTerm t;
    t.kind = FogTermKind::Polynomial;
    t.weight = weight;
    t.cellMode = mode;
    const int a = std::clamp(axis, 0, 2);
    t.cellHalfSize[a] = halfSize;
    t.cellCentre[a] = centre;
    for (size_t n = 0; n < coeffs.size(); ++n) {
        FogMonomial m{coeffs[n], 0, 0, 0};
        (a == 0 ? m.px : a == 1 ? m.py : m.pz) = int(n);
        t.monomials.push_back(m);
    }
    return t;
}

FogTerm FogTerm::point(double weight, glm::dvec3 centre, double c, double d) {
    FogTerm t;
    t.kind = FogTermKind::Point;
    t.weight = weight;
    t.centre = centre;
    t.c = c;
    t.d = d;
    return t;
}

FogTerm FogTerm::line(double weight, glm::dvec3 point, glm::dvec3 axis, double c, double d) {
    FogTerm t = FogTerm::point(weight, point, c, d);
    t.kind = FogTermKind::Line;
    t.axis = axis;
    return t;
}

FogTerm FogTerm::sphere(double weight, glm::dvec3 centre, double radius, double c, double d) {
    FogTerm t = FogTerm::point(weight, centre, c, d);
    t.kind = FogTermKind::Sphere;
    t.radius = radius;
    return t;
}

Result<Fog> Fog::create(FogDesc desc) {
    if (!finite(desc.colour)) return makeError("FogDesc.colour must be finite");
    if (!finite(desc.farDistanceWorld) || desc.farDistanceWorld < 0.0)
        return makeError("FogDesc.farDistanceWorld must be finite and >= 0 (0 = no cut-off; got " + fmt(desc.farDistanceWorld) + ")");
    for (size_t i = 0; i < desc.wind.keys.size(); ++i) {
        const std::string n = "FogDesc.wind.keys[" + std::to_string(i) + "]";
        if (!finite(desc.wind.keys[i].timeSec) || !finite(desc.wind.keys[i].velocity)) return makeError(n + " must be finite");
        if (i > 0 && desc.wind.keys[i].timeSec < desc.wind.keys[i - 1].timeSec)
            return makeError("FogDesc.wind.keys must be sorted by timeSec (" + n + " comes before its predecessor)");
    }
    for (size_t i = 0; i < desc.terms.size(); ++i)
        if (Status s = checkTerm(desc.terms[i], "FogDesc.terms[" + std::to_string(i) + "]"); !s) return Error{s.error()};
    if (Status s = checkNonNegative(desc); !s) return Error{s.error()};
    Fog fog;
    fog.mDesc = std::move(desc);
    // The structure key (Fog::glslKey): a hash of the GLSL of the default
    // options, made once here so that a pass compares two integers per frame.
    auto glsl = fogGlsl(fog);
    if (!glsl) return makeError(glsl.error());
    // The generated code is the fog's compile time (term count alone does not
    // bound it: degree and variables multiply it), refused before any GL sees it.
    if (const std::uint64_t bytes = glsl->termBytes; bytes > fog.mDesc.shaderBudgetBytes)
        return makeError("FogDesc.terms: the shader of its " + std::to_string(fog.mDesc.terms.size()) + " terms needs " +
                         std::to_string(bytes) + " bytes of GLSL, over FogDesc.shaderBudgetBytes = " +
                         std::to_string(fog.mDesc.shaderBudgetBytes) +
                         " (fewer or lower-degree polynomial terms, or raise the budget knowingly: docs/fog.md, \"What a fog's shader costs\")");
    std::uint64_t h = 1469598103934665603ull; // FNV-1a
    for (unsigned char c : glsl->source) h = (h ^ c) * 1099511628211ull;
    fog.mGlslKey = h | 1u; // never 0 (0: no fog)
    return fog;
}

double Fog::density(glm::dvec3 x, double tSec) const {
    if (!finite(x) || !finite(tSec)) return std::numeric_limits<double>::quiet_NaN();
    if (mDesc.terms.empty()) return 0.0;
    return std::max(0.0, fogdetail::evaluate(fogdetail::freeze(mDesc, tSec, x), glm::dvec3(0.0)));
}

double Fog::opticalDepth(glm::dvec3 o, glm::dvec3 p, double tSec) const {
    if (!finite(o) || !finite(p) || !finite(tSec)) return std::numeric_limits<double>::infinity();
    if (mDesc.terms.empty()) return 0.0;
    // Relative to o: the eye's own phases and cells are reduced in double once,
    // and the segment is integrated from 0 (docs/fog.md, "far from the origin").
    const double tau = fogdetail::integrate(fogdetail::freeze(mDesc, tSec, o), glm::dvec3(0.0), p - o);
    // The density is non-negative, so a negative result is rounding; clamp.
    return std::max(0.0, tau);
}

double Fog::transmittance(glm::dvec3 o, glm::dvec3 p, double tSec) const {
    if (!finite(o) || !finite(p) || !finite(tSec)) return 0.0;
    if (mDesc.farDistanceWorld > 0.0 && glm::length(p - o) > mDesc.farDistanceWorld) return 0.0;
    const double tau = opticalDepth(o, p, tSec);
    return std::exp(-tau); // exp(-inf) = 0; tau >= 0 so f in [0, 1]
}

glm::dvec3 Fog::apply(glm::dvec3 o, glm::dvec3 p, double tSec, glm::dvec3 colourIn) const {
    const double f = transmittance(o, p, tSec);
    return f * colourIn + (1.0 - f) * mDesc.colour;
}

} // namespace splatfx
