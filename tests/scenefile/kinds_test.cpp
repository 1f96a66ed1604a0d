// The registry of scene-file kinds (sdk/src/scenefile/kinds.cpp), CPU only:
// the table, the messages that list it and the readers behind it agree, so a
// kind added with one file and one table row is offered, named and built.
#include <algorithm>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "scenefile/kinds.hpp"
#include "splatfx/scene_file.hpp"

namespace {

const std::string kHead = R"("format": "splatfx-scene", "version": 1)";

splatfx::Result<splatfx::SceneFile> parse(const std::string& body) {
    splatfx::Materials m(splatfx::Footprint{});
    return splatfx::parseSceneFile("{" + kHead + ", " + body + "}", "dir/scene.json", m);
}

// The smallest entry each kind builds from (grid needs its lattice; solver
// kinds a small domain so the test stays fast).
std::string minimalEffect(const std::string& kind) {
    if (kind == "grid") return R"({"kind": "grid", "dims": [3, 3, 3]})";
    if (kind == "smoke" || kind == "dust") return R"({"kind": ")" + kind + R"(", "dims": [4, 4, 4]})";
    if (kind == "vdb")
        return R"({"kind": "vdb", "files": ")" SPLATFX_SOURCE_DIR R"(/samples/20-vdb-smoke/data/fluid_data_####.vdb", "lastFrame": 2})";
    return R"({"kind": ")" + kind + R"("})";
}

} // namespace

TEST(SceneFileKinds, TablesHaveUniqueNamesAndEveryEffectKindAReader) {
    std::set<std::string_view> names;
    for (const auto& k : splatfx::scenefile::effectKinds()) {
        EXPECT_TRUE(names.insert(k.name).second) << "effect kind listed twice: " << k.name;
        EXPECT_NE(k.read, nullptr) << k.name;
        EXPECT_EQ(splatfx::scenefile::findEffectKind(k.name), &k);
    }
    EXPECT_EQ(splatfx::scenefile::findEffectKind("fog"), nullptr);
    std::set<std::string_view> types;
    for (const auto& g : splatfx::scenefile::geometryKinds()) {
        EXPECT_TRUE(types.insert(g.name).second) << "geometry type listed twice: " << g.name;
        EXPECT_EQ(splatfx::scenefile::findGeometryKind(g.name), &g);
    }
    EXPECT_EQ(splatfx::scenefile::findGeometryKind("torus"), nullptr);
    // A missing type is read on as a box, so the table must have one.
    ASSERT_NE(splatfx::scenefile::findGeometryKind("box"), nullptr);
}

TEST(SceneFileKinds, AnUnknownKindNamesEveryKnownKind) {
    auto r = parse(R"("effects": [{"kind": "fgo"}])");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("dir/scene.json: effects[0].kind: unknown value \"fgo\""), std::string::npos) << r.error();
    std::string listed;
    for (const std::string& k : splatfx::scenefile::effectKindNames()) listed += (listed.empty() ? "" : ", ") + ("\"" + k + "\"");
    EXPECT_NE(r.error().find("expected one of " + listed), std::string::npos) << r.error();
    // The list is the documented one (docs/scene-format.md), in its order;
    // "vdb" only in builds with OpenVDB (splatfx::vdb).
    const std::string vdb = SPLATFX_WITH_VDB ? ", vdb" : "";
    EXPECT_EQ(listed,
              std::string(R"("fire", "smoke", "steam", "dust", "fireToSmoke", "ghosts", "grid", "gas", "particles")") + (SPLATFX_WITH_VDB ? R"(, "vdb")" : ""));
    auto missing = parse(R"("effects": [{"name": "a"}])");
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().find("missing \"kind\" (one of fire, smoke, steam, dust, fireToSmoke, ghosts, grid, gas, particles" + vdb + ")"),
              std::string::npos)
        << missing.error();
}

TEST(SceneFileKinds, AnUnknownGeometryTypeNamesEveryKnownType) {
    auto r = parse(R"("geometry": [{"type": "torus"}])");
    ASSERT_FALSE(r);
    for (const std::string& t : splatfx::scenefile::geometryKindNames())
        EXPECT_NE(r.error().find("\"" + t + "\""), std::string::npos) << t << " not offered in:\n" << r.error();
    auto missing = parse(R"("geometry": [{}])");
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().find(R"(missing "type" ("plane", "box", "cylinder", "sphere", "mesh", "heightmap" or "empty"))"), std::string::npos)
        << missing.error();
}

TEST(SceneFileKinds, EveryRegisteredKindBuildsFromItsSmallestEntry) {
    for (const std::string& kind : splatfx::scenefile::effectKindNames()) {
        auto r = parse(R"("effects": [)" + minimalEffect(kind) + "]");
        ASSERT_TRUE(r) << kind << ": " << r.error();
        ASSERT_EQ(r->effects.size(), 1u) << kind;
        EXPECT_EQ(r->effects[0].kind, kind);
        EXPECT_EQ(r->effects[0].name, kind + "0");
    }
    for (const auto& g : splatfx::scenefile::geometryKinds()) {
        if (g.read) continue; // types with keys of their own (mesh) need a file; scene_file_test covers them
        auto r = parse(R"("geometry": [{"type": ")" + std::string(g.name) + R"("}])");
        ASSERT_TRUE(r) << g.name << ": " << r.error();
        EXPECT_EQ(r->geometry.at(0).type, g.type) << g.name;
    }
}

TEST(SceneFileKinds, SmokeAndDustShareOneReaderButKeepTheirOwnKeys) {
    // settle is dust's, substeps and texturesPerSec smoke's: each is unknown to the other.
    auto smoke = parse(R"("effects": [{"kind": "smoke", "dims": [4, 4, 4], "settle": 1}])");
    ASSERT_FALSE(smoke);
    EXPECT_NE(smoke.error().find("effects[0].settle: unknown key"), std::string::npos) << smoke.error();
    auto dust = parse(R"("effects": [{"kind": "dust", "dims": [4, 4, 4], "substeps": 2}])");
    ASSERT_FALSE(dust);
    EXPECT_NE(dust.error().find("effects[0].substeps: unknown key"), std::string::npos) << dust.error();
    EXPECT_TRUE(parse(R"("effects": [{"kind": "smoke", "dims": [4, 4, 4], "substeps": 2, "texturesPerSec": 1}])"));
    EXPECT_TRUE(parse(R"("effects": [{"kind": "dust", "dims": [4, 4, 4], "settle": 1}])"));
    // Both refuse their own motion with the kind named.
    for (const char* kind : {"smoke", "dust"}) {
        auto moved = parse(std::string(R"("effects": [{"kind": ")") + kind + R"(", "dims": [4, 4, 4], "motion": {"velocity": [1, 0, 0]}}])");
        ASSERT_FALSE(moved) << kind;
        EXPECT_NE(moved.error().find(std::string("solver effects (\"") + kind + "\") stay put"), std::string::npos) << moved.error();
    }
}

TEST(SceneFileKinds, AGasTakesOnlyItsTypesKeysAndNamesBadValues) {
    auto fog = parse(R"("effects": [{"kind": "gas", "dims": [6, 3, 6], "gas": {"type": "fog", "frontSpeed": 2, "turbulence": {"octaves": 3}}}])");
    ASSERT_TRUE(fog) << fog.error();
    ASSERT_EQ(fog->effects.size(), 1u);
    // ellipse1 is the fog's: a steam gas does not take it (a misplaced key is not silently ignored).
    auto misplaced = parse(R"("effects": [{"kind": "gas", "gas": {"type": "steam", "ellipse1": 0.5}}])");
    ASSERT_FALSE(misplaced);
    EXPECT_NE(misplaced.error().find("effects[0].gas.ellipse1: unknown key"), std::string::npos) << misplaced.error();
    auto badType = parse(R"("effects": [{"kind": "gas", "gas": {"type": "smog"}}])");
    ASSERT_FALSE(badType);
    EXPECT_NE(badType.error().find("effects[0].gas.type"), std::string::npos) << badType.error();
    auto octaves = parse(R"("effects": [{"kind": "gas", "gas": {"turbulence": {"octaves": 40}}}])");
    ASSERT_FALSE(octaves);
    EXPECT_NE(octaves.error().find("effects[0].gas.turbulence.octaves"), std::string::npos) << octaves.error();
}

// "variation" (issue 25): every kind takes it; omitted, presets and the
// other kinds alike get the recommended variation (ghosts a smaller turn).
TEST(SceneFileKinds, EveryKindTakesAVariationAndDefaultsToTheRecommendedOne) {
    for (const std::string& kind : splatfx::scenefile::effectKindNames()) {
        std::string entry = minimalEffect(kind);
        auto r = parse(R"("effects": [)" + entry + "]");
        ASSERT_TRUE(r) << kind << ": " << r.error();
        const splatfx::Effect* e = r->scene.findEffect(r->effects[0].id);
        ASSERT_NE(e, nullptr) << kind;
        const splatfx::SplatVariation& v = e->layer(0).style.variation;
        EXPECT_EQ(v.jitter, 0.5f) << kind;
        EXPECT_TRUE(v.mirror) << kind;
        EXPECT_EQ(v.rotationRad, kind == "ghosts" ? 0.35f : splatfx::SplatVariation::recommended(0).rotationRad) << kind;
        entry.insert(entry.size() - 1, R"(, "variation": {"jitter": 0.25, "rotationDeg": 90, "mirror": false, "scaleLog2": 0.5})");
        auto given = parse(R"("effects": [)" + entry + "]");
        ASSERT_TRUE(given) << kind << ": " << given.error();
        const splatfx::SplatVariation& g = given->scene.findEffect(given->effects[0].id)->layer(0).style.variation;
        EXPECT_EQ(g.jitter, 0.25f);
        EXPECT_NEAR(g.rotationRad, 1.5707963f, 1e-6f);
        EXPECT_FALSE(g.mirror);
        EXPECT_EQ(g.scaleLog2, 0.5f);
    }
    auto plain = parse(R"("effects": [{"kind": "fire", "variation": {"jitter": 0, "rotationDeg": 0, "mirror": false}}])");
    ASSERT_TRUE(plain) << plain.error();
    EXPECT_FALSE(plain->scene.findEffect(plain->effects[0].id)->layer(0).style.variation.any()); // the paper's lattice
}

TEST(SceneFileKinds, ABadVariationIsNamed) {
    auto r = parse(R"("effects": [{"kind": "fire", "variation": {"jitter": 1.5, "rotationDeg": -5, "wobble": 1}}])");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("effects[0].variation.jitter"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("effects[0].variation.rotationDeg"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find("effects[0].variation.wobble: unknown key"), std::string::npos) << r.error();
}

TEST(SceneFileKinds, ParticlesBuildAndTheirBadInputIsNamed) {
    auto ok = parse(R"("effects": [{"kind": "particles", "rate": 30, "lifetimeSec": 1.5, "velocity": [0, 1, 0], "size": 0.05}])");
    ASSERT_TRUE(ok) << ok.error();
    ASSERT_EQ(ok->effects.size(), 1u);
    EXPECT_EQ(ok->effects[0].kind, "particles");
    auto negative = parse(R"("effects": [{"kind": "particles", "rate": -5}])");
    ASSERT_FALSE(negative);
    EXPECT_NE(negative.error().find("effects[0].rate"), std::string::npos) << negative.error();
    // A NaN is no JSON number: the file is refused where it is.
    auto nan = parse(R"("effects": [{"kind": "particles", "lifetimeSec": NaN}])");
    ASSERT_FALSE(nan);
    // The memory bomb: a million a second living ten seconds.
    auto bomb = parse(R"("effects": [{"kind": "particles", "rate": 1000000, "lifetimeSec": 10}])");
    ASSERT_FALSE(bomb);
    EXPECT_NE(bomb.error().find("effects[0].rate: rate * lifetimeSec = 10000000 particles alive at once exceeds maxParticles (65536)"),
              std::string::npos)
        << bomb.error();
    // maxParticles raises the cap only to kMaxParticles (2^24).
    auto raised = parse(R"("effects": [{"kind": "particles", "rate": 1000000, "lifetimeSec": 20, "maxParticles": 16777216}])");
    ASSERT_FALSE(raised);
    EXPECT_NE(raised.error().find("exceeds maxParticles (16777216)"), std::string::npos) << raised.error();
    auto over = parse(R"("effects": [{"kind": "particles", "maxParticles": 16777217}])");
    ASSERT_FALSE(over);
    EXPECT_NE(over.error().find("effects[0].maxParticles"), std::string::npos) << over.error();
}
