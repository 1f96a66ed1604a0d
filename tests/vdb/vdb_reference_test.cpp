// The VDB exact reference: the file's own voxels at full resolution
// (readVdbDensity + denseMedium) through renderVolumeExact, against which the
// resampling onto the coarse lattice shows its error.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <openvdb/tools/Interpolation.h>

#include "splatfx/vdb.hpp"
#include "vdb_reference.hpp"
#include "vdb_test_files.hpp"

using namespace splatfx;
using namespace splatfx::vdbtest;

namespace {

openvdb::FloatGrid::Ptr densityGrid(double voxelSize) {
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    g->setGridClass(openvdb::GRID_FOG_VOLUME);
    g->setTransform(xform(voxelSize));
    return g;
}

VdbImportDesc densityOnly(int n) { return {.temperatureGrid = "", .velocityGrid = "", .voxelsPerCell = n}; }

// Float alpha (2^-24) read back as -ln(1 - alpha): at most 2^-24 e^tau, with
// a factor 16 for the float camera's rounding of where each ray starts.
double depthTolerance(double tau) { return 16.0 * 0x1p-24 * std::exp(tau); }

} // namespace

// The reference reads what the file holds: a 2 x 3 x 5 box of voxels read
// back value for value, tiles filled, and its world origin the transform's.
TEST(VdbReference, ReadsTheFilesVoxelsAndTilesAtFullResolution) {
    const fs::path dir = tempDir();
    auto g = densityGrid(0.25);
    g->setTransform(xform(0.25, {1.0, -2.0, 0.5}));
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 2; ++x) g->tree().setValue({x, y, z}, float(1 + x + 2 * y + 6 * z));
    g->tree().addTile(1, openvdb::Coord(16, 0, 0), 0.5f, true); // voxels 16..23 on each axis
    write(dir / "r.vdb", {g});
    auto v = readVdbDensity((dir / "r.vdb").string(), {.temperatureGrid = "", .velocityGrid = ""});
    ASSERT_TRUE(v) << v.error();
    ASSERT_EQ(v->dims, glm::ivec3(24, 8, 8));
    EXPECT_EQ(v->voxelSize, 0.25);
    EXPECT_EQ(v->origin, glm::dvec3(1.0, -2.0, 0.5));
    auto at = [&](int x, int y, int z) { return v->values[(std::size_t(z) * 8 + y) * 24 + x]; };
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 2; ++x) EXPECT_EQ(at(x, y, z), float(1 + x + 2 * y + 6 * z));
    EXPECT_EQ(at(2, 0, 0), 0.0f);
    EXPECT_EQ(at(16, 7, 7), 0.5f);
    EXPECT_EQ(at(23, 0, 3), 0.5f);
}

// A constant density over a block-aligned box: every block mean is the
// value, so the coarse lattice and the full-resolution file are the same
// field and render identically (each piece between voxel faces is constant:
// the quadrature is exact; only float alpha differs).
TEST(VdbReference, AConstantBlockAlignedFieldRendersIdenticallyBothWays) {
    const fs::path dir = tempDir();
    auto g = densityGrid(0.1);
    g->tree().fill(openvdb::CoordBBox({0, 0, 0}, {11, 7, 15}), 0.8f, true);
    write(dir / "c.vdb", {g});
    auto seq = loadVdb((dir / "c.vdb").string(), densityOnly(4));
    auto fine = readVdbDensity((dir / "c.vdb").string(), densityOnly(4));
    ASSERT_TRUE(seq && fine);
    const Camera cam = orthoAlongZ({-0.05 - 0.2, -0.05 - 0.2}, {16, 12}, 0.1, 5.0); // a 2-voxel margin of empty pixels
    const auto a = pixelDepths(denseMedium(std::make_shared<DenseVoxels>(*fine), DenseFilter::Nearest, 1.0), cam);
    const auto b = pixelDepths(denseMedium(coarseVoxels(*seq), DenseFilter::Nearest, 1.0), cam);
    ASSERT_EQ(a.size(), b.size());
    int inside = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_NEAR(a[i], b[i], depthTolerance(a[i])) << i;
        inside += a[i] > 0.0;
        if (a[i] > 0.0) { EXPECT_NEAR(a[i], 0.8 * 16 * 0.1, depthTolerance(a[i])) << "tau = density * depth"; }
    }
    EXPECT_EQ(inside, 12 * 8);
}

// The resampling's error has a closed form on a ramp: density a + b i in
// file voxel column i, D voxels deep. A ray along z through column i sees
// tau = s D (a + b i) at full resolution, and the block's mean
// s D (a + b i_c) on the lattice (i_c the block's centre column), so the
// largest error is s D b (N - 1) / 2: first order in the block size N, and
// 0 at N = 1. Asserted per N to the float alpha's rounding.
TEST(VdbReference, ResamplingErrorOnARampIsFirstOrderInTheBlockSize) {
    const fs::path dir = tempDir();
    const double s = 0.05, a = 0.2, b = 0.05;
    const int D = 8;
    auto g = densityGrid(s);
    for (int z = 0; z < D; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 32; ++x) g->tree().setValue({x, y, z}, float(a + b * x));
    write(dir / "ramp.vdb", {g});
    auto fine = readVdbDensity((dir / "ramp.vdb").string(), densityOnly(1));
    ASSERT_TRUE(fine) << fine.error();
    const Camera cam = orthoAlongZ({-0.5 * s, -0.5 * s}, {32, 8}, s, 3.0);
    const auto truth = pixelDepths(denseMedium(std::make_shared<DenseVoxels>(*fine), DenseFilter::Nearest, 1.0), cam);
    for (int n : {1, 2, 4, 8}) {
        auto seq = loadVdb((dir / "ramp.vdb").string(), densityOnly(n));
        ASSERT_TRUE(seq) << seq.error();
        const auto got = pixelDepths(denseMedium(coarseVoxels(*seq), DenseFilter::Nearest, 1.0), cam);
        double worst = 0.0;
        for (std::size_t i = 0; i < got.size(); ++i) {
            const int col = int(i % 32);
            const double centre = (col / n) * n + 0.5 * (n - 1);
            EXPECT_NEAR(got[i] - truth[i], s * D * b * (centre - col), 2.0 * depthTolerance(truth[i])) << n << " column " << col;
            worst = std::max(worst, std::abs(got[i] - truth[i]));
        }
        EXPECT_NEAR(worst, s * D * b * (n - 1) / 2.0, 2.0 * depthTolerance(3.0)) << n;
    }
}

// Trilinear and nearest readings of the same voxels integrate to the same
// optical depth along an axis through voxel centres when the density is
// constant along that axis inside the box and the ray crosses it whole: the
// trilinear ramps at the two ends (half a voxel each side) add up to one voxel.
TEST(VdbReference, TrilinearAndNearestAgreeAlongAColumnOfConstantDensity) {
    auto v = std::make_shared<DenseVoxels>();
    v->dims = {3, 3, 6};
    v->voxelSize = 0.2;
    v->values.assign(3 * 3 * 6, 0.0f);
    for (int z = 0; z < 6; ++z) v->values[(std::size_t(z) * 3 + 1) * 3 + 1] = 1.5f; // the centre column
    const Camera cam = orthoAlongZ({-0.1, -0.1}, {3, 3}, 0.2, 4.0);
    const auto n = pixelDepths(denseMedium(v, DenseFilter::Nearest, 1.0), cam);
    const auto t = pixelDepths(denseMedium(v, DenseFilter::Trilinear, 1.0), cam);
    EXPECT_NEAR(n[4], 1.5 * 6 * 0.2, depthTolerance(1.8));
    EXPECT_NEAR(t[4], 1.5 * 6 * 0.2, depthTolerance(1.8));
    EXPECT_NEAR(t[0], 0.0, 1e-12) << "the trilinear reading is 0 along the neighbouring centres";
}

// The reference's dense copy is bounded: two voxels 1000 apart make a box of
// 1001 voxels, refused under a budget of 1000 naming the grid and the budget
// (a file whose active box is huge cannot make the reference allocate it).
TEST(VdbReference, ADenseBoxOverTheBudgetIsRefusedNamingIt) {
    const fs::path dir = tempDir();
    auto g = densityGrid(0.1);
    g->tree().setValue({0, 0, 0}, 1.0f);
    g->tree().setValue({1000, 0, 0}, 1.0f);
    write(dir / "far.vdb", {g});
    auto v = readVdbDensity((dir / "far.vdb").string(), densityOnly(1), 1000);
    ASSERT_FALSE(v);
    EXPECT_NE(v.error().find("grid 'density'"), std::string::npos) << v.error();
    EXPECT_NE(v.error().find("1001 voxels, more than 1000 (readVdbDensity's maxVoxels)"), std::string::npos) << v.error();
    EXPECT_TRUE(readVdbDensity((dir / "far.vdb").string(), densityOnly(1), 1001)) << "at the budget it is read";
}

// The trilinear reading is OpenVDB's own BoxSampler at any point, tiles
// included: 500 random points over a grid of random voxels beside a tile,
// the sampler in OpenVDB's float against the reference in double: equal to
// a few float roundings of values up to 2 (8 corner terms: 2^-20 relative).
TEST(VdbReference, TrilinearReadingIsOpenVdbsBoxSamplerEverywhere) {
    const fs::path dir = tempDir();
    auto g = randomDensity({0, 0, 0}, {6, 5, 4}, 0.2, 17);
    g->setTransform(xform(0.2));
    g->tree().addTile(1, openvdb::Coord(8, 0, 0), 1.25f, true);
    write(dir / "s.vdb", {g});
    auto v = readVdbDensity((dir / "s.vdb").string(), densityOnly(1));
    ASSERT_TRUE(v) << v.error();
    const ContinuousMedium m = denseMedium(std::make_shared<DenseVoxels>(*v), DenseFilter::Trilinear, 1.0);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto acc = g->getConstAccessor();
    for (int i = 0; i < 500; ++i) {
        const glm::dvec3 p = m.boxMin + glm::dvec3(u(rng), u(rng), u(rng)) * (m.boxMax - m.boxMin);
        const double want = openvdb::tools::BoxSampler::sample(acc, g->transform().worldToIndex(openvdb::Vec3d(p.x, p.y, p.z)));
        EXPECT_NEAR(m.sample(p).extinction, want, 2.0 * 0x1p-20) << p.x << "," << p.y << "," << p.z;
    }
}
