// Global (sec. 3.2) and local (sec. 3.3) texture dynamics: propagation moves
// texture along the flow, cycling has its period, and the stateless closed
// form equals the step-by-step recurrence.
#include <gtest/gtest.h>

#include <set>

#include "splatfx/dynamics.hpp"
#include "splatfx/grid.hpp"

using namespace splatfx;

namespace {

std::vector<std::uint8_t> occupancyOf(const Grid& g, glm::ivec3 dims) {
    std::vector<std::uint8_t> occ(std::size_t(dims.x) * dims.y * dims.z, 0);
    for (const Voxel& v : g.voxels) occ[(std::size_t(v.cell.z) * dims.y + v.cell.y) * dims.x + v.cell.x] = 1;
    return occ;
}

// A sparse, irregular lattice: a cone plus holes, so chains have many lengths.
Grid irregularLattice() {
    Grid g = *Grid::cone(3.0f, 9);
    std::vector<Voxel> kept;
    for (const Voxel& v : g.voxels)
        if (hashCell(v.cell, 99, 0) % 5 != 0) kept.push_back(v); // drop ~20 % of the cells
    g.voxels = kept;
    return g;
}

} // namespace

TEST(Propagation, MarkedTextureMovesOneVoxelPerStepUp) {
    const glm::ivec3 dims{3, 12, 3};
    Grid box = *Grid::box(dims);
    const auto occ = occupancyOf(box, dims);
    TexturePropagator prop(dims, 7);
    const std::uint32_t mark = 0xC0FFEEu;
    prop.setIndex({1, 0, 1}, mark);
    for (int n = 1; n < dims.y; ++n) {
        prop.stepFixed({0, 1, 0}, 0, occ);
        // With offset 0 the mark itself travels: exactly at row n, nowhere else.
        int found = 0;
        for (int z = 0; z < dims.z; ++z)
            for (int y = 0; y < dims.y; ++y)
                for (int x = 0; x < dims.x; ++x)
                    if (prop.index({x, y, z}) == mark) {
                        ++found;
                        EXPECT_EQ(glm::ivec3(x, y, z), glm::ivec3(1, n, 1)) << "step " << n;
                    }
        EXPECT_EQ(found, 1) << "step " << n;
    }
}

TEST(Propagation, OffsetIsAddedPerHop) {
    const glm::ivec3 dims{2, 6, 2};
    const auto occ = occupancyOf(*Grid::box(dims), dims);
    TexturePropagator prop(dims, 3);
    prop.setIndex({0, 0, 0}, 100);
    for (int n = 1; n <= 5; ++n) {
        prop.stepFixed({0, 1, 0}, 3, occ);
        EXPECT_EQ(prop.index({0, n, 0}), 100u + 3u * n);
    }
}

TEST(Propagation, MarkedTextureFollowsTheFlow) {
    // Uniform flow of one cell per step along +x (then diagonally): the mark
    // travels with it, one voxel per step.
    const glm::ivec3 dims{10, 4, 10};
    const std::vector<std::uint8_t> occ(std::size_t(dims.x) * dims.y * dims.z, 1);
    for (glm::vec3 flow : {glm::vec3(4, 0, 0), glm::vec3(4, 0, 4)}) {
        const std::vector<glm::vec3> vel(occ.size(), flow);
        TexturePropagator prop(dims, 1);
        const std::uint32_t mark = 0xABCDEFu;
        prop.setIndex({1, 2, 1}, mark);
        const glm::ivec3 hop(flow.x > 0 ? 1 : 0, 0, flow.z > 0 ? 1 : 0);
        const double dt = 1.0 / glm::length(flow); // exactly one cell of travel per call
        for (int n = 1; n <= 6; ++n) {
            prop.advanceFlow(vel, occ, dt, 0);
            EXPECT_EQ(prop.index(glm::ivec3(1, 2, 1) + n * hop), mark) << "step " << n;
            EXPECT_NE(prop.index(glm::ivec3(1, 2, 1) + (n - 1) * hop), mark) << "step " << n;
        }
    }
}

TEST(Propagation, SlowFlowHopsOnlyAfterAWholeCell) {
    const glm::ivec3 dims{6, 1, 1};
    const std::vector<std::uint8_t> occ(6, 1);
    const std::vector<glm::vec3> vel(6, glm::vec3(1, 0, 0)); // 1 cell / s
    TexturePropagator prop(dims, 1);
    prop.setIndex({0, 0, 0}, 42);
    for (int i = 0; i < 3; ++i) prop.advanceFlow(vel, occ, 0.3, 0); // 0.9 cells
    EXPECT_NE(prop.index({1, 0, 0}), 42u);
    prop.advanceFlow(vel, occ, 0.3, 0); // 1.2 cells: one hop
    EXPECT_EQ(prop.index({1, 0, 0}), 42u);
}

TEST(Propagation, StatelessEqualsStepByStep) {
    // The closed form of sec. 3.2's recurrence must equal running it, for every
    // voxel at every step, on irregular lattices and several directions.
    const Grid lattice = irregularLattice();
    glm::ivec3 dims(0);
    for (const Voxel& v : lattice.voxels) dims = glm::max(dims, v.cell + 1);
    const auto occ = occupancyOf(lattice, dims);
    for (glm::ivec3 dir : {glm::ivec3(0, 1, 0), glm::ivec3(1, 0, 0), glm::ivec3(1, 1, 0), glm::ivec3(0, -1, 1), glm::ivec3(0, 2, 0)}) {
        const PropagationDesc pd{.mode = Propagation::Fixed, .direction = dir, .stepsPerSec = 10.0f, .offset = 5};
        const std::uint32_t seed = 1234;
        TextureDynamics stateless(lattice, {.propagation = pd, .cycling = {.mode = Cycling::None}, .seed = seed});
        TexturePropagator steps(dims, seed);
        for (int n = 0; n <= 60; ++n) {
            if (n > 0) steps.stepFixed(dir, pd.offset, occ);
            const double t = (n + 0.5) / pd.stepsPerSec; // mid-step: floor(t * rate) = n without rounding doubt
            for (std::size_t i = 0; i < lattice.voxels.size(); ++i) {
                ASSERT_EQ(stateless.sample(i, t).texture, steps.index(lattice.voxels[i].cell))
                    << "direction (" << dir.x << "," << dir.y << "," << dir.z << ") step " << n << " voxel " << i;
                ASSERT_EQ(stateless.sampleCell(lattice.voxels[i].cell, t).texture, steps.index(lattice.voxels[i].cell));
            }
        }
    }
}

TEST(Propagation, StatelessFramesDoNotDependOnOrder) {
    const Grid lattice = *Grid::box({4, 10, 3});
    TextureDynamics tex(lattice, {});
    Grid a = lattice, b = lattice;
    tex.apply(a, 7.3);
    tex.apply(b, 0.1);
    tex.apply(b, 100.0);
    tex.apply(b, 7.3);
    for (std::size_t i = 0; i < a.voxels.size(); ++i) {
        EXPECT_EQ(a.voxels[i].texture, b.voxels[i].texture);
        EXPECT_EQ(a.voxels[i].phase, b.voxels[i].phase);
    }
}

TEST(Propagation, SourcesAreSeededDeterministically) {
    const Grid lattice = *Grid::box({3, 5, 3});
    const TextureDynamicsDesc d{.propagation = {.mode = Propagation::Fixed}, .cycling = {.mode = Cycling::None}, .seed = 5};
    TextureDynamics a(lattice, d), b(lattice, d);
    TextureDynamicsDesc other = d;
    other.seed = 6;
    TextureDynamics c(lattice, other);
    int differ = 0;
    for (std::size_t i = 0; i < lattice.voxels.size(); ++i) {
        EXPECT_EQ(a.sample(i, 3.21).texture, b.sample(i, 3.21).texture);
        differ += a.sample(i, 3.21).texture != c.sample(i, 3.21).texture;
    }
    EXPECT_GT(differ, int(lattice.voxels.size()) / 2) << "the seed must change the choice";
}

TEST(Cycling, OrderedHasTheConfiguredPeriod) {
    // Rate r: one texture per 1/r seconds; a set of N textures repeats every N/r.
    const CyclingDesc cd{.mode = Cycling::Ordered, .texturesPerSec = 4.0f, .rateJitter = 0.0f, .randomStart = true};
    const int setSize = 8;
    for (glm::ivec3 cell : {glm::ivec3(0), glm::ivec3(3, 7, 1), glm::ivec3(-2, 5, 9)}) {
        for (double t = 0.0; t < 5.0; t += 0.37) {
            const TextureSample s0 = cycleSample(cell, t, cd, 11);
            const TextureSample s1 = cycleSample(cell, t + 0.25, cd, 11);
            const TextureSample sN = cycleSample(cell, t + setSize / 4.0, cd, 11);
            EXPECT_EQ(s1.texture, s0.texture + 1) << "one tick per 1 / rate";
            EXPECT_EQ(sN.texture % setSize, s0.texture % setSize) << "period N / rate";
            EXPECT_NEAR(s1.phase, s0.phase, 1e-5f);
            EXPECT_GE(s0.phase, 0.0f);
            EXPECT_LT(s0.phase, 1.0f);
        }
    }
    // Within one tick, the phase (cross-fade weight) rises linearly at the rate.
    const TextureSample a = cycleSample({1, 1, 1}, 1.0, {.mode = Cycling::Ordered, .texturesPerSec = 4.0f, .randomStart = false}, 1);
    const TextureSample b = cycleSample({1, 1, 1}, 1.1, {.mode = Cycling::Ordered, .texturesPerSec = 4.0f, .randomStart = false}, 1);
    EXPECT_EQ(a.texture, 4u);
    EXPECT_NEAR(a.phase, 0.0f, 1e-6f);
    EXPECT_NEAR(b.phase, 0.4f, 1e-5f);
}

TEST(Cycling, RateJitterVariesPerVoxelWithinBounds) {
    const CyclingDesc cd{.mode = Cycling::Ordered, .texturesPerSec = 10.0f, .rateJitter = 0.3f, .randomStart = false};
    std::set<std::uint32_t> counts;
    for (int x = 0; x < 20; ++x) {
        const std::uint32_t ticks = cycleSample({x, 0, 0}, 100.0, cd, 3).texture; // 1000 +- 300
        EXPECT_GE(ticks, 700u);
        EXPECT_LE(ticks, 1300u);
        counts.insert(ticks);
    }
    EXPECT_GT(counts.size(), 10u) << "jitter must give voxels different rates";
}

TEST(Cycling, RandomSelectionChangesEveryTickAndIsDeterministic) {
    const CyclingDesc cd{.mode = Cycling::Random, .texturesPerSec = 5.0f, .randomStart = false};
    int changes = 0;
    std::set<std::uint32_t> layers;
    for (int k = 0; k < 200; ++k) {
        const TextureSample a = cycleSample({2, 3, 4}, (k + 0.5) / 5.0, cd, 9);
        const TextureSample b = cycleSample({2, 3, 4}, (k + 1.5) / 5.0, cd, 9);
        EXPECT_EQ(a.phase, 0.0f) << "random selection has no cross-fade";
        EXPECT_EQ(a.texture, cycleSample({2, 3, 4}, (k + 0.5) / 5.0, cd, 9).texture);
        EXPECT_EQ(a.texture, cycleSample({2, 3, 4}, (k + 0.9) / 5.0, cd, 9).texture) << "constant within a tick";
        changes += (a.texture % 8) != (b.texture % 8);
        layers.insert(a.texture % 8);
    }
    // Independent uniform picks from 8: P(same) = 1/8, so ~175 of 200 change;
    // 140 is more than 5 standard deviations (sd ~4.7) below that.
    EXPECT_GT(changes, 140);
    EXPECT_EQ(layers.size(), 8u) << "every texture of the set gets picked";
}

TEST(TextureDynamics, CombinesPropagationAndCycling) {
    const Grid lattice = *Grid::box({2, 6, 2});
    const TextureDynamicsDesc d{
        .propagation = {.mode = Propagation::Fixed, .stepsPerSec = 8.0f}, .cycling = {.mode = Cycling::Ordered, .texturesPerSec = 3.0f}, .seed = 4};
    TextureDynamics tex(lattice, d);
    for (std::size_t i = 0; i < lattice.voxels.size(); ++i) {
        const glm::ivec3 c = lattice.voxels[i].cell;
        const double t = 2.7;
        const std::uint32_t expected = propagatedIndex(c, tex.chainLength(i), propagationStep(t, d.propagation), d.propagation, d.seed) +
                                       cycleSample(c, t, d.cycling, d.seed).texture;
        EXPECT_EQ(tex.sample(i, t).texture, expected);
        EXPECT_EQ(tex.chainLength(i), c.y) << "a full box column: every cell below is upwind";
    }
}

// Chain lengths are memoized (one pass over the voxels, so a 4096x4096x1
// fire loads in seconds); they must equal the walk up each voxel's upwind
// chain, on a lattice with holes and for slanted directions.
TEST(TextureDynamics, MemoizedChainsEqualWalkingEachChain) {
    Grid g = *Grid::box({9, 13, 4});
    std::vector<Voxel> kept;
    std::uint32_t x = 7;
    for (const Voxel& v : g.voxels) {
        x = x * 1664525u + 1013904223u;
        if ((x >> 28) != 0) kept.push_back(v); // drop about one voxel in 16: chains break at the holes
    }
    g.voxels = kept;
    for (glm::ivec3 d : {glm::ivec3(0, 1, 0), glm::ivec3(1, 1, 0), glm::ivec3(0, -2, 1), glm::ivec3(-1, 0, 0)}) {
        TextureDynamicsDesc desc;
        desc.propagation = {.mode = Propagation::Fixed, .direction = d, .stepsPerSec = 4.0f};
        const TextureDynamics td(g, desc);
        auto occupied = [&](glm::ivec3 c) {
            for (const Voxel& v : g.voxels)
                if (v.cell == c) return true;
            return false;
        };
        for (std::size_t i = 0; i < g.voxels.size(); ++i) {
            int k = 0;
            while (occupied(g.voxels[i].cell - (k + 1) * d)) ++k;
            ASSERT_EQ(td.chainLength(i), k) << "voxel " << i << " direction " << d.x << "," << d.y << "," << d.z;
        }
    }
}
