// Hard cases of solver obstacles (docs/STABILITY.md, "Solver obstacles"):
// each test is named after what would go wrong.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/solver.hpp"

#include "obstacle_helpers.hpp"

using namespace splatfx;
using namespace obstacle_test;

namespace {

double planeFlux(const FluidSolver& s, int j) {
    double f = 0.0;
    for (int z = 0; z < s.dims().z; ++z)
        for (int x = 0; x < s.dims().x; ++x) f += s.faceVelocity(1, {x, j, z});
    return f;
}

} // namespace

TEST(StabilityObstacles, ObstacleFillingTheWholeGridLeavesNothingToSolve) {
    // Every cell solid: no unknowns (CG must not divide 0 by 0), the emitter
    // finds no fluid cell, every face carries the obstacle's velocity (0, at
    // rest), the sparse output is empty.
    auto s = FluidSolver::create({.dims = {5, 6, 4}, .spacing = glm::vec3(0.5f)});
    ASSERT_TRUE(s.ok());
    s->addEmitter({.desc = {.offset = {0, 1, 0}, .radius = 2.0f}});
    ASSERT_TRUE(s->addObstacle({.desc = {.shape = ObstacleShape::Box, .size = glm::vec3(50.0f)}}).ok());
    EXPECT_EQ(s->stats().solidCells, s->density().size());
    for (int i = 0; i < 10; ++i) s->step(0.1);
    EXPECT_TRUE(allFinite(*s));
    EXPECT_EQ(s->totalDensity(), 0.0);
    EXPECT_EQ(s->maxSpeed(), 0.0f);
    EXPECT_EQ(s->stats().lastPressureIterations, 0);
    Grid g;
    s->toGrid(g, {});
    EXPECT_TRUE(g.voxels.empty());
}

TEST(StabilityObstacles, OneCellGapCarriesTheWholeFlux) {
    // A wall across a vertical channel with one open cell. Every horizontal
    // plane carries the same flux F (side walls shut, div ~ 0), and in the
    // wall's planes the gap's face is the only one that is not a wall, so it
    // must carry F alone (here 30x the stream speed). Tolerance as
    // Obstacles.ChannelFlowAroundABox...: j * h * (cells in a layer) * max |div|
    // bound, with max |div| <= lastResidual * ||div u0|| + float storage.
    auto s = FluidSolver::create({.dims = {6, 10, 5},
                                  .spacing = glm::vec3(0.5f),
                                  .buoyancy = 0.0f,
                                  .pressureIterations = 2000,
                                  .pressureTolerance = 1e-10f,
                                  .closedFloor = false,
                                  .closedWalls = true,
                                  .closedCeiling = false});
    ASSERT_TRUE(s.ok());
    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {0, 5, 0}, {5, 5, 1})).ok());
    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {0, 5, 3}, {5, 5, 4})).ok());
    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {0, 5, 2}, {1, 5, 2})).ok());
    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {3, 5, 2}, {5, 5, 2})).ok());
    ASSERT_EQ(s->stats().solidCells, 29u);
    s->setUniformVelocity({0, 1, 0});
    s->step(0.0);
    EXPECT_LE(s->stats().lastResidual, 1e-8f);
    // ||div u0|| <= sqrt(30) * 2 / h: at most one blocked face per cell of the two layers beside the wall.
    const double div0 = std::sqrt(60.0) * 2.0 / 0.5;
    const double tolDiv = double(s->stats().lastResidual) * div0 + 6.0 * std::ldexp(1.0, -24) * s->maxSpeed() / 0.5;
    const double F = planeFlux(*s, 0);
    EXPECT_GT(F, 1.0);
    EXPECT_NEAR(s->faceVelocity(1, {2, 5, 2}), F, 5 * 0.5 * 30 * tolDiv);
    EXPECT_NEAR(s->faceVelocity(1, {2, 6, 2}), F, 6 * 0.5 * 30 * tolDiv);
    EXPECT_NEAR(planeFlux(*s, 10), F, 10 * 0.5 * 30 * tolDiv);
}

TEST(StabilityObstacles, ObstacleFasterThanACellPerStepStaysFiniteAndTight) {
    // A one-cell plate sweeping 3 cells per step through a plume: it jumps
    // over cells between voxelizations. Fields stay finite and non-negative,
    // no solid cell ever holds material, and the projection still converges
    // (the wall speed, 30 cells/s, is far above the gas's).
    auto s = FluidSolver::create({.dims = {24, 10, 6}, .spacing = glm::vec3(0.5f), .buoyancy = 5.0f, .pressureIterations = 300});
    ASSERT_TRUE(s.ok());
    s->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.5f, .density = 1.0f, .temperature = 2.0f, .rate = 10.0f}});
    const Motion sweep({{.timeSec = 0, .pose = {.position = {-6, 0, 0}}}, {.timeSec = 0.8, .pose = {.position = {6, 0, 0}}}});
    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {12, 0, 0}, {12, 6, 5}, Slip::None, sweep)).ok());
    for (int i = 0; i < 40; ++i) {
        s->step(0.1 / 3.0); // 0.5 world units = 1 cell per 1/30 s... times 3: 15 units/s over 0.8 s
        ASSERT_TRUE(allFinite(*s)) << "step " << i;
        for (int z = 0; z < 6; ++z)
            for (int y = 0; y < 10; ++y)
                for (int x = 0; x < 24; ++x)
                    if (s->solid({x, y, z})) {
                        ASSERT_EQ(s->density()[s->cellIndex({x, y, z})], 0.0f);
                    }
    }
    EXPECT_GT(s->stats().displacedDensity, 0.0);
}

TEST(StabilityObstacles, ObstacleTouchingTheGridBoundaryKeepsItsBoundaryFacesShut) {
    // A box that sticks out through the open ceiling and the open +x side:
    // the domain-boundary faces of its cells are walls too (no gas in or out
    // through the obstacle), and a rising plume beside it stays finite with
    // none inside it.
    auto s = FluidSolver::create({.dims = {10, 8, 6}, .spacing = glm::vec3(0.5f), .buoyancy = 6.0f, .closedWalls = false});
    ASSERT_TRUE(s.ok());
    s->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.0f, .density = 1.0f, .temperature = 2.0f, .rate = 8.0f}});
    const Obstacle corner{.desc = {.shape = ObstacleShape::Box, .size = {4, 3, 8}, .transform = glm::translate(glm::mat4(1.0f), {3.5f, 4.0f, 0})}};
    ASSERT_TRUE(s->addObstacle(corner).ok());
    ASSERT_TRUE(s->solid({9, 7, 0}) && s->solid({9, 7, 5}));
    for (int i = 0; i < 30; ++i) {
        s->step(0.1);
        ASSERT_TRUE(allFinite(*s));
        for (int z = 0; z < 6; ++z) {
            ASSERT_EQ(s->faceVelocity(1, {9, 8, z}), 0.0f) << "ceiling face of the obstacle";
            ASSERT_EQ(s->faceVelocity(0, {10, 7, z}), 0.0f) << "side face of the obstacle";
        }
    }
    EXPECT_GT(s->totalDensity(), 1.0);
}

TEST(StabilityObstacles, MeshSurfaceThroughCellCentresIsDeterministicAndBetweenOpenAndClosed) {
    // A mesh cube whose faces pass exactly through cell centres (and whose
    // corners sit on them): there the winding number is undefined (solid
    // angles of triangles seen edge-on: atan2(0, x)). The solid set must
    // contain the open cube's cells, stay inside the closed cube's, and be
    // the same on a second run.
    auto run = [] {
        auto s = FluidSolver::create({.dims = {9, 9, 9}});
        const glm::vec3 h(2.0f);
        const glm::vec3 v[8] = {{-h.x, -h.y, -h.z}, {h.x, -h.y, -h.z}, {h.x, h.y, -h.z}, {-h.x, h.y, -h.z},
                                {-h.x, -h.y, h.z},  {h.x, -h.y, h.z},  {h.x, h.y, h.z},  {-h.x, h.y, h.z}};
        const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                              {3, 6, 2}, {3, 7, 6}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
        std::vector<glm::vec3> tris;
        for (const auto& t : f)
            for (int i : t) tris.push_back(v[i]);
        // Centre the cube on cell (4, 4, 4): local (0, 4, 0).
        Obstacle cube;
        cube.desc.shape = ObstacleShape::Mesh;
        cube.desc.transform = glm::translate(glm::mat4(1.0f), {0, 4, 0});
        cube.desc.triangles = tris;
        EXPECT_TRUE(s->addObstacle(cube).ok());
        std::vector<bool> solid;
        for (int z = 0; z < 9; ++z)
            for (int y = 0; y < 9; ++y)
                for (int x = 0; x < 9; ++x) {
                    const glm::ivec3 c{x, y, z};
                    const glm::ivec3 r = glm::abs(c - glm::ivec3(4));
                    const int m = std::max({r.x, r.y, r.z});
                    if (m < 2) {
                        EXPECT_TRUE(s->solid(c)) << "interior " << x << y << z;
                    } else if (m > 2) {
                        EXPECT_FALSE(s->solid(c)) << "exterior " << x << y << z;
                    }
                    solid.push_back(s->solid(c));
                }
        return solid;
    };
    EXPECT_EQ(run(), run());
}

TEST(StabilityObstacles, RotatingObstacleWallVelocityIsOmegaCrossR) {
    // A box spinning about y at omega: the velocity imposed is the
    // displacement over the substep / dt, a chord of the circle: it turns by
    // omega dt / 2 from the tangent and is shorter by (omega dt)^2 / 24, so
    // |v - omega x r| <= |omega x r| (omega dt / 2 + (omega dt)^2 / 24),
    // plus float positions (4 * 8 * 2^-24 / dt, see the moving-box test).
    // At an interior solid cell the cell velocity is exact for a linear
    // field (faces between solid cells carry the mean of the two cells).
    const float omega = 1.0f;
    const double dt = 0.02;
    auto s = FluidSolver::create({.dims = {12, 6, 12}, .spacing = glm::vec3(0.5f), .buoyancy = 0.0f});
    ASSERT_TRUE(s.ok());
    const Motion spin({}, {.spinAxis = {0, 1, 0}, .spinRadPerSec = omega});
    Obstacle paddle;
    paddle.desc.size = {4, 2, 2.5f};
    paddle.desc.transform = glm::translate(glm::mat4(1.0f), {0, 1.5f, 0});
    paddle.motion = spin;
    ASSERT_TRUE(s->addObstacle(paddle).ok());
    s->step(dt);
    int checked = 0;
    for (int z = 1; z < 11; ++z)
        for (int y = 1; y < 5; ++y)
            for (int x = 1; x < 11; ++x) {
                const glm::ivec3 c{x, y, z};
                bool interior = s->solid(c);
                for (int a = 0; a < 3 && interior; ++a)
                    for (int side = -1; side <= 1; side += 2) {
                        glm::ivec3 nb = c;
                        nb[a] += side;
                        interior = interior && s->solid(nb);
                    }
                if (!interior) continue;
                const glm::vec3 p = s->localPosition(c);
                const glm::vec3 expected(omega * p.z, 0.0f, -omega * p.x);
                const float w = omega * float(dt);
                const float tol = glm::length(expected) * (0.5f * w + w * w / 24.0f) + float(4.0 * 8.0 * std::ldexp(1.0, -24) / dt);
                EXPECT_LE(glm::length(s->velocityAt(c) - expected), tol) << x << "," << y << "," << z;
                ++checked;
            }
    EXPECT_GT(checked, 10);
}

TEST(StabilityObstacles, ZeroStepWithAMovingObstacleDividesByNothing) {
    // dt = 0: the displacement over the substep is 0 / 0; the obstacle is
    // taken at rest (wall velocity exactly 0), nothing else changes.
    auto s = FluidSolver::create({.dims = {8, 6, 6}, .buoyancy = 0.0f});
    ASSERT_TRUE(s.ok());
    for (float& d : s->density()) d = 0.5f;
    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {2, 1, 1}, {4, 3, 3}, Slip::None, Motion({}, {.velocity = {50, 0, 0}}))).ok());
    const std::vector<float> before = s->density();
    for (int i = 0; i < 3; ++i) s->step(0.0);
    EXPECT_EQ(s->density(), before);
    EXPECT_EQ(s->maxSpeed(), 0.0f);
}

TEST(StabilityObstacles, ClosedPocketSqueezedByAPistonStillConverges) {
    // A piston across a closed box moving along x: both pockets are closed
    // and the piston pushes gas into one and out of the other, an
    // inconsistent (singular) pressure system. Each pocket's mean divergence
    // is removed, so CG still converges to the requested residual, and the
    // gas in each pocket keeps that (unavoidable) mean divergence only.
    auto s = FluidSolver::create({.dims = {12, 5, 5},
                                  .spacing = glm::vec3(0.5f),
                                  .buoyancy = 0.0f,
                                  .pressureIterations = 500,
                                  .pressureTolerance = 1e-8f,
                                  .closedWalls = true,
                                  .closedCeiling = true});
    ASSERT_TRUE(s.ok());
    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {5, 0, 0}, {5, 4, 4}, Slip::Free, Motion({}, {.velocity = {0.5f, 0, 0}}))).ok());
    for (int i = 0; i < 5; ++i) {
        s->step(0.05);
        EXPECT_LE(s->stats().lastResidual, 1e-8f) << "step " << i;
        EXPECT_TRUE(allFinite(*s));
    }
}

TEST(StabilityObstacles, ObstacleOutsideTheGridChangesNothing) {
    // An obstacle that covers no cell: the run is bit for bit the run without
    // it (the same arithmetic in the same order), not merely close.
    auto run = [](bool withObstacle) {
        auto s = FluidSolver::create({.dims = {8, 10, 6}, .spacing = glm::vec3(0.5f), .buoyancy = 5.0f, .closedWalls = false});
        s->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.0f}});
        Obstacle far;
        far.desc.transform = glm::translate(glm::mat4(1.0f), {100, 0, 0});
        if (withObstacle) {
            EXPECT_TRUE(s->addObstacle(far).ok());
        }
        for (int i = 0; i < 20; ++i) s->step(0.1);
        EXPECT_EQ(s->stats().solidCells, 0u);
        return s->density();
    };
    EXPECT_EQ(run(true), run(false));
}
