// OpenVDB import at its numerical edges (docs/STABILITY.md, "VDB import"):
// each test is named after what would go wrong. The reference is the file's
// own voxels summed in double: a coarse cell's optical depth is
// extinction * (sum of its block's densities) * voxelSize / N^2 (the mean of
// the N^2 axis rays through the block), and over a frame the optical depth
// times the cell's face area sums to extinction times the integrated density.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "splatfx/vdb.hpp"
#include "vdb_reference.hpp"
#include "vdb_test_files.hpp"

using namespace splatfx;
using namespace splatfx::vdbtest;

namespace {

openvdb::FloatGrid::Ptr densityGrid(double voxelSize, openvdb::Vec3d origin = openvdb::Vec3d(0.0)) {
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    g->setGridClass(openvdb::GRID_FOG_VOLUME);
    g->setTransform(xform(voxelSize, origin));
    return g;
}

VdbImportDesc densityOnly(int voxelsPerCell = 0) { return {.temperatureGrid = "", .velocityGrid = "", .voxelsPerCell = voxelsPerCell}; }

// The full-resolution reference (readVdbDensity, each voxel a cube) and the
// coarse lattice (each cell a cube of its optical depth over its edge), each
// pixel's optical depth along -z, one pixel per file voxel column.
struct BothWays {
    std::vector<double> file, lattice;
};
BothWays renderBothWays(const fs::path& file, int n, const Camera& cam) {
    BothWays out;
    auto seq = loadVdb(file.string(), densityOnly(n));
    auto fine = readVdbDensity(file.string(), densityOnly(n));
    EXPECT_TRUE(seq && fine);
    if (!seq || !fine) return out;
    out.file = pixelDepths(denseMedium(std::make_shared<DenseVoxels>(*fine), DenseFilter::Nearest, 1.0), cam);
    out.lattice = pixelDepths(denseMedium(coarseVoxels(*seq), DenseFilter::Nearest, 1.0), cam);
    return out;
}

// Float alpha (2^-24) read back as -ln(1 - alpha): at most 2^-24 e^tau, with
// a factor 16 for the float camera's rounding of where each ray starts.
double depthTolerance(double tau) { return 16.0 * 0x1p-24 * std::exp(tau); }

// Sum over every cell of optical depth x face area, against extinction x the
// file's integrated density: the filter conserves it exactly but for float
// rounding of each cell (2^-24 relative each, summed).
void expectConserved(const GridSequence& seq, const openvdb::FloatGrid& g, double extinction = 1.0) {
    const double vs = g.voxelSize()[0];
    double file = 0.0;
    for (auto it = g.cbeginValueOn(); it; ++it) file += double(*it) * double(it.getVoxelCount()) * vs * vs * vs; // tiles: their extent
    double lattice = 0.0;
    const double face = double(seq.spacing.x) * double(seq.spacing.y);
    for (float d : seq.frames[0].opticalDepth) lattice += double(d) * face;
    EXPECT_NEAR(lattice, extinction * file, extinction * file * 1e-6 + 1e-300);
}

} // namespace

// The smallest grid: one active voxel makes one coarse cell whose optical
// depth is exactly extinction * value * voxelSize / N^2 (N = 1 here).
TEST(VdbStability, OneActiveVoxelIsOneCellOfTheExactDepth) {
    const fs::path dir = tempDir();
    auto g = densityGrid(0.1);
    g->tree().setValue({3, -2, 7}, 0.75f);
    write(dir / "one.vdb", {g});
    auto seq = loadVdb((dir / "one.vdb").string(), densityOnly());
    ASSERT_TRUE(seq) << seq.error();
    ASSERT_EQ(seq->dims, glm::ivec3(1, 1, 1));
    EXPECT_NEAR(seq->frames[0].opticalDepth[0], 0.75 * 0.1, 0.075 * 0x1p-23);
}

// Blocks are aligned to multiples of N in index space; at negative indices
// that needs floor division (truncation would split a block across zero and
// lose or double voxels there).
TEST(VdbStability, NegativeIndicesAlignBlocksByFloorDivision) {
    const fs::path dir = tempDir();
    auto g = randomDensity({-10, -7, -5}, {-1, -1, -1}, 0.2, 21);
    write(dir / "neg.vdb", {g});
    auto seq = loadVdb((dir / "neg.vdb").string(), densityOnly(4));
    ASSERT_TRUE(seq) << seq.error();
    // x in [-12, -1]: 3 blocks; y in [-8, -1]: 2; z in [-8, -1]: 2.
    EXPECT_EQ(seq->dims, glm::ivec3(3, 2, 2));
    expectConserved(*seq, *g);
}

// Index coordinates near 2^24, where a float can no longer count single
// voxels: block indices are integers (never floats), so nothing merges or
// drops, and the world position keeps the double transform's origin.
TEST(VdbStability, IndicesNearTwoToTheTwentyFourKeepEveryVoxel) {
    const fs::path dir = tempDir();
    const int base = (1 << 24) - 6;
    auto g = randomDensity({base, 0, 0}, {base + 11, 5, 5}, 0.01, 5);
    write(dir / "far.vdb", {g});
    auto seq = loadVdb((dir / "far.vdb").string(), densityOnly(3));
    ASSERT_TRUE(seq) << seq.error();
    EXPECT_EQ(seq->dims.x, 4 + ((base % 3) != 0 ? 1 : 0));
    expectConserved(*seq, *g);
}

// A transform translated 10^6 world units: the lattice's world position is
// within float's resolution there (0.0625) of the file's.
TEST(VdbStability, AGridAMillionUnitsFromTheOriginLandsWhereItIs) {
    const fs::path dir = tempDir();
    auto g = densityGrid(0.5, {1e6, -2e5, 3e5});
    for (int i = 0; i < 4; ++i) g->tree().setValue({i, 0, 0}, 1.0f);
    write(dir / "offset.vdb", {g});
    auto seq = loadVdb((dir / "offset.vdb").string(), densityOnly(4));
    ASSERT_TRUE(seq) << seq.error();
    Grid lattice;
    seq->sample(0.0, lattice);
    const glm::vec3 p = lattice.worldPosition({0, 0, 0});
    const openvdb::Vec3d want = g->transform().indexToWorld(openvdb::Vec3d(1.5, 1.5, 1.5));
    EXPECT_NEAR(p.x, want[0], 0.0625);
    EXPECT_NEAR(p.y, want[1], 0.0625);
    EXPECT_NEAR(p.z, want[2], 0.0625);
}

// Voxel sizes of 10^-4 (OpenVDB's own transforms refuse much smaller) and
// 10^4 world units: the depth scales with them (tau = density * N *
// voxelSize), opacity stays in [0, 1], nothing underflows to NaN.
TEST(VdbStability, VoxelSizesFromATenthOfAMillimetreToTenKilometresScaleTheDepth) {
    for (double vs : {1e-4, 1e4}) {
        const fs::path dir = tempDir();
        auto g = densityGrid(vs);
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j)
                for (int k = 0; k < 2; ++k) g->tree().setValue({i, j, k}, 0.5f);
        write(dir / "s.vdb", {g});
        auto seq = loadVdb((dir / "s.vdb").string(), densityOnly(2));
        ASSERT_TRUE(seq) << seq.error();
        EXPECT_NEAR(seq->frames[0].opticalDepth[0], 0.5 * 2 * vs, 0.5 * 2 * vs * 1e-6) << vs;
        Grid lattice;
        seq->sample(0.0, lattice);
        for (const Voxel& v : lattice.voxels) EXPECT_TRUE(v.opacity >= 0.0f && v.opacity <= 1.0f) << vs;
    }
}

// Densities of 10^30 (a unit mistake in a bake): the depth is large but
// finite and the voxel fully opaque, not inf * 0 = NaN.
TEST(VdbStability, DensitiesOfTenToTheThirtyAreOpaqueNotNaN) {
    const fs::path dir = tempDir();
    auto g = densityGrid(0.1);
    g->tree().setValue({0, 0, 0}, 1e30f);
    g->tree().setValue({1, 0, 0}, 1e-30f);
    write(dir / "huge.vdb", {g});
    auto seq = loadVdb((dir / "huge.vdb").string(), densityOnly(2));
    ASSERT_TRUE(seq) << seq.error();
    EXPECT_TRUE(std::isfinite(seq->frames[0].opticalDepth[0]));
    Grid lattice;
    seq->sample(0.0, lattice);
    ASSERT_EQ(lattice.voxels.size(), 1u);
    EXPECT_EQ(lattice.voxels[0].opacity, 1.0f);
}

// Subnormal densities (10^-40) are kept as tiny depths: finite, >= 0.
TEST(VdbStability, SubnormalDensitiesGiveTinyFiniteDepths) {
    const fs::path dir = tempDir();
    auto g = densityGrid(1.0);
    g->tree().setValue({0, 0, 0}, 1e-40f);
    write(dir / "tiny.vdb", {g});
    auto seq = loadVdb((dir / "tiny.vdb").string(), densityOnly(1));
    ASSERT_TRUE(seq) << seq.error();
    EXPECT_GE(seq->frames[0].opticalDepth[0], 0.0f);
    EXPECT_TRUE(std::isfinite(seq->frames[0].opticalDepth[0]));
}

// A simulation's undershoot (-10^-3) or a NaN in the density is refused
// naming the grid, not averaged into a negative or NaN depth.
TEST(VdbStability, NegativeAndNaNDensitiesAreRefusedNotAveraged) {
    for (float bad : {-1e-3f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        const fs::path dir = tempDir();
        auto g = densityGrid(0.1);
        g->tree().setValue({0, 0, 0}, 1.0f);
        g->tree().setValue({1, 0, 0}, bad);
        write(dir / "bad.vdb", {g});
        auto seq = loadVdb((dir / "bad.vdb").string(), densityOnly(2));
        ASSERT_FALSE(seq) << bad;
        EXPECT_NE(seq.error().find("grid 'density'"), std::string::npos) << seq.error();
        EXPECT_NE(seq.error().find("negative, NaN or infinite densities"), std::string::npos) << seq.error();
    }
}

// Active voxels of value 0 are empty air: they neither add depth nor weight
// the temperature (a 0/0 if a block held only such voxels).
TEST(VdbStability, ActiveZeroDensityVoxelsAddNothingAndWeighNothing) {
    const fs::path dir = tempDir();
    auto d = densityGrid(0.1);
    auto t = openvdb::FloatGrid::create(0.0f);
    t->setName("temperature");
    t->setTransform(d->transform().copy());
    d->tree().setValue({0, 0, 0}, 2.0f), t->tree().setValue({0, 0, 0}, 400.0f);
    d->tree().setValue({1, 0, 0}, 0.0f), t->tree().setValue({1, 0, 0}, 5000.0f); // active, empty: its heat is not seen
    d->tree().setValue({4, 0, 0}, 0.0f), t->tree().setValue({4, 0, 0}, 900.0f);  // a block of nothing but empty air
    write(dir / "z.vdb", {d, t});
    auto seq = loadVdb((dir / "z.vdb").string(), {.velocityGrid = "", .voxelsPerCell = 2, .temperatureHot = 500.0f, .temperatureCold = 300.0f});
    ASSERT_TRUE(seq) << seq.error();
    ASSERT_EQ(seq->dims.x, 3);
    EXPECT_NEAR(seq->frames[0].colorCoord[0], 1.0 - (400.0 - 300.0) / 200.0, 1e-6);
    for (float c : seq->frames[0].colorCoord) EXPECT_TRUE(c >= 0.0f && c <= 1.0f);
    EXPECT_EQ(seq->frames[0].opticalDepth[seq->cellIndex({2, 0, 0})], 0.0f);
}

// Values stored in inactive voxels (OpenVDB keeps a whole leaf's values) are
// not density: only active ones count.
TEST(VdbStability, ValuesOfInactiveVoxelsAreIgnored) {
    const fs::path dir = tempDir();
    auto g = densityGrid(0.1);
    g->tree().setValue({0, 0, 0}, 1.0f);
    g->tree().setValueOff({1, 0, 0}, 50.0f);
    write(dir / "off.vdb", {g});
    auto seq = loadVdb((dir / "off.vdb").string(), densityOnly(2));
    ASSERT_TRUE(seq) << seq.error();
    // One voxel of density 1 in a 2^3 block: 1 * 0.1 / 2^2 (the 50 stored beside it would make it 51x that).
    EXPECT_NEAR(seq->frames[0].opticalDepth[0], 1.0 * 0.1 / 4.0, 1e-8);
}

// A temperature grid of one value everywhere (automatic range: hot == cold)
// maps to the hot end, not 0/0.
TEST(VdbStability, AUniformTemperatureWithAnAutomaticRangeIsHotNotNaN) {
    const fs::path dir = tempDir();
    auto d = randomDensity({0, 0, 0}, {7, 7, 7}, 0.1, 9);
    auto t = openvdb::FloatGrid::create(0.0f);
    t->setName("temperature");
    t->setTransform(d->transform().copy());
    for (auto it = d->cbeginValueOn(); it; ++it) t->tree().setValue(it.getCoord(), 350.0f);
    write(dir / "u.vdb", {d, t});
    auto seq = loadVdb((dir / "u.vdb").string(), {.velocityGrid = "", .voxelsPerCell = 2});
    ASSERT_TRUE(seq) << seq.error();
    for (std::size_t i = 0; i < seq->cellCount(); ++i)
        if (seq->frames[0].opticalDepth[i] > 0.0f) { EXPECT_EQ(seq->frames[0].colorCoord[i], 0.0f); }
}

// Velocities of 10^20 voxels/s are finite and scaled (the playback clamps
// what it advects with), NaN velocities refused naming the grid.
TEST(VdbStability, EnormousVelocitiesStayFiniteAndNaNVelocitiesAreRefused) {
    const fs::path dir = tempDir();
    auto d = densityGrid(0.1);
    auto v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    v->setName("velocity");
    v->setTransform(d->transform().copy());
    d->tree().setValue({0, 0, 0}, 1.0f);
    v->tree().setValue({0, 0, 0}, openvdb::Vec3s(1e20f, 0.0f, 0.0f));
    write(dir / "fast.vdb", {d, v});
    auto fast = loadVdb((dir / "fast.vdb").string(), {.temperatureGrid = "", .voxelsPerCell = 1});
    ASSERT_TRUE(fast) << fast.error();
    EXPECT_TRUE(std::isfinite(fast->frames[0].velocityCellsPerSec[0].x));
    v->tree().setValue({0, 0, 0}, openvdb::Vec3s(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f));
    write(dir / "nan.vdb", {d, v});
    auto nan = loadVdb((dir / "nan.vdb").string(), {.temperatureGrid = "", .voxelsPerCell = 1});
    ASSERT_FALSE(nan);
    EXPECT_NE(nan.error().find("NaN or infinite velocities"), std::string::npos) << nan.error();
}

// maxCellsPerAxis 1 and voxelsPerCell far beyond the grid: the whole grid is
// one cell holding all its density (nothing clipped by a block edge).
TEST(VdbStability, OneCellForTheWholeGridHoldsAllItsDensity) {
    const fs::path dir = tempDir();
    auto g = randomDensity({-3, 2, 5}, {8, 9, 13}, 0.05, 13);
    write(dir / "all.vdb", {g});
    for (VdbImportDesc desc : {VdbImportDesc{.temperatureGrid = "", .velocityGrid = "", .maxCellsPerAxis = 1},
                               VdbImportDesc{.temperatureGrid = "", .velocityGrid = "", .voxelsPerCell = 1000}}) {
        auto seq = loadVdb((dir / "all.vdb").string(), desc);
        ASSERT_TRUE(seq) << seq.error();
        EXPECT_LE(seq->cellCount(), 8u) << "at most one block per axis, two where the grid straddles a block edge";
        expectConserved(*seq, *g);
    }
}

// A tile (an 8^3 constant region stored as one value) that straddles coarse
// block edges (N = 3 does not divide 8): filled region by region, its
// density split exactly between the blocks it overlaps.
TEST(VdbStability, ATileStraddlingBlockEdgesSplitsItsDensityExactly) {
    const fs::path dir = tempDir();
    auto g = densityGrid(0.1);
    g->tree().addTile(1, openvdb::Coord(8, 8, 8), 0.5f, true);
    write(dir / "tile.vdb", {g});
    auto seq = loadVdb((dir / "tile.vdb").string(), densityOnly(3));
    ASSERT_TRUE(seq) << seq.error();
    expectConserved(*seq, *g);
    // The corner block [6, 8]^3 holds one voxel of the tile, (8, 8, 8): 0.5 * 0.1 / 3^2.
    const float corner = seq->frames[0].opticalDepth[seq->cellIndex({0, 0, 0})];
    EXPECT_NEAR(corner, 0.5 * 0.1 / 9.0, 1e-8);
    // An interior block [9, 11]^3 is all tile: 27 voxels, 0.5 * 27 * 0.1 / 9.
    EXPECT_NEAR(seq->frames[0].opticalDepth[seq->cellIndex({1, 1, 1})], 0.5 * 27.0 * 0.1 / 9.0, 1e-7);
}

// Two frames whose boxes do not overlap: one lattice over their union; each
// frame's density stays in its own cells, none lost at the union's edges.
TEST(VdbStability, FramesWithDisjointBoxesShareOneLatticeWithoutLoss) {
    const fs::path dir = tempDir();
    auto a = randomDensity({0, 0, 0}, {5, 5, 5}, 0.1, 1);
    auto b = randomDensity({40, 0, 0}, {45, 5, 5}, 0.1, 2);
    write(dir / "f_0001.vdb", {a});
    write(dir / "f_0002.vdb", {b});
    auto seq = loadVdbSequence((dir / "f_####.vdb").string(), 1, 2, densityOnly(2));
    ASSERT_TRUE(seq) << seq.error();
    ASSERT_EQ(seq->frames.size(), 2u);
    double sumA = 0.0, sumB = 0.0, fileA = 0.0, fileB = 0.0;
    const double face = double(seq->spacing.x) * double(seq->spacing.y);
    for (float d : seq->frames[0].opticalDepth) sumA += d * face;
    for (float d : seq->frames[1].opticalDepth) sumB += d * face;
    for (auto it = a->cbeginValueOn(); it; ++it) fileA += double(*it) * 1e-3;
    for (auto it = b->cbeginValueOn(); it; ++it) fileB += double(*it) * 1e-3;
    EXPECT_NEAR(sumA, fileA, fileA * 1e-6);
    EXPECT_NEAR(sumB, fileB, fileB * 1e-6);
}

// ---- Against the full-resolution reference (renderVolumeExact through the file's voxels) ----

// Active voxels only on the first slice x = 4 of the block [4, 7] (N = 4),
// seen edge-on along z: the file has tau = rho D s in that one column, the
// lattice rho D s / N in each of the block's N columns. Per column the error
// is that closed form (the largest, rho D s (1 - 1/N), on the face), summed
// over the columns it is 0: the resampling moves depth sideways, never loses it.
TEST(VdbStability, VoxelsAllOnOneCoarseCellFaceSpreadOverTheBlockButKeepTheirDepth) {
    const fs::path dir = tempDir();
    const double s = 0.1, rho = 1.0;
    const int D = 8;
    auto g = densityGrid(s);
    for (int z = 0; z < D; ++z)
        for (int y = 0; y < 8; ++y) g->tree().setValue({4, y, z}, float(rho));
    write(dir / "face.vdb", {g});
    const BothWays r = renderBothWays(dir / "face.vdb", 4, orthoAlongZ({-0.5 * s, -0.5 * s}, {12, 8}, s, 3.0));
    ASSERT_EQ(r.file.size(), 96u);
    double sumFile = 0.0, sumLattice = 0.0;
    for (std::size_t i = 0; i < r.file.size(); ++i) {
        const int col = int(i % 12);
        EXPECT_NEAR(r.file[i], col == 4 ? rho * D * s : 0.0, depthTolerance(0.8)) << col;
        EXPECT_NEAR(r.lattice[i], col >= 4 && col < 8 ? rho * D * s / 4.0 : 0.0, depthTolerance(0.2)) << col;
        sumFile += r.file[i], sumLattice += r.lattice[i];
    }
    EXPECT_NEAR(sumLattice, sumFile, 96 * depthTolerance(0.8));
}

// Ten voxels along x with N = 3: blocks [0, 2], [3, 5], [6, 8] and a last
// block [9, 11] holding one voxel. Columns 0..8 render exactly as the file
// (a uniform density: each block mean is the value); the partial block
// spreads its one column over three at a third of the depth, summed the same.
TEST(VdbStability, ABlockSizeNotDividingTheGridKeepsThePartialBlocksDepth) {
    const fs::path dir = tempDir();
    const double s = 0.1;
    auto g = densityGrid(s);
    g->tree().fill(openvdb::CoordBBox({0, 0, 0}, {9, 5, 5}), 0.5f, true);
    write(dir / "partial.vdb", {g});
    const BothWays r = renderBothWays(dir / "partial.vdb", 3, orthoAlongZ({-0.5 * s, -0.5 * s}, {12, 6}, s, 3.0));
    ASSERT_EQ(r.file.size(), 72u);
    const double tau = 0.5 * 6 * s; // density x depth
    for (std::size_t i = 0; i < r.file.size(); ++i) {
        const int col = int(i % 12);
        if (col < 9) {
            EXPECT_NEAR(r.lattice[i], r.file[i], depthTolerance(tau)) << col;
        } else {
            EXPECT_NEAR(r.file[i], col == 9 ? tau : 0.0, depthTolerance(tau)) << col;
            EXPECT_NEAR(r.lattice[i], tau / 3.0, depthTolerance(tau)) << col;
        }
    }
}

// The automatic block size at exactly the limit: a grid 24 voxels long with
// maxCellsPerAxis 24 gets N = 1 (a rounding of 24 / 24 up to 2 would halve
// the lattice), so the lattice's cells are the file's voxels and a random
// density renders identically both ways, column by column.
TEST(VdbStability, AGridExactlyMaxCellsLongIsImportedAtTheFilesOwnVoxelSize) {
    const fs::path dir = tempDir();
    auto g = randomDensity({0, 0, 0}, {23, 5, 3}, 0.1, 31);
    g->setTransform(xform(0.1));
    write(dir / "edge.vdb", {g});
    auto seq = loadVdb((dir / "edge.vdb").string(), {.temperatureGrid = "", .velocityGrid = "", .maxCellsPerAxis = 24});
    auto fine = readVdbDensity((dir / "edge.vdb").string(), densityOnly(0));
    ASSERT_TRUE(seq && fine);
    EXPECT_EQ(seq->spacing.x, 0.1f) << "one file voxel per cell";
    const Camera cam = orthoAlongZ({-0.05, -0.05}, {24, 6}, 0.1, 3.0);
    const auto a = pixelDepths(denseMedium(std::make_shared<DenseVoxels>(*fine), DenseFilter::Nearest, 1.0), cam);
    const auto b = pixelDepths(denseMedium(coarseVoxels(*seq), DenseFilter::Nearest, 1.0), cam);
    ASSERT_EQ(a.size(), b.size());
    double largest = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_NEAR(b[i], a[i], depthTolerance(a[i])) << i;
        largest = std::max(largest, a[i]);
    }
    EXPECT_GT(largest, 0.5);
}

// A sheet one voxel thin (z = 5, inside the block [4, 7]) seen head-on: the
// block's mean rho / N over its N voxels of depth is rho s again, so every
// ray keeps the sheet's depth exactly, though the lattice is four times thicker.
TEST(VdbStability, AOneVoxelThinSheetSeenHeadOnKeepsItsDepthExactly) {
    const fs::path dir = tempDir();
    const double s = 0.1, rho = 2.0;
    auto g = densityGrid(s);
    g->tree().fill(openvdb::CoordBBox({0, 0, 5}, {15, 11, 5}), float(rho), true);
    write(dir / "sheet.vdb", {g});
    const BothWays r = renderBothWays(dir / "sheet.vdb", 4, orthoAlongZ({-0.5 * s, -0.5 * s}, {16, 12}, s, 3.0));
    ASSERT_EQ(r.file.size(), 192u);
    for (std::size_t i = 0; i < r.file.size(); ++i) {
        EXPECT_NEAR(r.file[i], rho * s, depthTolerance(0.2)) << i;
        EXPECT_NEAR(r.lattice[i], rho * s, depthTolerance(0.2)) << i;
    }
}

// One voxel of 10^6 among voxels of 0.1: the reference's quadrature takes
// a piece of extinction 10^6 (exp(-10^5) underflows to exactly 0, no NaN),
// the spike's column is opaque and its neighbours keep tau = 0.1 D s; the
// lattice makes the whole block column opaque (its depth, the block's sum
// (10^6 + 63 x 0.1) s / N^2, is finite): the error of resampling a spike is
// 1 - exp(-0.1 D s) of alpha on the block's other columns, and that is what
// the reference shows.
TEST(VdbStability, ADensitySpikeOfAMillionInOneVoxelIsOpaqueInTheReferenceAndFinite) {
    const fs::path dir = tempDir();
    const double s = 0.1;
    auto g = densityGrid(s);
    g->tree().fill(openvdb::CoordBBox({0, 0, 0}, {3, 3, 3}), 0.1f, true);
    g->tree().setValue({1, 2, 3}, 1e6f);
    write(dir / "spike.vdb", {g});
    auto seq = loadVdb((dir / "spike.vdb").string(), densityOnly(4));
    auto fine = readVdbDensity((dir / "spike.vdb").string(), densityOnly(4));
    ASSERT_TRUE(seq && fine);
    EXPECT_NEAR(seq->frames[0].opticalDepth[0], (1e6 + 63 * 0.1) * s / 16.0, 1e6 * s / 16.0 * 0x1p-22);
    Materials mat{Footprint{}};
    const Camera cam = orthoAlongZ({-0.5 * s, -0.5 * s}, {4, 4}, s, 3.0);
    for (bool lattice : {false, true}) {
        VolumeField f(mat);
        f.addMedium(denseMedium(lattice ? coarseVoxels(*seq) : std::make_shared<DenseVoxels>(*fine), DenseFilter::Nearest, 1.0));
        auto img = renderVolumeExact(f, cam, {.tolerance = 1e-9, .threads = 1});
        ASSERT_TRUE(img);
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 4; ++x) {
                const bool spike = x == 1 && y == 4 - 1 - 2; // image rows top first
                const double want = lattice || spike ? 1.0 : -std::expm1(-0.1 * 4 * s);
                EXPECT_NEAR(img->at(x, y, 3), want, 1e-6) << lattice << " " << x << "," << y;
            }
    }
}

// A lattice of an odd number of blocks along x and an even one along z
// (Grid::localPosition centres both axes differently) under a translation
// that is no multiple of anything: the lattice must sit on the file's voxels.
// Pixels sample 0.45 voxel from the block edges, so a misplacement of more
// than 0.05 voxel moves a column of depth to the wrong pixel.
TEST(VdbStability, ALatticeOfOddAndEvenBlockCountsSitsOnTheFilesVoxels) {
    const fs::path dir = tempDir();
    const double s = 0.1;
    auto g = densityGrid(s, {0.37, -1.13, 0.051});
    g->tree().fill(openvdb::CoordBBox({0, 0, 0}, {11, 7, 7}), 0.5f, true); // 3 x 2 x 2 blocks of 4
    write(dir / "place.vdb", {g});
    // Pixel size s, grid of pixel centres shifted to 0.05 voxel inside each voxel's upper edge.
    const BothWays r =
        renderBothWays(dir / "place.vdb", 4, orthoAlongZ({0.37 - 0.5 * s + 0.45 * s - 2 * s, -1.13 - 0.5 * s + 0.45 * s - 2 * s}, {16, 12}, s, 3.0));
    ASSERT_EQ(r.file.size(), 192u);
    int inside = 0;
    for (std::size_t i = 0; i < r.file.size(); ++i) {
        EXPECT_NEAR(r.lattice[i], r.file[i], depthTolerance(0.4)) << i;
        inside += r.file[i] > 0.0;
    }
    EXPECT_EQ(inside, 12 * 8);
}
