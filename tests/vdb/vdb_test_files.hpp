// Writing small OpenVDB files for the VDB tests (OpenVDB's C++ API), one temp
// folder per test.
#pragma once

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

namespace splatfx::vdbtest {

namespace fs = std::filesystem;

// One folder per test, under the system temp folder.
inline fs::path tempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path d = fs::temp_directory_path() / (std::string("splatfx-vdb-") + info->test_suite_name() + "-" + info->name());
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

inline openvdb::math::Transform::Ptr xform(double voxelSize, openvdb::Vec3d origin = openvdb::Vec3d(0.0)) {
    auto t = openvdb::math::Transform::createLinearTransform(voxelSize);
    t->postTranslate(origin);
    return t;
}

inline void write(const fs::path& p, const openvdb::GridPtrVec& grids) {
    openvdb::initialize();
    openvdb::io::File(p.string()).write(grids);
}

// Deterministic densities on [lo, hi] (inclusive), some cells left empty.
inline openvdb::FloatGrid::Ptr randomDensity(openvdb::Coord lo, openvdb::Coord hi, double voxelSize, unsigned seed) {
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    g->setGridClass(openvdb::GRID_FOG_VOLUME);
    g->setTransform(xform(voxelSize, {0.25, -1.0, 0.5}));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    auto acc = g->getAccessor();
    for (int z = lo.z(); z <= hi.z(); ++z)
        for (int y = lo.y(); y <= hi.y(); ++y)
            for (int x = lo.x(); x <= hi.x(); ++x) {
                const float v = u(rng);
                if (v > 0.3f) acc.setValue({x, y, z}, 2.0f * v);
            }
    return g;
}

inline std::string readBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void writeBytes(const fs::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

} // namespace splatfx::vdbtest
