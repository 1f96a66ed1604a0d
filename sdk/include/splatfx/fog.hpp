// splatfx/fog.hpp: analytic non-homogeneous fog with wind (Biri, Michelin & Arques 2002).
//
// The extinction coefficient is a weighted sum of functions whose line
// integrals are known in closed form (eq. 7): constants, cosines of a
// projection and products of two, polynomials made periodic over a reference
// cell (or zero outside it), and equipotentials 1 / (c + d r^2) of points,
// lines and spheres. The optical depth along a segment, hence the
// transmittance f of eq. 6/8, costs a few function evaluations and no ray
// march. Wind (a velocity that may change with time) slides every term and
// any parameter may follow a keyframed curve: the fog is a pure function of
// time. Fog::create validates that the density can never go negative.
// The same closed forms are emitted as GLSL 4.50 (fogGlsl) with float
// parameters computed here in double relative to a reference point (the eye),
// so rays far from the origin or 1e5 units long stay accurate in float.
// See docs/fog.md for the model, the integrals and the numerics.
//
// It does not draw anything, read depth buffers or parse scene files; the GL
// fog pass and the per-fragment splat fog use fogGlsl() and
// Fog::glslParameters().
//
//   auto fog = splatfx::Fog::create(splatfx::paperFig6Fog());
//   if (!fog) { std::fprintf(stderr, "%s\n", fog.error().c_str()); return 1; }
//   double f = fog->transmittance(eye, point, timeSec);  // C = f C_in + (1 - f) C_fog
//
// Threading: a Fog is immutable after create(); every const member may be
// called from any number of threads at once.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/result.hpp"

namespace splatfx {

// A scalar that follows keyframes (timeSec, value), linear in between and
// held constant before the first and after the last. Keys must be sorted by
// time. An empty curve means "not animated" (the field's base value is used).
struct FogCurve {
    std::vector<glm::dvec2> keys; // (timeSec, value); default empty

    bool empty() const { return keys.empty(); }
    // The value at tSec, or `base` when the curve is empty.
    double at(double tSec, double base) const;
};

// Wind as a velocity that is piecewise linear in time: keyframes
// (timeSec, velocity in world units per second), held constant before the
// first and after the last key. Constant wind is one key; a ramp is two.
// The fog is displaced by D(t) = integral_0^t v(s) ds, computed exactly
// (piecewise quadratic), so D(0) = 0 and negative times run the wind backwards.
// Direction and speed that change with time are a change of this vector:
// velocity = speed(t) * direction(t) sampled at keys, interpolated as a vector.
struct FogWindKey {
    double timeSec = 0.0;     // default 0
    glm::dvec3 velocity{0.0}; // world units per second; default 0 (calm)
};
struct FogWind {
    std::vector<FogWindKey> keys; // sorted by timeSec; default empty (no wind)

    static FogWind constant(glm::dvec3 velocity) { return FogWind{{{0.0, velocity}}}; }
    // Velocity v0 at t0 changing linearly to v1 at t1 (held outside [t0, t1]).
    static FogWind ramp(double t0Sec, glm::dvec3 v0, double t1Sec, glm::dvec3 v1) { return FogWind{{{t0Sec, v0}, {t1Sec, v1}}}; }
    glm::dvec3 velocity(double tSec) const;
    // Exact integral of velocity over [0, tSec].
    glm::dvec3 displacement(double tSec) const;
};

enum class FogTermKind {
    Constant,      // weight
    Cosine,        // weight * cos(dot(wave, x) + phase): wave = k * unit direction (k in rad per world unit)
    CosineProduct, // weight * cos(dot(wave, x) + phase) * cos(dot(wave2, x) + phase2)
    Polynomial,    // weight * P(u), u = (x - cellCentre) / cellHalfSize in the reference cell [-1, 1]^3
    Point,         // weight / (c + d |x - centre|^2)
    Line,          // weight / (c + d r^2), r the distance to the line through centre along axis
    Sphere,        // weight / (c + d max(0, |x - centre|^2 - radius^2)): 1/c inside the ball (docs/fog.md)
};

// How a potential (Point, Line, Sphere) enters the optical depth.
enum class FogPotentialForm {
    // The default: 1 / (c + d r^2) is a density (per world unit), integrated
    // along the ray in closed form. Physically consistent: a path split in two
    // has the depth of the whole, so splats and the host fogged at different
    // depths along one ray agree.
    Density,
    // Biri et al. eq. 9 as printed: the term adds weight / (c + d r^2) to the
    // optical depth, r the distance between the segment OP and the object (a
    // depth, not a density: weight is dimensionless). It grows as the segment
    // reaches nearer the object and never with length, so it is not additive
    // over split paths. Needs weight >= 0 (docs/fog.md, "The paper's eq. 9").
    Segment,
};

enum class FogCellMode {
    Periodic,    // the reference cell repeats over all space (Biri et al. Fig. 3)
    ZeroOutside, // the polynomial is zero outside its cell (on the axes it depends on)
};

// One monomial coeff * u^px * v^py * w^pz of a polynomial in cell coordinates.
struct FogMonomial {
    double coeff = 0.0; // default 0
    int px = 0;         // power of u (x axis); default 0
    int py = 0;         // power of v (y axis); default 0
    int pz = 0;         // power of w (z axis); default 0
};

// One term c_i gamma_i(x) of eq. 7. Fields a kind does not use are ignored.
// The factory functions below fill the fields of each kind.
struct FogTerm {
    FogTermKind kind = FogTermKind::Constant; // default Constant
    double weight = 1.0;                      // c_i, extinction per world unit; default 1
    FogCurve weightOverTime;                  // replaces weight when not empty; default empty
    double windFactor = 1.0;                  // the term moves by windFactor * D(t) (0 = not sensitive to wind); default 1
    FogWind motion;                           // the term's own motion, added to the wind's (e.g. a drifting potential); default none

    // Cosine, CosineProduct
    glm::dvec3 wave{1.0, 0.0, 0.0};  // k * direction, rad per world unit; default (1, 0, 0)
    double phase = 0.0;              // rad; default 0
    FogCurve phaseOverTime;          // replaces phase (of the first factor) when not empty; default empty
    FogCurve waveScaleOverTime;      // multiplies wave and wave2 (shrink / expand, sec. 5); empty = 1; default empty
    glm::dvec3 wave2{0.0, 0.0, 1.0}; // second factor (CosineProduct); default (0, 0, 1)
    double phase2 = 0.0;             // rad; default 0

    // Polynomial
    std::vector<FogMonomial> monomials;           // shape A; total degree <= kFogMaxDegree; default empty
    std::vector<FogMonomial> monomialsB;          // shape B; when not empty the shape is (1 - s) A + s B; default empty
    FogCurve blendOverTime;                       // s(t) in [0, 1]; empty = 0 (shape A); default empty
    glm::dvec3 cellCentre{0.0};                   // world; default origin
    glm::dvec3 cellHalfSize{1.0};                 // C per axis, world units, > 0; default (1, 1, 1)
    FogCellMode cellMode = FogCellMode::Periodic; // default Periodic

    // Point, Line, Sphere
    glm::dvec3 centre{0.0};         // world; default origin
    glm::dvec3 axis{0.0, 1.0, 0.0}; // Line direction (normalized by create); default +y
    double radius = 0.0;            // Sphere radius, world units; default 0
    double c = 1.0;                 // > 0 (finite density at r = 0); default 1
    double d = 1.0;                 // >= 0, per world unit^2; default 1
    FogPotentialForm form = FogPotentialForm::Density; // default Density (Segment: the paper's eq. 9 as printed)
    FogCurve cOverTime;             // replaces c when not empty (every key > 0); default empty
    FogCurve dOverTime;             // replaces d when not empty (every key >= 0); default empty

    static FogTerm constant(double weight);
    // weight * cos(k * dot(direction, x) + phase); direction is normalized.
    static FogTerm cosine(double weight, double k, glm::dvec3 direction, double phase = 0.0);
    static FogTerm cosineProduct(double weight, double k1, glm::dvec3 dir1, double phase1, double k2, glm::dvec3 dir2, double phase2);
    // weight * sum_n coeffs[n] * u^n along one axis (0 = x, 1 = y, 2 = z), u = (x_axis - centre) / halfSize.
    static FogTerm polynomial1D(double weight, int axis, std::vector<double> coeffs, double halfSize, FogCellMode mode = FogCellMode::Periodic,
                                double centre = 0.0);
    static FogTerm point(double weight, glm::dvec3 centre, double c, double d);
    static FogTerm line(double weight, glm::dvec3 point, glm::dvec3 axis, double c, double d);
    static FogTerm sphere(double weight, glm::dvec3 centre, double radius, double c, double d);
};

inline constexpr int kFogMaxDegree = 9; // total degree of a polynomial term: 5-point Gauss-Legendre is exact

struct FogDesc {
    std::vector<FogTerm> terms;        // default empty: no fog (transmittance 1 everywhere)
    glm::dvec3 colour{0.8, 0.8, 0.85}; // C_fog of eq. 5, linear RGB; default (0.8, 0.8, 0.85)
    double farDistanceWorld = 0.0;     // beyond it fully fogged (sec. 4.2); default 0 = no cut-off
    FogWind wind;                      // default: calm
    // Bytes of GLSL the terms may generate beyond the closed forms every fog
    // shares (fogGlsl): polynomials are generated code, about 1.7 KB a
    // degree-9 term, and every pass that fogs compiles it in time growing
    // faster than its size (docs/fog.md, "What a fog's shader costs").
    // Checked by Fog::create. Default 2^15 (32 KiB, about 18 degree-9
    // polynomial terms; cosines and potentials cost nothing here).
    std::uint64_t shaderBudgetBytes = 1ull << 15;
};

// A quadrature result (integrateFogNumerically).
struct FogQuadrature {
    double value = 0.0;         // optical depth
    double errorEstimate = 0.0; // sum of |Kronrod - Gauss| over accepted intervals
    long evaluations = 0;       // density evaluations
    bool converged = false;     // the tolerance was met within the interval budget
};

class Fog {
public:
    // Validates every field (finite numbers, c > 0, d >= 0, cell sizes > 0,
    // degrees, sorted keys) and that the density is non-negative everywhere at
    // every time (sec. 3.2.1's rule c_0 >= sum |c_i| generalised: constants
    // minus cosine amplitudes plus polynomial minima over their cells plus
    // negative potential peaks). On failure the message names the term
    // (terms[i]), the field or where the density goes negative.
    static Result<Fog> create(FogDesc desc);

    const FogDesc& desc() const { return mDesc; }
    bool empty() const { return mDesc.terms.empty(); }

    // K_t(x) at time tSec, per world unit (NaN for a non-finite x or tSec).
    double density(glm::dvec3 x, double tSec) const;
    // Exact integral of K_t along the segment [o, p] at time tSec (double,
    // integrated relative to o). Non-finite o, p or tSec give +infinity (an
    // invalid depth is treated as infinitely far: fully fogged).
    double opticalDepth(glm::dvec3 o, glm::dvec3 p, double tSec) const;
    // f = exp(-opticalDepth) of eq. 6, or 0 beyond farDistanceWorld. In [0, 1], never NaN.
    double transmittance(glm::dvec3 o, glm::dvec3 p, double tSec) const;
    // eq. 5: f * colourIn + (1 - f) * colour.
    glm::dvec3 apply(glm::dvec3 o, glm::dvec3 p, double tSec, glm::dvec3 colourIn) const;

    glm::dvec3 windDisplacement(double tSec) const { return mDesc.wind.displacement(tSec); }

    // An upper bound on the optical depth term `term` adds along any segment
    // of length at most maxLengthWorld inside the box [lo, hi], at tSec
    // (docs/fog.md, "Terms out of view"), or +infinity where there is none:
    // constants, cosines and periodic polynomials fill space, as does a
    // zero-outside polynomial whose cell meets the box. Potentials are bounded
    // by their density at the box's nearest point times the length, and
    // points and spheres also by their integral along a whole line. A term a
    // Scene drops is one whose bounds, summed with the others it drops, stay
    // under a stated depth: no pixel's fog transmittance moves by more.
    // Expects term < desc().terms.size().
    double termDepthBound(std::size_t term, double tSec, glm::dvec3 lo, glm::dvec3 hi, double maxLengthWorld) const;
    // This fog with only the terms where keep[i] is true (colour, far
    // cut-off and wind kept), validated again by create(): it fails when the
    // remaining terms can go negative (a dropped term held them up). Expects
    // keep.size() == desc().terms.size().
    Result<Fog> withTerms(const std::vector<bool>& keep) const;

    // Parameters of the GLSL from fogGlsl(*this) at time tSec, as vec4s for
    // glUniform4fv(location of FogGlsl::uniformName, count, data). Computed
    // in double relative to `reference` (world): the shader's positions are
    // world - reference. Pass the eye (or a point near the rays) every frame.
    std::vector<glm::vec4> glslParameters(double tSec, glm::dvec3 reference) const;
    // Identifies the structure of fogGlsl(*this)'s source (the terms' kinds,
    // polynomial shapes, counts; not the parameters): two fogs with equal keys
    // get the same source for the same options, so a pass rebuilds its
    // programs only when the key changes. Never 0. Computed once by create().
    std::uint64_t glslKey() const { return mGlslKey; }

private:
    Fog() = default;
    FogDesc mDesc; // validated; Line axes normalized
    std::uint64_t mGlslKey = 0;
};

// Options of the GLSL generator.
struct FogGlslOptions {
    std::string prefix = "splatfx_fog"; // prefix of every emitted name; default "splatfx_fog"
    int uniformLocation = -1;           // explicit layout(location) of the parameter array; default -1 (none)
    // A multi-variable periodic polynomial on a general ray is a walk over the
    // cells it crosses; past this many cells the rest of the ray is taken at
    // the cell's mean density (an approximation, docs/fog.md). 1D polynomials
    // and rays moving along one variable count cells in O(1). Default 1024.
    int maxPolynomialCells = 1024;
};

// GLSL 4.50 source (no #version line: include it in any stage): the SDK's
// fog.glsl (the closed forms every fog shares, the same text the GL passes
// compile) followed by this fog's terms (the parameter array, a function per
// polynomial, their sum), defining
//   uniform vec4 <prefix>_params[N];
//   uniform vec3 <prefix>_colour;  uniform float <prefix>_far;   (set by the host: FogDesc colour, farDistanceWorld)
//   float <prefix>_optical_depth(vec3 oRel, vec3 pRel)   // positions relative to the reference point
//   float <prefix>_transmittance(vec3 oRel, vec3 pRel)   // exp(-depth), 0 beyond the far cut-off
//   vec3  <prefix>_apply(vec3 oRel, vec3 pRel, vec3 colourIn)  // eq. 5
// Fill <prefix>_params with Fog::glslParameters(t, reference) each frame.
struct FogGlsl {
    std::string source;
    std::string uniformName; // "<prefix>_params"
    int vec4Count = 0;       // N (at least 1)
    // Bytes of `source` generated for this fog's terms (all but the shared
    // fog.glsl): what FogDesc::shaderBudgetBytes bounds.
    std::uint64_t termBytes = 0;
};
// Fails only for invalid options.
Result<FogGlsl> fogGlsl(const Fog& fog, const FogGlslOptions& options = {});

// Adaptive Gauss-Kronrod (7/15) quadrature of the density along [o, p] at
// time tSec to an absolute tolerance on the optical depth. The reference
// renderer and the tests use it to check the closed forms. The segment is
// first cut into pieces short against the highest cosine frequency and the
// smallest polynomial cell so that no feature is stepped over.
FogQuadrature integrateFogNumerically(const Fog& fog, glm::dvec3 o, glm::dvec3 p, double tSec, double absTolerance = 1e-10,
                                      long maxEvaluations = 20'000'000);

// The paper's example fogs (sec. 6), in the paper's units (x, y, z as in
// its formulas; scale the scene or the desc to taste).
// Fig. 6: 1 + 1/2 cos(5 pi y) + 1/5 cos(7 pi (y + 0.1 x)) + 1/5 cos(5 pi (y - 0.05 x))
//         + 1/10 cos(pi x) cos(pi z / 2).
FogDesc paperFig6Fog();
// Fig. 7: two 1D polynomials with coefficients {0.8, -1, 0, 0, 1} on X and on Z.
FogDesc paperFig7Fog(double cellHalfSizeWorld = 10.0);
// Fig. 8: a constant fog plus four point equipotentials centred on trees.
FogDesc paperFig8Fog();

} // namespace splatfx
