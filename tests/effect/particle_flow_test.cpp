// Particles carried by a solver's velocity field (FlowParticles, King et al.
// 1999, sec. 6): against a path integrated by hand in a constant field, and
// deterministic in a simulated one.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/effect.hpp"
#include "splatfx/particle_flow.hpp"

namespace splatfx {
namespace {

TEST(FlowParticles, AConstantFieldCarriesEveryParticleFromItsBirthPointAtTheFieldsWorldVelocity) {
    // Grid-local velocity v everywhere; the grid scaled by 2 and moved: world velocity W = 2 v.
    // By hand: a particle born at b at the emitter's point x0 is at x0 + W (t - b) at t (the field is
    // constant, so the path is a straight line whatever the steps). The emitter's own flight
    // (velocity 5 up, gravity) must not enter. Tolerance: each of the 60 float steps rounds the position
    // (|x| < 8) to half an ulp, 4.8e-7, twice (midpoint and end): 60 * 1e-6 = 6e-5, so 1e-4.
    auto solver = FluidSolver::create({.dims = {6, 8, 6}, .spacing = glm::vec3(0.5f)});
    ASSERT_TRUE(solver) << solver.error();
    const glm::vec3 v(0.3f, 1.0f, -0.2f);
    solver->setUniformVelocity(v);
    const glm::mat4 gridToWorld = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(1, 2, 3)), glm::vec3(2.0f));
    const glm::vec3 W = glm::mat3(gridToWorld) * v;
    const glm::vec3 x0(0.5f, 1.0f, -0.5f);
    const ParticleEmitter e = *ParticleEmitter::create({.position = x0, .ratePerSec = 10, .velocity = {0, 5, 0}, .lifetimeSec = 3,
                                                        .acceleration = {0, -9.81f, 0}, .texturesPerSec = 2});
    FlowParticles flow(e);
    for (int f = 0; f <= 60; ++f) flow.advanceTo(f / 24.0, *solver, gridToWorld);
    const double t = 60 / 24.0;
    std::vector<Particle> closed;
    e.particlesAt(t, closed);
    ASSERT_EQ(flow.particles().size(), closed.size());
    ASSERT_EQ(flow.particles().size(), 25u); // births 0.05 ... 2.45
    for (std::size_t i = 0; i < closed.size(); ++i) {
        const Particle& p = flow.particles()[i];
        ASSERT_EQ(p.id, closed[i].id);
        const double age = t - (p.id + 0.5) / 10.0;
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(p.position[a], x0[a] + W[a] * age, 1e-4) << "particle " << p.id << " axis " << a;
            // Trilinear weights summing to 1 times v, then the 3x3: a few float ulps of |W| <= 2.1.
            EXPECT_NEAR(p.velocity[a], W[a], 4e-6f);
        }
        // Appearance is the emitter's, a function of age: the same as its closed-form particle.
        EXPECT_EQ(p.texture, closed[i].texture);
        EXPECT_EQ(p.opacity, closed[i].opacity);
        EXPECT_EQ(p.sizeWorld, closed[i].sizeWorld);
        EXPECT_EQ(p.colorCoord, closed[i].colorCoord);
    }
}

TEST(FlowParticles, TheFlowOfASimulatedPlumeIsFollowedTheSameWayTwice) {
    // A buoyant plume (solver steps and particles advanced together): the same inputs give the same
    // particles bit for bit, and they rise with the plume (the flow at the source points up).
    auto make = [] {
        auto s = FluidSolver::create({.dims = {8, 12, 8}, .spacing = glm::vec3(0.25f)});
        EXPECT_TRUE(s) << s.error();
        s->addEmitter({.desc = {.offset = {0.0f, 0.4f, 0.0f}, .radius = 0.4f, .density = 1.0f, .temperature = 2.0f}});
        return std::move(*s);
    };
    FluidSolver a = make(), b = make();
    const ParticleEmitter e = *ParticleEmitter::create({.position = {0, 0.4f, 0}, .halfExtent = {0.2f, 0.1f, 0.2f}, .ratePerSec = 30, .lifetimeSec = 2});
    FlowParticles fa(e), fb(e);
    const glm::mat4 m(1.0f);
    for (int f = 1; f <= 36; ++f) {
        a.step(1.0 / 24.0), b.step(1.0 / 24.0);
        fa.advanceTo(f / 24.0, a, m), fb.advanceTo(f / 24.0, b, m);
    }
    ASSERT_EQ(fa.particles().size(), fb.particles().size());
    ASSERT_GT(fa.particles().size(), 30u);
    double rise = 0.0;
    for (std::size_t i = 0; i < fa.particles().size(); ++i) {
        EXPECT_EQ(fa.particles()[i].position, fb.particles()[i].position);
        EXPECT_TRUE(std::isfinite(fa.particles()[i].position.y));
        rise += fa.particles()[i].position.y - 0.4;
    }
    EXPECT_GT(rise / double(fa.particles().size()), 0.05) << "the plume's flow carries its particles up";
}

} // namespace
} // namespace splatfx
