// The coarse-grid Eulerian solver (sec. 3.1): transport, conservation,
// unconditional stability, determinism, sparse output.
#include <gtest/gtest.h>

#include <cmath>

#include "sanitized.hpp"
#include "splatfx/solver.hpp"

using namespace splatfx;

namespace {

// A blob of density and heat in the lower middle of the domain.
void addBlob(FluidSolver& s, glm::ivec3 centre, float radiusCells, float density, float temperature) {
    const glm::ivec3 d = s.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                const float r = glm::length(glm::vec3(glm::ivec3(x, y, z) - centre));
                if (r > radiusCells) continue;
                const float w = 1.0f - r / (radiusCells + 1.0f);
                s.density()[s.cellIndex({x, y, z})] = density * w;
                s.temperature()[s.cellIndex({x, y, z})] = s.desc().ambientTemperature + temperature * w;
            }
}

FluidSolverDesc closedBox() {
    return {.dims = {12, 16, 10},
            .spacing = glm::vec3(0.5f),
            .buoyancy = 6.0f,
            .weight = 0.5f,
            .windWorld = {2, 0, 1},
            .windCoupling = 0.5f,
            .velocityDamping = 0.1f,
            .densityDissipation = 0.0f,
            .temperatureDissipation = 0.3f,
            .closedFloor = true,
            .closedWalls = true,
            .closedCeiling = true};
}

struct FieldCheck {
    bool finite = true;
    float minDensity = 0.0f, maxDensity = 0.0f, minTemp = 0.0f, maxTemp = 0.0f;
};

FieldCheck check(const FluidSolver& s) {
    FieldCheck c;
    c.minDensity = c.maxDensity = s.density()[0];
    c.minTemp = c.maxTemp = s.temperature()[0];
    for (std::size_t i = 0; i < s.density().size(); ++i) {
        const float d = s.density()[i], t = s.temperature()[i];
        c.finite = c.finite && std::isfinite(d) && std::isfinite(t);
        c.minDensity = std::min(c.minDensity, d), c.maxDensity = std::max(c.maxDensity, d);
        c.minTemp = std::min(c.minTemp, t), c.maxTemp = std::max(c.maxTemp, t);
    }
    c.finite = c.finite && std::isfinite(s.maxSpeed());
    for (const glm::vec3& v : s.cellVelocities()) c.finite = c.finite && std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    return c;
}

} // namespace

TEST(Solver, IntegerShiftTransportIsExact) {
    // Uniform flow of exactly one cell per step, no projection and no forces:
    // every backtrace lands on a cell centre, trilinear weights are exactly 1
    // and 0, so advection must copy the blob one cell along, bit for bit,
    // and the total is unchanged (tolerance 0).
    auto s = FluidSolver::create({.dims = {16, 8, 8},
                                  .spacing = glm::vec3(0.5f),
                                  .buoyancy = 0.0f,
                                  .velocityDamping = 0.0f,
                                  .temperatureDissipation = 0.0f,
                                  .pressureIterations = 0,
                                  .closedFloor = false});
    ASSERT_TRUE(s.ok()) << s.error();
    addBlob(*s, {3, 4, 4}, 1.5f, 1.0f, 0.0f);
    const std::vector<float> start = s->density();
    const double mass = s->totalDensity();
    s->setUniformVelocity({0.5f, 0.0f, 0.0f}); // 0.5 units / s = 1 cell / s
    for (int n = 1; n <= 6; ++n) {
        s->step(1.0);
        EXPECT_EQ(s->totalDensity(), mass) << "step " << n;
        for (int z = 0; z < 8; ++z)
            for (int y = 0; y < 8; ++y)
                for (int x = n; x < 16; ++x) ASSERT_EQ(s->density()[s->cellIndex({x, y, z})], start[s->cellIndex({x - n, y, z})]) << "step " << n;
    }
}

TEST(Solver, ConservesMassInAClosedBoxWithCorrection) {
    // Buoyant, windy, swirling flow in a closed box; no sources, no density
    // dissipation. With conserveMass each step rescales density in double
    // precision and rounds each cell to float: a relative error of at most
    // 2^-24 per cell, so at most 2^-24 of the total per step, plus the double
    // sums (n * 2^-53 relative, n = 1920 cells). Errors can accumulate over S
    // steps: tolerance S * (2^-24 + n * 2^-53).
    FluidSolverDesc d = closedBox();
    d.conserveMass = true;
    auto s = FluidSolver::create(d);
    ASSERT_TRUE(s.ok()) << s.error();
    addBlob(*s, {6, 3, 5}, 3.0f, 1.0f, 2.0f);
    const double mass = s->totalDensity();
    const int steps = 120;
    const double n = double(s->density().size());
    const double tol = steps * (std::ldexp(1.0, -24) + n * std::ldexp(1.0, -53));
    float peakSpeed = 0.0f;
    for (int i = 0; i < steps; ++i) {
        s->step(i % 3 == 0 ? 1.0 : 0.05); // mixes huge and small steps
        peakSpeed = std::max(peakSpeed, s->maxSpeed());
    }
    EXPECT_GT(peakSpeed, 1.0f) << "the flow must actually move material";
    EXPECT_LE(std::abs(s->totalDensity() / mass - 1.0), tol);
}

TEST(Solver, WithoutCorrectionSemiLagrangianDrifts) {
    // The same run without the correction: interpolation gains or loses
    // material, far beyond the tolerance above. This is why the correction
    // exists, and shows the conservation test can fail.
    auto s = FluidSolver::create(closedBox());
    ASSERT_TRUE(s.ok());
    addBlob(*s, {6, 3, 5}, 3.0f, 1.0f, 2.0f);
    const double mass = s->totalDensity();
    for (int i = 0; i < 120; ++i) s->step(i % 3 == 0 ? 1.0 : 0.05);
    EXPECT_GT(std::abs(s->totalDensity() / mass - 1.0), 1e-4);
}

TEST(Solver, StaysFiniteAndBoundedForAnyTimeStep) {
    // Any dt (0, tiny, normal, 1 s, 10 s) and speeds far above the CFL limit:
    // advection is a convex combination of old values, sources relax
    // implicitly towards their targets, decay is implicit, so density stays in
    // [0, max(initial, emitter target)] and temperature in [ambient, ambient + max].
    // Upper/lower bounds get a relative slack of 1e-4: trilinear weights are
    // rounded to float and may sum to 1 + 4 * 2^-24; over 40 steps of 2
    // substeps (two interpolations each: RK2 midpoint values do not enter
    // scalars, so one per substep) that is at most 80 * 2.4e-7 = 2e-5 < 1e-4.
    // Non-negativity needs no slack: weights and values are >= 0.
    const float slack = 1e-4f;
    for (double dt : {0.0, 1e-6, 1.0 / 30.0, 1.0, 10.0}) {
        for (bool fast : {false, true}) {
            FluidSolverDesc d{.dims = {8, 12, 8},
                              .spacing = glm::vec3(0.5f),
                              .buoyancy = 20.0f,
                              .ambientTemperature = 0.5f,
                              .windWorld = {5, 0, 0},
                              .windCoupling = 1.0f,
                              .densityDissipation = 0.1f,
                              .substeps = 2};
            auto s = FluidSolver::create(d);
            ASSERT_TRUE(s.ok());
            s->addEmitter({.desc = {.offset = {0, 1, 0},
                                    .radius = 1.0f,
                                    .density = 1.0f,
                                    .temperature = 3.0f,
                                    .rate = 50.0f,
                                    .velocity = {0, 40, 0},
                                    .injectVelocity = true}});
            addBlob(*s, {4, 6, 4}, 2.0f, 0.8f, 1.0f);
            if (fast) s->setUniformVelocity({3000.0f, -5000.0f, 2000.0f}); // thousands of cells per step
            // 40 steps; sanitized 10 (the bounds hold at every step, so fewer still test them).
            for (int i = 0; i < splatfx::test::count(40, 10); ++i) {
                s->step(dt);
                const FieldCheck c = check(*s);
                ASSERT_TRUE(c.finite) << "dt " << dt << " step " << i;
                ASSERT_GE(c.minDensity, 0.0f) << "dt " << dt;
                ASSERT_LE(c.maxDensity, 1.0f * (1.0f + slack)) << "dt " << dt;
                ASSERT_GE(c.minTemp, 0.5f * (1.0f - slack)) << "dt " << dt;
                ASSERT_LE(c.maxTemp, 3.5f * (1.0f + slack)) << "dt " << dt;
            }
        }
    }
}

TEST(Solver, ProjectionRemovesDivergence) {
    auto s = FluidSolver::create({.dims = {10, 10, 10}, .buoyancy = 5.0f, .pressureIterations = 200, .pressureTolerance = 1e-7f});
    ASSERT_TRUE(s.ok());
    addBlob(*s, {5, 3, 5}, 2.5f, 1.0f, 1.0f);
    s->step(0.1);
    // CG stopped at the requested relative residual (or ran out of iterations).
    EXPECT_LE(s->stats().lastResidual, 1e-6f);
    EXPECT_GT(s->stats().lastPressureIterations, 0);
}

TEST(Solver, IsDeterministic) {
    auto run = [] {
        FluidSolverDesc d = closedBox();
        d.closedWalls = false;
        d.closedCeiling = false;
        auto s = FluidSolver::create(d);
        const Motion m({}, {.velocity = {0.7f, 0, 0}});
        s->addEmitter({.desc = {.offset = {-2, 0.5f, 0}, .radius = 0.8f}, .motion = m});
        for (int i = 0; i < 50; ++i) s->step(0.04);
        return std::pair{s->density(), s->temperature()};
    };
    const auto a = run(), b = run();
    EXPECT_EQ(a.first, b.first);
    EXPECT_EQ(a.second, b.second);
}

TEST(Solver, HeatRisesAndMaterialLeavesThroughAnOpenTop) {
    auto s = FluidSolver::create({.dims = {6, 12, 6}, .buoyancy = 8.0f, .temperatureDissipation = 0.0f});
    ASSERT_TRUE(s.ok());
    addBlob(*s, {3, 2, 3}, 1.5f, 1.0f, 1.0f);
    auto centroidY = [&] {
        double m = 0, my = 0;
        for (int z = 0; z < 6; ++z)
            for (int y = 0; y < 12; ++y)
                for (int x = 0; x < 6; ++x) {
                    const float d = s->density()[s->cellIndex({x, y, z})];
                    m += d, my += d * y;
                }
        return my / m;
    };
    const double y0 = centroidY(), m0 = s->totalDensity();
    for (int i = 0; i < 20; ++i) s->step(0.1);
    EXPECT_GT(centroidY(), y0 + 1.5) << "buoyancy lifts the hot blob";
    for (int i = 0; i < 200; ++i) s->step(0.1);
    EXPECT_LT(s->totalDensity(), 0.5 * m0) << "it leaves through the open top";
}

TEST(Solver, SparseOutputFollowsTheMaterial) {
    auto s = FluidSolver::create({.dims = {8, 10, 8}, .temperatureDissipation = 0.0f});
    ASSERT_TRUE(s.ok());
    Grid g;
    s->toGrid(g, {});
    EXPECT_TRUE(g.voxels.empty()) << "no material, no voxels";
    s->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.0f, .rate = 10.0f}});
    for (int i = 0; i < 10; ++i) s->step(0.05);
    s->toGrid(g, {.minOpacity = 0.05f, .color = ColorSource::Temperature, .stretchPerSpeed = 0.2f, .maxStretch = 0.5f});
    ASSERT_FALSE(g.voxels.empty()) << "voxels appear where material arrives";
    EXPECT_LT(g.voxels.size(), 8u * 10u * 8u) << "and only there";
    EXPECT_TRUE(g.validate().ok()) << g.validate().error();
    EXPECT_EQ(g.dims, s->dims());
    for (const Voxel& v : g.voxels) {
        EXPECT_GE(v.opacity, 0.05f);
        EXPECT_LE(glm::length(v.stretch), 0.5f + 1e-5f);
        EXPECT_EQ(g.localPosition(v.cell), s->localPosition(v.cell));
    }
    // Switch the source off and let everything dissipate: voxels disappear.
    s->emitters().clear();
    auto fading = FluidSolver::create({.dims = {8, 10, 8}, .densityDissipation = 2.0f});
    fading->density() = s->density();
    for (int i = 0; i < 50; ++i) fading->step(0.1);
    fading->toGrid(g, {.minOpacity = 0.05f});
    EXPECT_TRUE(g.voxels.empty()) << "voxels disappear where material fades";
}

TEST(Solver, BadDescsAreReportedByField) {
    EXPECT_EQ(FluidSolver::create({.dims = {8, 0, 8}}).error(), "FluidSolverDesc.dims y must be at least 1, got 0");
    EXPECT_EQ(FluidSolver::create({.dims = {1024, 1024, 1024}}).error(), "FluidSolverDesc.dims asks for 1073741824 cells; the limit is 16777216");
    EXPECT_EQ(FluidSolver::create({.velocityDamping = -1.0f}).error(), "FluidSolverDesc.velocityDamping must be finite and >= 0, got -1.000000");
    EXPECT_EQ(FluidSolver::create({.substeps = 0}).error(), "FluidSolverDesc.substeps must be in [1, 1000], got 0");
    EXPECT_EQ(FluidSolver::create({.conserveMass = true}).error(),
              "FluidSolverDesc.conserveMass needs a closed domain (closedFloor, closedWalls and closedCeiling all true); "
              "with open faces material leaves and the total is not conserved");
}
