// A solver effect's "obstacles" (docs/scene-format.md): entries naming the
// file's geometry or giving their own shape, and the messages for bad ones.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/scene_file.hpp"

namespace {

splatfx::Result<splatfx::SceneFile> parse(const std::string& body) {
    splatfx::Materials m(splatfx::Footprint{});
    return splatfx::parseSceneFile(R"({"format": "splatfx-scene", "version": 1, )" + body + "}", "dir/scene.json", m);
}

const splatfx::FluidSolver& solverOf(const splatfx::SceneFile& f) {
    const splatfx::FluidSolver* s = f.scene.effect(f.effects.at(0).id).solver();
    EXPECT_NE(s, nullptr);
    return *s;
}

void expectError(const std::string& body, const std::string& what) {
    auto r = parse(body);
    ASSERT_FALSE(r) << "accepted: " << body;
    EXPECT_NE(r.error().find(what), std::string::npos) << r.error();
}

const std::string kSmoke = R"("kind": "smoke", "dims": [8, 8, 4], "spacing": 0.5)";

} // namespace

TEST(SceneFileObstacles, NamedGeometryGivesItsShapePlacementAndMotion) {
    // The deck is attached to a moving anchor: the obstacle rides the same
    // motion and the composed placement, as the host draws it.
    auto r = parse(R"("geometry": [
        {"name": "crane", "type": "empty", "motion": {"keys": [{"time": 0, "position": [0, 0, 0]}, {"time": 2, "position": [1, 0, 0]}]}},
        {"name": "deck", "type": "box", "attachTo": "crane", "size": [3, 0.5, 2], "position": [0, 2.5, 0]}],
      "effects": [{)" + kSmoke + R"(, "obstacles": [{"geometry": "deck", "slip": "none"}]}])");
    ASSERT_TRUE(r) << r.error();
    const splatfx::FluidSolver& s = solverOf(*r);
    ASSERT_EQ(s.obstacles().size(), 1u);
    const splatfx::Obstacle& o = s.obstacles()[0];
    EXPECT_EQ(o.desc.shape, splatfx::ObstacleShape::Box);
    EXPECT_EQ(o.desc.size, glm::vec3(3, 0.5f, 2));
    EXPECT_EQ(o.desc.slip, splatfx::Slip::None);
    EXPECT_EQ(glm::vec3(o.objectToWorld(2.0)[3]), glm::vec3(1, 2.5f, 0));
    // The deck (y 2.25..2.75) covers the layer of cells at y = 2.5 (row 5), 6 cells wide, all 4 deep.
    EXPECT_EQ(s.stats().solidCells, 6u * 4u);
    EXPECT_TRUE(s.solid({4, 5, 0}));
}

TEST(SceneFileObstacles, InlineShapesAndMeshesAreRead) {
    auto r = parse(R"("effects": [{)" + kSmoke + R"(, "obstacles": [
        {"type": "plane", "size": [100, 1, 100], "position": [0, 0.6, 0]},
        {"type": "mesh", "position": [0, 2, 0], "slip": "free",
         "triangles": [[0,0,0],[1,0,0],[0,1,0], [0,0,0],[0,0,1],[1,0,0], [0,0,0],[0,1,0],[0,0,1], [1,0,0],[0,0,1],[0,1,0]],
         "motion": {"velocity": [0.5, 0, 0]}}]}])");
    ASSERT_TRUE(r) << r.error();
    const splatfx::FluidSolver& s = solverOf(*r);
    ASSERT_EQ(s.obstacles().size(), 2u);
    EXPECT_EQ(s.obstacles()[0].desc.shape, splatfx::ObstacleShape::Plane);
    EXPECT_EQ(s.obstacles()[1].desc.shape, splatfx::ObstacleShape::Mesh);
    EXPECT_EQ(s.obstacles()[1].desc.triangles.size(), 12u);
    // The ground covers rows 0 and 1 (y 0 and 0.5 <= 0.6): 2 * 8 * 4 cells; the small tetrahedron none.
    EXPECT_EQ(s.stats().solidCells, 64u);
}

TEST(SceneFileObstacles, BadEntriesNameTheField) {
    const std::string geo = R"("geometry": [{"name": "deck", "type": "box"}, {"name": "cow", "type": "mesh", "mesh": ")" SPLATFX_SOURCE_DIR
                            R"(/samples/03-cow-through-fire/scene.json"}], )";
    auto with = [&](const std::string& obstacles) { return geo + R"("effects": [{)" + kSmoke + R"(, "obstacles": )" + obstacles + "}]"; };
    expectError(with(R"([{"geometry": "dek"}])"), "effects[0].obstacles[0].geometry: no geometry named 'dek' (did you mean 'deck'?)");
    expectError(with(R"([{"geometry": "cow"}])"), "effects[0].obstacles[0].geometry: geometry 'cow' is a mesh, heightmap or empty anchor");
    expectError(with(R"([{"geometry": "deck", "size": 2}])"), "effects[0].obstacles[0].size: an obstacle naming \"geometry\" takes its shape");
    expectError(with(R"([{"geometry": "deck", "slip": "sticky"}])"), "effects[0].obstacles[0].slip: unknown value \"sticky\"");
    expectError(with(R"([{"size": 2}])"), "effects[0].obstacles[0]: missing \"type\"");
    expectError(with(R"([{"type": "box", "size": [1, 0, 1]}])"), "effects[0].obstacles[0].size");
    expectError(with(R"([{"type": "mesh"}])"), "effects[0].obstacles[0]: missing \"triangles\"");
    expectError(with(R"([{"type": "mesh", "triangles": [[0,0,0],[1,0,0]]}])"),
                "effects[0].obstacles[0]: triangles must hold three vertices per triangle (a non-zero multiple of 3), got 2");
    expectError(with(R"([{"type": "mesh", "triangles": [[0,0,0],[1,1,1],[2,2,2]]}])"),
                "effects[0].obstacles[0]: triangles: every triangle has zero area");
    expectError(with(R"([{"type": "mesh", "triangles": [[0,0,0],[1,0,"x"],[0,1,0]]}])"), "effects[0].obstacles[0].triangles[1]");
    expectError(with(R"([{"type": "box", "triangles": [[0,0,0],[1,0,0],[0,1,0]]}])"),
                "effects[0].obstacles[0].triangles: \"triangles\" belongs to \"type\": \"mesh\"");
    expectError(with(R"([{"type": "box", "attachTo": "deck", "motion": {"velocity": [1, 0, 0]}}])"),
                "effects[0].obstacles[0].motion: an obstacle either has its own \"motion\" or is attached to geometry; not both");
    expectError(with(R"({"type": "box"})"), "effects[0].obstacles: expected an array of at most 4096 obstacles");
    expectError(with(R"([{"type": "box", "colour": 1}])"), "effects[0].obstacles[0].colour: unknown key; keys allowed here: attachTo, geometry, motion");
}
