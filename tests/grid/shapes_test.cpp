// Shape voxelizer and flame shape (splatfx/shapes.hpp), CPU only: cell counts
// against lattice-point counts done with integers, weights against the
// closed forms of the soft edge, and every refusal naming its field.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "splatfx/presets.hpp"
#include "splatfx/shapes.hpp"

using splatfx::Shape;
using splatfx::voxelizeShapes;

namespace {

// A few float operations on values in [0, 1], each rounded to half an ulp
// (6e-8): a handful of them stay well below 1e-6.
constexpr float kFloatTol = 1e-6f;

// A soft edge this narrow puts every lattice point either fully in or fully
// out of a shape whose surface is at least 0.05 cells from every lattice point.
constexpr float kSharp = 0.05f;

} // namespace

TEST(Shapes, BoxCoversExactlyItsCornerCellsAndTheCellsBetween) {
    Shape box = Shape::box({1, 0, 2}, {3, 2, 3});
    box.softCells = kSharp;
    auto g = voxelizeShapes({box}, {.dims = {6, 5, 6}, .opacity = 1.0f});
    ASSERT_TRUE(g) << g.error();
    ASSERT_EQ(g->voxels.size(), 3u * 3u * 2u); // x 1..3, y 0..2, z 2..3
    for (const splatfx::Voxel& v : g->voxels) {
        EXPECT_GE(v.cell.x, 1);
        EXPECT_LE(v.cell.x, 3);
        EXPECT_LE(v.cell.y, 2);
        EXPECT_GE(v.cell.z, 2);
        EXPECT_LE(v.cell.z, 3);
        EXPECT_EQ(v.opacity, 1.0f); // half a cell inside every face: weight clamps to 1
    }
}

TEST(Shapes, SphereCoversTheLatticePointsWithinItsRadius) {
    // Radius 2.5 around (3, 3, 3): squared distances are integers, 6 < 6.25 < 7,
    // and the nearest, sqrt(6) = 2.449, is 0.05 inside (more than kSharp / 2).
    Shape ball = Shape::sphere({3, 3, 3}, 2.5f);
    ball.softCells = kSharp;
    auto g = voxelizeShapes({ball}, {.dims = {7, 7, 7}, .opacity = 1.0f});
    ASSERT_TRUE(g) << g.error();
    std::size_t expected = 0;
    for (int z = 0; z < 7; ++z)
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 7; ++x) expected += (x - 3) * (x - 3) + (y - 3) * (y - 3) + (z - 3) * (z - 3) <= 6 ? 1 : 0;
    EXPECT_EQ(g->voxels.size(), expected);
    for (const splatfx::Voxel& v : g->voxels) EXPECT_EQ(v.opacity, 1.0f);
}

TEST(Shapes, SoftEdgeIsHalfWeightOnTheSurfaceAndRampsOverSoftCells) {
    Shape ball = Shape::sphere({0, 0, 0}, 3.0f);
    ball.softCells = 2.0f;
    ball.opacity = 0.8f;
    EXPECT_NEAR(ball.insideCells({3, 0, 0}), 0.0f, kFloatTol);
    EXPECT_NEAR(ball.weight({3, 0, 0}), 0.4f, kFloatTol);    // on the surface: opacity / 2
    EXPECT_NEAR(ball.weight({2, 0, 0}), 0.8f, kFloatTol);    // softCells / 2 inside: full
    EXPECT_NEAR(ball.weight({3.5f, 0, 0}), 0.2f, kFloatTol); // a quarter of the ramp outside
    EXPECT_EQ(ball.weight({4.0f, 0, 0}), 0.0f);              // softCells / 2 outside: nothing
}

TEST(Shapes, ConeRadiusVariesLinearlyAndCapsIncludeTheEndCells) {
    const Shape cone = Shape::cone({0, 0, 0}, {0, 10, 0}, 4.0f, 2.0f);
    // Halfway up the radius is 3; the surface sits half a cell beyond it
    // (cells are points, and the shape covers each end cell whole).
    EXPECT_NEAR(cone.insideCells({3.5f, 5, 0}), 0.0f, kFloatTol);
    EXPECT_NEAR(cone.insideCells({0, 5, 0}), 3.5f, kFloatTol);
    // On the axis near an end, the cap is the nearer surface: half a cell beyond the end cell.
    EXPECT_NEAR(cone.insideCells({0, 0, 0}), 0.5f, kFloatTol);
    EXPECT_NEAR(cone.insideCells({0, 10.5f, 0}), 0.0f, kFloatTol);
    // A cylinder is a cone with equal radii.
    const Shape cyl = Shape::cylinder({0, 0, 0}, {0, 10, 0}, 2.0f);
    EXPECT_EQ(cyl.type, splatfx::ShapeType::Cone);
    EXPECT_NEAR(cyl.insideCells({2.5f, 3, 0}), 0.0f, kFloatTol);
    EXPECT_NEAR(cyl.insideCells({2.5f, 8, 0}), 0.0f, kFloatTol);
}

TEST(Shapes, StrongestShapeWinsWhereShapesOverlap) {
    Shape faint = Shape::box({0, 0, 0}, {4, 4, 4});
    faint.opacity = 0.25f;
    faint.softCells = kSharp;
    Shape strong = Shape::box({2, 2, 2}, {2, 2, 2});
    strong.softCells = kSharp;
    auto g = voxelizeShapes({faint, strong}, {.dims = {5, 5, 5}, .opacity = 1.0f});
    ASSERT_TRUE(g) << g.error();
    ASSERT_EQ(g->voxels.size(), 125u);
    for (const splatfx::Voxel& v : g->voxels) EXPECT_EQ(v.opacity, v.cell == glm::ivec3(2) ? 1.0f : 0.25f);
}

TEST(Shapes, NoShapesFillsEveryCellAndFadeRunsAlongTheAxis) {
    const glm::ivec3 dims{3, 5, 2};
    auto g = voxelizeShapes({}, {.dims = dims, .opacity = 0.8f, .fadeAxis = {0, 2, 0}, .fadeTo = 0.25f});
    ASSERT_TRUE(g) << g.error();
    ASSERT_EQ(g->voxels.size(), 30u);
    for (const splatfx::Voxel& v : g->voxels) {
        const double t = v.cell.y / 4.0; // position along +y over the lattice
        EXPECT_NEAR(v.opacity, 0.8 * (1.0 + (0.25 - 1.0) * t), kFloatTol);
        EXPECT_NEAR(v.colorCoord, t, kFloatTol);
    }
    // A diagonal axis: the colour coordinate is 0 at one corner and 1 at the opposite one.
    auto d = voxelizeShapes({}, {.dims = {4, 4, 4}, .fadeAxis = {1, 1, 1}});
    ASSERT_TRUE(d) << d.error();
    for (const splatfx::Voxel& v : d->voxels) EXPECT_NEAR(v.colorCoord, (v.cell.x + v.cell.y + v.cell.z) / 9.0, kFloatTol);
}

TEST(Shapes, CellsFadedToZeroAreLeftOut) {
    auto g = voxelizeShapes({}, {.dims = {2, 4, 2}, .opacity = 1.0f, .fadeTo = 0.0f});
    ASSERT_TRUE(g) << g.error();
    EXPECT_EQ(g->voxels.size(), 2u * 3u * 2u); // the top layer fades to exactly 0
    for (const splatfx::Voxel& v : g->voxels) EXPECT_LT(v.cell.y, 3);
}

TEST(Shapes, ShapesThatMissTheLatticeAreRefused) {
    auto away = voxelizeShapes({Shape::sphere({40, 40, 40}, 1.0f)}, {.dims = {3, 3, 3}});
    ASSERT_FALSE(away);
    EXPECT_EQ(away.error(), "the shapes cover no cell of the lattice (dims) at non-zero opacity");
    auto flat = voxelizeShapes({Shape::cone({1, 1, 1}, {1, 1, 1}, 2.0f, 2.0f)}, {.dims = {3, 3, 3}});
    ASSERT_FALSE(flat);
    EXPECT_NE(flat.error().find("cover no cell"), std::string::npos) << flat.error();
}

TEST(Shapes, BadInputNamesTheField) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    auto expect = [](const splatfx::Result<splatfx::Grid>& r, const char* fragment) {
        ASSERT_FALSE(r) << "accepted; expected an error naming " << fragment;
        EXPECT_NE(r.error().find(fragment), std::string::npos) << r.error();
    };
    expect(voxelizeShapes({}, {.dims = {3, 0, 3}}), "VoxelizeDesc.dims.y must be at least 1");
    expect(voxelizeShapes({}, {.dims = {4096, 4096, 4096}}), "VoxelizeDesc.dims asks for");
    expect(voxelizeShapes({}, {.opacity = nan}), "VoxelizeDesc.opacity");
    expect(voxelizeShapes({}, {.opacity = 1.5f}), "VoxelizeDesc.opacity must be in [0, 1]");
    expect(voxelizeShapes({}, {.fadeTo = -0.1f}), "VoxelizeDesc.fadeTo");
    expect(voxelizeShapes({}, {.fadeAxis = {0, 0, 0}}), "VoxelizeDesc.fadeAxis");
    expect(voxelizeShapes({}, {.fadeAxis = {nan, 1, 0}}), "VoxelizeDesc.fadeAxis");
    expect(voxelizeShapes({}, {.spacing = {1, 0, 1}}), "spacing.y");
    Shape soft = Shape::sphere({1, 1, 1}, 1.0f);
    soft.softCells = 0.0f;
    expect(voxelizeShapes({Shape::box({0, 0, 0}, {1, 1, 1}), soft}), "shapes[1].softCells");
    expect(voxelizeShapes({Shape::box({nan, 0, 0}, {1, 1, 1})}), "shapes[0].from/to");
    expect(voxelizeShapes({Shape::sphere({1, 1, 1}, -1.0f)}), "shapes[0].radiusFrom");
    Shape bright = Shape::box({0, 0, 0}, {1, 1, 1});
    bright.opacity = 2.0f;
    expect(voxelizeShapes({bright}), "shapes[0].opacity");
}

TEST(FlameShape, DenseAtTheBaseCentreThinningUpwardsAndEmptyAtTheCorners) {
    const glm::ivec3 dims{7, 20, 5};
    EXPECT_NEAR(splatfx::flameOpacity({3, 0, 2}, dims), 1.0f, kFloatTol);  // base, on the axis
    EXPECT_NEAR(splatfx::flameOpacity({3, 19, 2}, dims), 0.4f, kFloatTol); // top, on the axis: 1 - 0.6
    // Base corner: radius sqrt((3/3.5)^2 + (2/2.5)^2) = 1.17 is beyond the soft edge of the full width.
    EXPECT_EQ(splatfx::flameOpacity({0, 0, 0}, dims), 0.0f);
    // Along the axis it only thins; across a layer it only falls outwards.
    for (int y = 1; y < dims.y; ++y) EXPECT_LT(splatfx::flameOpacity({3, y, 2}, dims), splatfx::flameOpacity({3, y - 1, 2}, dims));
    for (int x = 4; x < dims.x; ++x) EXPECT_LE(splatfx::flameOpacity({x, 5, 2}, dims), splatfx::flameOpacity({x - 1, 5, 2}, dims));
    // topHeight 0.5: the flame ends halfway up (nothing from there to the top).
    EXPECT_EQ(splatfx::flameOpacity({3, 19, 2}, dims, 0.5f), 0.0f);
    EXPECT_GT(splatfx::flameOpacity({3, 9, 2}, dims, 0.5f), 0.0f);
}

TEST(FlameShape, FirePresetIsTheFlameScaledByItsOpacity) {
    splatfx::Materials m(splatfx::Footprint{});
    auto fire = splatfx::presets::fire(m, {.dims = {7, 20, 5}, .opacity = 0.55f});
    ASSERT_TRUE(fire) << fire.error();
    const splatfx::Grid& g = fire->grid();
    // The cells outside the flame (opacity 0) are left out of the effect.
    std::size_t inside = 0;
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 20; ++y)
            for (int x = 0; x < 7; ++x) inside += splatfx::flameOpacity({x, y, z}, {7, 20, 5}) > 0.0f ? 1 : 0;
    EXPECT_EQ(g.voxels.size(), inside);
    for (const splatfx::Voxel& v : g.voxels) EXPECT_EQ(v.opacity, 0.55f * splatfx::flameOpacity(v.cell, {7, 20, 5}));
}
