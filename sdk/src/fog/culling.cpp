// Bounds on one fog term's optical depth over a box (docs/fog.md, "Terms out
// of view"): what lets a Scene drop the terms a view cannot see.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "splatfx/fog.hpp"

namespace splatfx {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Distance from a point to the box (0 inside).
double distanceToBox(glm::dvec3 q, glm::dvec3 lo, glm::dvec3 hi) { return glm::length(q - glm::clamp(q, lo, hi)); }

} // namespace

double Fog::termDepthBound(std::size_t term, double tSec, glm::dvec3 lo, glm::dvec3 hi, double maxLengthWorld) const {
    assert(term < mDesc.terms.size() && "Fog::termDepthBound: term is not a term of this fog");
    constexpr double kNone = std::numeric_limits<double>::infinity();
    const FogTerm& t = mDesc.terms[term];
    // Where the term is at tSec: the wind's share plus its own motion (as the integrals see it).
    const glm::dvec3 D = t.windFactor * mDesc.wind.displacement(tSec) + t.motion.displacement(tSec);
    const double w = std::abs(t.weightOverTime.at(tSec, t.weight));
    const double L = std::max(0.0, maxLengthWorld);
    switch (t.kind) {
    case FogTermKind::Polynomial: {
        if (t.cellMode != FogCellMode::ZeroOutside) return kNone;
        // Zero outside its cell on the axes it depends on: a cell clear of the box on one of them adds nothing.
        for (int a = 0; a < 3; ++a) {
            bool used = false;
            for (const auto* ms : {&t.monomials, &t.monomialsB})
                for (const FogMonomial& m : *ms) used = used || (a == 0 ? m.px : a == 1 ? m.py : m.pz) > 0;
            if (!used) continue;
            const double c = t.cellCentre[a] + D[a], h = t.cellHalfSize[a];
            if (c + h < lo[a] || c - h > hi[a]) return 0.0;
        }
        return kNone; // meets the box, or depends on no axis (everywhere)
    }
    case FogTermKind::Point:
    case FogTermKind::Line:
    case FogTermKind::Sphere: {
        const double c = t.cOverTime.at(tSec, t.c), d = t.dOverTime.at(tSec, t.d);
        const glm::dvec3 q = t.centre + D;
        double rho = 0.0; // a lower bound on the distance every point of the box keeps from the centre (line, sphere's centre)
        if (t.kind == FogTermKind::Line) {
            // From the line to the box's bounding sphere.
            const glm::dvec3 mid = 0.5 * (lo + hi), v = mid - q;
            const double along = glm::dot(v, t.axis);
            rho = std::max(0.0, glm::length(v - along * t.axis) - 0.5 * glm::length(hi - lo));
        } else {
            rho = distanceToBox(q, lo, hi);
        }
        const double r2 = t.kind == FogTermKind::Sphere ? std::max(0.0, rho * rho - t.radius * t.radius) : rho * rho;
        // The paper's segment form adds at most its value at the box's nearest distance, whatever the length.
        if (t.form == FogPotentialForm::Segment) return w / (c + d * r2);
        // The density never exceeds its value at the nearest distance: times the longest segment.
        double bound = L * w / (c + d * r2);
        if (d > 0.0) {
            // Along a whole line: 1 / (c + d (h^2 + s^2)) integrates to at most pi / sqrt(c d); a
            // sphere adds at most its chord 2R at density 1 / c, and beyond it (s^2 - R^2 >= (|s| - R)^2)
            // the same pi / sqrt(c d).
            if (t.kind == FogTermKind::Point) bound = std::min(bound, w * kPi / std::sqrt(c * d));
            if (t.kind == FogTermKind::Sphere) bound = std::min(bound, w * (2.0 * t.radius / c + kPi / std::sqrt(c * d)));
        }
        return bound;
    }
    default: return kNone;
    }
}

Result<Fog> Fog::withTerms(const std::vector<bool>& keep) const {
    assert(keep.size() == mDesc.terms.size() && "Fog::withTerms: keep needs one entry per term");
    FogDesc d;
    d.colour = mDesc.colour;
    d.farDistanceWorld = mDesc.farDistanceWorld;
    d.wind = mDesc.wind;
    for (std::size_t i = 0; i < mDesc.terms.size(); ++i)
        if (i < keep.size() && keep[i]) d.terms.push_back(mDesc.terms[i]);
    return create(std::move(d));
}

} // namespace splatfx
