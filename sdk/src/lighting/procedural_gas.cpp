// Turbulent procedural gases (Ebert & Parent 1990, "Modeling and animating the
// gases"): density functions of position and time, moving the object's points
// through a fixed turbulent space.
#include "splatfx/procedural_gas.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "texture/noise.hpp"

namespace splatfx {
namespace {

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

Status positive(float v, const std::string& field) {
    if (!std::isfinite(v) || v <= 0.0f) return makeError(field + " must be a finite number > 0");
    return {};
}
Status nonNegative(float v, const std::string& field) {
    if (!std::isfinite(v) || v < 0.0f) return makeError(field + " must be a finite number >= 0");
    return {};
}
Status finite(float v, const std::string& field) {
    if (!std::isfinite(v)) return makeError(field + " must be finite");
    return {};
}

// The noise repeats every 256 lattice units on each axis (its permutation),
// so each octave is taken modulo 256 in double: a point 10^12 world units out,
// or moved through turbulent space for 10^6 s, keeps full precision and never
// overflows the lattice index.
double wrapNoise(double s) { return s - 256.0 * std::floor(s / 256.0); }

// Perlin 1985: turbulence(p) = sum_i |noise(2^i p)| / 2^i.
double turb(const detail::Noise4& noise, const GasTurbulenceDesc& d, glm::dvec3 p) {
    double sum = 0.0, scale = 1.0;
    const glm::dvec3 q = p * double(d.frequency);
    for (int i = 0; i < d.octaves; ++i) {
        const glm::dvec3 s = q / scale;
        sum += std::abs(noise(wrapNoise(s.x), wrapNoise(s.y), wrapNoise(s.z), 0.0)) * scale;
        scale *= 0.5;
    }
    return sum;
}

// A distance travelled through turbulent space, reduced modulo the
// turbulence's period (256 / frequency world units: every octave repeats
// within it), so the motion stays smooth at any time.
double travelled(double speed, double t, const GasTurbulenceDesc& d) {
    const double period = 256.0 / double(d.frequency);
    const double x = speed * t;
    return x - period * std::floor(x / period);
}

// 2 pi t / period, reduced to one turn in double first.
double turnAngle(double t, double periodSec) {
    const double p = double(periodSec);
    return 6.283185307179586 * ((t - p * std::floor(t / p)) / p);
}

double steam(const detail::Noise4& noise, const ProceduralGasDesc& g, glm::dvec3 p, double t) {
    const GasSteamDesc& s = g.steam;
    const double h = p.y - double(s.source.y);
    if (!(h >= 0.0) || h >= double(s.height)) return 0.0;
    const double hn = h / double(s.height);
    const double radius = double(s.sourceRadius) * (1.0 + double(s.spread) * hn);
    const glm::dvec2 r(p.x - double(s.source.x), p.z - double(s.source.z));
    const double radial = 1.0 - glm::dot(r, r) / (radius * radius);
    if (radial <= 0.0) return 0.0;
    // The steam's points rise through turbulent space along a helix.
    const double theta = turnAngle(t, s.swirlPeriodSec);
    const glm::dvec3 q =
        p - glm::dvec3(0.0, travelled(double(s.riseSpeed), t, g.turbulence), 0.0) + double(s.swirlRadius) * glm::dvec3(std::cos(theta), 0.0, std::sin(theta));
    // Dissipates with distance from the source (the paper: "decreasing the
    // opacity as a function of the distance from the glass"): linearly to 0 at height.
    const double d = double(s.opaque) * turb(noise, g.turbulence, q) * radial * (1.0 - hn);
    return std::pow(std::clamp(d, 0.0, 1.0), double(s.power));
}

double fog(const detail::Noise4& noise, const ProceduralGasDesc& g, glm::dvec3 p, double t) {
    const GasFogDesc& f = g.fog;
    // chess_fog (1): turbulence applied to the point "so that it appears more random".
    const double tmp = turb(noise, g.turbulence, p);
    // The front: a plane x = f advancing with time, deformed by the point's
    // turbulence so that it "does not appear as a plane".
    const double front = double(f.frontStart) + double(f.frontSpeed) * t + double(f.frontTurbulence) * (tmp - 0.5);
    if (p.x > front) return 0.0;
    const double thicken = std::min((front - p.x) / double(f.thickenDistance), 1.0);
    const glm::dvec3 pnt = p + glm::dvec3(2.0 + tmp, 0.5 + tmp, -2.0 - tmp);
    // Helical path: an ellipse in the y-z plane while drifting along x. The
    // paper's listing reads "direction.y = pnt.x + cyl.y"; pnt.y is meant (the
    // ellipse lies in the y-z plane).
    const double theta = turnAngle(t, f.swirlPeriodSec);
    const glm::dvec3 direction(pnt.x - travelled(double(f.driftPerSec), t, g.turbulence), pnt.y + double(f.ellipse1) * std::cos(theta),
                               pnt.z + double(f.ellipse2) * std::sin(theta));
    // (2), (3): grow to full density over fullDensitySec, then opaque and power.
    const double factor = std::clamp(t / double(f.fullDensitySec), 0.0, 1.0);
    const double d = turb(noise, g.turbulence, direction) * double(f.opaque) * factor * thicken;
    return std::pow(std::clamp(d, 0.0, 1.0), double(f.power));
}

double cloud(const detail::Noise4& noise, const ProceduralGasDesc& g, glm::dvec3 p, double t) {
    const GasCloudDesc& c = g.cloud;
    // The ellipsoid drifts with the wind; density falls to 0 at its surface so
    // the defining solid is not seen (the paper: "decreasing the density
    // based on the location within the volume").
    const glm::dvec3 e = (p - glm::dvec3(c.center) - glm::dvec3(c.windPerSec) * t) / glm::dvec3(c.radii);
    const double falloff = 1.0 - glm::dot(e, e);
    if (!(falloff > 0.0)) return 0.0;
    // The paper's clouds(): perturb the point by noise, a sine of the
    // turbulence, then 1 - (s + 1)^power / 2.
    glm::dvec3 q = p;
    const double n = noise(wrapNoise(q.x), wrapNoise(q.y), wrapNoise(q.z), 0.0);
    q.x += n;
    q.y += n;
    const double s = std::sin(turb(noise, g.turbulence, q) * double(c.frequency));
    const double v = 1.0 - std::pow(s + 1.0, double(c.power)) * 0.5;
    return std::clamp(double(c.opaque) * v * falloff, 0.0, 1.0);
}

float density(const detail::Noise4& noise, const ProceduralGasDesc& g, glm::vec3 p, double t) {
    if (!finite3(p) || !std::isfinite(t)) return 0.0f;
    double d = 0.0;
    switch (g.kind) {
    case GasKind::Steam: d = steam(noise, g, glm::dvec3(p), t); break;
    case GasKind::Fog: d = fog(noise, g, glm::dvec3(p), t); break;
    case GasKind::Cloud: d = cloud(noise, g, glm::dvec3(p), t); break;
    }
    return std::isfinite(d) ? float(std::clamp(d, 0.0, 1.0)) : 0.0f;
}

} // namespace

Status validateProceduralGas(const ProceduralGasDesc& g) {
    if (g.kind != GasKind::Steam && g.kind != GasKind::Fog && g.kind != GasKind::Cloud) return makeError("kind is not a GasKind");
    if (g.turbulence.octaves < 1 || g.turbulence.octaves > 12)
        return makeError("turbulence.octaves must be in [1, 12], got " + std::to_string(g.turbulence.octaves));
    if (Status s = positive(g.turbulence.frequency, "turbulence.frequency"); !s) return s;
    if (!(g.threshold >= 0.0f && g.threshold < 1.0f)) return makeError("threshold must be in [0, 1)");
    if (!(g.cellLength >= 0.0f) || !std::isfinite(g.cellLength)) return makeError("cellLength must be finite and >= 0");
    const GasSteamDesc& st = g.steam;
    for (int a = 0; a < 3; ++a)
        if (Status s = finite(st.source[a], "steam.source"); !s) return s;
    if (Status s = positive(st.sourceRadius, "steam.sourceRadius"); !s) return s;
    if (Status s = nonNegative(st.spread, "steam.spread"); !s) return s;
    if (Status s = positive(st.height, "steam.height"); !s) return s;
    if (Status s = finite(st.riseSpeed, "steam.riseSpeed"); !s) return s;
    if (Status s = positive(st.swirlPeriodSec, "steam.swirlPeriodSec"); !s) return s;
    if (Status s = nonNegative(st.swirlRadius, "steam.swirlRadius"); !s) return s;
    if (Status s = nonNegative(st.opaque, "steam.opaque"); !s) return s;
    if (Status s = positive(st.power, "steam.power"); !s) return s;
    const GasFogDesc& f = g.fog;
    if (Status s = positive(f.swirlPeriodSec, "fog.swirlPeriodSec"); !s) return s;
    if (Status s = nonNegative(f.ellipse1, "fog.ellipse1"); !s) return s;
    if (Status s = nonNegative(f.ellipse2, "fog.ellipse2"); !s) return s;
    if (Status s = finite(f.driftPerSec, "fog.driftPerSec"); !s) return s;
    if (Status s = positive(f.fullDensitySec, "fog.fullDensitySec"); !s) return s;
    if (Status s = nonNegative(f.opaque, "fog.opaque"); !s) return s;
    if (Status s = positive(f.power, "fog.power"); !s) return s;
    if (Status s = finite(f.frontStart, "fog.frontStart"); !s) return s;
    if (Status s = finite(f.frontSpeed, "fog.frontSpeed"); !s) return s;
    if (Status s = nonNegative(f.frontTurbulence, "fog.frontTurbulence"); !s) return s;
    if (Status s = positive(f.thickenDistance, "fog.thickenDistance"); !s) return s;
    const GasCloudDesc& c = g.cloud;
    for (int a = 0; a < 3; ++a) {
        if (Status s = finite(c.center[a], "cloud.center"); !s) return s;
        if (Status s = positive(c.radii[a], std::string("cloud.radii.") + "xyz"[a]); !s) return s;
        if (Status s = finite(c.windPerSec[a], "cloud.windPerSec"); !s) return s;
    }
    if (Status s = positive(c.frequency, "cloud.frequency"); !s) return s;
    if (Status s = positive(c.power, "cloud.power"); !s) return s;
    if (Status s = nonNegative(c.opaque, "cloud.opaque"); !s) return s;
    return {};
}

float gasTurbulence(const GasTurbulenceDesc& desc, glm::vec3 p) {
    const detail::Noise4 noise(desc.seed);
    return finite3(p) ? float(turb(noise, desc, glm::dvec3(p))) : 0.0f;
}

float proceduralGasDensity(const ProceduralGasDesc& desc, glm::vec3 world, double timeSec) {
    const detail::Noise4 noise(desc.turbulence.seed);
    return density(noise, desc, world, timeSec);
}

Result<Grid> sampleProceduralGas(const ProceduralGasDesc& desc, const Grid& lattice, double timeSec) {
    if (Status s = validateProceduralGas(desc); !s) return makeError(s.error());
    if (!std::isfinite(timeSec)) return makeError("timeSec must be finite");
    for (int a = 0; a < 3; ++a)
        if (lattice.dims[a] < 1) return makeError(std::string("lattice.dims.") + "xyz"[a] + " must be at least 1 (build the lattice with Grid::box)");
    const std::uint64_t n = std::uint64_t(lattice.dims.x) * std::uint64_t(lattice.dims.y) * std::uint64_t(lattice.dims.z);
    if (n > kMaxVoxels) return makeError("lattice.dims hold " + std::to_string(n) + " cells, more than kMaxVoxels");
    const detail::Noise4 noise(desc.turbulence.seed);
    Grid g;
    g.dims = lattice.dims;
    g.spacing = lattice.spacing;
    g.transform = lattice.transform;
    // The opacity of a cell of this lattice for a density given per cellLength (same depth per unit length).
    const double perCell = desc.cellLength > 0.0f
                               ? std::cbrt(double(lattice.spacing.x) * double(lattice.spacing.y) * double(lattice.spacing.z)) / double(desc.cellLength)
                               : 1.0;
    for (int z = 0; z < g.dims.z; ++z)
        for (int y = 0; y < g.dims.y; ++y)
            for (int x = 0; x < g.dims.x; ++x) {
                const glm::ivec3 cell(x, y, z);
                const float d = density(noise, desc, g.worldPosition(cell), timeSec);
                if (d <= desc.threshold) continue;
                Voxel v;
                v.cell = cell;
                v.opacity = perCell == 1.0 ? d : float(1.0 - std::pow(1.0 - double(d), perCell));
                g.voxels.push_back(v);
            }
    g.colorByHeight();
    return g;
}

} // namespace splatfx
