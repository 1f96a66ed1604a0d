// More hard cases of solver obstacles (docs/STABILITY.md, "Solver obstacles"):
// degenerate and extreme geometry, extreme steps, obstacles switched on and
// off or leaving the grid. Each test is named after what would go wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/solver.hpp"

#include "obstacle_helpers.hpp"

using namespace splatfx;
using namespace obstacle_test;

namespace {

constexpr double kUlp = 0x1p-24; // float's unit roundoff (half an ulp of 1)

std::size_t countSolid(const FluidSolver& s) {
    std::size_t n = 0;
    const glm::ivec3 d = s.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) n += s.solid({x, y, z}) ? 1 : 0;
    return n;
}

bool noDensityInSolids(const FluidSolver& s) {
    const glm::ivec3 d = s.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                if (s.solid({x, y, z}) && s.density()[s.cellIndex({x, y, z})] != 0.0f) return false;
    return true;
}

// Sum of squared face velocities over every face (the projection's energy).
double faceEnergy(const FluidSolver& s) {
    double e = 0.0;
    for (int a = 0; a < 3; ++a) {
        glm::ivec3 fd = s.dims();
        fd[a] += 1;
        for (int z = 0; z < fd.z; ++z)
            for (int y = 0; y < fd.y; ++y)
                for (int x = 0; x < fd.x; ++x) {
                    const double u = s.faceVelocity(a, {x, y, z});
                    e += u * u;
                }
    }
    return e;
}

} // namespace

TEST(ObstacleHardCases, ObstacleFarLargerThanTheGridCoversEveryCell) {
    // A ground box or a sky sphere given in kilometres (or 10^30 units) around
    // a grid of a few units: its bounds in lattice coordinates are far beyond
    // int's range. Converted to int unclamped (undefined behaviour; INT_MIN on
    // x86) they left the cell range empty: the obstacle covered nothing.
    // Boundary-inclusive inside tests give every cell, exactly.
    auto s = FluidSolver::create({.dims = {6, 5, 4}, .spacing = glm::vec3(0.01f)});
    ASSERT_TRUE(s.ok());
    const std::size_t all = s->density().size();
    const glm::mat4 below = glm::translate(glm::mat4(1.0f), {0.0f, -5e29f, 0.0f});
    const ObstacleDesc huge[] = {
        {.shape = ObstacleShape::Box, .size = glm::vec3(1e10f)},
        {.shape = ObstacleShape::Box, .size = glm::vec3(3e38f)},
        {.shape = ObstacleShape::Sphere, .size = glm::vec3(1e30f)}, // radius^2 overflows float: inside everywhere, as it should
        {.shape = ObstacleShape::Cylinder, .size = glm::vec3(1e30f), .transform = below},
        {.shape = ObstacleShape::Plane, .size = glm::vec3(1e30f), .transform = glm::translate(glm::mat4(1.0f), {0.0f, 1e3f, 0.0f})},
    };
    for (const ObstacleDesc& d : huge) {
        s->clearObstacles();
        ASSERT_TRUE(s->addObstacle({.desc = d}).ok());
        EXPECT_EQ(s->stats().solidCells, all) << "shape " << int(d.shape) << " size " << d.size.x;
        EXPECT_EQ(countSolid(*s), all);
    }
    // The same huge box 10^30 units away covers nothing, without overflow.
    s->clearObstacles();
    ASSERT_TRUE(s->addObstacle({.desc = {.size = glm::vec3(1e10f), .transform = glm::translate(glm::mat4(1.0f), glm::vec3(1e30f))}}).ok());
    EXPECT_EQ(s->stats().solidCells, 0u);
}

TEST(ObstacleHardCases, MicroStepWithAMovingObstacleImposesItsVelocityNotRoundingOverDt) {
    // A box that has moved at V = 1.5 units/s for 10 s (its motion's position
    // near 15, Motion's float time near 10: an ulp of 10^-6), stepped by
    // 10^-9 s or 10^-7 s (a host's leftover remainder). The displacement over
    // such a step is below float's resolution: displacement / dt was exactly 0
    // (the wall stood still for the step and the gas's energy about it halved)
    // or a multiple of 10^3 units/s. The velocity is the displacement over
    // max(dt, 1 ms): V within the rounding of the positions differenced,
    // each through Motion's float time (V t 2^-24) and at most two float
    // matrix products of magnitude <= 16 (2 x 16 x 2^-24), over that interval.
    const float V = 1.5f;
    auto s = FluidSolver::create({.dims = {20, 8, 6}, .spacing = glm::vec3(0.5f), .buoyancy = 0.0f, .velocityDamping = 0.0f, .closedWalls = false});
    ASSERT_TRUE(s.ok());
    Obstacle box = boxOverCells(*s, {6, 2, 2}, {8, 5, 3}, Slip::Free, Motion({}, {.velocity = {V, 0, 0}}));
    box.desc.transform = glm::translate(glm::mat4(1.0f), {-15.0f, 0.0f, 0.0f}) * box.desc.transform; // over cells 6..8 again at t = 10 s
    ASSERT_TRUE(s->addObstacle(box).ok());
    for (int i = 0; i < 10; ++i) s->step(1.0);
    ASSERT_EQ(s->stats().solidCells, 24u);
    for (double dt : {1e-9, 1e-7}) {
        FluidSolver c = *s;
        c.step(dt);
        const double t = c.time(), interval = 1e-3;
        const float tol = float(2.0 * (V * t + 2.0 * 16.0) * kUlp / interval);
        int walls = 0;
        for (int z = 2; z <= 3; ++z)
            for (int y = 2; y <= 5; ++y) {
                EXPECT_NEAR(c.faceVelocity(0, {6, y, z}), V, tol) << "dt " << dt; // the box's -x face
                EXPECT_NEAR(c.faceVelocity(0, {9, y, z}), V, tol) << "dt " << dt; // its +x face
                walls += 2;
            }
        EXPECT_EQ(walls, 16);
        EXPECT_TRUE(allFinite(c));
    }
}

TEST(ObstacleHardCases, AnalyticSurfacesThroughCellCentresCountTheirBoundaryInside) {
    // Surfaces passing exactly through cell centres (every coordinate a
    // multiple of the 0.5 spacing, exact in float): boundary points count as
    // inside (obstacle.hpp), so the solid cells are the lattice points in the
    // closed shape, counted in closed form. Radius 2 cells: i^2 + j^2 + k^2 <= 4
    // holds at 33 points (1 + 6 + 12 + 8 + 6), i^2 + k^2 <= 4 at 13.
    auto s = FluidSolver::create({.dims = {9, 9, 9}, .spacing = glm::vec3(0.5f)});
    ASSERT_TRUE(s.ok());
    const glm::vec3 centre = s->localPosition({4, 4, 4});
    struct Case {
        ObstacleDesc desc;
        std::size_t cells;
    };
    const Case cases[] = {
        {{.shape = ObstacleShape::Sphere, .size = glm::vec3(2.0f), .transform = glm::translate(glm::mat4(1.0f), centre)}, 33},
        {{.shape = ObstacleShape::Box, .size = glm::vec3(2.0f), .transform = glm::translate(glm::mat4(1.0f), centre)}, 5 * 5 * 5},
        // y from the centre of layer 3 to that of layer 5: three layers of 13.
        {{.shape = ObstacleShape::Cylinder, .size = {2.0f, 1.0f, 2.0f}, .transform = glm::translate(glm::mat4(1.0f), s->localPosition({4, 3, 4}))}, 3 * 13},
        // |x|, |z| <= 2 cells, layers 0..3 below its plane through the centres of layer 3.
        {{.shape = ObstacleShape::Plane, .size = {2.0f, 1.0f, 2.0f}, .transform = glm::translate(glm::mat4(1.0f), s->localPosition({4, 3, 4}))}, 5 * 4 * 5},
    };
    for (const Case& c : cases) {
        s->clearObstacles();
        ASSERT_TRUE(s->addObstacle({.desc = c.desc}).ok());
        EXPECT_EQ(s->stats().solidCells, c.cells) << "shape " << int(c.desc.shape);
    }
}

TEST(ObstacleHardCases, CheckerboardOfObstaclesIsolatesEveryFluidCellAndNothingMoves) {
    // 256 one-cell obstacles on the odd cells of a closed 8^3 box: every fluid
    // cell is its own closed pressure region (256 singular blocks) and every
    // face is a wall. Buoyancy pushes, nothing may move: speed exactly 0, CG
    // given a zero right side (no iterations), and each fluid cell's density
    // the emitter's implicit relaxation in closed form (advection at zero
    // velocity reads the cell itself: weight exactly 1). The closed form is
    // the same float expression: EXPECT_FLOAT_EQ's 4 ulps allow the compiler
    // another order of the operations.
    const float dt = 0.1f;
    auto s = FluidSolver::create({.dims = {8, 8, 8}, .spacing = glm::vec3(0.5f), .buoyancy = 5.0f, .closedWalls = true, .closedCeiling = true});
    ASSERT_TRUE(s.ok());
    const EmitterDesc e{.offset = {0.25f, 2.0f, 0.25f}, .radius = 1.6f, .density = 1.0f, .temperature = 2.0f, .rate = 4.0f};
    s->addEmitter({.desc = e});
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x)
                if ((x + y + z) % 2 == 1) {
                    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {x, y, z}, {x, y, z})).ok());
                }
    ASSERT_EQ(s->obstacles().size(), 256u);
    ASSERT_EQ(s->stats().solidCells, 256u);
    const int steps = 5;
    for (int i = 0; i < steps; ++i) s->step(dt);
    EXPECT_EQ(s->maxSpeed(), 0.0f);
    EXPECT_EQ(s->stats().lastPressureIterations, 0);
    int fed = 0;
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                const float got = s->density()[s->cellIndex({x, y, z})];
                if (s->solid({x, y, z})) {
                    ASSERT_EQ(got, 0.0f);
                    continue;
                }
                const glm::vec3 w = s->localPosition({x, y, z}) - e.offset;
                const float r2 = glm::dot(w, w) / (e.radius * e.radius);
                const float weight = r2 < 1.0f ? (1.0f - r2) * (1.0f - r2) : 0.0f;
                float want = 0.0f;
                for (int i = 0; i < steps && weight > 0.0f; ++i) {
                    const float a = dt * e.rate * weight;
                    want = std::max(want, (want + a * e.density) / (1.0f + a));
                }
                EXPECT_FLOAT_EQ(got, want) << x << "," << y << "," << z;
                fed += want > 0.0f ? 1 : 0;
            }
    EXPECT_GT(fed, 10);
}

TEST(ObstacleHardCases, EmitterBuriedInAnObstacleEmitsNothingAndOneTouchingItFeedsOnlyFluidCells) {
    // An emitter whose whole region lies inside an obstacle: no material may
    // appear anywhere (it skips solid cells; nothing is handed on, since no
    // solid cell ever held any). One centred on the obstacle's face: only its
    // fluid half is fed, each cell by the implicit relaxation in closed form
    // (no buoyancy: the gas stays at rest, advection reads each cell itself;
    // 4 ulps as the checkerboard test).
    const float dt = 0.1f;
    auto make = [](glm::vec3 offset) {
        auto s = FluidSolver::create({.dims = {9, 9, 9}, .spacing = glm::vec3(0.5f), .buoyancy = 0.0f});
        EXPECT_TRUE(s.ok());
        s->addEmitter({.desc = {.offset = offset, .radius = 0.9f, .density = 1.0f, .temperature = 2.0f, .rate = 6.0f}});
        EXPECT_TRUE(s->addObstacle(boxOverCells(*s, {2, 2, 2}, {6, 6, 6})).ok());
        return std::move(*s);
    };
    FluidSolver buried = make(glm::vec3(0.0f, 2.0f, 0.0f)); // cell (4, 4, 4): 0.9 < the 1.0 to the box's faces
    for (int i = 0; i < 10; ++i) buried.step(dt);
    EXPECT_EQ(buried.totalDensity(), 0.0);
    EXPECT_EQ(buried.stats().displacedDensity, 0.0);
    for (float t : buried.temperature()) ASSERT_EQ(t, 0.0f);

    const glm::vec3 onFace = buried.localPosition({4, 6, 4}) + glm::vec3(0.0f, 0.25f, 0.0f); // the box's top face
    FluidSolver touching = make(onFace);
    touching.step(dt);
    int fed = 0;
    for (int z = 0; z < 9; ++z)
        for (int y = 0; y < 9; ++y)
            for (int x = 0; x < 9; ++x) {
                const float got = touching.density()[touching.cellIndex({x, y, z})];
                const glm::vec3 w = touching.localPosition({x, y, z}) - onFace;
                const float r2 = glm::dot(w, w) / (0.9f * 0.9f);
                if (touching.solid({x, y, z}) || r2 >= 1.0f) {
                    ASSERT_EQ(got, 0.0f) << x << "," << y << "," << z;
                    continue;
                }
                const float a = dt * 6.0f * (1.0f - r2) * (1.0f - r2);
                EXPECT_FLOAT_EQ(got, a / (1.0f + a)) << x << "," << y << "," << z;
                EXPECT_GE(y, 7);
                ++fed;
            }
    EXPECT_EQ(fed, 10) << "the 9 cells of layer 7 within 0.75 across, and (4, 8, 4)";
}

TEST(ObstacleHardCases, CoincidentObstaclesActAsOneBitForBit) {
    // The same moving no-slip box listed twice: the cells are the first one's,
    // so nothing may be counted, handed over or imposed twice: the run is bit
    // for bit the run with it listed once.
    auto run = [](int copies) {
        auto s = FluidSolver::create({.dims = {10, 10, 6}, .spacing = glm::vec3(0.5f), .buoyancy = 5.0f, .closedWalls = false});
        s->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.0f, .temperature = 2.0f, .rate = 8.0f}});
        const Motion drift({}, {.velocity = {0.8f, 0.0f, 0.0f}});
        for (int i = 0; i < copies; ++i) EXPECT_TRUE(s->addObstacle(boxOverCells(*s, {2, 3, 1}, {4, 5, 4}, Slip::None, drift)).ok());
        for (int i = 0; i < 20; ++i) s->step(0.1);
        return std::move(*s);
    };
    const FluidSolver one = run(1), two = run(2);
    EXPECT_EQ(two.stats().solidCells, one.stats().solidCells);
    EXPECT_EQ(two.stats().displacedDensity, one.stats().displacedDensity);
    EXPECT_GT(one.stats().displacedDensity, 0.0) << "the box must have driven through smoke";
    EXPECT_EQ(two.density(), one.density());
    EXPECT_EQ(two.temperature(), one.temperature());
    EXPECT_EQ(two.cellVelocities(), one.cellVelocities());
}

TEST(ObstacleHardCases, ObstacleThatLeftTheGridLeavesNoTraceBitForBit) {
    // A box driven out through the open +x side at 6 units/s: while leaving
    // it covers cells at the boundary (their material handed inwards); once
    // it covers none, the run must go on bit for bit as the same state with
    // the obstacle removed (no stale wall faces, no pressure regions split,
    // no sampling around solids that are gone).
    auto s = FluidSolver::create({.dims = {10, 8, 6}, .spacing = glm::vec3(0.5f), .buoyancy = 5.0f, .closedWalls = false});
    ASSERT_TRUE(s.ok());
    s->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.0f, .temperature = 2.0f, .rate = 8.0f}});
    ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {3, 2, 2}, {4, 3, 3}, Slip::None, Motion({}, {.velocity = {6.0f, 0.0f, 0.0f}}))).ok());
    int i = 0;
    for (; i < 40 && (i == 0 || s->stats().solidCells > 0); ++i) {
        s->step(0.05);
        ASSERT_TRUE(allFinite(*s) && noDensityInSolids(*s)) << "step " << i;
    }
    ASSERT_EQ(s->stats().solidCells, 0u) << "the box must have left within 2 s";
    EXPECT_GT(i, 3);
    FluidSolver removed = *s;
    removed.clearObstacles();
    for (int k = 0; k < 10; ++k) s->step(0.05), removed.step(0.05);
    EXPECT_EQ(s->density(), removed.density());
    EXPECT_EQ(s->cellVelocities(), removed.cellVelocities());
}

TEST(ObstacleHardCases, ObstacleSwitchedOnOverSmokeAndOffAgainLeavesNoGhost) {
    // A box switched on over a rising plume, off again, and on again. On: what
    // it covers is handed to fluid cells, so the total is unchanged up to the
    // float additions of the hand-over (each rounds by 2^-24 of the receiving
    // cell's value, at most the total: moved cells x 2^-24 x total). Off: the
    // cells it covered are gas again and fill from the plume below.
    auto s = FluidSolver::create({.dims = {8, 12, 6}, .spacing = glm::vec3(0.5f), .buoyancy = 5.0f, .closedWalls = false});
    ASSERT_TRUE(s.ok());
    s->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.0f, .temperature = 2.0f, .rate = 8.0f}});
    const Obstacle lid = boxOverCells(*s, {2, 4, 1}, {5, 5, 4});
    auto underLid = [&] {
        double d = 0.0;
        for (int z = 1; z <= 4; ++z)
            for (int y = 4; y <= 5; ++y)
                for (int x = 2; x <= 5; ++x) d += s->density()[s->cellIndex({x, y, z})];
        return d;
    };
    for (int round = 0; round < 2; ++round) {
        for (int i = 0; i < 10; ++i) s->step(0.1);
        const double covered = underLid(), before = s->totalDensity(), displaced = s->stats().displacedDensity;
        ASSERT_GT(covered, 0.1) << "the plume must have reached the lid's cells";
        ASSERT_TRUE(s->addObstacle(lid).ok());
        EXPECT_EQ(s->stats().solidCells, 32u);
        EXPECT_NEAR(s->stats().displacedDensity - displaced, covered, 32.0 * kUlp * before);
        EXPECT_NEAR(s->totalDensity(), before, 32.0 * kUlp * before);
        EXPECT_EQ(underLid(), 0.0);
        for (int i = 0; i < 10; ++i) s->step(0.1);
        EXPECT_TRUE(allFinite(*s) && noDensityInSolids(*s));
        s->clearObstacles();
        EXPECT_EQ(s->stats().solidCells, 0u);
        EXPECT_EQ(countSolid(*s), 0u);
    }
    for (int i = 0; i < 10; ++i) s->step(0.1);
    EXPECT_GT(underLid(), 0.1) << "the freed cells fill again";
}

TEST(ObstacleHardCases, ZeroDampingAndExtremeStepsAroundAnObstacleKeepTheMaximumPrinciple) {
    // No damping, no wind, no cooling (nothing relaxes the velocity), a static
    // deck, steps from 10^-6 s to 10 s: every update of density and
    // temperature is a convex combination or a relaxation towards the
    // emitter's targets, so each stays within [0, target]. Float: each
    // renormalized trilinear read is a ratio of two sums of 8 rounded
    // products (<= 18 ulps above its largest input) and the relaxation adds
    // 3: the bound grows by 21 ulps a step at most (32 used).
    for (double dt : {1e-6, 0.1, 10.0}) {
        auto s = FluidSolver::create({.dims = {8, 10, 6},
                                      .spacing = glm::vec3(0.5f),
                                      .buoyancy = 8.0f,
                                      .velocityDamping = 0.0f,
                                      .temperatureDissipation = 0.0f,
                                      .closedWalls = true});
        ASSERT_TRUE(s.ok());
        s->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.0f, .density = 1.0f, .temperature = 2.0f, .rate = 8.0f}});
        ASSERT_TRUE(s->addObstacle(boxOverCells(*s, {1, 6, 0}, {5, 6, 5})).ok());
        for (int i = 1; i <= 20; ++i) {
            s->step(dt);
            const double grow = 1.0 + 32.0 * i * kUlp;
            for (float d : s->density()) ASSERT_TRUE(d >= 0.0f && d <= grow) << "dt " << dt << " step " << i << ": " << d;
            for (float t : s->temperature()) ASSERT_TRUE(t >= 0.0f && t <= 2.0 * grow) << "dt " << dt << " step " << i << ": " << t;
            ASSERT_TRUE(std::isfinite(s->maxSpeed()) && noDensityInSolids(*s)) << "dt " << dt;
        }
        EXPECT_GT(s->totalDensity(), 0.0);
    }
}

TEST(ObstacleHardCases, ExtremelyAnisotropicCellsNeverGainEnergyInTheProjection) {
    // Cells 0.01 x 1 x 100 (Laplacian weights 10^4, 1, 10^-4: a condition
    // number CG cannot beat in 60 iterations) around a box in a uniform flow.
    // Stopped early, CG from zero still lowers the A-norm error at every
    // iteration, so the projected faces' energy (the field minus the gradient
    // part removed so far) never exceeds the field's before it; each stored
    // face rounds by 2^-24 of itself (2 x 2^-24 of the energy).
    FluidSolverDesc d{.dims = {8, 6, 6}, .spacing = {0.01f, 1.0f, 100.0f}, .buoyancy = 0.0f, .closedFloor = false, .closedWalls = false};
    FluidSolverDesc unprojected = d;
    unprojected.pressureIterations = 0;
    auto s = FluidSolver::create(d), s0 = FluidSolver::create(unprojected);
    ASSERT_TRUE(s.ok() && s0.ok());
    const Obstacle box = boxOverCells(*s, {3, 2, 2}, {4, 3, 3});
    ASSERT_TRUE(s->addObstacle(box).ok() && s0->addObstacle(box).ok());
    for (FluidSolver* f : {&*s, &*s0}) f->setUniformVelocity({1.0f, 1.0f, 1.0f}), f->step(0.0);
    const double before = faceEnergy(*s0), after = faceEnergy(*s);
    EXPECT_LE(after, before * (1.0 + 2.0 * kUlp));
    EXPECT_LT(after, before) << "the box blocks part of the flow: the projection must remove some";
    EXPECT_TRUE(allFinite(*s));
}

TEST(ObstacleHardCases, PointSizedObstacleOnACellCentreMarksExactlyThatCell) {
    // An obstacle of size 10^-30 (a sphere's radius^2 underflows to 0) is
    // solid only where a cell centre lies in it: exactly on a centre, that
    // one cell (its boundary counts as inside); between centres, none. The
    // one solid cell is a wall in a uniform flow: its six faces exactly 0.
    auto s = FluidSolver::create({.dims = {7, 7, 7}, .spacing = glm::vec3(0.5f), .buoyancy = 0.0f, .closedFloor = false, .closedWalls = false});
    ASSERT_TRUE(s.ok());
    const glm::vec3 c = s->localPosition({3, 3, 3});
    for (ObstacleShape shape : {ObstacleShape::Box, ObstacleShape::Sphere}) {
        s->clearObstacles();
        ASSERT_TRUE(s->addObstacle({.desc = {.shape = shape, .size = glm::vec3(1e-30f), .transform = glm::translate(glm::mat4(1.0f), c + glm::vec3(0.25f))}}).ok());
        EXPECT_EQ(s->stats().solidCells, 0u) << "between centres";
        s->clearObstacles();
        ASSERT_TRUE(s->addObstacle({.desc = {.shape = shape, .size = glm::vec3(1e-30f), .transform = glm::translate(glm::mat4(1.0f), c)}}).ok());
        EXPECT_EQ(s->stats().solidCells, 1u);
        EXPECT_TRUE(s->solid({3, 3, 3}));
    }
    s->setUniformVelocity({0.3f, 1.0f, -0.7f});
    s->step(0.0);
    for (int a = 0; a < 3; ++a) {
        glm::ivec3 hi(3);
        hi[a] += 1;
        EXPECT_EQ(s->faceVelocity(a, {3, 3, 3}), 0.0f) << "axis " << a;
        EXPECT_EQ(s->faceVelocity(a, hi), 0.0f) << "axis " << a;
    }
    EXPECT_TRUE(allFinite(*s));
}
