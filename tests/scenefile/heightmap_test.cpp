// The "heightmap" geometry type and the "groundFog" volume kind: a
// terrain and a fog layer read from one 16-bit PGM share every sample point,
// the fog layer reaches the Frame through Scene::prepare, and bad input is a
// message naming the field.
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/frame.hpp"
#include "splatfx/scene_file.hpp"

namespace fs = std::filesystem;

namespace {

// A w x h 16-bit binary PGM (big-endian) in a fresh folder; value(i, j) in codes.
struct TempTerrain {
    fs::path dir;
    int w = 0, h = 0;
    std::vector<int> codes;
    TempTerrain(int width, int height, const std::string& tag) : w(width), h(height) {
        dir = fs::temp_directory_path() / ("splatfx-heightmap-" + tag + "-" + std::to_string(::getpid()));
        fs::create_directories(dir);
        std::ofstream f(dir / "dem.pgm", std::ios::binary);
        f << "P5\n" << w << " " << h << "\n65535\n";
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i) {
                // A valley along x = middle: low in the centre, high at the sides.
                const int c = 1000 + 4000 * std::abs(2 * i - (w - 1)) + 100 * j;
                codes.push_back(c);
                f.put(char(c >> 8)).put(char(c & 255));
            }
    }
    ~TempTerrain() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    splatfx::Result<splatfx::SceneFile> parse(const std::string& body, splatfx::Materials& m) const {
        return splatfx::parseSceneFile(R"({"format": "splatfx-scene", "version": 1, )" + body + "}", (dir / "scene.json").string(), m);
    }
};

} // namespace

TEST(SceneFileHeightmap, TerrainAndGroundFogShareEverySamplePoint) {
    const TempTerrain t(9, 5, "share");
    splatfx::Materials m(splatfx::Footprint{});
    const float spacing = 2.0f, scale = 100.0f, fogTop = 6.0f;
    const glm::vec3 pos{10.0f, -1.0f, 4.0f};
    auto r = t.parse(R"("geometry": [{"name": "terrain", "type": "heightmap", "heightmap": "dem.pgm", "spacing": 2, "heightScale": 100,
                         "position": [10, -1, 4]}],
                        "volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "spacing": 2, "heightScale": 100,
                         "position": [10, -1, 4], "step": 2, "fogTop": 6}])",
                     m);
    ASSERT_TRUE(r) << r.error();
    ASSERT_EQ(r->geometry.size(), 1u);
    const splatfx::GeometryDesc& g = r->geometry[0];
    EXPECT_EQ(g.type, splatfx::GeometryType::Heightmap);
    EXPECT_EQ(fs::path(g.heightmapPath), t.dir / "dem.pgm");
    EXPECT_FLOAT_EQ(g.heightmapSpacing, spacing);
    EXPECT_FLOAT_EQ(g.heightmapScale, scale);
    ASSERT_EQ(r->volumes.size(), 1u);
    const splatfx::EffectId fogId = r->volumes[0].id;
    ASSERT_NE(r->scene.findGroundFog(fogId), nullptr);

    // Every vertex of every emitted tetrahedron is either a terrain sample of
    // the step-2 grid (the heightmap geometry's own point, placed at `pos`)
    // or on the fog top above one.
    std::vector<glm::vec3> terrain;
    for (int j = 0; j < t.h; j += 2)
        for (int i = 0; i < t.w; i += 2)
            terrain.push_back(pos + splatfx::heightmapPoint(i, j, t.w, t.h, float(t.codes[std::size_t(j * t.w + i)]) / 65535.0f, spacing, scale));
    const splatfx::Camera cam = splatfx::Camera::lookAt(pos + glm::vec3(0, 40, 30), pos, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.5f, 500.0f);
    splatfx::Frame frame;
    EXPECT_TRUE(r->scene.prepare(0.0, cam, m, frame));
    ASSERT_EQ(frame.volumes().size(), 1u);
    const auto& tets = frame.volumes()[0].lod.tets;
    ASSERT_GT(tets.size(), 0u) << "the valley lies under the fog top";
    std::size_t onTerrain = 0;
    for (const splatfx::Tetrahedron& tet : tets)
        for (const glm::vec3& p : tet.position) {
            bool matched = false;
            for (const glm::vec3& q : terrain) {
                // The same float formula on both sides, up to one rounding of the addition.
                const bool sameColumn = std::abs(p.x - q.x) < 1e-4f && std::abs(p.z - q.z) < 1e-4f;
                if (!sameColumn) continue;
                if (std::abs(p.y - q.y) < 1e-4f) matched = true, ++onTerrain;
                else if (std::abs(p.y - fogTop) < 1e-4f && q.y < fogTop) matched = true;
            }
            EXPECT_TRUE(matched) << "vertex (" << p.x << ", " << p.y << ", " << p.z << ") is neither a terrain sample nor on the fog top";
        }
    EXPECT_GT(onTerrain, 0u);
    // Disabled: nothing reaches the frame.
    r->scene.setEnabled(fogId, false);
    splatfx::Frame off;
    EXPECT_TRUE(r->scene.prepare(0.0, cam, m, off));
    EXPECT_TRUE(off.volumes().empty());
}

TEST(SceneFileHeightmap, BadInputNamesTheField) {
    const TempTerrain t(9, 5, "bad");
    splatfx::Materials m(splatfx::Footprint{});
    auto expectError = [&](const std::string& body, const std::string& part) {
        auto r = t.parse(body, m);
        ASSERT_FALSE(r) << body;
        EXPECT_NE(r.error().find(part), std::string::npos) << r.error();
    };
    expectError(R"("geometry": [{"type": "heightmap"}])", R"(geometry[0]: missing "heightmap")");
    expectError(R"("geometry": [{"type": "heightmap", "heightmap": "nope.pgm"}])", "geometry[0].heightmap: heightmap file 'nope.pgm' not found");
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm"}])", R"(volumes[0]: missing "fogTop")");
    // 8 x 4 cells: a step of 3 divides neither.
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "fogTop": 1, "step": 3}])", "volumes[0].step: must divide");
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "gone.pgm", "fogTop": 1}])", "volumes[0].heightmap:");
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "fogTop": 1, "colour": [2, 0, 0]}])", "volumes[0].colour");
    expectError(R"("volumes": [{"kind": "fogg"}])", "unknown kind 'fogg' (known: clouds, groundFog)");
    // The LOD keys: only with "lod", in range.
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "fogTop": 1, "detailC": 2}])",
                R"(volumes[0].detailC: only with "lod": true)");
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "fogTop": 1, "lod": true, "detailC": -1}])", "volumes[0].detailC");
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "fogTop": 1, "lod": true, "minAccuracyC": 0}])",
                "volumes[0].minAccuracyC");
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "fogTop": 1, "lod": 3}])", "volumes[0].lod");
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "fogTop": 1, "lod": true, "terrainGeometry": "nope"}])",
                "volumes[0].terrainGeometry: names no heightmap geometry ('nope')");
    expectError(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "fogTop": 1, "terrainGeometry": "t"}])",
                R"(volumes[0].terrainGeometry: only with "lod": true)");
}

// "lod": true builds the LOD layer with the file's C, and detailC / morph
// reach the per-frame refinement: the fog's bottom then lies on the LOD
// terrain, fewer tetrahedra from afar than at full resolution.
TEST(SceneFileHeightmap, GroundFogLodKeys) {
    const TempTerrain t(15, 9, "lod"); // codes stay below 65536
    splatfx::Materials m(splatfx::Footprint{});
    auto lod = t.parse(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "spacing": 2, "heightScale": 100,
                          "fogTop": 200, "lod": true, "detailC": 0.5, "minAccuracyC": 3, "morph": false}])",
                       m);
    auto full = t.parse(R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "spacing": 2, "heightScale": 100, "fogTop": 200}])", m);
    ASSERT_TRUE(lod) << lod.error();
    ASSERT_TRUE(full) << full.error();
    EXPECT_TRUE(lod->groundFogTerrain.empty());
    ASSERT_EQ(lod->volumes.size(), 1u);
    const splatfx::EffectOptions& o = lod->scene.options(lod->volumes[0].id);
    EXPECT_FLOAT_EQ(o.refine.detailC, 0.5f);
    EXPECT_FALSE(o.refine.morph);
    const splatfx::Camera cam = splatfx::Camera::lookAt({0, 600, 900}, {0, 0, 0}, {0, 1, 0}, glm::radians(40.0f), {64, 48}, 0.5f, 5000.0f);
    splatfx::Frame a, b;
    EXPECT_TRUE(lod->scene.prepare(0.0, cam, m, a));
    EXPECT_TRUE(full->scene.prepare(0.0, cam, m, b));
    ASSERT_EQ(a.volumes().size(), 1u);
    ASSERT_EQ(b.volumes().size(), 1u);
    EXPECT_EQ(a.volumes()[0].lod.stats.fullResolution, b.volumes()[0].lod.tets.size());
    EXPECT_LT(a.volumes()[0].lod.tets.size(), b.volumes()[0].lod.tets.size());
    EXPECT_GT(a.volumes()[0].lod.tets.size(), 0u);
}

// "terrainGeometry" ignored the named geometry's own heightmap, spacing,
// heightScale and position: the layer now takes them from it (a layer giving
// none of them builds what the same values written out build), and a value
// the layer gives that disagrees, or a geometry it cannot follow, is refused
// naming the field.
TEST(SceneFileHeightmap, TerrainGeometryGivesTheLayerTheGeometrysTerrain) {
    const TempTerrain t(15, 9, "terrain-geometry");
    splatfx::Materials m(splatfx::Footprint{});
    const std::string geometry =
        R"("geometry": [{"name": "terrain", "type": "heightmap", "heightmap": "dem.pgm", "spacing": 2, "heightScale": 100, "position": [10, -1, 4]}], )";
    auto taken = t.parse(geometry + R"("volumes": [{"kind": "groundFog", "fogTop": 200, "lod": true, "terrainGeometry": "terrain"}])", m);
    auto written = t.parse(geometry + R"("volumes": [{"kind": "groundFog", "heightmap": "dem.pgm", "spacing": 2, "heightScale": 100,
                                          "position": [10, -1, 4], "fogTop": 200, "lod": true}])",
                           m);
    auto agreeing = t.parse(geometry + R"("volumes": [{"kind": "groundFog", "heightmap": "./dem.pgm", "spacing": 2, "heightScale": 100,
                                           "position": [10, -1, 4], "fogTop": 200, "lod": true, "terrainGeometry": "terrain"}])",
                            m);
    ASSERT_TRUE(taken) << taken.error();
    ASSERT_TRUE(written) << written.error();
    ASSERT_TRUE(agreeing) << agreeing.error();
    ASSERT_EQ(taken->groundFogTerrain.size(), 1u);
    EXPECT_EQ(taken->groundFogTerrain[0].geometry, "terrain");
    const splatfx::GroundFog* a = taken->scene.findGroundFog(taken->volumes[0].id);
    const splatfx::GroundFog* b = written->scene.findGroundFog(written->volumes[0].id);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->boundsWorld().lo, b->boundsWorld().lo);
    EXPECT_EQ(a->boundsWorld().hi, b->boundsWorld().hi);
    // The same tetrahedra and the same terrain mesh, to the bit.
    const splatfx::Camera cam = splatfx::Camera::lookAt({10, 300, 200}, {10, 0, 4}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.5f, 5000.0f);
    splatfx::Frame fa, fb;
    ASSERT_TRUE(taken->scene.prepare(0.0, cam, m, fa));
    ASSERT_TRUE(written->scene.prepare(0.0, cam, m, fb));
    ASSERT_EQ(fa.volumes().size(), 1u);
    ASSERT_EQ(fb.volumes().size(), 1u);
    const auto &ta = fa.volumes()[0].lod.tets, &tb = fb.volumes()[0].lod.tets;
    ASSERT_GT(ta.size(), 0u);
    ASSERT_EQ(ta.size(), tb.size());
    for (std::size_t i = 0; i < ta.size(); ++i)
        for (int k = 0; k < 4; ++k) ASSERT_EQ(ta[i].position[k], tb[i].position[k]) << "tetrahedron " << i;
    // The terrain mesh the host draws for the geometry (keepTerrain): the same whether the layer takes the values or repeats them.
    splatfx::Frame fc;
    ASSERT_TRUE(agreeing->scene.prepare(0.0, cam, m, fc));
    EXPECT_FALSE(taken->scene.groundFogTerrain(taken->volumes[0].id).empty());
    EXPECT_EQ(taken->scene.groundFogTerrain(taken->volumes[0].id), agreeing->scene.groundFogTerrain(agreeing->volumes[0].id));

    auto expectError = [&](const std::string& geo, const std::string& layerKeys, const std::string& message) {
        auto r = t.parse(geo + R"("volumes": [{"kind": "groundFog", "fogTop": 200, "lod": true, "terrainGeometry": "terrain")" + layerKeys + "}]", m);
        ASSERT_FALSE(r) << layerKeys;
        EXPECT_NE(r.error().find(message), std::string::npos) << r.error();
    };
    expectError(geometry, R"(, "spacing": 1)",
                "volumes[0].spacing: 1 disagrees with terrainGeometry 'terrain': its spacing is 2 (geometry[0].spacing); leave it out to take the "
                "geometry's");
    expectError(geometry, R"(, "heightScale": 50)", "volumes[0].heightScale: 50 disagrees with terrainGeometry 'terrain': its heightScale is 100");
    expectError(geometry, R"(, "position": [0, 0, 0])",
                "volumes[0].position: [0, 0, 0] disagrees with terrainGeometry 'terrain': its position is [10, -1, 4] (geometry[0].position)");
    expectError(geometry, R"(, "heightmap": "other.pgm")", "volumes[0].heightmap: 'other.pgm' is not the file of terrainGeometry 'terrain'");
    const std::string rotated = R"("geometry": [{"name": "terrain", "type": "heightmap", "heightmap": "dem.pgm", "rotationDeg": [0, 90, 0]}], )";
    expectError(rotated, "", "volumes[0].terrainGeometry: geometry 'terrain' (geometry[0]) is rotated or scaled");
    const std::string scaled = R"("geometry": [{"name": "terrain", "type": "heightmap", "heightmap": "dem.pgm", "scale": 2}], )";
    expectError(scaled, "", "volumes[0].terrainGeometry: geometry 'terrain' (geometry[0]) is rotated or scaled");
    const std::string moving = R"("geometry": [{"name": "cart", "type": "empty", "motion": {"velocity": [1, 0, 0]}},
                                               {"name": "terrain", "type": "heightmap", "heightmap": "dem.pgm", "attachTo": "cart"}], )";
    expectError(moving, "", "volumes[0].terrainGeometry: geometry 'terrain' (geometry[1]) moves");
}

// "lighting" on a ground fog layer (issue 27): the layer is lit by the scene's
// sun with the block's gas desc and its own colour and extinction; without
// it the layer stays unlit, drawn with its transfer function.
TEST(SceneFileHeightmap, GroundFogLightingKeyLightsTheLayer) {
    const TempTerrain t(9, 5, "lit");
    splatfx::Materials m(splatfx::Footprint{});
    auto r = t.parse(R"("lights": [{"type": "directional", "direction": [0.3, -1, 0.2]}],
                        "volumes": [{"kind": "groundFog", "name": "lit", "heightmap": "dem.pgm", "fogTop": 0.8, "extinctionPerWorld": 2,
                                     "colour": [0.8, 0.85, 0.9], "lighting": {"enabled": true, "albedo": 0.7}},
                                    {"kind": "groundFog", "name": "plain", "heightmap": "dem.pgm", "fogTop": 0.8},
                                    {"kind": "groundFog", "name": "quiet", "heightmap": "dem.pgm", "fogTop": 0.8,
                                     "lighting": {"enabled": true, "castsShadow": false}}])",
                     m);
    ASSERT_TRUE(r) << r.error();
    ASSERT_EQ(r->volumes.size(), 3u);
    const splatfx::EffectId lit = r->volumes[0].id, plain = r->volumes[1].id;
    EXPECT_TRUE(r->scene.options(lit).lighting.enabled);
    EXPECT_FLOAT_EQ(r->scene.options(lit).lighting.gas.albedo, 0.7f);
    EXPECT_FALSE(r->scene.options(plain).lighting.enabled);
    const splatfx::Camera cam = splatfx::Camera::lookAt({4, 30, 30}, {4, 0, 2}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.5f, 500.0f);
    splatfx::Frame frame;
    ASSERT_TRUE(r->scene.prepare(0.0, cam, m, frame));
    const splatfx::GroundFog* fog = r->scene.findGroundFog(lit);
    ASSERT_TRUE(fog->lit());
    EXPECT_TRUE(r->scene.status(lit).lit);
    EXPECT_FALSE(r->scene.findGroundFog(plain)->lit());
    EXPECT_FLOAT_EQ(fog->lighting().extinctionPerWorld, 2.0f);
    EXPECT_NEAR(fog->lighting().color.g, 0.85f, 1e-6f);
    EXPECT_EQ(fog->lighting().sun.direction, glm::vec3(0.3f, -1.0f, 0.2f));
    // A lit layer casts by default (into the scene shadow, as a cloud); "castsShadow": false keeps it out.
    EXPECT_TRUE(r->scene.status(lit).inSceneShadow);
    EXPECT_TRUE(r->scene.status(r->volumes[2].id).lit);
    EXPECT_FALSE(r->scene.status(r->volumes[2].id).inSceneShadow);
    EXPECT_FALSE(r->scene.status(plain).inSceneShadow);
}
