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

constexpr float kTwoPi = 6.283185307179586f;

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

// Perlin 1985: turbulence(p) = sum_i |noise(2^i p)| / 2^i.
float turb(const detail::Noise4& noise, const GasTurbulenceDesc& d, glm::vec3 p) {
    double sum = 0.0, scale = 1.0;
    const glm::dvec3 q = glm::dvec3(p) * double(d.frequency);
    for (int i = 0; i < d.octaves; ++i) {
        const glm::dvec3 s = q / scale;
        sum += std::abs(noise(s.x, s.y, s.z, 0.0)) * scale;
        scale *= 0.5;
    }
    return float(sum);
}

float steam(const detail::Noise4& noise, const ProceduralGasDesc& g, glm::vec3 p, float t) {
    const GasSteamDesc& s = g.steam;
    const float h = p.y - s.source.y;
    if (!(h >= 0.0f) || h >= s.height) return 0.0f;
    const float hn = h / s.height;
    const float radius = s.sourceRadius * (1.0f + s.spread * hn);
    const glm::vec2 r(p.x - s.source.x, p.z - s.source.z);
    const float radial = 1.0f - glm::dot(r, r) / (radius * radius);
    if (radial <= 0.0f) return 0.0f;
    // The steam's points rise through turbulent space along a helix.
    const float theta = kTwoPi * t / s.swirlPeriodSec;
    const glm::vec3 q = p - glm::vec3(0.0f, s.riseSpeed * t, 0.0f) + s.swirlRadius * glm::vec3(std::cos(theta), 0.0f, std::sin(theta));
    // Dissipates with distance from the source (the paper: "decreasing the
    // opacity as a function of the distance from the glass"): linearly to 0 at height.
    const float d = s.opaque * turb(noise, g.turbulence, q) * radial * (1.0f - hn);
    return std::pow(std::clamp(d, 0.0f, 1.0f), s.power);
}

float fog(const detail::Noise4& noise, const ProceduralGasDesc& g, glm::vec3 p, float t) {
    const GasFogDesc& f = g.fog;
    // chess_fog (1): turbulence applied to the point "so that it appears more random".
    const float tmp = turb(noise, g.turbulence, p);
    // The front: a plane x = f advancing with time, deformed by the point's
    // turbulence so that it "does not appear as a plane".
    const float front = f.frontStart + f.frontSpeed * t + f.frontTurbulence * (tmp - 0.5f);
    if (p.x > front) return 0.0f;
    const float thicken = std::min((front - p.x) / f.thickenDistance, 1.0f);
    const glm::vec3 pnt = p + glm::vec3(2.0f + tmp, 0.5f + tmp, -2.0f - tmp);
    // Helical path: an ellipse in the y-z plane while drifting along x. The
    // paper's listing reads "direction.y = pnt.x + cyl.y"; pnt.y is meant (the
    // ellipse lies in the y-z plane).
    const float theta = kTwoPi * t / f.swirlPeriodSec;
    const glm::vec3 direction(pnt.x - t * f.driftPerSec, pnt.y + f.ellipse1 * std::cos(theta), pnt.z + f.ellipse2 * std::sin(theta));
    // (2), (3): grow to full density over fullDensitySec, then opaque and power.
    const float factor = std::clamp(t / f.fullDensitySec, 0.0f, 1.0f);
    const float d = turb(noise, g.turbulence, direction) * f.opaque * factor * thicken;
    return std::pow(std::clamp(d, 0.0f, 1.0f), f.power);
}

float cloud(const detail::Noise4& noise, const ProceduralGasDesc& g, glm::vec3 p, float t) {
    const GasCloudDesc& c = g.cloud;
    // The ellipsoid drifts with the wind; density falls to 0 at its surface so
    // the defining solid is not seen (the paper: "decreasing the density
    // based on the location within the volume").
    const glm::vec3 e = (p - c.center - c.windPerSec * t) / c.radii;
    const float falloff = 1.0f - glm::dot(e, e);
    if (falloff <= 0.0f) return 0.0f;
    // The paper's clouds(): perturb the point by noise, a sine of the
    // turbulence, then 1 - (s + 1)^power / 2.
    glm::vec3 q = p;
    const float n = float(noise(q.x, q.y, q.z, 0.0));
    q.x += n;
    q.y += n;
    const float s = std::sin(turb(noise, g.turbulence, q) * c.frequency);
    const float v = 1.0f - std::pow(s + 1.0f, c.power) * 0.5f;
    return std::clamp(c.opaque * v * falloff, 0.0f, 1.0f);
}

float density(const detail::Noise4& noise, const ProceduralGasDesc& g, glm::vec3 p, float t) {
    if (!finite3(p) || !std::isfinite(t)) return 0.0f;
    float d = 0.0f;
    switch (g.kind) {
    case GasKind::Steam: d = steam(noise, g, p, t); break;
    case GasKind::Fog: d = fog(noise, g, p, t); break;
    case GasKind::Cloud: d = cloud(noise, g, p, t); break;
    }
    return std::isfinite(d) ? std::clamp(d, 0.0f, 1.0f) : 0.0f;
}

} // namespace

Status validateProceduralGas(const ProceduralGasDesc& g) {
    if (g.kind != GasKind::Steam && g.kind != GasKind::Fog && g.kind != GasKind::Cloud) return makeError("kind is not a GasKind");
    if (g.turbulence.octaves < 1 || g.turbulence.octaves > 12)
        return makeError("turbulence.octaves must be in [1, 12], got " + std::to_string(g.turbulence.octaves));
    if (Status s = positive(g.turbulence.frequency, "turbulence.frequency"); !s) return s;
    if (!(g.threshold >= 0.0f && g.threshold < 1.0f)) return makeError("threshold must be in [0, 1)");
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
    return finite3(p) ? turb(noise, desc, p) : 0.0f;
}

float proceduralGasDensity(const ProceduralGasDesc& desc, glm::vec3 world, float timeSec) {
    const detail::Noise4 noise(desc.turbulence.seed);
    return density(noise, desc, world, timeSec);
}

Result<Grid> sampleProceduralGas(const ProceduralGasDesc& desc, const Grid& lattice, float timeSec) {
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
    for (int z = 0; z < g.dims.z; ++z)
        for (int y = 0; y < g.dims.y; ++y)
            for (int x = 0; x < g.dims.x; ++x) {
                const glm::ivec3 cell(x, y, z);
                const float d = density(noise, desc, g.worldPosition(cell), timeSec);
                if (d <= desc.threshold) continue;
                Voxel v;
                v.cell = cell;
                v.opacity = d;
                g.voxels.push_back(v);
            }
    g.colorByHeight();
    return g;
}

} // namespace splatfx
