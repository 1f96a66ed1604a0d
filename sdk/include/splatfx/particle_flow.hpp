// splatfx/particle_flow.hpp: particles carried by a solver's velocity field.
//
// King et al. 1999, sec. 6: particle systems "as a control for the object
// dynamics". A ParticleEmitter (particles.hpp) decides who is alive and how
// each looks: births on its slot clock at a point of its box, lifetime, size,
// opacity, colour and texture cycling, all functions of age. FlowParticles
// keeps that and replaces the emitter's closed-form flight with the flow of a
// FluidSolver (solver.hpp): each particle moves by a midpoint (RK2) step
// through the solver's staggered velocity, trilinear between its faces, per
// advance; a newborn moves from its birth point over its age. The emitter's
// velocity, spread, acceleration, drag and wind are not used.
//
// Stateful (positions are integrated step by step) and deterministic: the same
// emitter, solver states and times give the same particles, bit for bit.
// Outside the solver's grid a particle sees the nearest boundary's velocity.
// Particles are matched between advances by id, so births must stay below
// 2^32 slots (ids are then the slot indices: 1000 a second for 49 days).
// Draw them through an Effect::fromParticles with ratePerSec 0
// (Effect::setParticles) or SplatBuilder::add.
//
//   splatfx::FlowParticles flow(*splatfx::ParticleEmitter::create(desc));
//   per frame: solver.step(dt); flow.advanceTo(t, solver, gridToWorld);
//              sparks.setParticles(flow.particles());
//
// Threading: one writer (advanceTo); particles() may be read between calls.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "splatfx/particles.hpp"
#include "splatfx/solver.hpp"

namespace splatfx {

class FlowParticles {
public:
    explicit FlowParticles(const ParticleEmitter& emitter);

    // Brings the particles to timeSec (finite; a time not after the last
    // advance changes nothing): the ones alive before move by one midpoint
    // step of timeSec - the last time, newborns by one step of their age from
    // their birth point. gridToWorld maps the solver's grid-local units to
    // world (the solver effect's transform; its velocities are grid-local).
    void advanceTo(double timeSec, const FluidSolver& solver, const glm::mat4& gridToWorld);
    // The particles alive at the last advance, oldest first; velocity is the
    // flow's at the particle (it stretches the kernel as the emitter's would).
    const std::vector<Particle>& particles() const { return mParticles; }
    double time() const { return mTime; }

    // World velocity of the solver's flow at a world point (trilinear between
    // the staggered faces, clamped to the grid).
    static glm::vec3 flowVelocity(const FluidSolver& solver, const glm::mat4& gridToWorld, glm::vec3 world);

private:
    ParticleEmitter mBirths; // the emitter with no flight: every particle at its birth point
    std::vector<Particle> mParticles, mNow;
    double mTime = 0.0;
    bool mStarted = false;
};

} // namespace splatfx
