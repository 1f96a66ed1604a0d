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
// Threading: plain functions of their arguments.
#pragma once

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

struct EmittedLightDesc {
    bool enabled = false; // default false: the effect lights nothing
    int lights = 2;       // point lights fitted, [1, kMaxEmittedLights]; default 2
    float scale = 1.0f;   // intensity multiplier, >= 0 (1: the splats' own emission); default 1
    bool occlusion = true; // attenuate by the volume's transmittance out of each splat; default true
    // World distance beyond which the host's surfaces are taken to get none of
    // its light: an emitter out of view is still simulated (not drawn) when
    // its bounds grown by this reach the view (Scene). Default: no limit.
    float reachWorld = 1e30f;
};

// Checks desc (the message names the field).
Status validate(const EmittedLightDesc& desc);

// Fits desc.lights point lights (fewer when there are fewer emitting splats)
// to the emission of `splats` (one effect's, any order), brightest first.
// Colours come from materials' colour tables at each splat's colour
// coordinate times its texture's RGB (packedColor: the splat's RGB8 colour
// instead, as a lit Scene draws). Deterministic. Fails on a bad desc.
Result<std::vector<EmittedLight>> fitEmittedLights(std::span<const Splat> splats, const Materials& materials, const EmittedLightDesc& desc,
                                                   bool packedColor = false);

// The irradiance the lights give a surface point with unit normal n
// (what splatfx_emittedIrradiance computes in GLSL), linear RGB.
glm::vec3 emittedIrradiance(std::span<const EmittedLight> lights, glm::vec3 point, glm::vec3 normal);

} // namespace splatfx
