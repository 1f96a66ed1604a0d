// Scene files that ask for something the reader used to drop or change
// silently: duplicate JSON keys (the JSON library keeps the last), a scene
// shadow cast by a light the scene does not have, and times later than the
// dynamics hold exactly. Each is an error naming the file, the field and
// what was expected, and nothing is built.
#include <string>

#include <gtest/gtest.h>

#include "splatfx/scene_file.hpp"

namespace {

const std::string kHead = R"({"format": "splatfx-scene", "version": 1,)";

splatfx::Result<splatfx::SceneFile> parseText(const std::string& text, int maxErrors = 8) {
    splatfx::Materials m(splatfx::Footprint{});
    splatfx::SceneFileOptions options;
    options.maxErrors = maxErrors;
    return splatfx::parseSceneFile(text, "dir/scene.json", m, options);
}

splatfx::Result<splatfx::SceneFile> parse(const std::string& body) { return parseText(kHead + "\n" + body + "}"); }

} // namespace

// "density": 0.5, "density": 1e6 became 1e6; "dims" twice built the larger grid.
TEST(SceneFileStrict, DuplicateKeysAreAnErrorNamingBothPlaces) {
    // Line 2 column 32 and line 3 column 17 (columns count bytes from 1).
    auto r = parseText(kHead + "\n"
                               "  \"effects\": [{\"kind\": \"fire\", \"opacity\": 0.5,\n"
                               "                \"opacity\": 1}]}");
    ASSERT_FALSE(r.ok()) << "a duplicate key was accepted";
    EXPECT_EQ(r.error(), "dir/scene.json:3:17: effects[0].opacity: duplicate key; it is also given at dir/scene.json:2:32 "
                         "(JSON keeps only one of them: remove the other)");

    // Nested in arrays and objects; the second occurrence is reported where it is.
    r = parse(R"("effects": [{"kind": "fire"}, {"kind": "smoke", "dims": [4, 4, 4], "motion": {"velocity": [1, 0, 0], "velocity": [2, 0, 0]}}])");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("effects[1].motion.velocity: duplicate key; it is also given at dir/scene.json:2:"), std::string::npos) << r.error();

    // The top level, and a key written with an escape is the same key to JSON.
    r = parse(R"("seed": 1, "s\u0065ed": 2)");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(),
              "dir/scene.json:2:12: seed: duplicate key; it is also given at dir/scene.json:2:1 (JSON keeps only one of them: remove the other)");

    // Every duplicate is listed, up to maxErrors.
    r = parse(R"("output": {"size": [64, 48], "size": [8192, 8192], "fps": 24, "fps": 12})");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("output.size: duplicate key"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("output.fps: duplicate key"), std::string::npos) << r.error();
    r = parseText(kHead + R"("output": {"size": [64, 48], "size": [8192, 8192], "fps": 24, "fps": 12}})", 1);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().find("output.fps"), std::string::npos) << r.error();

    // The same key in different objects, and key-like strings among values, are not duplicates.
    r = parse(R"("title": "seed", "effects": [{"kind": "fire", "name": "kind"}, {"kind": "fire", "name": "b"}], "seed": 3)");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->seed, 3u);
    EXPECT_EQ(r->effects.size(), 2u);
    // Quotes and backslashes inside strings do not end them.
    r = parse(R"("title": "a \"seed\": 1, \\", "seed": 4)");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->seed, 4u);
}

// "light": 63 with one light was accepted, and the scene shadow was off.
TEST(SceneFileStrict, ASceneShadowLightPastTheLightsIsAnError) {
    auto r = parse(R"("lights": [{"type": "directional", "direction": [0, -1, 0]}], "sceneShadow": {"light": 63})");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(), "dir/scene.json: sceneShadow.light: expected the index of one of the scene's 1 light(s), 0 to 0, got 63");
    r = parse(R"("sceneShadow": {"dims": 32})");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(), "dir/scene.json: sceneShadow.light: the scene has no \"lights\"; the scene shadow is cast by one of them (add one, or "
                         "set \"enabled\": false)");

    // The last light, and a shadow switched off with no lights, are fine.
    r = parse(R"("lights": [{"type": "directional"}, {"type": "point", "position": [0, 3, 0]}], "sceneShadow": {"light": 1})");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->scene.sceneShadow().light, 1u);
    r = parse(R"("sceneShadow": {"enabled": false})");
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_FALSE(r->scene.sceneShadow().enabled);
}

// Times the scene could never be prepared at (Scene::prepare refuses them)
// are refused where the file asks for them.
TEST(SceneFileStrict, TimesLaterThanTheDynamicsHoldAreRefused) {
    auto r = parse(R"("output": {"frames": 100000, "fps": 0.1})");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(), "dir/scene.json: output.frames: 100000 frames at 0.1 fps end at 999990 s, later than 262144 s (kMaxTimeSec, about 72.8 "
                         "hours), the latest time the effects' dynamics hold exactly; fewer frames or a higher fps");
    r = parse(R"("camera": {"keys": [{"time": 0}, {"time": 300000, "position": [1, 2, 3]}]})");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("camera.keys[1].time: expected a number in [0, 262144], got 300000"), std::string::npos) << r.error();
    r = parse(R"("effects": [{"kind": "fire", "motion": {"keys": [{"time": 1e300}]}}])");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("effects[0].motion.keys[0].time: expected a number in [0, 262144], got 1e+300"), std::string::npos) << r.error();

    // The bound itself is a time the file may reach.
    r = parse(R"("output": {"frames": 26215, "fps": 0.1}, "camera": {"keys": [{"time": 0}, {"time": 262144, "position": [1, 2, 3]}]})");
    ASSERT_TRUE(r.ok()) << r.error();
}
