// splatfx/emitted_light.hpp: an emissive volume (a fire, embers, a glowing
// gas) as light for the host's surfaces.
//
// King et al. 1999 (sec. 6) leave out "illumination issues, such as for fire,
// in which the volume is a light source"; games give every fire a light. A
// splat draws premultiplied colour c * alpha over its ellipse; seen from any
// direction it is the same ellipse (the billboard faces the eye), so it
// radiates the intensity I = integral of c * alpha over the ellipse's area
// (linear RGB x world area), and a surface point at distance d whose normal
// makes the angle theta with the splat receives I cos(theta) / d^2.
// fitEmittedLights sums that over an effect's splats into a few point lights
// (weighted k-means on their centres), each splat's intensity first
// multiplied by the transmittance out of the volume (the volume's own
// occlusion along the six axis directions, through the splats' optical depth
// binned on a coarse grid, each splat taking its mean opacity). The lights follow the splats every frame, so they
// flicker with the textures' cycling and move with the effect.
// reference::emittedIrradianceExact gives the exact irradiance the same
// splats give a surface point (occlusion along every ray included), which is
// what the fit is measured against (docs/lighting.md, "Volumes as light").
//
// Hosts read the lights from Frame::emittedLights() (a Scene fills them for
// effects with EffectOptions::emitsLight) and add them in GLSL with
// splatfx_emittedIrradiance(worldPos, normal) from shadowGlsl(), whose
// uniforms gl::setShadowUniforms sets.
//
// The alternative (EmittedLightMode::Grid, fitEmittedGrid): the irradiance
// itself at the nodes of a coarse box around the emitter, for the six axis
// normals, summed over the splats with each splat-node ray's own occlusion
// (marched through the binned optical depth); sampled trilinearly by
// splatfx_emittedGridIrradiance(worldPos, normal); outside the box a point
// source at the emitter's centre calibrated at the box. It errs less than
// point lights inside the flame, more outside it (docs/BENCHMARKS.md).
//
// Threading: plain functions of their arguments.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/materials.hpp"
#include "splatfx/result.hpp"
#include "splatfx/splats.hpp"

namespace splatfx {

// What shadowGlsl()'s arrays hold: a frame passes at most this many lights.
inline constexpr int kMaxEmittedLights = 8;

struct EmittedLight {
    glm::vec3 position{0.0f};  // world
    float radius = 0.0f;       // world: the RMS spread of its splats about `position` (softens the near field)
    glm::vec3 intensity{0.0f}; // linear RGB x world area, before occlusion
    // The share of the light leaving the volume along +x, +y, +z (plus) and
    // -x, -y, -z (minus); towards a unit direction w it is sum_a w_a^2 times
    // the factor of w_a's sign. So the irradiance at distance d, angle theta:
    // intensity x escape(w) x cos(theta) / (d^2 + radius^2). 1: no occlusion.
    glm::vec3 escapePlus{1.0f}, escapeMinus{1.0f};
};

// What shadowGlsl()'s grid uniform holds: 32 nodes x 6 normals x RGB is 144
// vec4, 576 of the 1024 fragment uniform components GL 4.5 guarantees.
inline constexpr int kMaxEmittedGridNodes = 32;

enum class EmittedLightMode {
    PointLights, // fitEmittedLights: a few point lights (Scene fills Frame::emittedLights)
    Grid,        // fitEmittedGrid: an irradiance grid around the emitter
};

struct EmittedLightDesc {
    bool enabled = false; // default false: the effect lights nothing
    EmittedLightMode mode = EmittedLightMode::PointLights; // default PointLights
    int lights = 1;       // point lights fitted, [1, kMaxEmittedLights]; default 1 (the Pareto point: docs/BENCHMARKS.md)
    float scale = 1.0f;   // intensity multiplier, >= 0 (1: the splats' own emission); default 1
    bool occlusion = true; // attenuate by the volume's transmittance out of each splat; default true
    // World distance beyond which the host's surfaces are taken to get none of
    // its light: an emitter out of view is still simulated (not drawn) when
    // its bounds grown by this reach the view (Scene). Default: no limit.
    float reachWorld = 1e30f;
    // Grid: nodes per axis (each >= 2, product <= kMaxEmittedGridNodes) over
    // the emitting splats' centres' bounds grown by gridMargin (world, >= 0)
    // on every side. Defaults 3 x 3 x 3, 0.5.
    glm::ivec3 gridDims{3, 3, 3};
    float gridMargin = 0.5f;
};

// The irradiance grid (EmittedLightMode::Grid). dims 0: no grid (gives 0).
struct EmittedGrid {
    glm::ivec3 dims{0};
    glm::vec3 boxMin{0.0f}, boxMax{0.0f}; // world; the nodes span it, corners included
    glm::vec3 centre{0.0f};               // emission-weighted centre: where the point source outside the box sits
    // Per node (x fastest, then y, z): the irradiance (linear RGB) a surface
    // with normal +x, -x, +y, -y, +z, -z receives there; a unit normal n
    // gets sum_a n_a^2 times its sign's value (exact for an axis normal).
    std::vector<std::array<glm::vec3, 6>> nodes;
};

// Checks desc (the message names the field).
Status validate(const EmittedLightDesc& desc);

// Fits desc.lights point lights (fewer when the emitting splats have fewer distinct centres)
// to the emission of `splats` (one effect's, any order), brightest first.
// Colours come from materials' colour tables at each splat's colour
// coordinate times its texture's RGB (packedColor: the splat's RGB8 colour
// instead, as a lit Scene draws). Deterministic. Fails on a bad desc.
Result<std::vector<EmittedLight>> fitEmittedLights(std::span<const Splat> splats, const Materials& materials, const EmittedLightDesc& desc,
                                                   bool packedColor = false);

// The irradiance grid of `splats`' emission (desc.gridDims, desc.gridMargin,
// desc.scale, desc.occlusion as for the lights): at each node, the sum over
// the splats of intensity x transmittance / (d^2 + a^2) times the cosine to
// each axis normal, a^2 = the splat's (u, v) unit-disc area / pi (the exact
// on-axis irradiance of a uniform disc facing the node), the transmittance
// marched along the splat-node ray through the splats' binned optical depth
// (the splat's own excluded). Cost: nodes x splats x the bins a ray crosses.
// Deterministic. Fails on a bad desc; an empty grid without emitting splats.
Result<EmittedGrid> fitEmittedGrid(std::span<const Splat> splats, const Materials& materials, const EmittedLightDesc& desc, bool packedColor = false);

// The grid's irradiance at a point with unit normal n: trilinear inside the box; outside, a point source at the
// centre whose intensity is read from the six values at the box's nearest point q, plus the grid's departure from it at q
// falling as (|q - c| / |p - c|)^4 (what splatfx_emittedGridIrradiance computes in GLSL).
glm::vec3 emittedIrradiance(const EmittedGrid& grid, glm::vec3 point, glm::vec3 normal);

// The irradiance the lights give a surface point with unit normal n
// (what splatfx_emittedIrradiance computes in GLSL), linear RGB.
glm::vec3 emittedIrradiance(std::span<const EmittedLight> lights, glm::vec3 point, glm::vec3 normal);

} // namespace splatfx
