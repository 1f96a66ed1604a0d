// splatfx/particles.hpp: textured splats at particle positions.
//
// King et al. 1999, sec. 6: "With the ability to use splat locations,
// instead of a rectangular grid, particle systems could also be investigated
// as a control for the object dynamics." A Particle is a splat centre off the
// lattice: a world position, a kernel size, a velocity (which may stretch the
// kernel along the flow), an opacity, a colour coordinate and a texture.
// SplatBuilder::add(particles, materials, ParticleStyle) (splats.hpp) turns
// them into the same Splat list the grid's voxels go to, so one exact
// back-to-front sort and the depth cut treat both together; the GL renderer
// and the reference draw them unchanged.
//
// A ParticleEmitter is a particle system that is a pure function of time:
// particle n is born at startSec + (n + 1/2) / ratePerSec at a point of the
// emitter's box placed by a Motion, with a velocity, lifetime and texture
// drawn from (n, seed), and moves under a constant acceleration (buoyancy,
// gravity) and linear drag towards a wind, in closed form. Any time can be
// evaluated in any order at a cost linear in the particles alive; a frame
// step longer than the lifetime loses nothing. Effect::fromParticles
// (effect.hpp) schedules one in a Scene; a host with its own particle system
// hands its particles to SplatBuilder::add or Effect::setParticles instead.
// It does not render, sort or read files, does not collide particles with
// anything, and does not read a solver's velocity field (particles fly in
// the closed-form field above).
//
//   auto em = splatfx::ParticleEmitter::create({.ratePerSec = 40, .lifetimeSec = 2});
//   std::vector<splatfx::Particle> now;
//   em->particlesAt(timeSec, now);  builder.add(now, materials, style);
//
// Threading: ParticleEmitter is an immutable value (any thread may read it).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/motion.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

// One splat centre off the lattice. Sizes and opacities mean what a voxel's
// do: a particle of sizeWorld s draws exactly as a voxel of a grid with
// spacing s (no rotation) at the same centre, so a particle and a voxel of
// equal size and opacity carry the same material.
struct Particle {
    glm::vec3 position{0.0f};  // world units; default origin
    float sizeWorld = 0.1f;    // world length of one kernel unit (a voxel's spacing), > 0; default 0.1
    glm::vec3 velocity{0.0f};  // world units / s; stretches the kernel (ParticleStyle::stretchPerSpeed); default 0
    float opacity = 1.0f;      // [0, 1] as Voxel::opacity (clamped); default 1
    float colorCoord = 0.0f;   // [0, 1] into the style's colour table (e.g. age / lifetime); default 0
    std::uint32_t texture = 0; // texture index within the style's set; default 0
    float phase = 0.0f;        // [0, 1) cross-fade towards the next texture; default 0
    std::uint32_t id = 0;      // stable identity: seeds the texture's rotation and mirroring (SplatVariation); default 0
};

// A particle system evaluated in closed form (see the header comment).
// Object space is the Motion's (EffectDesc::motion); velocities, the
// acceleration and the wind are world vectors.
struct ParticleEmitterDesc {
    glm::vec3 position{0.0f};       // emitter box centre, object space; default origin
    glm::vec3 halfExtent{0.0f};     // births uniform in position +- halfExtent, >= 0; default a point
    float ratePerSec = 20.0f;       // births per second, >= 0 (0: host-fed only); default 20
    double startSec = 0.0;          // first birth slot; default 0
    double stopSec = 1e30;          // no births at or after it; default never
    glm::vec3 velocity{0, 1, 0};    // mean initial velocity, world units / s; default 1 up
    glm::vec3 velocitySpread{0.0f}; // + - uniform per axis, >= 0; default 0
    float lifetimeSec = 2.0f;       // >= 0 (0: nothing is ever alive); default 2
    float lifetimeJitter = 0.0f;    // lifetime * (1 - jitter * u), u uniform in [0, 1), [0, 1]; default 0
    glm::vec3 acceleration{0.0f};   // buoyancy / gravity, world units / s^2; default 0
    float dragPerSec = 0.0f;        // dv/dt = acceleration + drag * (wind - v), >= 0; default 0
    glm::vec3 wind{0.0f};           // world units / s; default 0
    float sizeWorld = 0.1f;         // kernel unit at birth, > 0; default 0.1
    float sizeEndWorld = 0.1f;      // ... at death (linear in age), > 0; default 0.1
    float opacity = 1.0f;           // peak opacity, [0, 1]; default 1
    float fadeIn = 0.05f;           // fraction of the life over which opacity ramps up, [0, 1]; default 0.05
    float fadeOut = 0.3f;           // fraction of the life over which it ramps down, [0, 1]; default 0.3
    float colorFrom = 0.0f;         // colour coordinate at birth, [0, 1]; default 0
    float colorTo = 1.0f;           // ... at death (linear in age), [0, 1]; default 1
    float texturesPerSec = 0.0f;    // local dynamics (sec. 3.3): textures cycled per second of age, [0, 1000]; default 0
    float stretchPerSpeed = 0.0f;   // ParticleStyle::stretchPerSpeed; default 0
    float maxStretch = 4.0f;        // ParticleStyle::maxStretch; default 4
    std::uint32_t seed = 1;         // default 1
    // Most particles alive at once: ratePerSec * lifetimeSec may not exceed
    // it (create fails, naming both), so a typo cannot allocate millions.
    // At most kMaxParticles; default 65536.
    std::uint32_t maxParticles = 65536;
};

// Hard ceiling on ParticleEmitterDesc::maxParticles and on the particles a
// host hands to Effect::setParticles: kMaxVoxels, the grid's own.
inline constexpr std::uint32_t kMaxParticles = 1u << 24;

// The message naming the first bad field of d ("ratePerSec must be finite and
// >= 0, got -1"), a flight reaching more than 1e18 world units from the
// origin (float positions), or a budget exceeded; empty when d is valid.
// `field` prefixes the names.
std::string checkParticleEmitter(const ParticleEmitterDesc& d, const std::string& field = "");

class ParticleEmitter {
public:
    // Fails on a bad field (checkParticleEmitter) or a memory budget the rate
    // and lifetime would exceed (maxParticles); the message names the fields.
    static Result<ParticleEmitter> create(const ParticleEmitterDesc& desc, const Motion& motion = {});

    // The particles alive at timeSec (finite), replacing `out`'s contents,
    // oldest first. Particle ids are birth indices.
    void particlesAt(double timeSec, std::vector<Particle>& out) const;
    // Most particles alive at any time (the budget create checked).
    std::uint64_t maxAlive() const;
    // Conservative world box of every particle centre alive in [t0, t1] (no
    // splat extent); empty when none can be.
    Aabb centerBounds(double t0, double t1) const;
    // Largest kernel size and stretch factor a particle can have.
    float maxSizeWorld() const;
    const ParticleEmitterDesc& desc() const { return mDesc; }
    const Motion& motion() const { return mMotion; }

    // Closed-form flight (exposed for tests): position and velocity after
    // `ageSec` of a particle born at x0 with velocity v0.
    static glm::dvec3 flightPosition(const ParticleEmitterDesc& d, glm::dvec3 x0, glm::dvec3 v0, double ageSec);
    static glm::dvec3 flightVelocity(const ParticleEmitterDesc& d, glm::dvec3 v0, double ageSec);

private:
    ParticleEmitter(const ParticleEmitterDesc& d, const Motion& m) : mDesc(d), mMotion(m) {}
    ParticleEmitterDesc mDesc;
    Motion mMotion;
};

} // namespace splatfx
