// ParticleEmitter: a particle system that is a pure function of time
// (particles.hpp). Particle n is born in slot n at startSec + (n + 1/2) / rate;
// everything else about it is drawn from hash(n, seed), and its flight under
// dv/dt = a + k (w - v) is integrated in closed form, so any frame is
// evaluated directly and a long step loses nothing.
#include "splatfx/particles.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>

#include "splatfx/dynamics.hpp" // hash32, hashUnit

namespace splatfx {
namespace {

constexpr std::uint32_t kParticleSalt = 0x9a71c1e5u; // apart from the other hashes of the same seed

// Farthest a particle may fly from the emitter's origin (checkParticleEmitter):
// a float position whose squared distance (the splat builder's) stays finite
// (3 * 10^36 < FLT_MAX), instead of infinite centres and bounds.
constexpr double kMaxReach = 1e18;

// kMaxTimeSec (effect_kind.hpp): no later time is evaluated by a Scene.
constexpr double kLatestSec = 262144.0;

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The draws of particle n: seven uniforms in [0, 1) and a texture index.
struct Draw {
    float u[8];
    std::uint32_t texture;
};
Draw drawParticle(std::uint64_t n, std::uint32_t seed) {
    Draw d;
    std::uint32_t h = hash32(hash32(seed ^ kParticleSalt) ^ std::uint32_t(n));
    h = hash32(h ^ std::uint32_t(n >> 32) * 0x85ebca6bu);
    for (float& u : d.u) {
        h = hash32(h + 0x9e3779b9u);
        u = hashUnit(h);
    }
    d.texture = hash32(h ^ 0x7e47u);
    return d;
}

// g(a) = (1 - e^{-k a}) / k and h(a) = (a - g(a)) / k, the coefficients of
// v0 and of the drift a + k w in the position; a and a^2 / 2 when k = 0.
// Both increase with a. expm1 keeps g exact when k a is small.
double flightG(double k, double a) { return k > 0.0 ? -std::expm1(-k * a) / k : a; }
double flightH(double k, double a) {
    if (!(k > 0.0)) return 0.5 * a * a;
    // (a - g) / k loses everything to cancellation when k a is small: its series.
    const double x = k * a;
    if (x < 1e-3) return a * a * (0.5 - x / 6.0 + x * x / 24.0);
    return (a - flightG(k, a)) / k;
}

} // namespace

std::string checkParticleEmitter(const ParticleEmitterDesc& d, const std::string& f) {
    auto num = [](double x) {
        char b[32];
        std::snprintf(b, sizeof b, "%g", x);
        return std::string(b);
    };
    auto vec = [](glm::vec3 v) {
        char b[96];
        std::snprintf(b, sizeof b, "(%g, %g, %g)", double(v.x), double(v.y), double(v.z));
        return std::string(b);
    };
    auto unit = [&](const char* name, float x) -> std::string {
        return x >= 0.0f && x <= 1.0f ? std::string() : f + name + " must be in [0, 1], got " + num(x);
    };
    if (!finite3(d.position)) return f + "position must be finite, got " + vec(d.position);
    if (!finite3(d.halfExtent) || glm::any(glm::lessThan(d.halfExtent, glm::vec3(0.0f))))
        return f + "halfExtent must be finite and >= 0, got " + vec(d.halfExtent);
    // Slot indices stay exact doubles (below 2^52) over [startSec, 2^18 s] at rates up to 10^9.
    if (!(d.ratePerSec >= 0.0f && d.ratePerSec <= 1e9f)) return f + "ratePerSec must be in [0, 1e9], got " + num(d.ratePerSec);
    if (!(std::abs(d.startSec) <= kLatestSec)) return f + "startSec must be in [-262144, 262144] s, got " + num(d.startSec);
    if (!(d.stopSec >= d.startSec)) return f + "stopSec must be >= startSec, got " + num(d.stopSec);
    if (!finite3(d.velocity)) return f + "velocity must be finite, got " + vec(d.velocity);
    if (!finite3(d.velocitySpread) || glm::any(glm::lessThan(d.velocitySpread, glm::vec3(0.0f))))
        return f + "velocitySpread must be finite and >= 0, got " + vec(d.velocitySpread);
    if (!(d.lifetimeSec >= 0.0f) || !std::isfinite(d.lifetimeSec)) return f + "lifetimeSec must be finite and >= 0, got " + num(d.lifetimeSec);
    for (std::string e : {unit("lifetimeJitter", d.lifetimeJitter), unit("opacity", d.opacity), unit("fadeIn", d.fadeIn), unit("fadeOut", d.fadeOut),
                          unit("colorFrom", d.colorFrom), unit("colorTo", d.colorTo)})
        if (!e.empty()) return e;
    if (!finite3(d.acceleration)) return f + "acceleration must be finite, got " + vec(d.acceleration);
    if (!(d.dragPerSec >= 0.0f) || !std::isfinite(d.dragPerSec)) return f + "dragPerSec must be finite and >= 0, got " + num(d.dragPerSec);
    if (!finite3(d.wind)) return f + "wind must be finite, got " + vec(d.wind);
    if (!(d.sizeWorld > 0.0f) || !std::isfinite(d.sizeWorld)) return f + "sizeWorld must be finite and > 0, got " + num(d.sizeWorld);
    if (!(d.sizeEndWorld > 0.0f) || !std::isfinite(d.sizeEndWorld)) return f + "sizeEndWorld must be finite and > 0, got " + num(d.sizeEndWorld);
    if (!(d.texturesPerSec >= 0.0f && d.texturesPerSec <= 1000.0f)) return f + "texturesPerSec must be in [0, 1000], got " + num(d.texturesPerSec);
    if (!(d.stretchPerSpeed >= 0.0f) || !std::isfinite(d.stretchPerSpeed))
        return f + "stretchPerSpeed must be finite and >= 0, got " + num(d.stretchPerSpeed);
    if (!(d.maxStretch >= 0.0f) || !std::isfinite(d.maxStretch)) return f + "maxStretch must be finite and >= 0, got " + num(d.maxStretch);
    // The flight's reach per axis stays well inside float range (positions are
    // floats; the splat builder squares them): at most kMaxReach from the origin.
    {
        const double g = flightG(d.dragPerSec, d.lifetimeSec), h = flightH(d.dragPerSec, d.lifetimeSec);
        const glm::dvec3 drift = glm::abs(glm::dvec3(d.acceleration) + double(d.dragPerSec) * glm::dvec3(d.wind));
        const glm::dvec3 reach = glm::abs(glm::dvec3(d.position)) + glm::dvec3(d.halfExtent) +
                                 (glm::abs(glm::dvec3(d.velocity)) + glm::dvec3(d.velocitySpread)) * g + drift * h;
        const double most = std::max({reach.x, reach.y, reach.z});
        if (!(most <= kMaxReach))
            return f + "velocity, acceleration and lifetimeSec reach " + num(most) + " world units from the origin, past " + num(kMaxReach) +
                   " (float positions); lower them";
    }
    if (d.maxParticles > kMaxParticles)
        return f + "maxParticles must be at most " + std::to_string(kMaxParticles) + ", got " + std::to_string(d.maxParticles);
    // The budget: at most ceil(rate * lifetime) slots are alive at once (births are 1 / rate apart).
    const double alive = std::ceil(double(d.ratePerSec) * double(d.lifetimeSec));
    if (alive > double(d.maxParticles))
        return f + "ratePerSec * lifetimeSec = " + (alive < 1e15 ? std::to_string(std::uint64_t(alive)) : num(alive)) +
               " particles alive at once exceeds maxParticles = " + std::to_string(d.maxParticles) +
               "; lower the rate or the lifetime, or raise maxParticles (at most " + std::to_string(kMaxParticles) + ")";
    return {};
}

Result<ParticleEmitter> ParticleEmitter::create(const ParticleEmitterDesc& desc, const Motion& motion) {
    if (std::string e = checkParticleEmitter(desc); !e.empty()) return makeError(e);
    return ParticleEmitter(desc, motion);
}

std::uint64_t ParticleEmitter::maxAlive() const { return std::uint64_t(std::ceil(double(mDesc.ratePerSec) * double(mDesc.lifetimeSec))); }

float ParticleEmitter::maxSizeWorld() const { return std::max(mDesc.sizeWorld, mDesc.sizeEndWorld); }

glm::dvec3 ParticleEmitter::flightPosition(const ParticleEmitterDesc& d, glm::dvec3 x0, glm::dvec3 v0, double age) {
    const double k = d.dragPerSec;
    // dv/dt = a + k (w - v): v relaxes towards the terminal velocity (a + k w) / k.
    const glm::dvec3 drift = glm::dvec3(d.acceleration) + k * glm::dvec3(d.wind);
    return x0 + v0 * flightG(k, age) + drift * flightH(k, age);
}

glm::dvec3 ParticleEmitter::flightVelocity(const ParticleEmitterDesc& d, glm::dvec3 v0, double age) {
    const double k = d.dragPerSec;
    const glm::dvec3 drift = glm::dvec3(d.acceleration) + k * glm::dvec3(d.wind);
    // dg/da = e^{-k a}, dh/da = g(a).
    return v0 * std::exp(-k * age) + drift * flightG(k, age);
}

void ParticleEmitter::particlesAt(double t, std::vector<Particle>& out) const {
    out.clear();
    const ParticleEmitterDesc& d = mDesc;
    if (!std::isfinite(t) || !(d.ratePerSec > 0.0f) || !(d.lifetimeSec > 0.0f)) return;
    const double rate = d.ratePerSec, life = d.lifetimeSec;
    // Slot n is born at b(n) = startSec + (n + 1/2) / rate and alive while
    // b(n) <= t < b(n) + its lifetime (<= life): n in [t - life - start, t - start] * rate - 1/2.
    const double last = std::min(std::floor((t - d.startSec) * rate - 0.5), std::ceil((d.stopSec - d.startSec) * rate - 0.5) - 1.0);
    const double first = std::max(std::ceil((t - life - d.startSec) * rate - 0.5), 0.0);
    if (!(last >= first)) return;
    // Far past kLatestSec slot indices stop being exact doubles (and the loop would not advance).
    if (!(last < 0x1p52)) return;
    out.reserve(std::size_t(last - first + 1.0));
    // A motion at rest places every birth alike: its matrix once, not per particle.
    const bool still = mMotion.isStatic();
    const Pose rest = still ? mMotion.sample(0.0) : Pose{};
    const glm::mat4 restMatrix = rest.matrix();
    for (double nf = first; nf <= last; nf += 1.0) {
        const std::uint64_t n = std::uint64_t(nf);
        const double birth = d.startSec + (nf + 0.5) / rate;
        if (birth > t || birth >= d.stopSec) continue; // the bounds above are exact in theory; rounding is checked here
        const Draw r = drawParticle(n, d.seed);
        const double lifetime = life * (1.0 - double(d.lifetimeJitter) * r.u[0]);
        const double age = t - birth;
        if (!(age < lifetime)) continue;
        const Pose pose = still ? rest : mMotion.sample(birth); // the emitter where the particle was born; it then flies free
        const glm::vec3 local = d.position + d.halfExtent * glm::vec3(2.0f * r.u[1] - 1.0f, 2.0f * r.u[2] - 1.0f, 2.0f * r.u[3] - 1.0f);
        const glm::dvec3 x0 = glm::dvec3((still ? restMatrix : pose.matrix()) * glm::vec4(local, 1.0f));
        const glm::dvec3 v0 =
            glm::dvec3(d.velocity + d.velocitySpread * glm::vec3(2.0f * r.u[4] - 1.0f, 2.0f * r.u[5] - 1.0f, 2.0f * r.u[6] - 1.0f));
        const double x = age / lifetime; // [0, 1)
        Particle p;
        p.position = glm::vec3(flightPosition(d, x0, v0, age));
        p.velocity = glm::vec3(flightVelocity(d, v0, age));
        p.sizeWorld = float(d.sizeWorld + (d.sizeEndWorld - d.sizeWorld) * x);
        // Opacity over life: linear ramps over the first fadeIn and last fadeOut of it, scaled by the pose's fade.
        double env = 1.0;
        if (d.fadeIn > 0.0f) env = std::min(env, x / d.fadeIn);
        if (d.fadeOut > 0.0f) env = std::min(env, (1.0 - x) / d.fadeOut);
        p.opacity = float(std::clamp(env, 0.0, 1.0) * d.opacity * std::max(pose.opacity, 0.0f));
        p.colorCoord = float(d.colorFrom + (d.colorTo - d.colorFrom) * x);
        // Local dynamics (sec. 3.3): the particle's texture cycles with its age from a random start.
        const double cycle = age * d.texturesPerSec + r.u[7];
        const double whole = std::floor(cycle);
        p.texture = r.texture + std::uint32_t(std::fmod(whole, 4294967296.0));
        p.phase = float(cycle - whole);
        p.id = std::uint32_t(n) ^ std::uint32_t(n >> 32);
        out.push_back(p);
    }
}

Aabb ParticleEmitter::centerBounds(double t0, double t1) const {
    if (t1 < t0) std::swap(t0, t1);
    const ParticleEmitterDesc& d = mDesc;
    if (!(d.ratePerSec > 0.0f) || !(d.lifetimeSec > 0.0f)) return {};
    // Births that can be alive in [t0, t1]: in [t0 - life, t1] and [startSec, stopSec].
    const double b0 = std::max(t0 - double(d.lifetimeSec), d.startSec), b1 = std::min(t1, d.stopSec);
    if (!(b1 >= b0)) return {};
    const Aabb births = mMotion.sweep(Aabb{d.position - d.halfExtent, d.position + d.halfExtent}, b0, b1);
    // Displacement v0 g(a) + drift h(a) with g in [0, g(life)], h in [0, h(life)],
    // v0 per axis in velocity +- spread: each term's range includes 0.
    const double k = d.dragPerSec, gMax = flightG(k, d.lifetimeSec), hMax = flightH(k, d.lifetimeSec);
    const glm::dvec3 drift = glm::dvec3(d.acceleration) + k * glm::dvec3(d.wind);
    const glm::dvec3 vLo = glm::dvec3(d.velocity - d.velocitySpread), vHi = glm::dvec3(d.velocity + d.velocitySpread);
    glm::dvec3 lo(0.0), hi(0.0);
    for (int i = 0; i < 3; ++i) {
        lo[i] = std::min(0.0, vLo[i] * gMax) + std::min(0.0, drift[i] * hMax);
        hi[i] = std::max(0.0, vHi[i] * gMax) + std::max(0.0, drift[i] * hMax);
    }
    // Float rounding of the positions particlesAt computes: a relative 1e-5 of the reach, plus 1e-5.
    Aabb out = births.plus(Aabb{glm::vec3(lo), glm::vec3(hi)});
    const float slack = 1e-5f * (glm::length(out.hi - out.lo) + glm::length(out.hi) + glm::length(out.lo)) + 1e-5f;
    return out.expanded(slack);
}

} // namespace splatfx
