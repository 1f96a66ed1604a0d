#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "splatfx/grid.hpp"

using splatfx::Grid;

TEST(Grid, BoxFillsEveryCell) {
    auto g = Grid::box({7, 20, 5});
    ASSERT_TRUE(g) << g.error();
    EXPECT_EQ(g->voxels.size(), 7u * 20u * 5u);
    EXPECT_EQ(g->dims, glm::ivec3(7, 20, 5));
    // Colour coordinate is normalized height: 0 at the base, 1 at the top.
    for (const auto& v : g->voxels) EXPECT_FLOAT_EQ(v.colorCoord, v.cell.y / 19.0f);
}

TEST(Grid, LocalPositionIsCentredOnXzAndHonoursSpacing) {
    auto g = Grid::box({3, 2, 5}, {0.5f, 2.0f, 1.0f});
    ASSERT_TRUE(g);
    EXPECT_EQ(g->localPosition({1, 0, 2}), glm::vec3(0.0f));
    EXPECT_EQ(g->localPosition({2, 1, 4}), glm::vec3(0.5f, 2.0f, 2.0f));
}

TEST(Grid, SphereCountMatchesLatticePointsInside) {
    const float r = 3.0f;
    auto g = Grid::sphere(r);
    ASSERT_TRUE(g);
    size_t expected = 0;
    for (int x = -3; x <= 3; ++x)
        for (int y = -3; y <= 3; ++y)
            for (int z = -3; z <= 3; ++z) expected += (x * x + y * y + z * z <= 9) ? 1 : 0;
    EXPECT_EQ(g->voxels.size(), expected);
}

TEST(Grid, CylinderHasTheSameDiscOnEveryLayer) {
    auto g = Grid::cylinder(2.0f, 6);
    ASSERT_TRUE(g);
    std::vector<int> perLayer(6, 0);
    for (const auto& v : g->voxels) ++perLayer[size_t(v.cell.y)];
    for (int n : perLayer) EXPECT_EQ(n, 13); // lattice points with x^2 + z^2 <= 4
}

TEST(Grid, ConeNarrowsWithHeightAndKeepsItsTip) {
    auto g = Grid::cone(4.0f, 8);
    ASSERT_TRUE(g);
    std::vector<int> perLayer(8, 0);
    for (const auto& v : g->voxels) ++perLayer[size_t(v.cell.y)];
    for (int y = 1; y < 8; ++y) EXPECT_LE(perLayer[size_t(y)], perLayer[size_t(y - 1)]);
    EXPECT_GE(perLayer[7], 1);
    EXPECT_GT(perLayer[0], perLayer[7]);
}

TEST(Grid, FromDenseIsSparse) {
    std::vector<float> op(2 * 2 * 2, 0.0f);
    op[0] = 0.5f;
    op[7] = 1.0f;
    auto g = Grid::fromDense({2, 2, 2}, op);
    ASSERT_TRUE(g) << g.error();
    ASSERT_EQ(g->voxels.size(), 2u);
    EXPECT_EQ(g->voxels[0].cell, glm::ivec3(0, 0, 0));
    EXPECT_FLOAT_EQ(g->voxels[0].opacity, 0.5f);
    EXPECT_EQ(g->voxels[1].cell, glm::ivec3(1, 1, 1));
}

TEST(GridBadInput, EmptyGridIsRejectedWithTheField) {
    auto g = Grid::box({0, 20, 5});
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error(), "box dims.x must be at least 1, got 0");
    auto d = Grid::fromDense({2, 1, 1}, {0.0f, 0.0f});
    ASSERT_FALSE(d);
    EXPECT_NE(d.error().find("every opacity is 0"), std::string::npos) << d.error();
}

TEST(GridBadInput, AbsurdSizeIsRejected) {
    auto g = Grid::box({1000, 1000, 1000});
    ASSERT_FALSE(g);
    EXPECT_NE(g.error().find("asks for 1000000000 voxels"), std::string::npos) << g.error();
}

TEST(GridBadInput, NanAndNegativeOpacityAreRejected) {
    auto n = Grid::fromDense({2, 1, 1}, {0.5f, std::numeric_limits<float>::quiet_NaN()});
    ASSERT_FALSE(n);
    EXPECT_NE(n.error().find("opacity[1] (cell 1,0,0) is nan"), std::string::npos) << n.error();
    auto neg = Grid::fromDense({1, 1, 1}, {-0.25f});
    ASSERT_FALSE(neg);
    EXPECT_NE(neg.error().find("is -0.25"), std::string::npos) << neg.error();

    auto g = Grid::box({2, 2, 2});
    ASSERT_TRUE(g);
    g->voxels[3].opacity = -1.0f;
    const auto s = g->validate();
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "voxel 3: opacity is -1; expected a finite value in [0, 1]");
}

TEST(GridBadInput, SpacingMustBePositive) {
    auto g = Grid::box({2, 2, 2}, {1.0f, 0.0f, 1.0f});
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error(), "grid spacing.y must be a positive finite number, got 0");
}
