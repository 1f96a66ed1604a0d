// The example host's mesh loader refuses hostile files cleanly (issue 13):
// out-of-range indices, headers claiming more elements than the file can
// hold or than the budget allows, and non-regular files.
#include <filesystem>
#include <fstream>

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "mesh.hpp"

namespace fs = std::filesystem;

namespace {

std::string writeFile(const std::string& name, const std::string& bytes) {
    const fs::path dir = fs::path(splatfx::test::outputDir());
    fs::create_directories(dir);
    const fs::path p = dir / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
}

void expectRefused(const std::string& path, const std::string& fragment) {
    auto m = scenehost::loadMesh(path);
    ASSERT_FALSE(m) << path << " loaded";
    EXPECT_NE(m.error().find(path), std::string::npos) << m.error();
    EXPECT_NE(m.error().find(fragment), std::string::npos) << m.error();
}

const char* kPlyHeader = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";

} // namespace

TEST(SceneHostMesh, AGoodTriangleLoads) {
    auto m = scenehost::loadMesh(writeFile("good.ply", std::string(kPlyHeader) + "3 0 1 2\n"));
    ASSERT_TRUE(m) << m.error();
    EXPECT_EQ(m->indices.size(), 3u);
}

TEST(SceneHostMesh, AFaceIndexPastTheVerticesIsAnError) {
    auto m = scenehost::loadMesh(writeFile("bad_index.ply", std::string(kPlyHeader) + "3 0 1 99999999\n"));
    EXPECT_FALSE(m && !m->indices.empty()) << "a face pointing past the vertices must not be drawn";
}

TEST(SceneHostMesh, AnOffHeaderClaimingAHundredMillionFacesIsRefusedBeforeReading) {
    expectRefused(writeFile("bomb.off", "OFF\n100000000 100000000 0\n0 0 0\n"), "over the mesh budget");
}

TEST(SceneHostMesh, APlyClaimingMoreVerticesThanItsBytesIsRefused) {
    expectRefused(writeFile("short.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 2000000\nproperty float x\n"
                                         "property float y\nproperty float z\nend_header\n"),
                  "but the file has only");
}

TEST(SceneHostMesh, AFifoIsNotRead) {
    const std::string fifo = (fs::path(splatfx::test::outputDir()) / "mesh.fifo").string();
    fs::create_directories(splatfx::test::outputDir());
    fs::remove(fifo);
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    expectRefused(fifo, "not a regular file");
}
