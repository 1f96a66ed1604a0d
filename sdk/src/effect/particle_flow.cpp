// FlowParticles (particle_flow.hpp): the emitter's particles carried by a
// solver's velocity field instead of their closed-form flight.
#include "splatfx/particle_flow.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace splatfx {
namespace {

// The same emitter with no flight: particlesAt gives each particle at its
// birth point (the birth draws do not depend on the flight fields).
ParticleEmitter withoutFlight(const ParticleEmitter& e) {
    ParticleEmitterDesc d = e.desc();
    d.velocity = glm::vec3(0.0f);
    d.velocitySpread = glm::vec3(0.0f);
    d.acceleration = glm::vec3(0.0f);
    d.dragPerSec = 0.0f;
    d.wind = glm::vec3(0.0f);
    Result<ParticleEmitter> r = ParticleEmitter::create(d, e.motion());
    assert(r && "FlowParticles: an emitter valid with a flight is valid without one");
    return r ? std::move(*r) : e;
}

// Grid-local velocity at p in cell coordinates (cell centres at integers):
// each component trilinear between its faces, face i along the axis at i - 1/2.
glm::vec3 velocityInCells(const FluidSolver& s, glm::vec3 p) {
    const glm::ivec3 dims = s.dims();
    glm::vec3 v(0.0f);
    for (int a = 0; a < 3; ++a) {
        glm::ivec3 fd = dims;
        fd[a] += 1;
        glm::vec3 q = p;
        q[a] += 0.5f;
        q = glm::clamp(q, glm::vec3(0.0f), glm::vec3(fd - 1));
        const glm::ivec3 i0 = glm::min(glm::ivec3(glm::floor(q)), fd - 1), i1 = glm::min(i0 + 1, fd - 1);
        const glm::vec3 f = q - glm::vec3(i0);
        float sum = 0.0f;
        for (int c = 0; c < 8; ++c) {
            const glm::ivec3 i((c & 1) ? i1.x : i0.x, (c & 2) ? i1.y : i0.y, (c & 4) ? i1.z : i0.z);
            const float w = ((c & 1) ? f.x : 1.0f - f.x) * ((c & 2) ? f.y : 1.0f - f.y) * ((c & 4) ? f.z : 1.0f - f.z);
            if (w != 0.0f) sum += w * s.faceVelocity(a, i);
        }
        v[a] = sum;
    }
    return v;
}

// World velocity at a world point; toLocal = inverse(gridToWorld), toWorld = its 3x3.
glm::vec3 worldVelocity(const FluidSolver& s, const glm::mat4& toLocal, const glm::mat3& toWorld, glm::vec3 world) {
    const glm::vec3 local = glm::vec3(toLocal * glm::vec4(world, 1.0f));
    return toWorld * velocityInCells(s, (local - s.localPosition(glm::ivec3(0))) / s.desc().spacing);
}

} // namespace

FlowParticles::FlowParticles(const ParticleEmitter& emitter) : mBirths(withoutFlight(emitter)) {}

glm::vec3 FlowParticles::flowVelocity(const FluidSolver& s, const glm::mat4& gridToWorld, glm::vec3 world) {
    return worldVelocity(s, glm::inverse(gridToWorld), glm::mat3(gridToWorld), world);
}

void FlowParticles::advanceTo(double t, const FluidSolver& solver, const glm::mat4& gridToWorld) {
    if (!std::isfinite(t) || (mStarted && !(t > mTime))) return;
    const double dt = mStarted ? t - mTime : 0.0;
    const ParticleEmitterDesc& d = mBirths.desc();
    const glm::mat4 toLocal = glm::inverse(gridToWorld);
    const glm::mat3 toWorld(gridToWorld);
    auto flow = [&](glm::vec3 world) { return worldVelocity(solver, toLocal, toWorld, world); };
    // One midpoint step: exact in a constant field, second order in a smooth one.
    auto move = [&](glm::vec3 x, double h) {
        const float hf = float(h);
        const glm::vec3 mid = x + 0.5f * hf * flow(x);
        return x + hf * flow(mid);
    };
    mBirths.particlesAt(t, mNow); // oldest first: ids ascending, as mParticles
    std::size_t j = 0;
    for (Particle& p : mNow) {
        while (j < mParticles.size() && mParticles[j].id < p.id) ++j; // died since
        if (j < mParticles.size() && mParticles[j].id == p.id) {
            p.position = move(mParticles[j].position, dt);
        } else {
            // Born since the last advance (or before the first): from its birth point over its age.
            const double birth = d.startSec + (double(p.id) + 0.5) / double(d.ratePerSec);
            p.position = move(p.position, std::max(t - birth, 0.0));
        }
        p.velocity = flow(p.position);
    }
    std::swap(mParticles, mNow);
    mTime = t;
    mStarted = true;
}

} // namespace splatfx
