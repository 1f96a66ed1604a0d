// The scene files' effect kind "vdb" (sdk/src/scenefile/kinds/vdb.cpp), CPU
// only: the sample's baked smoke builds, import errors arrive at the effect's
// "files" path naming the file, frame and grid, and a build without OpenVDB
// says what it lacks instead of "unknown kind".
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "splatfx/scene_file.hpp"

namespace {

const std::string kHead = R"("format": "splatfx-scene", "version": 1)";
const std::string kFiles = std::string(SPLATFX_SOURCE_DIR) + "/samples/20-vdb-smoke/data/fluid_data_####.vdb";

splatfx::Result<splatfx::SceneFile> parse(const std::string& effect) {
    splatfx::Materials m(splatfx::Footprint{});
    return splatfx::parseSceneFile("{" + kHead + R"(, "effects": [)" + effect + "]}", "dir/scene.json", m);
}

} // namespace

#if SPLATFX_WITH_VDB

TEST(SceneFileVdb, TheSampleSceneBuilds) {
    splatfx::Materials m(splatfx::Footprint{});
    auto f = splatfx::loadSceneFile(std::string(SPLATFX_SOURCE_DIR) + "/samples/20-vdb-smoke/scene.json", m);
    ASSERT_TRUE(f) << f.error();
    ASSERT_EQ(f->effects.size(), 1u);
    EXPECT_EQ(f->effects[0].kind, "vdb");
    const splatfx::Aabb box = f->scene.kind(f->effects[0].id).bounds(0.0, 2.0);
    // The bake stands on the ground (Blender's z-up domain turned y-up by the file's rotation).
    EXPECT_FALSE(box.empty());
    EXPECT_GT(box.hi.y, 2.0f);
}

TEST(SceneFileVdb, ImportErrorsNameFileFrameAndGrid) {
    auto r = parse(R"({"kind": "vdb", "files": ")" + kFiles + R"(", "lastFrame": 3, "grids": {"temperature": "heat"}})");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("effects[0].files"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("fluid_data_0001.vdb' (frame 1), grid 'heat': no such grid in the file"), std::string::npos) << r.error();
}

TEST(SceneFileVdb, KeysAreChecked) {
    auto r = parse(R"({"kind": "vdb", "files": ")" + kFiles + R"(", "velocityUnit": "mph", "temperatureHot": 3})");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("effects[0].velocityUnit"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("give both \"temperatureHot\" and \"temperatureCold\""), std::string::npos) << r.error();
    auto m = parse(R"({"kind": "vdb"})");
    ASSERT_FALSE(m);
    EXPECT_NE(m.error().find("missing \"files\""), std::string::npos) << m.error();
}

// A real frame with four bytes of its density grid's metadata changed (the
// delayed-load entry count, which OpenVDB allocates as given): the scene file
// is refused at the effect's "files", naming the file, before OpenVDB reads it.
TEST(SceneFileVdb, CorruptedFileRefusedAtFiles) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "splatfx-scenefile-vdb-corrupt";
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ifstream in(std::string(SPLATFX_SOURCE_DIR) + "/samples/20-vdb-smoke/data/fluid_data_0010.vdb", std::ios::binary);
    std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const std::size_t type = bytes.find("__delayedload", bytes.find("density"));
    ASSERT_NE(type, std::string::npos);
    const std::uint32_t huge = 0x7fffffff;
    std::memcpy(&bytes[type + 13 + 4], &huge, 4);
    std::ofstream(dir / "smoke.vdb", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    auto r = parse(R"({"kind": "vdb", "files": ")" + (dir / "smoke.vdb").string() + R"(", "grids": {"temperature": "flame"}})");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("effects[0].files"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("smoke.vdb' (frame 0): refused before OpenVDB reads it: grid 'density''s metadata 'file_delayed_load' claims "
                             "2147483647 leaves"),
              std::string::npos)
        << r.error();
    fs::remove_all(dir);
}

#else

TEST(SceneFileVdb, ABuildWithoutOpenVdbSaysSo) {
    auto r = parse(R"({"kind": "vdb", "files": ")" + kFiles + R"("})");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("kind \"vdb\" needs splatfx built with OpenVDB"), std::string::npos) << r.error();
}

#endif
