// Object dynamics (sec. 3.1): keyframes hit their keys, procedures add up,
// sweeps bound the motion, emitters ride their object.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/motion.hpp"
#include "splatfx/solver.hpp"

using namespace splatfx;

namespace {

std::vector<Keyframe> threeKeys() {
    return {
        {.timeSec = 0.0, .pose = {.position = {0, 0, 0}, .scale = glm::vec3(1), .opacity = 0.0f, .growth = 0.0f}},
        {.timeSec = 2.0,
         .pose =
             {.position = {4, 2, 0}, .rotation = glm::angleAxis(1.0f, glm::vec3(0, 1, 0)), .scale = glm::vec3(2), .opacity = 1.0f, .growth = 1.0f},
         .easing = Easing::Smooth},
        {.timeSec = 5.0, .pose = {.position = {4, 2, -6}, .rotation = glm::angleAxis(1.0f, glm::vec3(0, 1, 0)), .scale = glm::vec3(0.5f, 2, 1)}},
    };
}

} // namespace

TEST(Motion, KeyframesAreHitExactly) {
    const Motion m(threeKeys());
    for (const Keyframe& k : threeKeys()) {
        const Pose p = m.sample(k.timeSec);
        EXPECT_EQ(p.position, k.pose.position) << "t = " << k.timeSec;
        EXPECT_EQ(p.scale, k.pose.scale);
        EXPECT_EQ(p.opacity, k.pose.opacity);
        EXPECT_EQ(p.growth, k.pose.growth);
        EXPECT_NEAR(std::abs(glm::dot(p.rotation, glm::normalize(k.pose.rotation))), 1.0f, 1e-6f);
    }
    // Held before the first and after the last key.
    EXPECT_EQ(m.sample(-3.0).position, glm::vec3(0));
    EXPECT_EQ(m.sample(99.0).position, glm::vec3(4, 2, -6));
}

TEST(Motion, InterpolatesWithItsEasing) {
    const Motion m(threeKeys());
    // Linear segment [0, 2]: a quarter of the way at t = 0.5.
    EXPECT_NEAR(m.sample(0.5).position.x, 1.0f, 1e-5f);
    EXPECT_NEAR(m.sample(0.5).opacity, 0.25f, 1e-6f);
    // Smooth segment [2, 5]: smoothstep(1/3) = 7/27 of the way at t = 3.
    EXPECT_NEAR(m.sample(3.0).position.z, -6.0f * 7.0f / 27.0f, 1e-5f);
    const Motion stepped({{.timeSec = 0, .pose = {.position = {1, 0, 0}}, .easing = Easing::Step}, {.timeSec = 1, .pose = {.position = {2, 0, 0}}}});
    EXPECT_EQ(stepped.sample(0.999).position.x, 1.0f);
    EXPECT_EQ(stepped.sample(1.0).position.x, 2.0f);
}

TEST(Motion, ProceduralPartsAddOnTop) {
    const Motion m({}, {.velocity = {1, 0, 0}, .spinAxis = {0, 0, 1}, .spinRadPerSec = 0.5f, .bobAmplitude = {0, 0.2f, 0}, .bobHz = 0.25f});
    const Pose p = m.sample(1.0); // bob at a quarter period: sin(pi / 2) = 1
    EXPECT_NEAR(p.position.x, 1.0f, 1e-6f);
    EXPECT_NEAR(p.position.y, 0.2f, 1e-6f);
    const glm::vec3 x = p.rotation * glm::vec3(1, 0, 0);
    EXPECT_NEAR(x.x, std::cos(0.5f), 1e-6f);
    EXPECT_NEAR(x.y, std::sin(0.5f), 1e-6f);
    EXPECT_FALSE(m.isStatic());
    EXPECT_TRUE(Motion().isStatic());
}

TEST(Motion, BadKeysAreReportedByField) {
    auto keys = threeKeys();
    keys[2].timeSec = 1.0;
    Result<Motion> r = Motion::create(keys);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(), "keyframe 2: timeSec 1.000000 must be greater than the previous key's 2.000000");
    keys = threeKeys();
    keys[1].pose.scale.y = 0.0f;
    EXPECT_EQ(Motion::create(keys).error(), "keyframe 1: pose.scale must be positive and finite on every axis");
    keys = threeKeys();
    keys[0].pose.growth = 1.5f;
    EXPECT_EQ(Motion::create(keys).error(), "keyframe 0: pose.growth must be in [0, 1], got 1.500000");
}

TEST(Motion, SweepContainsEveryPointOfTheMotion) {
    const Aabb box{{-1, 0, -0.5f}, {1, 3, 0.5f}};
    const std::vector<Motion> motions = {
        Motion(threeKeys()),
        Motion(threeKeys(), {.velocity = {0.5f, 0, 0}, .spinRadPerSec = 1.3f, .bobAmplitude = {0.1f, 0.3f, 0}, .bobHz = 2.0f}),
        Motion({}, {.velocity = {-2, 0, 1}}),
    };
    for (std::size_t mi = 0; mi < motions.size(); ++mi) {
        const Motion& m = motions[mi];
        for (auto [t0, t1] : {std::pair{0.0, 5.0}, std::pair{1.0, 1.5}, std::pair{1.9, 2.1}, std::pair{4.0, 9.0}}) {
            const Aabb s = m.sweep(box, t0, t1);
            for (int k = 0; k <= 200; ++k) {
                const double t = t0 + (t1 - t0) * k / 200.0;
                const glm::mat4 x = m.matrix(t);
                for (int c = 0; c < 8; ++c) {
                    const glm::vec3 p = glm::vec3(x * glm::vec4(box.corner(c), 1.0f));
                    // 1e-4: float rounding of the matrix products (values are O(10)).
                    EXPECT_TRUE(s.expanded(1e-4f).contains(p)) << "motion " << mi << " t " << t << " corner " << c;
                }
            }
        }
    }
}

TEST(Motion, SweepOfATranslationIsTight) {
    const Motion m({{.timeSec = 0, .pose = {.position = {0, 0, 0}}}, {.timeSec = 1, .pose = {.position = {10, 0, 0}}}});
    const Aabb s = m.sweep({{-1, -1, -1}, {1, 1, 1}}, 0.0, 0.5);
    EXPECT_NEAR(s.lo.x, -1.0f, 1e-6f);
    EXPECT_NEAR(s.hi.x, 6.0f, 1e-6f);
    EXPECT_NEAR(s.hi.y, 1.0f, 1e-6f);
}

TEST(Growth, RevealsMaterialFromTheOrigin) {
    EXPECT_EQ(growthFactor(0.0f, 10.0f, 0.0f, 1.0f), 0.0f) << "growth 0: nothing";
    EXPECT_EQ(growthFactor(10.0f, 10.0f, 1.0f, 1.0f), 1.0f) << "growth 1: everything, fully";
    EXPECT_EQ(growthFactor(2.0f, 10.0f, 0.5f, 1.0f), 1.0f);
    EXPECT_EQ(growthFactor(8.0f, 10.0f, 0.5f, 1.0f), 0.0f);
    EXPECT_GT(growthFactor(5.0f, 10.0f, 0.5f, 1.0f), 0.0f);
    EXPECT_LT(growthFactor(5.0f, 10.0f, 0.5f, 1.0f), 1.0f);
}

TEST(Emitter, FollowsItsObject) {
    const Motion cart({{.timeSec = 0, .pose = {.position = {-3, 0, 0}}},
                       {.timeSec = 3, .pose = {.position = {3, 0, 0}, .rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0))}}});
    const Emitter e{.desc = {.offset = {1, 0.5f, 0}, .radius = 0.6f}, .motion = cart};
    for (double t : {0.0, 0.7, 1.5, 3.0, 4.0}) {
        const glm::vec3 expected = glm::vec3(cart.matrix(t) * glm::vec4(1, 0.5f, 0, 1));
        EXPECT_NEAR(glm::length(e.worldCenter(t) - expected), 0.0f, 1e-6f);
    }
    EXPECT_NEAR(glm::length(e.worldCenter(3.0) - glm::vec3(3, 0.5f, -1)), 0.0f, 1e-5f) << "rotated offset";

    // In a solver, material appears where the emitter is now, not where it will be.
    auto solver = FluidSolver::create({.dims = {16, 4, 4}, .spacing = glm::vec3(0.5f), .buoyancy = 0.0f, .temperatureDissipation = 0.0f});
    ASSERT_TRUE(solver.ok());
    const Motion slide({{.timeSec = 0, .pose = {.position = {-3, 0, 0}}}, {.timeSec = 3, .pose = {.position = {3, 0, 0}}}});
    solver->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 0.6f, .rate = 20.0f}, .motion = slide});
    for (int i = 0; i < 15; ++i) solver->step(0.1); // to t = 1.5: centre at x = 0
    auto densityNear = [&](float worldX) {
        float best = 0.0f;
        for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 16; ++x) {
                    const glm::vec3 p = solver->localPosition({x, y, z});
                    if (std::abs(p.x - worldX) < 0.3f && std::abs(p.y - 0.5f) < 0.3f)
                        best = std::max(best, solver->density()[solver->cellIndex({x, y, z})]);
                }
        return best;
    };
    EXPECT_GT(densityNear(-0.25f), 0.3f) << "fed where the object is";
    EXPECT_EQ(densityNear(2.75f), 0.0f) << "nothing ahead of the object";
}
