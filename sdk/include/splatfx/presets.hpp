// splatfx/presets.hpp: ready-made effects for the paper's scenes.
//
// Each preset takes a descriptor (every field defaulted, so `{}` is valid),
// registers the texture sets and colour tables it needs in the caller's
// Materials (procedural Perlin turbulence when no texture-set folder is
// given, King et al. 1999 sec. 4), and returns an Effect:
//   fire         Fig. 1: 7x20x5 grid, colour by height (sec. 2 step 4),
//                upward propagation (sec. 3.2) + ordered cycling (sec. 3.3)
//   smoke        solver plume from an emitter (which can ride a moving
//                object, Fig. 9), textures follow the flow, smoke table
//   steam        Fig. 5: 2x2x20 grid, 16 turbulence textures, inter-voxel
//                advection upwards, white thinning with height
//   dust         solver cloud kicked up by a moving object (Fig. 4): heavy,
//                settles, textures follow the flow
//   fireToSmoke  one lattice, two layers: fire (fire set + table) below,
//                smoke (its own set + table) above (sec. 2 step 4)
//   ghosts       Fig. 10: faces flashing across a head and dissipating above
//                it (random selection, sec. 3.3); procedural faces if no
//                texture set is given
// A preset fails only when a given texture set is empty or a field is out of
// range; the message names the field. Presets are GL-free and file-free
// (splatfx::core): to use a texture-set folder, load it first with
// loadTextureSet (splatfx::io) and pass the set, e.g.
// `.textureSet = *loadTextureSet("textures/fire8")`.
// Sharing: a preset registers its sets and tables by content (see
// materials.hpp); a procedural set is keyed by what makes it (the turbulence
// parameters and textureSeed), so presets with equal texture parameters share
// one set and skip regenerating it: a level of 1000 fires with different
// `seed`s holds one fire set. `seed` varies the texture dynamics per effect
// (each voxel's texture and phase), which is what tells two effects apart;
// give `textureSeed` different values only when effects must also use
// different texture images (each value is one more set). A given set equal
// to one already registered is shared the same way.
// It does not render or schedule anything.
//
//   splatfx::Materials materials(splatfx::Footprint{});
//   auto fire = splatfx::presets::fire(materials, {.dims = {7, 20, 5}});
//   if (!fire) return fail(fire.error());
//
// Threading: presets touch only their arguments.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/effect.hpp"
#include "splatfx/materials.hpp"

namespace splatfx::presets {

struct FireDesc {
    glm::ivec3 dims{7, 20, 5};              // lattice cells; default the paper's Fig. 1 grid
    glm::vec3 spacing{0.5f};                // world units between voxels; default 0.5
    glm::vec3 position{0.0f};               // world position of the base centre; default origin
    std::optional<TextureSet> textureSet{}; // detail textures (e.g. a loaded folder); default none (procedural turbulence)
    int textureCount = 8;                   // procedural textures; default 8
    float opacity = 0.55f;                  // opacity at the core of the base, (0, 1]; default 0.55
    float propagationStepsPerSec = 8.0f;    // global dynamics: cells per second the detail rises; default 8
    float texturesPerSec = 6.0f;            // local dynamics rate; default 6
    bool crossfade = true;                  // cross-fade consecutive textures; default true
    Motion motion{};                        // object dynamics (keyframes, procedure); default at rest
    std::uint32_t seed = 1;                 // texture dynamics (which texture each voxel shows when); default 1
    // Per-splat variation hiding the voxel lattice (splats.hpp); its seed is combined with `seed`;
    // default SplatVariation::recommended (jitter 0.5, any rotation, mirrored). {} gives the paper's lattice.
    SplatVariation variation = SplatVariation::recommended(0);
    std::uint32_t textureSeed = 1;          // procedural texture set; equal values share one set in Materials; default 1
};
Result<Effect> fire(Materials& materials, const FireDesc& desc = {});

struct SmokeDesc {
    glm::ivec3 dims{10, 20, 10};              // solver cells; default 10x20x10
    glm::vec3 spacing{0.5f};                  // world units per cell; default 0.5
    glm::vec3 position{0.0f};                 // world position of the domain's base centre; default origin
    glm::vec3 sourceOffset{0.0f, 0.5f, 0.0f}; // emitter centre in the source object's frame; default 0.5 up
    float sourceRadius = 0.75f;               // emitter radius, world units; default 0.75
    Motion sourceMotion{};                    // the object the chimney sits on; default at rest at `position`
    glm::vec3 windWorld{1.0f, 0.0f, 0.0f};    // world units/s; default 1 along +x
    float dissipation = 0.15f;                // 1/s smoke thinning; default 0.15
    std::optional<TextureSet> textureSet{};   // default none (procedural turbulence)
    int textureCount = 8;                     // default 8
    float texturesPerSec = 3.0f;              // local dynamics rate; default 3
    int substeps = 1;                         // solver substeps per step; default 1
    // Solids the smoke flows around (a bridge deck, a roof), world placement (obstacle.hpp); default none
    std::vector<Obstacle> obstacles{};
    std::uint32_t seed = 1;                   // texture dynamics (which texture each voxel shows when); default 1
    // Per-splat variation hiding the voxel lattice (splats.hpp); its seed is combined with `seed`;
    // default SplatVariation::recommended (jitter 0.5, any rotation, mirrored). {} gives the paper's lattice.
    SplatVariation variation = SplatVariation::recommended(0);
    std::uint32_t textureSeed = 1;            // procedural texture set; equal values share one set in Materials; default 1
};
Result<Effect> smoke(Materials& materials, const SmokeDesc& desc = {});

struct SteamDesc {
    glm::ivec3 dims{2, 20, 2};              // lattice; default the paper's Fig. 5 grid
    glm::vec3 spacing{0.25f};               // world units; default 0.25
    glm::vec3 position{0.0f};               // world position of the base (the spout); default origin
    std::optional<TextureSet> textureSet{}; // default none (procedural turbulence)
    int textureCount = 16;                  // default 16 (sec. 5.2)
    float opacity = 0.35f;                  // at the spout; default 0.35
    float propagationStepsPerSec = 10.0f;   // inter-voxel advection rate; default 10
    float texturesPerSec = 4.0f;            // default 4
    Motion motion{};                        // default at rest
    std::uint32_t seed = 1;                 // texture dynamics (which texture each voxel shows when); default 1
    // Per-splat variation hiding the voxel lattice (splats.hpp); its seed is combined with `seed`;
    // default SplatVariation::recommended (jitter 0.5, any rotation, mirrored). {} gives the paper's lattice.
    SplatVariation variation = SplatVariation::recommended(0);
    std::uint32_t textureSeed = 1;          // procedural texture set; equal values share one set in Materials; default 1
};
Result<Effect> steam(Materials& materials, const SteamDesc& desc = {});

// A turbulent procedural gas (Ebert & Parent 1990; procedural_gas.hpp):
// steam from a glass, fog rolling in (chess_fog), an ellipsoidal cloud,
// sampled into a lattice of `dims` cells placed with its base centre at
// `position`; the gas's own coordinates are world coordinates.
struct GasDesc {
    ProceduralGasDesc gas{};                // which gas and its parameters; default rising steam
    glm::ivec3 dims{16, 16, 16};            // lattice cells sampled per update; default 16^3
    glm::vec3 spacing{0.125f};              // world units; default 0.125
    glm::vec3 position{0.0f};               // world position of the lattice's base centre; default origin
    std::optional<TextureSet> textureSet{}; // default none (procedural turbulence)
    int textureCount = 16;                  // default 16
    float opacity = 1.0f;                   // scales the gas's density into splat opacity, (0, 1]; default 1
    float texturesPerSec = 3.0f;            // local dynamics' cycling rate; default 3
    Motion motion{};                        // moves the lattice; default at rest
    std::uint32_t seed = 1;                 // texture cycling; default 1
    // Per-splat variation hiding the voxel lattice (splats.hpp); its seed is combined with `seed`;
    // default SplatVariation::recommended (jitter 0.5, any rotation, mirrored). {} gives the paper's lattice.
    SplatVariation variation = SplatVariation::recommended(0);
    std::uint32_t textureSeed = 1;          // procedural texture set; equal values share one set in Materials; default 1
};
Result<Effect> gas(Materials& materials, const GasDesc& desc = {});

struct DustDesc {
    glm::ivec3 dims{24, 6, 12};                // solver cells; default 24x6x12
    glm::vec3 spacing{0.5f};                   // world units per cell; default 0.5
    glm::vec3 position{0.0f};                  // world position of the domain's base centre; default origin
    Motion sourceMotion{};                     // the animal kicking up dust; default at rest at `position`
    glm::vec3 sourceOffset{0.0f, 0.25f, 0.0f}; // hooves, in the animal's frame; default 0.25 up
    float sourceRadius = 0.8f;                 // world units; default 0.8
    glm::vec3 windWorld{0.0f};                 // default none
    float settle = 0.6f;                       // downward pull per unit density, world units/s^2; default 0.6
    float dissipation = 0.3f;                  // 1/s; default 0.3
    std::optional<TextureSet> textureSet{};    // default none (procedural turbulence)
    int textureCount = 8;                      // default 8
    std::vector<Obstacle> obstacles{};         // solids the dust flows around, world placement (obstacle.hpp); default none
    std::uint32_t seed = 1;                    // texture dynamics (which texture each voxel shows when); default 1
    // Per-splat variation hiding the voxel lattice (splats.hpp); its seed is combined with `seed`;
    // default SplatVariation::recommended (jitter 0.5, any rotation, mirrored). {} gives the paper's lattice.
    SplatVariation variation = SplatVariation::recommended(0);
    std::uint32_t textureSeed = 1;             // procedural texture set; equal values share one set in Materials; default 1
};
Result<Effect> dust(Materials& materials, const DustDesc& desc = {});

struct FireToSmokeDesc {
    glm::ivec3 dims{7, 32, 5};                   // lattice; default 7x32x5
    glm::vec3 spacing{0.5f};                     // default 0.5
    glm::vec3 position{0.0f};                    // default origin
    float split = 0.45f;                         // normalized height where smoke takes over, (0, 1); default 0.45
    float blend = 0.15f;                         // overlap of the two layers, normalized height; default 0.15
    std::optional<TextureSet> fireTextureSet{};  // default none (procedural turbulence)
    std::optional<TextureSet> smokeTextureSet{}; // default none (procedural, softer turbulence)
    float propagationStepsPerSec = 8.0f;         // default 8
    float texturesPerSec = 5.0f;                 // default 5
    Motion motion{};                             // default at rest
    std::uint32_t seed = 1;                      // texture dynamics (which texture each voxel shows when); default 1
    // Per-splat variation hiding the voxel lattice (splats.hpp); its seed is combined with `seed`;
    // default SplatVariation::recommended (jitter 0.5, any rotation, mirrored). {} gives the paper's lattice.
    SplatVariation variation = SplatVariation::recommended(0);
    std::uint32_t textureSeed = 1;               // procedural texture set; equal values share one set in Materials; default 1
};
Result<Effect> fireToSmoke(Materials& materials, const FireToSmokeDesc& desc = {});

struct GhostsDesc {
    float headRadiusCells = 3.0f;           // the head's voxel sphere; default 3
    int plumeCells = 8;                     // cells of rising, dissipating faces above it; default 8
    glm::vec3 spacing{0.3f};                // default 0.3
    glm::vec3 position{0.0f};               // world position of the base; default origin
    std::optional<TextureSet> textureSet{}; // face images; default none (procedural faces)
    int textureCount = 12;                  // procedural faces; default 12
    float opacity = 0.4f;                   // default 0.4
    float texturesPerSec = 5.0f;            // random selection rate; default 5
    float propagationStepsPerSec = 4.0f;    // faces drifting upwards; default 4
    std::uint32_t seed = 1;                 // texture dynamics (which texture each voxel shows when); default 1
    // Per-splat variation hiding the voxel lattice (splats.hpp); its seed is combined with `seed`. Faces keep
    // roughly upright, so their features at the cell's size line up along the column: the size varies
    // instead (docs/BENCHMARKS.md, "The voxel lattice"). Default jitter 0.5, rotation +-0.35 rad,
    // mirrored, scale 2^+-0.5.
    SplatVariation variation{.jitter = 0.5f, .rotationRad = 0.35f, .mirror = true, .scaleLog2 = 0.5f};
    std::uint32_t textureSeed = 1;          // procedural texture set; equal values share one set in Materials; default 1
};
Result<Effect> ghosts(Materials& materials, const GhostsDesc& desc = {});

// Embers rising over a fire (King et al. 1999, sec. 6: splats at particle
// positions, Effect::fromParticles): sparks born in a box over the fire,
// lifted by buoyancy and drifting with a wind, fading through the fire colour
// table from yellow to dark red. Warmed up: births start warmUpSec before t = 0.
struct EmbersDesc {
    glm::vec3 position{0.0f, 3.2f, 0.0f};        // emitter box centre, world; default 3.2 above the origin (inside FireDesc{}'s flame)
    glm::vec3 halfExtent{1.0f, 1.6f, 0.7f};       // >= 0; default 1, 1.6, 0.7
    float ratePerSec = 45.0f;                     // births per second, >= 0; default 45
    float warmUpSec = 5.0f;                       // births start this long before t = 0, >= 0; default 5
    float lifetimeSec = 4.2f;                     // >= 0; default 4.2
    float lifetimeJitter = 0.5f;                  // [0, 1]; default 0.5
    glm::vec3 velocity{0.0f, 2.6f, 0.0f};         // world units / s; default 2.6 up
    glm::vec3 velocitySpread{1.6f, 1.4f, 1.6f};   // + - per axis, >= 0; default 1.6, 1.4, 1.6
    glm::vec3 acceleration{0.0f, 0.8f, 0.0f};     // buoyancy, world units / s^2; default 0.8 up
    float dragPerSec = 0.4f;                      // towards the wind, >= 0; default 0.4
    glm::vec3 wind{1.1f, 0.0f, 0.3f};             // world units / s; default 1.1, 0, 0.3
    float sizeWorld = 0.065f;                     // kernel unit at birth, > 0; default 0.065
    float sizeEndWorld = 0.03f;                   // ... at death, > 0; default 0.03
    float opacity = 1.0f;                         // [0, 1]; default 1
    float stretchPerSpeed = 0.4f;                 // streaks along the flight, s, >= 0; default 0.4
    float texturesPerSec = 8.0f;                  // local dynamics; default 8
    std::optional<TextureSet> textureSet{};       // default none (procedural turbulence)
    int textureCount = 8;                         // procedural textures; default 8
    Motion motion{};                              // moves the emitter (particles trail); default at rest
    std::uint32_t seed = 1;                       // default 1
    std::uint32_t textureSeed = 1;                // procedural texture set; default 1
    SplatVariation variation = SplatVariation::recommended(0); // rotation and mirroring per particle; default recommended
};
Result<Effect> embers(Materials& materials, const EmbersDesc& desc = {});

// A set of simple procedural faces (pale oval, dark eyes and mouth), the
// fallback texture set for ghosts.
TextureSet proceduralFaces(int count, int size, std::uint32_t seed);

} // namespace splatfx::presets
