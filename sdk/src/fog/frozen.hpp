// The fog at one instant, relative to a reference point: what the closed-form
// integrals, the quadrature and the GLSL parameters are computed from.
// Everything time-dependent (curves, wind) is resolved here, in double, so
// the integrals below see a static field in coordinates relative to `ref`.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "splatfx/fog.hpp"

namespace splatfx::fogdetail {

// amp * cos(dot(w, xRel) + alpha); a CosineProduct is two of these (product to sum).
struct Wave {
    glm::dvec3 w{0.0};
    double alpha = 0.0; // phase at the reference point, reduced to [-pi, pi]
    double amp = 0.0;
};

struct Poly {
    std::vector<FogMonomial> mono; // weight and blend folded in; fixed exponent set
    glm::dvec3 uRef{0.0};          // cell coordinates of the reference (wrapped to [-1, 1) on periodic axes)
    glm::dvec3 halfSize{1.0};
    bool used[3] = {false, false, false}; // axes with a non-zero power in A or B
    int usedCount = 0;
    int usedAxis = -1; // the axis when usedCount == 1
    FogCellMode mode = FogCellMode::Periodic;
};

struct Potential {
    FogTermKind kind = FogTermKind::Point;
    glm::dvec3 qRel{0.0}; // centre relative to the reference
    glm::dvec3 axis{0.0, 1.0, 0.0};
    double radius2 = 0.0;
    double c = 1.0, d = 1.0, weight = 0.0;
    bool segment = false; // FogPotentialForm::Segment: weight / (c + d r^2) of the segment, not a density
};

// Squared distance r^2 of FogTermKind's measure between the segment
// oRel + s e, s in [0, L] (e unit) and the potential's object: the nearest
// point for a point, the nearest approach for a line, the power of the
// nearest point with respect to a sphere (0 inside).
double segmentDistance2(const Potential& p, glm::dvec3 oRel, glm::dvec3 e, double L);

struct Frozen {
    double constant = 0.0;
    std::vector<Wave> waves;
    std::vector<Poly> polys;
    std::vector<Potential> pots;
};

Frozen freeze(const FogDesc& desc, double tSec, glm::dvec3 ref);
double evalPoly(const Poly& p, glm::dvec3 u); // u in the reference cell
double evaluate(const Frozen& f, glm::dvec3 xRel);
double integrate(const Frozen& f, glm::dvec3 oRel, glm::dvec3 pRel);

// Cell-walk cap for multi-variable periodic polynomials (documented in docs/fog.md).
inline constexpr long kMaxCellsPerRay = 1L << 22;

} // namespace splatfx::fogdetail
