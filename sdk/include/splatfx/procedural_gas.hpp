// splatfx/procedural_gas.hpp: turbulent procedural gases (steam, fog, clouds)
// as stateless object dynamics, sampled into a coarse grid.
//
// Ebert & Parent 1990, "Modeling and animating the gases": a gas's density is
// a turbulence-based function of position, animated by moving the points of
// the object through a fixed turbulent space (not by animating the space).
// Every density here is a pure function of (world position, time, desc), so
// any time can be sampled in any order: steam rising from a source and
// dissipating with distance from it, fog rolling in behind a turbulent front
// along a helical path (the paper's chess_fog), ellipsoidal clouds.
// Turbulence is Perlin's sum of |noise| octaves over the SDK's seeded
// gradient noise. It does not light, shadow or draw the gas (lighting.hpp,
// splats.hpp).
//
//   auto lattice = splatfx::Grid::box({24, 32, 24}, glm::vec3(0.125f));   // cells to sample
//   splatfx::ProceduralGasDesc steam{.kind = splatfx::GasKind::Steam};
//   auto grid = splatfx::sampleProceduralGas(steam, *lattice, 2.5);      // Result<Grid>
//
// Threading: pure functions; call from any thread.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "splatfx/grid.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

enum class GasKind {
    Steam, // rising from `source`, dissipating with height
    Fog,   // rolling in along +x behind a turbulent front, helical swirl (chess_fog)
    Cloud, // an ellipsoid of turbulent density drifting with the wind
};

struct GasTurbulenceDesc {
    std::uint32_t seed = 1; // noise permutation; default 1
    int octaves = 4;        // |noise| octaves summed, [1, 12]; default 4
    float frequency = 1.0f; // noise cycles per world unit at the first octave, > 0; default 1
};

struct GasSteamDesc {
    glm::vec3 source{0.0f};      // world centre of the source disc (a glass's rim); default origin
    float sourceRadius = 0.3f;   // world radius of the plume at the source, > 0; default 0.3
    float spread = 1.5f;         // the plume's radius grows by this factor over `height`, >= 0; default 1.5
    float height = 2.0f;         // world height at which the steam has dissipated, > 0; default 2
    float riseSpeed = 0.4f;      // world units per second the steam rises through turbulent space; default 0.4
    float swirlPeriodSec = 6.0f; // one turn of the helical drift, > 0; default 6
    float swirlRadius = 0.3f;    // world radius of the helical drift through turbulent space, >= 0; default 0.3
    float opaque = 1.6f;         // density scale (the paper's opaque), >= 0; default 1.6
    float power = 1.5f;          // density exponent (the paper's power), > 0; default 1.5
};

// The paper's chess_fog, with frames turned into seconds: frame_num * DOWN
// is driftPerSec * t; theta = 2 pi t / swirlPeriodSec (SWIRL_FRAMES * SWIRL
// per frame); the ellipse's diameters ELLIPSE1/ELLIPSE2; min(frame /
// FULL_FOG, 1) is min(t / fullDensitySec, 1). The front f = frontStart +
// frontSpeed * t, deformed by turbulence; density is zero beyond it (x > f)
// and grows to full over thickenDistance behind it.
struct GasFogDesc {
    float swirlPeriodSec = 8.0f; // one turn of the ellipse in the y-z plane, > 0; default 8
    // The ellipse's axes along y and z (ELLIPSE1, ELLIPSE2; the paper calls
    // them diameters, its code multiplies cos and sin by them), world units, >= 0.
    float ellipse1 = 0.6f;        // default 0.6
    float ellipse2 = 0.3f;        // default 0.3
    float driftPerSec = 0.25f;    // horizontal motion through turbulent space (DOWN per frame); default 0.25
    float fullDensitySec = 4.0f;  // time to grow from nothing to full density (FULL_FOG), > 0; default 4
    float opaque = 1.2f;          // density scale, >= 0; default 1.2
    float power = 1.3f;           // density exponent, > 0; default 1.3
    float frontStart = -2.0f;     // world x of the front at t = 0; default -2
    float frontSpeed = 0.5f;      // world units per second the front advances along +x; default 0.5
    float frontTurbulence = 0.8f; // world amplitude of the front's deformation, >= 0; default 0.8
    float thickenDistance = 1.0f; // world distance behind the front to full density, > 0; default 1
};

struct GasCloudDesc {
    glm::vec3 center{0.0f};                 // world centre at t = 0; default origin
    glm::vec3 radii{2.0f, 1.0f, 1.5f};      // world semi-axes, each > 0; default (2, 1, 1.5)
    glm::vec3 windPerSec{0.2f, 0.0f, 0.0f}; // the cloud drifts with the wind, through turbulent space; default (0.2, 0, 0)
    float frequency = 3.0f;                 // the paper's clouds(): sine frequency through turbulent space, > 0; default 3
    float power = 1.0f;                     // ... and its exponent, > 0; default 1
    float opaque = 1.0f;                    // density scale, >= 0; default 1
};

struct ProceduralGasDesc {
    GasKind kind = GasKind::Steam; // default Steam
    GasTurbulenceDesc turbulence{};
    GasSteamDesc steam{};
    GasFogDesc fog{};
    GasCloudDesc cloud{};
    // Cells whose density is at most this are left out of the grid (sparse). [0, 1); default 0.01.
    float threshold = 0.01f;
    // The cell size the density is the opacity of, world units. 0: every
    // cell's opacity is the density, whatever the lattice's spacing (the
    // paper's per-sample density: halving the spacing doubles the optical
    // depth). > 0: a lattice of spacing s (the cube root of its cell volume)
    // gets 1 - (1 - density)^(s / cellLength), the same optical depth per
    // unit length at any spacing, so the spacing is a pure quality knob
    // (splatfx-bench gases). >= 0; default 0.
    float cellLength = 0.0f;
};

// Fails on a desc field out of range; the message names it ("fog.power must be > 0").
Status validateProceduralGas(const ProceduralGasDesc& desc);

// Perlin 1985 turbulence, sum over octaves of |noise(2^i f p)| / 2^i, about [0, 1].
// Expects a valid desc (see validateProceduralGas).
float gasTurbulence(const GasTurbulenceDesc& desc, glm::vec3 p);

// Density in [0, 1] at a world point and time, the gas's opacity there.
// Expects a valid desc; non-finite input gives 0. Evaluated in double, with
// travel through turbulent space and swirl angles reduced by their periods,
// so the motion is as smooth at 10^6 s as at 0 (docs/STABILITY.md, gases).
float proceduralGasDensity(const ProceduralGasDesc& desc, glm::vec3 world, double timeSec);

// Samples the density at every cell of `lattice`'s dims (its spacing and
// transform give the world positions, as Grid::worldPosition) and returns a
// grid with the same lattice holding the cells above desc.threshold, with
// opacity = density (scaled to the cell by desc.cellLength when it is set),
// colour coordinate = normalized height, texture 0.
// Fails on a bad desc, a non-finite time, or a lattice with no dims.
Result<Grid> sampleProceduralGas(const ProceduralGasDesc& desc, const Grid& lattice, double timeSec);

} // namespace splatfx
