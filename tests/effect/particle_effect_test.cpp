// Splats at particle positions (King et al. 1999, sec. 6): the closed-form
// emitter against independent integrations and counts, the particle effect's
// bounds and scheduling, and particles in the grid's one sorted splat list.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/effect.hpp"
#include "splatfx/particles.hpp"
#include "splatfx/splats.hpp"

namespace splatfx {
namespace {

// Float rounding of a position computed in double and stored in float, after
// the pose matrix (a float 4x4 product, 3 roundings per component): a few
// ulps of the largest magnitude involved. 8 ulps covers it with room.
float floatSlack(float magnitude) { return 8.0f * std::ldexp(std::max(magnitude, 1.0f), -23); }

std::vector<Particle> at(const ParticleEmitter& e, double t) {
    std::vector<Particle> out;
    e.particlesAt(t, out);
    return out;
}

TEST(ParticleEmitter, SameSeedGivesTheSameParticlesAndAnotherSeedOthers) {
    ParticleEmitterDesc d{.halfExtent = {0.3f, 0.1f, 0.3f}, .ratePerSec = 50, .velocitySpread = {0.5f, 0.2f, 0.5f}, .lifetimeSec = 1.5f,
                          .lifetimeJitter = 0.4f, .texturesPerSec = 5, .seed = 7};
    const ParticleEmitter a = *ParticleEmitter::create(d), b = *ParticleEmitter::create(d);
    // Evaluated in a different order: stateless, so it cannot matter.
    const std::vector<Particle> b2 = at(b, 2.0), b1 = at(b, 1.25), a1 = at(a, 1.25), a2 = at(a, 2.0);
    ASSERT_GT(a1.size(), 30u);
    ASSERT_EQ(a1.size(), b1.size());
    ASSERT_EQ(a2.size(), b2.size());
    for (std::size_t i = 0; i < a1.size(); ++i) {
        EXPECT_EQ(a1[i].position, b1[i].position);
        EXPECT_EQ(a1[i].velocity, b1[i].velocity);
        EXPECT_EQ(a1[i].texture, b1[i].texture);
        EXPECT_EQ(a1[i].id, b1[i].id);
    }
    d.seed = 8;
    const std::vector<Particle> c1 = at(*ParticleEmitter::create(d), 1.25);
    int differ = 0;
    for (std::size_t i = 0; i < std::min(a1.size(), c1.size()); ++i) differ += a1[i].position != c1[i].position;
    EXPECT_GT(differ, int(a1.size()) / 2) << "another seed must draw other particles";
}

TEST(ParticleEmitter, ConstantVelocityFliesInAStraightLineFromItsBirthSlot) {
    // Birth of slot n at (n + 1/2) / rate; no forces: x = p + v (t - birth).
    const ParticleEmitterDesc d{.position = {1, 2, 3}, .ratePerSec = 10, .velocity = {0.5f, 2.0f, -1.0f}, .lifetimeSec = 3};
    const ParticleEmitter e = *ParticleEmitter::create(d);
    const double t = 4.37;
    const std::vector<Particle> ps = at(e, t);
    ASSERT_EQ(ps.size(), 30u); // births 1.45, 1.55, ..., 4.35 in (t - 3, t]
    for (const Particle& p : ps) {
        const double birth = (p.id + 0.5) / 10.0;
        const glm::dvec3 want = glm::dvec3(1, 2, 3) + glm::dvec3(0.5, 2.0, -1.0) * (t - birth);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(p.position[i], want[i], floatSlack(12.0f)) << "particle " << p.id;
        EXPECT_EQ(p.velocity, d.velocity);
    }
}

TEST(ParticleEmitter, BuoyancyAndDragMatchAnIndependentIntegration) {
    // dv/dt = a + k (w - v), integrated by classical RK4 here with h = 1e-3 s
    // over 2 s: the global error is O(h^4) times the derivatives' scale
    // (about 1e-12 here), so the closed form must agree to 1e-9.
    for (float k : {0.0f, 0.7f, 1e-6f}) {
        const ParticleEmitterDesc d{.acceleration = {0.2f, 3.0f, 0.0f}, .dragPerSec = k, .wind = {1.0f, 0.0f, -0.5f}};
        const glm::dvec3 x0(0.1, 0.2, 0.3), v0(-0.4, 1.0, 0.25);
        const glm::dvec3 a(d.acceleration), w(d.wind);
        auto f = [&](glm::dvec3 v) { return a + double(k) * (w - v); };
        glm::dvec3 x = x0, v = v0;
        const double h = 1e-3;
        for (int i = 0; i < 2000; ++i) {
            const glm::dvec3 k1v = f(v), k1x = v;
            const glm::dvec3 k2v = f(v + 0.5 * h * k1v), k2x = v + 0.5 * h * k1v;
            const glm::dvec3 k3v = f(v + 0.5 * h * k2v), k3x = v + 0.5 * h * k2v;
            const glm::dvec3 k4v = f(v + h * k3v), k4x = v + h * k3v;
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        }
        const glm::dvec3 cx = ParticleEmitter::flightPosition(d, x0, v0, 2.0), cv = ParticleEmitter::flightVelocity(d, v0, 2.0);
        for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(cx[i], x[i], 1e-9) << "k " << k << " axis " << i;
            EXPECT_NEAR(cv[i], v[i], 1e-9) << "k " << k << " axis " << i;
        }
    }
    // Without drag it is the parabola x0 + v0 t + a t^2 / 2 exactly.
    const ParticleEmitterDesc g{.acceleration = {0.0f, -9.81f, 0.0f}};
    EXPECT_NEAR(ParticleEmitter::flightPosition(g, {0, 0, 0}, {1, 5, 0}, 1.5).y, 5.0 * 1.5 - 0.5 * 9.81f * 2.25, 1e-12);
}

TEST(ParticleEmitter, BirthAndDeathCountsFollowTheSlots) {
    // Slots 1/rate apart: alive at t are the births in (t - life, t] within [start, stop).
    const ParticleEmitter e = *ParticleEmitter::create({.ratePerSec = 10, .startSec = 1.0, .stopSec = 3.0, .lifetimeSec = 1.0});
    EXPECT_EQ(at(e, 0.9).size(), 0u);  // before the first slot (1.05)
    EXPECT_EQ(at(e, 1.07).size(), 1u); // 1.05
    EXPECT_EQ(at(e, 2.5).size(), 10u); // 1.55 ... 2.45
    EXPECT_EQ(at(e, 3.5).size(), 5u);  // 2.55 ... 2.95: no births from stopSec on
    EXPECT_EQ(at(e, 3.96).size(), 0u); // the last (2.95) died at 3.95
    const std::vector<Particle> ps = at(e, 2.5);
    EXPECT_EQ(ps.front().id, 5u); // slot n is born at 1 + (n + 1/2) / 10: 1.55 is slot 5
    EXPECT_EQ(ps.back().id, 14u);
    EXPECT_EQ(e.maxAlive(), 10u);
}

TEST(ParticleEmitter, LateTimesKeepTheBirthSlotsExact) {
    // Near kMaxTimeSec at 1000 births a second the slot index passes 2^28: the
    // birth times (double) still fall 1 ms apart, so exactly rate * life are alive.
    const ParticleEmitter e = *ParticleEmitter::create({.ratePerSec = 1000, .velocity = {0, 1, 0}, .lifetimeSec = 0.25f});
    const double t = kMaxTimeSec - 0.1234;
    const std::vector<Particle> ps = at(e, t);
    EXPECT_EQ(ps.size(), 250u);
    for (const Particle& p : ps) {
        EXPECT_TRUE(std::isfinite(p.position.y));
        EXPECT_GE(p.position.y, -1e-3f);
        EXPECT_LE(p.position.y, 0.25f + 1e-3f); // |v| * lifetime, plus float rounding of the age (t ~ 2^18: 2^-34 s) and position
    }
}

TEST(ParticleEmitter, TexturesCycleWithAgeAndColourAndSizeFollowTheLife) {
    // Local dynamics (sec. 3.3) per particle: texture + phase advance by
    // texturesPerSec * age, so 0.5 s later the same particle is 2 textures on.
    const ParticleEmitterDesc d{.ratePerSec = 4, .lifetimeSec = 2, .sizeWorld = 0.1f, .sizeEndWorld = 0.3f, .colorFrom = 0.2f, .colorTo = 0.8f,
                                .texturesPerSec = 4};
    const ParticleEmitter e = *ParticleEmitter::create(d);
    const std::vector<Particle> a = at(e, 3.0), b = at(e, 3.5);
    int matched = 0;
    for (const Particle& p : a)
        for (const Particle& q : b)
            if (p.id == q.id) {
                ++matched;
                EXPECT_EQ(q.texture - p.texture, 2u) << "particle " << p.id;
                EXPECT_NEAR(q.phase, p.phase, 1e-5f);
                const double age = 3.5 - (q.id + 0.5) / 4.0; // closed form of the life fraction
                EXPECT_NEAR(q.colorCoord, 0.2 + 0.6 * age / 2.0, 1e-6);
                EXPECT_NEAR(q.sizeWorld, 0.1 + 0.2 * age / 2.0, 1e-6);
            }
    EXPECT_GE(matched, 5);
}

TEST(ParticleEmitter, BadFieldsAndTheParticleBudgetAreNamed) {
    auto err = [](const ParticleEmitterDesc& d) {
        auto r = ParticleEmitter::create(d);
        return r ? std::string() : r.error();
    };
    EXPECT_NE(err({.ratePerSec = -1}).find("ratePerSec must be in [0, 1e9], got -1"), std::string::npos);
    EXPECT_NE(err({.ratePerSec = std::numeric_limits<float>::quiet_NaN()}).find("ratePerSec"), std::string::npos);
    EXPECT_NE(err({.velocity = {0, std::numeric_limits<float>::quiet_NaN(), 0}}).find("velocity must be finite"), std::string::npos);
    EXPECT_NE(err({.sizeWorld = 0}).find("sizeWorld must be finite and > 0"), std::string::npos);
    const std::string bomb = err({.ratePerSec = 1e9f, .lifetimeSec = 10});
    EXPECT_NE(bomb.find("exceeds maxParticles = 65536"), std::string::npos) << bomb;
    EXPECT_NE(err({.maxParticles = kMaxParticles + 1}).find("maxParticles must be at most"), std::string::npos);
    // 10^30 a second living 10^-30 s passes the budget (one alive) but its slot indices would
    // leave the exact doubles (and the loop over them stall): refused by the rate's range.
    EXPECT_NE(err({.ratePerSec = 1e30f, .lifetimeSec = 1e-30f}).find("ratePerSec must be in [0, 1e9]"), std::string::npos);
    EXPECT_NE(err({.startSec = -1e30}).find("startSec must be in [-262144, 262144] s"), std::string::npos);
}

// The Splat the builder makes of one voxel, and of a particle put at the
// voxel's centre with the voxel's spacing, opacity, colour and texture.
TEST(ParticleSplats, AParticleAtAVoxelCentreDrawsAsThatVoxel) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::fire());
    const Camera cam = Camera::lookAt({0.7f, 1.1f, 5.0f}, {0, 0.5f, 0}, {0, 1, 0}, 0.9f, {64, 48});
    Grid g;
    g.spacing = glm::vec3(0.4f);
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(0.3f, 0.6f, -0.2f));
    g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.45f, .colorCoord = 0.3f, .stretch = {0.0f, 0.8f, 0.0f}});
    const glm::vec3 centre = g.worldPosition({0, 0, 0});
    // Voxel::stretch is in lattice units; the particle's comes from its velocity: 0.8 = 1.6 * 0.5 s.
    const Particle p{.position = centre, .sizeWorld = 0.4f, .velocity = {0.0f, 1.6f, 0.0f}, .opacity = 0.45f, .colorCoord = 0.3f};
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    b.add(std::span<const Particle>(&p, 1), mat, {.splat = {.textured = false}, .stretchPerSpeed = 0.5f});
    ASSERT_EQ(b.splats().size(), 2u);
    const Splat &v = b.splats()[0], &q = b.splats()[1];
    // Same math in float from the same inputs through different roundings of the
    // centre (lattice product vs the particle's translation): a few ulps.
    const float tol = floatSlack(6.0f);
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(q.center[i], v.center[i], tol);
        EXPECT_NEAR(q.axisU[i], v.axisU[i], tol);
        EXPECT_NEAR(q.axisV[i], v.axisV[i], tol);
    }
    EXPECT_NEAR(q.density, v.density, 1e-5f * v.density);
    EXPECT_NEAR(q.depth, v.depth, tol);
    EXPECT_EQ(q.color & 0x00ffffffu, v.color & 0x00ffffffu);
    EXPECT_NEAR(rayScaleRho(std::uint8_t(q.color >> 24)), rayScaleRho(std::uint8_t(v.color >> 24)), 0.012f); // one 1.1 % code step
}

TEST(ParticleSplats, AParticleBetweenTwoVoxelsInDepthIsSortedBetweenThem) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::constant({1, 1, 1, 1}));
    const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.9f, {64, 48});
    Grid g; // two voxels on the view axis at view depths 2 and 6
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -2));
    g.voxels = {{.cell = {0, 0, 0}, .opacity = 0.5f}, {.cell = {0, 0, -4}, .opacity = 0.5f}};
    const std::vector<Particle> ps = {{.position = {0.01f, 0, -4}, .sizeWorld = 1.0f, .opacity = 0.5f, .id = 1},
                                      {.position = {0, 0.01f, -7}, .sizeWorld = 1.0f, .opacity = 0.5f, .id = 2}};
    SplatBuilder b;
    b.begin(cam);
    b.add(ps, mat, {.splat = {.textured = false}}); // particles first: only the sort can interleave them
    b.add(g, mat, {.textured = false});
    b.sort(SortMode::Exact);
    ASSERT_EQ(b.splats().size(), 4u);
    std::vector<float> depths;
    for (const Splat& s : b.splats()) depths.push_back(s.depth);
    EXPECT_NEAR(depths[0], 7.0f, 1e-4f); // particle 2, farthest
    EXPECT_NEAR(depths[1], 6.0f, 1e-4f); // voxel
    EXPECT_NEAR(depths[2], 4.0f, 1e-4f); // particle 1: between the voxels
    EXPECT_NEAR(depths[3], 2.0f, 1e-4f); // voxel
}

TEST(ParticleSplats, BehindTheEyeIsCulledTheNearPlaneKeptAndABadHostParticleDroppedAlone) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::constant({1, 1, 1, 1}));
    const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.9f, {64, 48});
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<Particle> ps = {
        {.position = {0, 0, 3}, .sizeWorld = 0.2f},                    // behind the eye, wholly
        {.position = {0, 0, -cam.nearPlane()}, .sizeWorld = 0.2f},     // centred on the near plane: kept (the depth cut shares it)
        {.position = {0, 0, -3}, .sizeWorld = 0.2f, .velocity = {nan, 0, 0}}, // a host's NaN velocity
        {.position = {0, 0, -3}, .sizeWorld = -1.0f},                  // a negative size
        {.position = {0.2f, 0, -3}, .sizeWorld = 0.2f, .velocity = {1, 0, 0}},
    };
    SplatBuilder b;
    b.begin(cam);
    b.add(ps, mat, {.splat = {.textured = false}, .stretchPerSpeed = 0.3f});
    EXPECT_EQ(b.stats().voxelsIn, 5u);
    EXPECT_EQ(b.stats().culled, 1u);
    EXPECT_EQ(b.stats().rejected, 2u);
    ASSERT_EQ(b.splats().size(), 2u);
    for (const Splat& s : b.splats()) EXPECT_TRUE(std::isfinite(s.density) && std::isfinite(s.axisU.x) && std::isfinite(s.axisV.y));
}

Effect embers(ParticleEmitterDesc d = {}, EffectDesc e = {}) {
    e.name = "embers";
    auto r = Effect::fromParticles(d, e);
    EXPECT_TRUE(r) << r.error();
    return std::move(*r);
}

TEST(ParticleEffect, BoundsHoldEverySplatOverTheInterval) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::fire());
    EffectDesc e;
    e.motion = Motion({{.timeSec = 0, .pose = {.position = {-1, 0, 0}}}, {.timeSec = 3, .pose = {.position = {2, 0.5f, 0}}}});
    Effect fx = embers({.halfExtent = {0.4f, 0.1f, 0.4f}, .ratePerSec = 40, .velocity = {0, 1.5f, 0}, .velocitySpread = {0.6f, 0.5f, 0.6f},
                        .lifetimeSec = 1.2f, .lifetimeJitter = 0.5f, .acceleration = {0, 1.0f, 0}, .dragPerSec = 0.8f, .wind = {0.7f, 0, 0},
                        .sizeWorld = 0.05f, .sizeEndWorld = 0.12f, .stretchPerSpeed = 0.2f, .maxStretch = 2.0f},
                       e);
    const Aabb box = fx.bounds(0.5, 2.5);
    ASSERT_FALSE(box.empty());
    const Camera cam = Camera::lookAt({0.5f, 1, 8}, {0.5f, 1, 0}, {0, 1, 0}, 1.2f, {64, 48});
    SplatBuilderDesc bd;
    bd.frustumCull = false;
    SplatBuilder b(bd);
    std::size_t seen = 0;
    for (double t = 0.5; t <= 2.5; t += 0.05) {
        fx.update(t);
        b.begin(cam);
        fx.emit(b, mat, {.textured = false});
        for (const Splat& s : b.splats())
            for (float su : {-1.0f, 1.0f})
                for (float sv : {-1.0f, 1.0f}) {
                    ++seen;
                    const glm::vec3 corner = s.center + su * s.axisU + sv * s.axisV;
                    ASSERT_TRUE(box.contains(corner)) << "t " << t << " corner " << corner.x << "," << corner.y << "," << corner.z;
                }
    }
    EXPECT_GT(seen, 1000u);
    EXPECT_TRUE(fx.bounds(10.0, 10.0).empty() == false); // the emitter never stops: material still there
}

TEST(ParticleEffect, ZeroLifetimeIsNeverAliveAndNeverDividesByIt) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::fire());
    Effect none = embers({.lifetimeSec = 0.0f});
    none.update(3.0);
    SplatBuilder b;
    b.begin(Camera::lookAt({0, 1, 5}, {0, 1, 0}, {0, 1, 0}, 0.9f, {64, 48}));
    EXPECT_EQ(none.emit(b, mat, {.textured = false}), 0u);
    EXPECT_FALSE(none.alive(3.0, {}));
    EXPECT_TRUE(none.bounds(0, 10).empty());
    EXPECT_EQ(none.costCells(), 0u);
}

TEST(ParticleEffect, AStepFiftyLifetimesLongIsTheFrameEvaluatedDirectly) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::fire());
    Effect stepped = embers({.ratePerSec = 30, .velocitySpread = {0.3f, 0.3f, 0.3f}, .lifetimeSec = 0.2f, .texturesPerSec = 4});
    Effect direct = stepped;
    stepped.update(0.1);
    stepped.step(10.0);
    direct.update(10.1);
    SplatBuilder b1, b2;
    b1.begin(Camera::lookAt({0, 1, 5}, {0, 1, 0}, {0, 1, 0}, 0.9f, {64, 48}));
    b2.begin(b1.camera());
    ASSERT_EQ(stepped.emit(b1, mat, {.textured = false}), direct.emit(b2, mat, {.textured = false}));
    ASSERT_GT(b1.splats().size(), 3u);
    for (std::size_t i = 0; i < b1.splats().size(); ++i) EXPECT_EQ(b1.splats()[i].center, b2.splats()[i].center);
}

TEST(ParticleEffect, ObjectDynamicsOffFreezesTheParticlesAtTimeZero) {
    Effect fx = embers({.ratePerSec = 10, .startSec = -3.0, .velocity = {0, 1, 0}, .lifetimeSec = 2, .texturesPerSec = 5});
    Effect still = fx;
    still.setToggles({.object = false});
    fx.update(0.0);
    still.update(7.0);
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::fire());
    const Camera cam = Camera::lookAt({0, 1, 5}, {0, 1, 0}, {0, 1, 0}, 0.9f, {64, 48});
    SplatBuilder b0, b1;
    b0.begin(cam), b1.begin(cam);
    ASSERT_EQ(fx.emit(b0, mat, {.textured = false}), still.emit(b1, mat, {.textured = false})) << "object dynamics off: the particles of t = 0";
    ASSERT_GT(b0.splats().size(), 10u);
    for (std::size_t i = 0; i < b0.splats().size(); ++i) EXPECT_EQ(b0.splats()[i].center, b1.splats()[i].center);
}

TEST(ParticleEffect, HostParticlesAreDrawnBoundedAndOnlyAParticleEffectTakesThem) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::fire());
    Effect fx = embers({.ratePerSec = 0}); // host-fed only
    EXPECT_FALSE(fx.alive(1.0, {}));
    const std::vector<Particle> host = {{.position = {5, 1, 0}, .sizeWorld = 0.2f, .opacity = 0.8f},
                                        {.position = {-2, 3, 1}, .sizeWorld = 0.1f, .velocity = {std::numeric_limits<float>::infinity(), 0, 0}}};
    ASSERT_TRUE(fx.setParticles(host));
    EXPECT_TRUE(fx.alive(1.0, {}));
    const Aabb box = fx.bounds(0, 1);
    EXPECT_TRUE(box.contains({5, 1, 0}));
    EXPECT_FALSE(box.contains({-2, 3, 1})) << "a particle the builder drops must not widen the bounds";
    SplatBuilder b;
    b.begin(Camera::lookAt({0, 1, 10}, {0, 1, 0}, {0, 1, 0}, 1.2f, {64, 48}));
    EXPECT_EQ(fx.emit(b, mat, {.textured = false}), 1u);
    EXPECT_EQ(b.stats().rejected, 1u);
    Effect grid = *Effect::fromGrid(*Grid::box({2, 2, 2}), {});
    const Status s = grid.setParticles(host);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("needs a particle effect"), std::string::npos);
    EffectDesc two;
    two.layers = {EffectLayer{}, EffectLayer{}};
    auto r = Effect::fromParticles({}, two);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("one layer"), std::string::npos);
}

} // namespace
} // namespace splatfx
