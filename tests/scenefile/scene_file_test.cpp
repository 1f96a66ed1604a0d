// Scene-file parser tests (CPU): what a valid file builds, and that every kind
// of bad input is refused with a message naming the file, the field and what
// was expected.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "splatfx/scene_file.hpp"
#include "splatfx/texture_set_io.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kHead = R"("format": "splatfx-scene", "version": 1)";

splatfx::Result<splatfx::SceneFile> parse(const std::string& body, const std::string& path = "dir/scene.json") {
    splatfx::Materials m(splatfx::Footprint{});
    return splatfx::parseSceneFile("{" + kHead + (body.empty() ? "" : ", " + body) + "}", path, m);
}

// Expects failure and every fragment in the message.
void expectError(const std::string& body, std::initializer_list<const char*> fragments, const std::string& path = "dir/scene.json") {
    auto r = parse(body, path);
    ASSERT_FALSE(r.ok()) << "accepted: " << body;
    for (const char* f : fragments) EXPECT_NE(r.error().find(f), std::string::npos) << "missing '" << f << "' in:\n" << r.error();
}

std::string corpus(const char* name) {
    std::ifstream in(std::string(SPLATFX_SCENEFILE_CORPUS) + "/" + name);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(SceneFile, MinimalFileHasDefaults) {
    auto r = parse("");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->scene.size(), 0u);
    EXPECT_EQ(r->output.size, glm::ivec2(640, 480));
    EXPECT_EQ(r->output.frames, 48);
    EXPECT_EQ(r->output.name, "dir"); // the scene file's folder
    ASSERT_EQ(r->camera.keys.size(), 1u);
}

TEST(SceneFile, FullCorpusFileBuildsEverything) {
    splatfx::Materials m(splatfx::Footprint{});
    auto r = splatfx::parseSceneFile(corpus("full.json"), "corpus/full.json", m);
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->scene.size(), 7u);
    ASSERT_EQ(r->effects.size(), 7u);
    EXPECT_EQ(r->effects[0].kind, "fire");
    EXPECT_EQ(r->effects[0].name, "fire0");
    EXPECT_EQ(r->effects[6].name, "blob");
    EXPECT_TRUE(r->effects[6].traditional);
    EXPECT_FALSE(r->scene.options(r->effects[3].id).enabled);
    EXPECT_FALSE(r->scene.effect(r->effects[0].id).desc().enabled.global);
    EXPECT_FALSE(r->scene.effect(r->effects[4].id).isStateless()); // smoke is a solver effect
    EXPECT_EQ(r->output.size, glm::ivec2(64, 48));
    EXPECT_EQ(r->camera.keys.size(), 2u);
    EXPECT_FALSE(r->camera.smooth);
    EXPECT_NEAR(r->camera.keys[1].fovYRad, glm::radians(50.0f), 1e-6f);
    ASSERT_EQ(r->geometry.size(), 5u);
    EXPECT_EQ(r->geometry[1].type, splatfx::GeometryType::Empty);
}

TEST(SceneFile, AttachedObjectsShareTheRootMotionAndComposePlacements) {
    auto r = parse(R"("geometry": [
        {"name": "train", "type": "empty", "position": [0, 1, 0],
         "motion": {"keys": [{"time": 0, "position": [0, 0, 0]}, {"time": 2, "position": [10, 0, 0]}]}},
        {"name": "boiler", "type": "box", "attachTo": "train", "position": [1, 0, 0]},
        {"name": "chimney", "type": "box", "attachTo": "boiler", "position": [0, 2, 0]}],
      "effects": [{"kind": "fire", "dims": [2, 3, 2], "attachTo": "chimney", "position": [0, 0.5, 0]}])");
    ASSERT_TRUE(r.ok()) << r.error();
    const splatfx::GeometryDesc& chimney = r->geometry[2];
    EXPECT_EQ(chimney.attachedTo, "boiler");
    // World at t = 1: root motion (5, 0, 0) after train (0, 1, 0), boiler (1, 0, 0), chimney (0, 2, 0).
    const glm::vec3 p = glm::vec3(chimney.motion.matrix(1.0) * chimney.transform * glm::vec4(0, 0, 0, 1));
    EXPECT_NEAR(glm::distance(p, glm::vec3(6, 3, 0)), 0.0f, 1e-5f);
    // The fire rides along: its grid moves with the train (the flame's base sits 0.5 above the chimney).
    splatfx::Effect& fire = r->scene.effect(r->effects[0].id);
    fire.update(1.0);
    const glm::vec3 base = glm::vec3(fire.grid().transform * glm::vec4(0, 0, 0, 1));
    EXPECT_NEAR(glm::distance(base, glm::vec3(6, 3.5f, 0)), 0.0f, 1e-5f);
}

TEST(SceneFile, SeedOptionChangesEveryEffectSeed) {
    splatfx::Materials m(splatfx::Footprint{});
    const std::string text = "{" + kHead + R"(, "seed": 5, "effects": [{"kind": "fire", "dims": [2, 3, 2]}]})";
    auto a = splatfx::parseSceneFile(text, "s.json", m);
    auto b = splatfx::parseSceneFile(text, "s.json", m, {.seed = 6});
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->seed, 5u);
    EXPECT_EQ(b->seed, 6u);
    EXPECT_NE(a->scene.effect(0).desc().textures.seed, b->scene.effect(0).desc().textures.seed);
}

TEST(SceneFile, SyntaxErrorGivesLineAndColumn) {
    splatfx::Materials m(splatfx::Footprint{});
    auto r = splatfx::parseSceneFile("{\n  \"format\": \"splatfx-scene\",\n  \"version\": 1,,\n}", "bad.json", m);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("bad.json:3:"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("syntax error"), std::string::npos) << r.error();
}

TEST(SceneFile, WrongFormatOrVersionIsRefusedFirst) {
    splatfx::Materials m(splatfx::Footprint{});
    auto r = splatfx::parseSceneFile(R"({"format": "splatfx-texture-set", "version": 1})", "x.json", m);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("x.json: format: expected \"splatfx-scene\""), std::string::npos) << r.error();
    r = splatfx::parseSceneFile(R"({"format": "splatfx-scene", "version": 2})", "x.json", m);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("version: expected 1, got 2 (written by a newer splatfx)"), std::string::npos) << r.error();
}

TEST(SceneFile, WrongTypeNamesTheField) {
    expectError(R"("effects": [{"kind": "fire", "dims": "big"}])",
                {"dir/scene.json: effects[0].dims: expected an array of 3 integers", "got a string \"big\""});
    expectError(R"("output": {"frames": 2.5})", {"output.frames: expected an integer in [1, 100000], got 2.5"});
    expectError(R"("effects": [{"kind": "fire", "crossfade": 1}])", {"effects[0].crossfade: expected true or false, got a number 1"});
}

TEST(SceneFile, UnknownEffectKindListsTheKinds) {
    expectError(R"("effects": [{"kind": "fires"}])", {"effects[0].kind: unknown value \"fires\" (did you mean \"fire\"?)", "ghosts"});
}

TEST(SceneFile, MissingTextureSetNamesTheFolder) {
    expectError(R"("effects": [{"kind": "fire"}, {"kind": "steam", "textureSet": "no/such/set"}])",
                {"effects[1].textureSet: texture set 'no/such/set' not found", "dir/no/such/set/manifest.json"});
}

TEST(SceneFile, MissingTextureSetFallsBackWhenAskedTo) {
    auto r = parse(R"("effects": [{"kind": "ghosts", "textureSet": {"folder": "no/faces", "ifMissing": "procedural", "count": 5}}])");
    ASSERT_TRUE(r.ok()) << r.error();
}

// Presets take texture sets in memory (splatfx::core reads no files): the
// reader loads a preset's folder itself, so the preset gets exactly that set,
// and a folder that exists but does not load is an error at the effect.
TEST(SceneFile, PresetTextureFoldersAreLoadedByTheReader) {
    const std::string set = std::string(SPLATFX_SOURCE_DIR) + "/textures/photo-fire-8x32";
    splatfx::Materials m(splatfx::Footprint{});
    const std::uint32_t sets = m.setCount(), layers = m.layerCount();
    auto r =
        splatfx::parseSceneFile("{" + kHead + R"(, "effects": [{"kind": "fire", "textureSet": {"folder": ")" + set + R"("}}]})", "dir/scene.json", m);
    ASSERT_TRUE(r.ok()) << r.error();
    auto direct = splatfx::loadTextureSet(set);
    ASSERT_TRUE(direct) << direct.error();
    ASSERT_EQ(m.setCount(), sets + 1);
    ASSERT_EQ(m.layerCount() - layers, std::uint32_t(direct->count()));
    // The same set registered by hand gives the same layers, texel for texel
    // (procedural turbulence of the same count would not).
    splatfx::TextureSet grey = *direct;
    grey.color = false; // what the fire preset does with a set it is given
    splatfx::Materials expected(splatfx::Footprint{});
    const std::uint32_t first = expected.layerCount();
    expected.addTextureSet(grey);
    for (std::uint32_t k = 0; k < std::uint32_t(direct->count()); ++k)
        EXPECT_EQ(m.layer(layers + k), expected.layer(first + k)) << "layer " << k << " is not the folder's";

    const fs::path broken = fs::temp_directory_path() / ("splatfx-broken-set-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    fs::create_directories(broken);
    std::ofstream(broken / "manifest.json") << R"({"format": "splatfx-texture-set", "version": 1, "textures": ["t000.png"]})";
    expectError(R"("effects": [{"kind": "steam"}, {"kind": "fire", "textureSet": {"folder": ")" + broken.string() + R"("}}])",
                {"effects[1]", "t000.png"});
    fs::remove_all(broken);
}

TEST(SceneFile, AbsurdSizesAreRefusedBeforeAllocating) {
    expectError(R"("effects": [{"kind": "fire", "dims": [1000, 1000, 1000]}])",
                {"effects[0].dims: 1000x1000x1000 (grid effects) needs 1000000000 cells, over the budget of 16777216 (raise Budgets::effectCells)"});
    expectError(R"("effects": [{"kind": "smoke", "dims": [100, 100, 100]}])",
                {"effects[0].dims:", "over the budget of 262144", "solver", "Budgets::solverCells"});
    expectError(R"("effects": [{"kind": "grid", "dims": [5, 99999, 5]}])", {"effects[0].dims[1]: expected an integer in [1, 4096], got 99999"});
    expectError(R"("output": {"size": [100000, 10]})", {"output.size[0]: expected an integer in [16, 8192], got 100000"});
}

TEST(SceneFile, NonFiniteAndHugeValuesAreRefused) {
    // The library gives no position for an overflowing literal; the reader finds it (line 1, after the head).
    expectError(R"("effects": [{"kind": "fire", "position": [0, 1e999, 0]}])",
                {"dir/scene.json:1:", ": number overflow parsing '1e999' (expected a finite number)"});
    expectError(R"("effects": [{"kind": "fire", "position": [0, 1e30, 0]}])",
                {"effects[0].position[1]: expected a number in [-1e+06, 1e+06], got 1e+30"});
    expectError(R"("camera": {"fovDeg": 0})", {"camera.fovDeg: expected a number in [1, 170], got 0"});
}

// Bytes after a NUL were silently ignored; now the NUL itself is the error, with its place.
TEST(SceneFile, ANulByteIsRefusedWhereItIs) {
    splatfx::Materials m(splatfx::Footprint{});
    const std::string text = std::string("{\"format\": \"splatfx-scene\", \"version\": 1}\n", 42) + std::string(1, '\0') + "garbage";
    auto r = splatfx::parseSceneFile(text, "dir/scene.json", m);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("dir/scene.json:2:1: a NUL byte"), std::string::npos) << r.error();
}

TEST(SceneFile, UnknownKeysAreReportedWithASuggestion) {
    expectError(R"("effects": [{"kind": "fire", "dimz": [7, 20, 5]}])", {"effects[0].dimz: unknown key (did you mean \"dims\"?)"});
    expectError(R"("outptu": {})", {"outptu: unknown key (did you mean \"output\"?)"});
    // Keys of another kind are unknown here: fire has no "split".
    expectError(R"("effects": [{"kind": "fire", "split": 0.5}])", {"effects[0].split: unknown key"});
}

TEST(SceneFile, SeveralProblemsAreReportedAtOnce) {
    auto r = parse(R"("output": {"frames": -1, "fps": "fast"}, "effects": [{"kind": "fire", "opacity": 2}])");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("output.frames"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("output.fps"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("effects[0].opacity"), std::string::npos) << r.error();
}

TEST(SceneFile, AttachmentErrors) {
    expectError(R"("geometry": [{"name": "cow", "type": "box"}], "effects": [{"kind": "fire", "attachTo": "cwo"}])",
                {"effects[0].attachTo: no geometry named 'cwo' (did you mean 'cow'?)"});
    expectError(R"("geometry": [{"name": "a", "type": "box", "attachTo": "b"}, {"name": "b", "type": "box", "attachTo": "a"}])",
                {"geometry[0].attachTo: attachment chain through 'b' loops"});
    expectError(R"("effects": [{"kind": "smoke", "motion": {"velocity": [1, 0, 0]}}])", {"effects[0].motion: solver effects"});
}

TEST(SceneFile, MotionErrorsNameTheKey) {
    expectError(R"("geometry": [{"type": "box", "motion": {"keys": [{"time": 1}, {"time": 1}]}}])",
                {"geometry[0].motion.keys[1].time: key times must increase strictly"});
    expectError(R"("geometry": [{"type": "box", "motion": {"keys": [{"time": 0, "easing": "bouncy"}]}}])",
                {"geometry[0].motion.keys[0].easing: unknown value \"bouncy\""});
}

TEST(SceneFile, MissingMeshNamesTheResolvedPath) {
    expectError(R"("geometry": [{"type": "mesh", "mesh": "cow.obj"}])", {"geometry[0].mesh: mesh file 'cow.obj' not found", "dir/cow.obj"});
}

TEST(SceneFile, DeepNestingIsRefused) {
    std::string deep(200, '[');
    expectError(R"("title": )" + deep, {"nesting deeper than 64 levels"});
}

TEST(SceneFile, GridShapesVoxelizeWithinTheLattice) {
    auto r = parse(R"("effects": [{"kind": "grid", "dims": [9, 9, 9], "shapes": [{"type": "sphere", "center": [4, 4, 4], "radius": 2}]}])");
    ASSERT_TRUE(r.ok()) << r.error();
    const splatfx::Grid& g = r->scene.effect(0).grid();
    // Cells whose centre is within radius + soft edge: about (4/3) pi 2.4^3 = 58; the soft edge keeps it between the 2.0 and 2.8 balls.
    EXPECT_GT(g.voxels.size(), 33u);
    EXPECT_LT(g.voxels.size(), 93u);
    for (const splatfx::Voxel& v : g.voxels) EXPECT_LE(glm::distance(glm::vec3(v.cell), glm::vec3(4)), 2.0f + 0.75f);
    expectError(R"("effects": [{"kind": "grid", "dims": [3, 3, 3], "shapes": [{"type": "sphere", "center": [40, 40, 40], "radius": 1}]}])",
                {"effects[0].shapes: the shapes cover no cell"});
}

TEST(SceneFile, LoadSceneFileReportsAMissingFile) {
    splatfx::Materials m(splatfx::Footprint{});
    auto r = splatfx::loadSceneFile("definitely/not/here.json", m);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(), "definitely/not/here.json: scene file not found");
}

TEST(SceneFile, PathsAreRelativeToTheFile) {
    const fs::path dir = fs::temp_directory_path() / "splatfx_scenefile_paths";
    fs::create_directories(dir / "meshes");
    std::ofstream(dir / "meshes" / "m.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    std::ofstream(dir / "scene.json") << "{" << kHead << R"(, "geometry": [{"type": "mesh", "mesh": "meshes/m.off"}]})";
    splatfx::Materials m(splatfx::Footprint{});
    auto r = splatfx::loadSceneFile((dir / "scene.json").string(), m);
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(fs::path(r->geometry[0].meshPath), (dir / "meshes" / "m.off").lexically_normal());
    fs::remove_all(dir);
}

} // namespace

// Budgets checked while reading, before the memory is spent (issue 13): a
// sampled set's texels, and the layers of all the scene's distinct sets (the
// error names the effect that crosses the limit).
TEST(SceneFile, TextureBudgetsAreCheckedBeforeBuilding) {
    expectError(R"("effects": [{"kind": "grid", "dims": [2, 2, 2], "textureSet": {"sampleImage": {"image": "x.png", "count": 256, "size": 1024}}}])",
                {"effects[0].textureSet.sampleImage: count 256 x size 1024^2 needs 268435456 texels, over the budget of 16777216 (raise "
                 "Budgets::sampledTexels)"});
    std::string effects;
    for (int i = 0; i < 300; ++i)
        effects += std::string(i ? ", " : "") + R"({"kind": "grid", "dims": [2, 2, 2], "textureSet": {"procedural": {"count": 16, "seed": )" +
                   std::to_string(i) + "}}}";
    expectError(R"("effects": [)" + effects + "]", {"effects[127]: the scene, with this effect, needs 2049 layers, over the budget of 2048 (raise "
                                                    "Budgets::textureLayers) in its distinct texture sets"});
}

// The budgets are the user's to raise (budget.hpp): the same files load once
// SceneFileOptions::budgets allows them, and only then.
TEST(SceneFile, RaisedBudgetsLetTheSameFileLoad) {
    const std::string smoke = R"({"format": "splatfx-scene", "version": 1, "effects": [{"kind": "smoke", "dims": [72, 72, 72]}]})";
    splatfx::Materials m(splatfx::Footprint{});
    auto refused = splatfx::parseSceneFile(smoke, "dir/scene.json", m);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().find("needs 373248 cells, over the budget of 262144 (raise Budgets::solverCells)"), std::string::npos)
        << refused.error();
    splatfx::SceneFileOptions raised;
    raised.budgets.solverCells = 400000;
    auto loaded = splatfx::parseSceneFile(smoke, "dir/scene.json", m, raised);
    ASSERT_TRUE(loaded) << loaded.error();
    EXPECT_EQ(loaded->effects.size(), 1u);
    // Lowering one works the same way: a 7x20x5 fire over a 500-cell budget is refused.
    splatfx::SceneFileOptions lowered;
    lowered.budgets.effectCells = 500;
    auto fire = splatfx::parseSceneFile(R"({"format": "splatfx-scene", "version": 1, "effects": [{"kind": "fire", "dims": [7, 20, 5]}]})",
                                        "dir/scene.json", m, lowered);
    ASSERT_FALSE(fire);
    EXPECT_NE(fire.error().find("needs 700 cells, over the budget of 500 (raise Budgets::effectCells)"), std::string::npos) << fire.error();
}

// (issue 15) Geometry opacity: transparent surfaces (default opaque), range-checked.
TEST(SceneFile, GeometryOpacityMarksTransparentSurfaces) {
    auto r = parse(R"("geometry": [{"type": "box"}, {"name": "glass", "type": "box", "opacity": 0.25}])");
    ASSERT_TRUE(r.ok()) << r.error();
    ASSERT_EQ(r->geometry.size(), 2u);
    EXPECT_EQ(r->geometry[0].opacity, 1.0f);
    EXPECT_EQ(r->geometry[1].opacity, 0.25f);
    expectError(R"("geometry": [{"type": "box", "opacity": 1.5}])", {"opacity"});
    expectError(R"("geometry": [{"type": "box", "opacity": -0.1}])", {"opacity"});
}
