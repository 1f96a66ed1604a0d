// Scene files: the "lights" list, "sceneShadow" and each effect's "lighting"
// (issue 16): what a valid block builds, and errors naming the field.
#include <cmath>

#include <gtest/gtest.h>

#include "splatfx/cloud.hpp"
#include "splatfx/scene_file.hpp"

namespace {

const std::string kHead = R"("format": "splatfx-scene", "version": 1)";

splatfx::Result<splatfx::SceneFile> parse(const std::string& body) {
    splatfx::Materials m(splatfx::Footprint{});
    return splatfx::parseSceneFile("{" + kHead + ", " + body + "}", "dir/scene.json", m);
}

void expectError(const std::string& body, std::initializer_list<const char*> fragments) {
    auto r = parse(body);
    ASSERT_FALSE(r.ok()) << "accepted: " << body;
    for (const char* f : fragments) EXPECT_NE(r.error().find(f), std::string::npos) << "missing '" << f << "' in:\n" << r.error();
}

} // namespace

TEST(SceneFileLights, LightsSceneShadowAndEffectLightingAreRead) {
    auto r = parse(R"("lights": [
        {"type": "directional", "direction": [0.3, -1, 0.2], "color": [1, 0.9, 0.8], "intensity": 1.5},
        {"type": "point", "position": [1, 2, 3], "intensity": 4, "radius": 0.1},
        {"type": "spot", "position": [0, 5, 0], "direction": [0, -1, 0], "innerConeDeg": 10, "outerConeDeg": 20}],
      "sceneShadow": {"light": 1, "dims": [32, 48, 16]},
      "effects": [{"kind": "steam", "lighting": {"albedo": 0.9, "phase": [{"g": 0.6, "weight": 3}, {"g": -0.3, "weight": 1}],
                                                 "selfShadow": "traced", "tableDims": 24, "ambient": [0.1, 0.1, 0.2],
                                                 "multipleScattering": 0.3, "castsShadow": false}},
                  {"kind": "fire"}])");
    ASSERT_TRUE(r.ok()) << r.error();
    const auto lights = r->scene.lights();
    ASSERT_EQ(lights.size(), 3u);
    EXPECT_EQ(lights[0].type, splatfx::LightType::Directional);
    EXPECT_EQ(lights[0].color, glm::vec3(1, 0.9f, 0.8f));
    EXPECT_FLOAT_EQ(lights[0].intensity, 1.5f);
    EXPECT_EQ(lights[1].type, splatfx::LightType::Point);
    EXPECT_EQ(lights[1].position, glm::vec3(1, 2, 3));
    EXPECT_FLOAT_EQ(lights[1].radiusWorld, 0.1f);
    EXPECT_EQ(lights[2].type, splatfx::LightType::Spot);
    EXPECT_NEAR(lights[2].innerConeRad, 10.0 * M_PI / 180.0, 1e-6);
    EXPECT_NEAR(lights[2].outerConeRad, 20.0 * M_PI / 180.0, 1e-6);
    EXPECT_EQ(r->scene.sceneShadow().light, 1u);
    EXPECT_EQ(r->scene.sceneShadow().dims, glm::ivec3(32, 48, 16));
    const splatfx::EffectLighting& l = r->scene.options(r->effects[0].id).lighting;
    EXPECT_TRUE(l.enabled);
    EXPECT_FLOAT_EQ(l.gas.albedo, 0.9f);
    ASSERT_EQ(l.gas.phase.lobeCount(), 2);
    EXPECT_FLOAT_EQ(l.gas.phase.lobe(0).g, 0.6f);
    EXPECT_FLOAT_EQ(l.gas.phase.lobe(0).weight, 0.75f); // normalized
    EXPECT_EQ(l.selfShadow, splatfx::SelfShadow::Traced);
    EXPECT_EQ(l.tableDims, glm::ivec3(24));
    EXPECT_EQ(l.gas.ambient, glm::vec3(0.1f, 0.1f, 0.2f));
    EXPECT_FLOAT_EQ(l.gas.multipleScattering, 0.3f);
    EXPECT_FALSE(l.castsShadow);
    EXPECT_FALSE(r->scene.options(r->effects[1].id).lighting.enabled) << "no block: unlit";
}

TEST(SceneFileLights, BadInputNamesTheField) {
    expectError(R"("lights": [{"direction": [0, -1, 0]}])", {"lights[0]", "missing \"type\""});
    expectError(R"("lights": [{"type": "laser"}])", {"lights[0].type", "directional"});
    expectError(R"("lights": [{"type": "directional", "direction": [0, 0, 0]}])", {"lights[0].direction", "zero"});
    expectError(R"("lights": [{"type": "point", "intensity": -1}])", {"lights[0].intensity"});
    expectError(R"("lights": [{"type": "spot", "innerConeDeg": 50, "outerConeDeg": 20}])", {"lights[0].innerConeDeg"});
    expectError(R"("lights": [{"type": "point", "colour": [1, 1, 1]}])", {"lights[0]", "colour"});
    expectError(R"("lights": {"type": "point"})", {"lights: expected an array"});
    expectError(R"("sceneShadow": {"dims": [2048, 8, 8]})", {"sceneShadow.dims"});
    expectError(R"("sceneShadow": {"dims": 256})", {"sceneShadow.dims", "budget"});
    expectError(R"("effects": [{"kind": "steam", "lighting": {"albedo": 2}}])", {"effects[0].lighting.albedo"});
    expectError(R"("effects": [{"kind": "steam", "lighting": {"phase": [{"g": 1.5}]}}])", {"effects[0].lighting.phase[0].g"});
    expectError(R"("effects": [{"kind": "steam", "lighting": {"phase": []}}])", {"effects[0].lighting.phase", "1 to 4"});
    expectError(R"("effects": [{"kind": "steam", "lighting": {"selfShadow": "baked"}}])", {"effects[0].lighting.selfShadow", "table"});
    expectError(R"("effects": [{"kind": "steam", "lighting": {"tableDims": 0}}])", {"effects[0].lighting.tableDims"});
    expectError(R"("effects": [{"kind": "steam", "lighting": {"albdo": 0.5}}])", {"effects[0].lighting", "albdo"});
}

TEST(SceneFileLights, SceneShadowMaxLightsAndMemoryAreReadAndCheckedByName) {
    const std::string lights = R"("lights": [{"type": "directional"}, {"type": "point", "position": [0, 3, 0]}], )";
    auto r = parse(lights + R"("sceneShadow": {"maxLights": 2, "memoryMiB": 16, "dims": 32})");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->scene.sceneShadow().maxLights, 2);
    EXPECT_EQ(r->scene.sceneShadow().memoryBudgetBytes, 16ull << 20);
    r = parse(lights + R"("sceneShadow": {})");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->scene.sceneShadow().maxLights, splatfx::kMaxShadowLights) << "every light casts by default";
    expectError(lights + R"("sceneShadow": {"maxLights": 5})", {"sceneShadow.maxLights"});
    expectError(lights + R"("sceneShadow": {"maxLights": 0})", {"sceneShadow.maxLights"});
    expectError(lights + R"("sceneShadow": {"memoryMiB": 0})", {"sceneShadow.memoryMiB"});
    // One 64^3 table takes 4.25 MiB (17 bytes a node): a 4 MiB budget cannot hold even slot 0's.
    expectError(lights + R"("sceneShadow": {"memoryMiB": 4, "dims": 64})", {"sceneShadow.dims", "over the 4 MiB budget (memoryMiB)"});
}

// A cloud with "lighting" becomes a relightable Cloud (y up: dims [x, height,
// z]) lit by the scene; "lightModel" picks the model; a bad one is named.
TEST(SceneFileLights, LitCloudsAreRelightableAndTheirModelIsRead) {
    auto r = parse(R"("lights": [{"type": "directional", "direction": [0.3, -1, 0.2]}],
      "volumes": [{"kind": "clouds", "name": "c", "dims": [9, 5, 9], "tableScalars": 4, "tableLengths": 4,
                   "lightModel": "lowAlbedo", "lighting": {"albedo": 0.8}},
                  {"kind": "clouds", "dims": [9, 5, 9], "tableScalars": 4, "tableLengths": 4}])");
    ASSERT_TRUE(r.ok()) << r.error();
    ASSERT_EQ(r->volumes.size(), 2u);
    const splatfx::Cloud* lit = r->scene.findCloud(r->volumes[0].id);
    ASSERT_NE(lit, nullptr);
    EXPECT_EQ(lit->dims(), glm::ivec3(9, 5, 9));
    EXPECT_EQ(lit->lighting().model, splatfx::CloudLightModel::LowAlbedo);
    EXPECT_TRUE(r->scene.options(r->volumes[0].id).lighting.enabled);
    EXPECT_FLOAT_EQ(r->scene.options(r->volumes[0].id).lighting.gas.albedo, 0.8f);
    EXPECT_EQ(r->scene.findCloud(r->volumes[1].id), nullptr); // unlit: the baked LOD volume as before
    EXPECT_NE(r->scene.findLodVolume(r->volumes[1].id), nullptr);
    expectError(R"("volumes": [{"kind": "clouds", "dims": [9, 5, 9], "lightModel": "physical", "lighting": {}}])",
                {"volumes[0].lightModel", "expected \"roettger\" or \"lowAlbedo\", got 'physical'"});
}

// A moving sun: from "direction" at t = 0 to "directionEnd" at "moveSec"
// along the great circle (half the angle at half the time), then held.
// Float directions normalised: 1e-6.
TEST(SceneFileLights, ALightsDirectionMovesAlongTheGreatCircle) {
    auto r = parse(R"("lights": [{"type": "point"}, {"type": "directional", "direction": [1, 0, 0], "directionEnd": [0, -2, 0], "moveSec": 4}])");
    ASSERT_TRUE(r.ok()) << r.error();
    ASSERT_EQ(r->lightMotions.size(), 1u);
    const splatfx::LightMotion& m = r->lightMotions[0];
    EXPECT_EQ(m.light, 1u);
    const splatfx::Light base = r->scene.lights()[1];
    auto dir = [&](double t) { return m.at(base, t).direction; };
    EXPECT_NEAR(glm::length(dir(0.0) - glm::vec3(1, 0, 0)), 0.0, 1e-6);
    EXPECT_NEAR(glm::length(dir(2.0) - glm::vec3(std::sqrt(0.5f), -std::sqrt(0.5f), 0)), 0.0, 1e-6);
    EXPECT_NEAR(glm::length(dir(4.0) - glm::vec3(0, -1, 0)), 0.0, 1e-6);
    EXPECT_NEAR(glm::length(dir(9.0) - glm::vec3(0, -1, 0)), 0.0, 1e-6);
    EXPECT_EQ(m.at(base, 1.0).intensity, base.intensity);
    expectError(R"("lights": [{"type": "directional", "moveSec": 2}])", {"lights[0]", "\"moveSec\" needs \"directionEnd\""});
    expectError(R"("lights": [{"type": "directional", "directionEnd": [0, 0, 0]}])", {"lights[0].directionEnd", "must not be zero"});
}
