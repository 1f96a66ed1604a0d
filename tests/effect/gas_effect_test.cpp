// The procedural-gas kind of Effect (Effect::fromProceduralGas, presets::gas):
// stateless like grid effects (frame t is a pure function of t), its box
// holds every splat it draws, and the fog rolls in as procedural_gas.hpp says.
#include <gtest/gtest.h>

#include "splatfx/presets.hpp"

using namespace splatfx;

namespace {

presets::GasDesc fogDesc() {
    presets::GasDesc d;
    d.gas.kind = GasKind::Fog;
    d.gas.fog.frontStart = -1.0f;
    d.gas.fog.frontSpeed = 0.5f;
    d.dims = {20, 6, 12};
    d.spacing = glm::vec3(0.15f);
    return d;
}

bool sameVoxels(const Grid& a, const Grid& b) {
    if (a.voxels.size() != b.voxels.size() || a.transform != b.transform) return false;
    for (std::size_t i = 0; i < a.voxels.size(); ++i) {
        const Voxel &u = a.voxels[i], &v = b.voxels[i];
        if (u.cell != v.cell || u.opacity != v.opacity || u.texture != v.texture || u.phase != v.phase) return false;
    }
    return true;
}

} // namespace

TEST(GasEffect, FrameTDependsOnTAloneInAnyOrder) {
    Materials m(Footprint{});
    auto fx = presets::gas(m, fogDesc());
    ASSERT_TRUE(fx) << fx.error();
    EXPECT_TRUE(fx->isStateless());
    fx->update(5.0);
    const Grid at5 = fx->grid();
    ASSERT_FALSE(at5.voxels.empty());
    fx->update(1.5);
    fx->update(9.0);
    fx->update(5.0);
    EXPECT_TRUE(sameVoxels(fx->grid(), at5));
    // A second effect from the same desc, brought straight to 5 s, agrees.
    auto other = presets::gas(m, fogDesc());
    ASSERT_TRUE(other);
    other->update(5.0);
    EXPECT_TRUE(sameVoxels(other->grid(), at5));
}

TEST(GasEffect, TheLatticeStandsOnItsPositionCentredOnXAndZ) {
    Materials m(Footprint{});
    presets::GasDesc d = fogDesc();
    d.position = {1.0f, 0.5f, -2.0f};
    auto fx = presets::gas(m, d);
    ASSERT_TRUE(fx);
    const Grid& g = fx->grid();
    const glm::vec3 lo = g.worldPosition({0, 0, 0}), hi = g.worldPosition(d.dims - 1);
    EXPECT_NEAR(0.5f * (lo.x + hi.x), 1.0f, 1e-5f);
    EXPECT_NEAR(lo.y, 0.5f, 1e-5f);
    EXPECT_NEAR(0.5f * (lo.z + hi.z), -2.0f, 1e-5f);
    EXPECT_NEAR(hi.x - lo.x, 19 * 0.15f, 1e-4f);
}

TEST(GasEffect, TheFogRollsInAlongX) {
    Materials m(Footprint{});
    auto fx = presets::gas(m, fogDesc());
    ASSERT_TRUE(fx);
    // The lattice spans x in [-1.425, 1.425]; the front starts at -1 and moves +0.5/s.
    auto maxX = [&](double t) {
        fx->update(t);
        float hi = -1e9f;
        for (const Voxel& v : fx->grid().voxels) hi = std::max(hi, fx->grid().worldPosition(v.cell).x);
        return std::pair{fx->grid().voxels.size(), hi};
    };
    const auto [n1, x1] = maxX(1.0);
    const auto [n4, x4] = maxX(4.0);
    EXPECT_LT(n1, n4); // more of the lattice is fogged as the front advances
    EXPECT_LT(x1, x4); // and its leading edge has moved on
    // It grows from nothing (chess_fog's min(frame / FULL_FOG, 1) at frame 0).
    EXPECT_EQ(maxX(0.0).first, 0u);
}

TEST(GasEffect, BoundsHoldEverySplatCentreOverTheInterval) {
    Materials m(Footprint{});
    presets::GasDesc d = fogDesc();
    d.motion = Motion({Keyframe{.timeSec = 0.0, .pose = {.position = {0, 0, 0}}}, Keyframe{.timeSec = 6.0, .pose = {.position = {2, 1, 0}}}});
    auto fx = presets::gas(m, d);
    ASSERT_TRUE(fx);
    const Aabb box = fx->bounds(0.0, 6.0);
    for (double t = 0.0; t <= 6.0; t += 0.5) {
        fx->update(t);
        for (const Voxel& v : fx->grid().voxels) {
            const glm::vec3 p = fx->grid().worldPosition(v.cell);
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(p[a], box.lo[a]) << "t " << t;
                EXPECT_LE(p[a], box.hi[a]) << "t " << t;
            }
        }
    }
}

TEST(GasEffect, BadDescsAreNamed) {
    Materials m(Footprint{});
    presets::GasDesc d = fogDesc();
    d.gas.fog.power = 0.0f;
    auto bad = presets::gas(m, d);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("fog.power"), std::string::npos) << bad.error();
    d = fogDesc();
    d.dims = {0, 4, 4};
    auto empty = presets::gas(m, d);
    ASSERT_FALSE(empty);
    EXPECT_NE(empty.error().find("dims"), std::string::npos) << empty.error();
    d = fogDesc();
    d.dims = {1024, 1024, 1024};
    auto huge = presets::gas(m, d);
    ASSERT_FALSE(huge);
    EXPECT_NE(huge.error().find("kMaxVoxels"), std::string::npos) << huge.error();
}
