// Particles at their numerical edges (docs/STABILITY.md, "Particles"): the
// closed-form flight at drag -> 0 and drag -> infinity, reaches past float,
// lifetimes and fades at the float limits, the budget's boundary, birth slots
// at the instants they open and close, texture cycling after 2^18 s, and host
// particles with sizes and fields at the float limits. Each is asserted
// against the closed form (or its limit) with a tolerance derived in place.
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

std::vector<Particle> alive(const ParticleEmitter& e, double t) {
    std::vector<Particle> out;
    e.particlesAt(t, out);
    return out;
}

// Float rounding of a value computed in double and stored in float: half an
// ulp of its magnitude; 4 ulps leaves room for the pose product before it.
float floatUlps(double magnitude) { return 4.0f * std::ldexp(float(std::max(std::abs(magnitude), 1e-30)), -23); }

TEST(ParticleStability, DragBelowFloatsSmallestAndAtTheSeriesSwitchIsThePerturbedParabola) {
    // x(k) = x0 + v0 g + (A + k w) h with g = a - k a^2/2 + k^2 a^3/6 - ..., h = a^2/2 - k a^3/6 + k^2 a^4/24 - ...
    // First order in k: x = P + k D, P the parabola, D = -v0 a^2/2 - A a^3/6 + w a^2/2; the remainder is
    // below k^2 (|v0| a^3/6 + |A| a^4/24 + |w| a^3/6) (alternating series, k a <= 0.02 here). Computed as
    // (a - g)/k without the series, k = 1e-30 would give h = 0 (a - g cancels to nothing): 4 units off.
    // A and w as the desc stores them (floats), so only the flight's arithmetic is compared.
    const glm::dvec3 x0(0.1, -0.2, 0.3), v0(0.5, 1.0, -0.2), A(glm::vec3(0.3f, 2.0f, -0.1f)), w(glm::vec3(1.0f, 0.0f, 0.5f));
    const double a = 2.0;
    const float kmin = std::numeric_limits<float>::denorm_min();
    // 4.9999e-4 and 5.0001e-4: k a either side of the series' switch at 1e-3.
    for (float k : {kmin, 1e-38f, 1e-30f, 1e-12f, 4.9999e-4f, 5.0001e-4f, 1e-2f}) {
        const ParticleEmitterDesc d{.acceleration = glm::vec3(A), .dragPerSec = k, .wind = glm::vec3(w)};
        const double kd = k;
        const glm::dvec3 P = x0 + v0 * a + A * (a * a / 2.0);
        const glm::dvec3 D = -v0 * (a * a / 2.0) - A * (a * a * a / 6.0) + w * (a * a / 2.0);
        const glm::dvec3 x = ParticleEmitter::flightPosition(d, x0, v0, a);
        // v = v0 e^{-ka} + (A + k w) g: first order P' + k D', D' = -v0 a - A a^2/2 + w a; remainder k^2 (|v0| a^2/2 + |A| a^3/6 + |w| a^2/2).
        const glm::dvec3 Pv = v0 + A * a, Dv = -v0 * a - A * (a * a / 2.0) + w * a;
        const glm::dvec3 v = ParticleEmitter::flightVelocity(d, v0, a);
        for (int i = 0; i < 3; ++i) {
            const double remX = kd * kd * (std::abs(v0[i]) * a * a * a / 6.0 + std::abs(A[i]) * a * a * a * a / 24.0 + std::abs(w[i]) * a * a * a / 6.0);
            const double remV = kd * kd * (std::abs(v0[i]) * a * a / 2.0 + std::abs(A[i]) * a * a * a / 6.0 + std::abs(w[i]) * a * a / 2.0);
            // Double rounding: a few ulps of the terms summed (each below 10 here): 1e-14.
            EXPECT_NEAR(x[i], P[i] + kd * D[i], remX + 1e-14) << "k " << k << " axis " << i;
            EXPECT_NEAR(v[i], Pv[i] + kd * Dv[i], remV + 1e-14) << "k " << k << " axis " << i;
        }
    }
}

TEST(ParticleStability, EnormousDragPinsEveryParticleToTheWind) {
    // k -> infinity: v -> w + A / k and x -> x0 + w age + O(1/k) (the velocity relaxes within 1/k seconds).
    // Exactly: x - x0 - w age = v0 g + (A + k w) h - w age with g <= 1/k and h = (age - g)/k, so
    // |x - x0 - w age| <= (|v0| + |w|) / k + |A| age / k.
    const glm::vec3 v0(5, 3, 0), A(0, 2, 0), w(1, 0, -0.5f);
    for (float k : {1e6f, 1e30f, std::numeric_limits<float>::max()}) {
        const ParticleEmitter e = *ParticleEmitter::create({.ratePerSec = 10, .velocity = v0, .lifetimeSec = 2, .acceleration = A, .dragPerSec = k, .wind = w});
        const double t = 3.03;
        const std::vector<Particle> ps = alive(e, t);
        ASSERT_EQ(ps.size(), 20u); // births 1.05 ... 2.95 in (t - 2, t]
        const Aabb box = e.centerBounds(t, t);
        for (const Particle& p : ps) {
            const double age = t - (p.id + 0.5) / 10.0;
            for (int i = 0; i < 3; ++i) {
                const double bound = (std::abs(v0[i]) + std::abs(w[i]) + std::abs(A[i]) * age) / double(k);
                EXPECT_NEAR(p.position[i], w[i] * age, bound + floatUlps(w[i] * age)) << "k " << k << " particle " << p.id;
                EXPECT_NEAR(p.velocity[i], w[i], std::abs(A[i]) / double(k) + floatUlps(w[i])) << "k " << k;
            }
            EXPECT_TRUE(box.contains(p.position)) << "k " << k;
        }
    }
}

TEST(ParticleStability, AHugeVelocityFliesToItsReachAndAReachPastFloatIsRefused) {
    // 2e17 units a second for up to 2 s: 4e17, inside the 1e18 reach; positions are v age to float rounding.
    const ParticleEmitter e = *ParticleEmitter::create({.ratePerSec = 10, .velocity = {0, 2e17f, 0}, .lifetimeSec = 2});
    const double t = 5.01;
    const std::vector<Particle> ps = alive(e, t);
    ASSERT_EQ(ps.size(), 20u);
    const Aabb box = e.centerBounds(t, t);
    for (const Particle& p : ps) {
        const double want = 2e17 * (t - (p.id + 0.5) / 10.0);
        EXPECT_NEAR(p.position.y, want, floatUlps(want) + 2e17 * std::ldexp(t, -52)); // and the age's double rounding
        EXPECT_TRUE(std::isfinite(p.position.y) && box.contains(p.position));
    }
    // 3e38 for 2 s is infinite in float: centres and bounds would be inf (culling nothing). Refused, naming the fields.
    auto far = ParticleEmitter::create({.velocity = {0, 3e38f, 0}, .lifetimeSec = 2});
    ASSERT_FALSE(far);
    EXPECT_NE(far.error().find("velocity, acceleration and lifetimeSec reach 6e+38 world units"), std::string::npos) << far.error();
    // So is a reach made of a finite wind times an enormous drag, each allowed alone.
    auto windy = ParticleEmitter::create({.velocity = {0, 0, 0}, .lifetimeSec = 2, .dragPerSec = 1e30f, .wind = {1e20f, 0, 0}});
    ASSERT_FALSE(windy);
    EXPECT_NE(windy.error().find("reach 2e+20"), std::string::npos) << windy.error();
}

TEST(ParticleStability, WindWithoutDragIsIgnoredExactlyAndTinyDragTimesHugeWindIsItsProduct) {
    // dv/dt = A + k (w - v): with k = 0 the wind does not enter at all (0 * w must not be a NaN or a residue).
    const glm::dvec3 x0(1, 2, 3), v0(0.5, -1, 2);
    const ParticleEmitterDesc calm{.acceleration = {0, -9.81f, 0}};
    ParticleEmitterDesc windy = calm;
    windy.wind = {1e30f, -1e30f, 3.0f};
    for (double a : {0.0, 0.37, 2.0}) {
        EXPECT_EQ(ParticleEmitter::flightPosition(windy, x0, v0, a), ParticleEmitter::flightPosition(calm, x0, v0, a)) << a;
        EXPECT_EQ(ParticleEmitter::flightVelocity(windy, v0, a), ParticleEmitter::flightVelocity(calm, v0, a)) << a;
    }
    // k = 1e-30 against w = 1e30: the drift k w = 1 per s^2 is of the order of the rest. To first order in k
    // (the terms not multiplied by w): x = x0 + v0 a + (A + k w) a^2/2 - k (v0 a^2/2 + (A + k w) a^3/6), the
    // dropped k-terms below 1e-30 (their coefficients are O(1)); float rounding of k and w: k w = 1 to 2^-23.
    ParticleEmitterDesc tiny = calm;
    tiny.dragPerSec = 1e-30f;
    tiny.wind = {1e30f, 0, 0};
    const double kw = double(tiny.dragPerSec) * double(tiny.wind.x);
    const double a = 2.0;
    const glm::dvec3 x = ParticleEmitter::flightPosition(tiny, x0, v0, a);
    EXPECT_NEAR(x.x, x0.x + v0.x * a + kw * a * a / 2.0, 1e-12);
    EXPECT_NEAR(kw, 1.0, 2.0 * std::ldexp(1.0, -23));
    EXPECT_NEAR(x.y, x0.y + v0.y * a - 9.81f * a * a / 2.0, 1e-12);
}

TEST(ParticleStability, TheSmallestLifetimeLivesOnlyAtItsBirthInstant) {
    // lifetime = the smallest subnormal: a slot is alive only at t equal to its birth (age 0 < 1.4e-45),
    // whatever rounding the slot range's arithmetic does; its life fraction 0 / 1.4e-45 is 0, not NaN.
    const float life = std::numeric_limits<float>::denorm_min();
    const ParticleEmitter e =
        *ParticleEmitter::create({.position = {1, 2, 3}, .ratePerSec = 1000, .lifetimeSec = life, .fadeIn = 0.0f, .colorFrom = 0.25f});
    for (std::uint32_t n : {0u, 5u, 123u, 99999u}) {
        const double birth = 0.0 + (double(n) + 0.5) / 1000.0; // particlesAt's birth expression
        const std::vector<Particle> ps = alive(e, birth);
        ASSERT_EQ(ps.size(), 1u) << "slot " << n;
        EXPECT_EQ(ps[0].id, n);
        EXPECT_EQ(ps[0].position, glm::vec3(1, 2, 3)); // age 0: the birth point exactly
        EXPECT_EQ(ps[0].opacity, 1.0f);
        EXPECT_EQ(ps[0].colorCoord, 0.25f);
        EXPECT_EQ(alive(e, std::nextafter(birth, 1.0)).size(), 0u) << "slot " << n << " must be dead one double later";
    }
    EXPECT_EQ(e.maxAlive(), 1u); // ceil(1000 * 1.4e-45)
}

TEST(ParticleStability, FadesAtTheirLimitsGiveTheClosedFormEnvelope) {
    // fadeIn = the smallest subnormal: x / fadeIn is +inf for every x > 0 (the min picks the fade-out), 0 at x = 0;
    // fadeIn = fadeOut = 1: the triangle min(x, 1 - x). Envelope times opacity, to float rounding (2^-24 relative).
    const float sub = std::numeric_limits<float>::denorm_min();
    struct Case {
        float in, out;
    };
    for (Case c : {Case{sub, 1.0f}, Case{1.0f, 1.0f}, Case{sub, sub}, Case{0.0f, 0.0f}}) {
        const ParticleEmitter e = *ParticleEmitter::create({.ratePerSec = 4, .lifetimeSec = 2, .opacity = 0.8f, .fadeIn = c.in, .fadeOut = c.out});
        const double t = 7.1;
        const std::vector<Particle> ps = alive(e, t);
        ASSERT_EQ(ps.size(), 8u);
        for (const Particle& p : ps) {
            const double x = (t - (p.id + 0.5) / 4.0) / 2.0;
            double env = 1.0;
            if (c.in > 0.0f) env = std::min(env, x / double(c.in));
            if (c.out > 0.0f) env = std::min(env, (1.0 - x) / double(c.out));
            EXPECT_NEAR(p.opacity, 0.8 * std::clamp(env, 0.0, 1.0), 1e-6) << "fades " << c.in << ", " << c.out << " x " << x;
        }
    }
}

TEST(ParticleStability, TheBudgetsBoundaryIsExactAndMillionsAreCountedNotAllocated) {
    // rate * lifetime = 2^24 = kMaxParticles exactly (both floats exact): accepted; one slot more per second: refused.
    const ParticleEmitterDesc most{.ratePerSec = 16777216.0f, .lifetimeSec = 1.0f, .maxParticles = kMaxParticles};
    auto e = ParticleEmitter::create(most);
    ASSERT_TRUE(e) << e.error();
    EXPECT_EQ(e->maxAlive(), std::uint64_t(kMaxParticles));
    ParticleEmitterDesc over = most;
    over.ratePerSec = 16777218.0f; // the next float
    auto r = ParticleEmitter::create(over);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("16777218 particles alive at once exceeds maxParticles = 16777216"), std::string::npos) << r.error();
    // 16.7 million may be alive, but only the slots born so far are made: at t the closed form
    // floor(t rate - 1/2) + 1 (births (n + 1/2) / rate <= t), here 1677, not a 16.7-million vector.
    const double t = 1e-4;
    EXPECT_EQ(alive(*e, t).size(), std::size_t(std::floor(t * 16777216.0 - 0.5) + 1.0));
    auto fx = Effect::fromParticles(most, {});
    ASSERT_TRUE(fx) << fx.error();
    EXPECT_EQ(fx->costCells(), std::uint64_t(kMaxParticles)); // the scheduler's cost is the budget, not today's count
}

TEST(ParticleStability, ABirthSlotOpensAtItsInstantAndAStopAtThatInstantClosesIt) {
    // Slot 0 is born at start + 0.5 / rate; stopSec is exclusive ("no births at or after it").
    const double start = 2.0, rate = 8.0, first = start + 0.5 / rate;
    auto count = [&](double stop, double t) {
        return alive(*ParticleEmitter::create({.ratePerSec = float(rate), .startSec = start, .stopSec = stop, .lifetimeSec = 1}), t).size();
    };
    EXPECT_EQ(count(start, first + 0.1), 0u);                        // an empty interval births no one
    EXPECT_EQ(count(first, first + 0.1), 0u);                        // stop exactly at the first birth: excluded
    EXPECT_EQ(count(std::nextafter(first, 10.0), first + 0.1), 1u);  // one double later: slot 0 is born
    EXPECT_EQ(count(1e30, first), 1u);                               // at its birth instant (age 0) it is alive
    EXPECT_EQ(count(1e30, std::nextafter(first, 0.0)), 0u);          // one double before, not yet
    EXPECT_EQ(count(1e30, first + 1.0), 8u);                         // slot 0 dies at first + 1: births in (first, first + 1]
}

TEST(ParticleStability, AParticleAliveForTwoToTheEighteenSecondsKeepsItsTexturePhase) {
    // One particle born at 2^15 s, alive 2^18 s, cycling 1000 textures a second: at t near kMaxTimeSec its
    // cycle count is 2.3e8 (a float age or cycle would keep no fraction at all). A quarter of a period later
    // the texture index + phase has advanced by 0.25 (index modulo 2^32). Tolerance: the age's double
    // rounding (2^-34 s at 2^18) times 1000, plus the float phase's half ulp (2^-25) twice: under 1e-6.
    const ParticleEmitter e = *ParticleEmitter::create({.ratePerSec = 1.0f / 65536.0f, .lifetimeSec = 262144.0f, .texturesPerSec = 1000.0f});
    const double t0 = kMaxTimeSec - 0.1, t1 = t0 + 0.00025;
    const std::vector<Particle> a = alive(e, t0), b = alive(e, t1);
    ASSERT_EQ(a.size(), 4u); // births 32768, 98304, 163840, 229376
    ASSERT_EQ(b.size(), 4u);
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].id, b[i].id);
        const double advance = double(std::int32_t(b[i].texture - a[i].texture)) + double(b[i].phase) - double(a[i].phase);
        EXPECT_NEAR(advance, 0.25, 1e-6) << "particle " << a[i].id;
        EXPECT_GE(a[i].phase, 0.0f);
        EXPECT_LT(a[i].phase, 1.0f);
    }
}

TEST(ParticleSplats, SizesAtTheFloatLimitsAreDrawnToScaleOrDroppedAndCounted) {
    // A splat's axes scale with the particle's size (the kernel is size * I): |axisU| / size is the
    // same for every size drawn, to float rounding of the geometry (a few ulps: 1e-5 relative).
    // Sizes whose kernel determinant size^3 is not a normal float above 1e-12 (below 1e-4 world
    // units, or overflowing) are dropped and counted, never drawn with NaN or zero axes.
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::constant({1, 1, 1, 1}));
    const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.9f, {64, 48}, 0.01f, 1e6f);
    const float sizes[] = {0.0f, std::numeric_limits<float>::denorm_min(), 1e-30f, 1e-5f, 2e-4f, 0.01f, 0.5f, 3e12f, std::numeric_limits<float>::max()};
    SplatBuilderDesc bd;
    bd.frustumCull = false;
    bd.nearFade = false;
    std::vector<float> perSize;
    std::size_t dropped = 0;
    for (float s : sizes) {
        SplatBuilder b(bd);
        b.begin(cam);
        const Particle p{.position = {0.0f, 0.0f, -50.0f}, .sizeWorld = s, .opacity = 0.5f};
        b.add(std::span<const Particle>(&p, 1), mat, {.splat = {.textured = false}});
        EXPECT_EQ(b.splats().size() + b.stats().rejected + b.stats().culled, 1u);
        if (b.splats().empty()) {
            ++dropped;
            continue;
        }
        const Splat& sp = b.splats()[0];
        ASSERT_TRUE(std::isfinite(sp.density) && sp.density > 0.0f) << "size " << s;
        ASSERT_TRUE(std::isfinite(glm::length(sp.axisU)) && std::isfinite(glm::length(sp.axisV))) << "size " << s;
        perSize.push_back(glm::length(sp.axisU) / s);
    }
    ASSERT_GE(perSize.size(), 4u); // 2e-4 to 0.5 at least
    for (float r : perSize) EXPECT_NEAR(r, perSize.front(), 1e-5f * perSize.front());
    EXPECT_GE(dropped, 4u); // 0, the subnormal, 1e-30, 1e-5 (and FLT_MAX: its determinant overflows)
}

TEST(ParticleSplats, ANonFiniteOpacityColourPhaseOrPositionDropsOnlyThatParticle) {
    // The builder clamps opacity and colour into [0, 1]: std::clamp of a NaN is a NaN, which would reach
    // the density and the colour row. Each bad field drops its particle alone; the good one draws exactly
    // as it does by itself.
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::fire());
    const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.9f, {64, 48});
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const Particle good{.position = {0.1f, 0, -3}, .sizeWorld = 0.2f, .opacity = 0.6f, .colorCoord = 0.4f};
    std::vector<Particle> ps;
    for (int field = 0; field < 7; ++field) {
        Particle p = good;
        p.id = std::uint32_t(field + 1);
        switch (field) {
        case 0: p.opacity = nan; break;
        case 1: p.opacity = inf; break;
        case 2: p.colorCoord = nan; break;
        case 3: p.colorCoord = -inf; break;
        case 4: p.phase = nan; break;
        case 5: p.position.z = -inf; break;
        case 6: p.position.x = nan; break;
        }
        ps.push_back(p);
    }
    ps.push_back(good);
    SplatBuilder all, alone;
    all.begin(cam), alone.begin(cam);
    all.add(ps, mat, {.splat = {.textured = false}});
    alone.add(std::span<const Particle>(&good, 1), mat, {.splat = {.textured = false}});
    EXPECT_EQ(all.stats().rejected, 7u);
    ASSERT_EQ(all.splats().size(), 1u);
    ASSERT_EQ(alone.splats().size(), 1u);
    EXPECT_EQ(all.splats()[0].center, alone.splats()[0].center);
    EXPECT_EQ(all.splats()[0].density, alone.splats()[0].density);
    EXPECT_EQ(all.splats()[0].color, alone.splats()[0].color);
}

} // namespace
} // namespace splatfx
