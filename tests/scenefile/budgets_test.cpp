// Cost budgets of scene files (budget.hpp): a fog's shader, a heightmap
// geometry's mesh, lights x shadow tables, clouds and ground fog are each
// estimated from what the file states, before anything is built, and an
// estimate over its budget is refused naming the field, the estimate, the
// budget and the Budgets field that raises it. Every case here would cost
// gigabytes (or minutes of shader compile) if it were built: the tests pass
// only because nothing is.
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "splatfx/scene_file.hpp"

namespace fs = std::filesystem;

namespace {

struct TempDir {
    fs::path dir;
    explicit TempDir(const std::string& tag) {
        dir = fs::temp_directory_path() / ("splatfx-budgets-" + tag + "-" + std::to_string(::getpid()));
        fs::create_directories(dir);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    // A binary 8-bit PGM of w x h samples; with `full` false only its header
    // and one row (a crafted file claiming the size: nothing may decode it).
    void pgm(const std::string& name, int w, int h, bool full) const {
        std::ofstream f(dir / name, std::ios::binary);
        f << "P5\n" << w << " " << h << "\n255\n";
        const long n = full ? long(w) * h : w;
        for (long i = 0; i < n; ++i) f.put(char(i * 7 % 251));
    }
    splatfx::Result<splatfx::SceneFile> parse(const std::string& body, const splatfx::Budgets& budgets = {}) const {
        splatfx::Materials m(splatfx::Footprint{});
        splatfx::SceneFileOptions o;
        o.budgets = budgets;
        return splatfx::parseSceneFile(R"({"format": "splatfx-scene", "version": 1, )" + body + "}", (dir / "scene.json").string(), m, o);
    }
};

std::string repeat(const std::string& item, int n) {
    std::string out;
    for (int i = 0; i < n; ++i) out += (i ? ", " : "") + item;
    return out;
}

// n degree-9 polynomial fog terms (the documented maximum degree).
std::string polynomialFog(int n) {
    return R"("fog": {"terms": [{"kind": "constant", "weight": 50}, )" +
           repeat(R"({"kind": "polynomial", "axis": "y", "coeffs": [0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1], "halfSize": 4})", n - 1) +
           "]}";
}

// The estimate a refusal states ("... needs N bytes").
unsigned long long estimateOf(const splatfx::Result<splatfx::SceneFile>& r) {
    EXPECT_FALSE(r.ok());
    const std::string e = r ? std::string() : r.error();
    const std::size_t at = e.find(" needs ");
    return at == std::string::npos ? 0ull : std::stoull(e.substr(at + 7));
}

void expectAll(const splatfx::Result<splatfx::SceneFile>& r, std::initializer_list<std::string> parts) {
    ASSERT_FALSE(r.ok()) << "accepted";
    for (const std::string& p : parts) EXPECT_NE(r.error().find(p), std::string::npos) << "missing '" << p << "' in:\n" << r.error();
}

} // namespace

TEST(SceneFileBudgets, TheFogsShaderIsBudgetedBeforeAnyGlSeesIt) {
    const TempDir t("fog");
    // 256 terms (the most a file may list) hung the first frame's compile.
    auto big = t.parse(polynomialFog(256));
    expectAll(big, {"fog.terms: the shader of its 256 terms needs ", " bytes of GLSL, over the budget of 32768 (raise Budgets::fogShaderBytes)"});
    // A few terms fit the default; the same file loads when the budget is raised.
    EXPECT_TRUE(t.parse(polynomialFog(4)).ok());
    splatfx::Budgets raised;
    raised.fogShaderBytes = 1ull << 26;
    auto loaded = t.parse(polynomialFog(256), raised);
    ASSERT_TRUE(loaded.ok()) << loaded.error();
    ASSERT_NE(loaded->scene.fog(), nullptr);
    EXPECT_EQ(loaded->scene.fog()->desc().terms.size(), 256u);
    // Cosines and potentials are a loop over their parameters: 256 of them
    // (Fig. 6 plus 256 points took 79 s to compile) cost what two cost.
    splatfx::Budgets tight;
    tight.fogShaderBytes = 1;
    auto points = [](int n) {
        return R"("fog": {"preset": "fig6", "terms": [)" + repeat(R"({"kind": "point", "centre": [1, 2, 3], "c": 1, "d": 1, "weight": 0.01})", n) +
               "]}";
    };
    EXPECT_TRUE(t.parse(points(250)).ok());
    EXPECT_LE(estimateOf(t.parse(points(250), tight)), estimateOf(t.parse(points(2), tight)) + 4); // the loop counts' digits
    // The estimate grows with the terms: a budget between 8 and 16 terms' sizes splits them.
    const unsigned long long b8 = estimateOf(t.parse(polynomialFog(8), tight)), b16 = estimateOf(t.parse(polynomialFog(16), tight));
    EXPECT_GT(b16, b8);
    EXPECT_GT(b8, 0u);
}

TEST(SceneFileBudgets, AHeightmapGeometryIsBudgetedFromTheImageHeader) {
    const TempDir t("heightmap");
    // 8192^2 claimed by a file of a few kilobytes: 6.5-8 GB as a mesh.
    t.pgm("huge.pgm", 8192, 8192, false);
    expectAll(t.parse(R"("geometry": [{"name": "terrain", "type": "heightmap", "heightmap": "huge.pgm"}])"),
              {"geometry[0].heightmap: 'huge.pgm' (8192x8192) as a mesh needs 67108864 vertices, over the budget of 20000000 "
               "(raise Budgets::heightmapVertices)"});
    // A real image: within the budget it loads, below it the same message shape.
    t.pgm("small.pgm", 40, 30, true);
    EXPECT_TRUE(t.parse(R"("geometry": [{"type": "heightmap", "heightmap": "small.pgm"}])").ok());
    splatfx::Budgets low;
    low.heightmapVertices = 1199;
    expectAll(t.parse(R"("geometry": [{"type": "heightmap", "heightmap": "small.pgm"}])", low),
              {"'small.pgm' (40x30) as a mesh needs 1200 vertices, over the budget of 1199 (raise Budgets::heightmapVertices)"});
}

TEST(SceneFileBudgets, LightsTimesShadowTablesAreBudgetedForTheWholeScene) {
    const TempDir t("lights");
    // 64 lights x 8 effects x 128^3 tables: 7.2 GB and a generic out-of-memory before.
    const std::string lights = R"("lights": [)" + repeat(R"({"type": "directional"})", 64) + "]";
    const std::string effects = R"("effects": [)" + repeat(R"({"kind": "steam", "lighting": {"selfShadow": "table", "tableDims": 128}})", 8) + "]";
    // 64 x 8 x 128^3 x 17 bytes, plus the 64^3 scene shadow.
    const unsigned long long bytes = 64ull * 8 * 128 * 128 * 128 * 17 + 64ull * 64 * 64 * 17;
    expectAll(t.parse(lights + ", " + effects),
              {"lights: the shadow tables of 64 light(s) x 8 table-lit effect(s) (the largest effects[0].lighting.tableDims 128x128x128) and "
               "sceneShadow.dims 64x64x64 needs " +
               std::to_string(bytes) + " bytes, over the budget of 1073741824 (raise Budgets::lightingBytes)"});
    // One light: 8 tables of 34 MiB fit.
    EXPECT_TRUE(t.parse(R"("lights": [{"type": "directional"}], )" + effects).ok());
    // Traced self-shadowing builds no tables.
    EXPECT_TRUE(t.parse(lights + R"(, "effects": [{"kind": "steam", "lighting": {"selfShadow": "traced", "tableDims": 128}}])").ok());
}

TEST(SceneFileBudgets, ATableTheSceneCouldNeverBuildIsRefusedNotDrawnUnlit) {
    const TempDir t("table");
    // 256^3 is in the documented range, but each table is built within 64 MiB:
    // it rendered unlit, byte for byte the unlit image, with exit 0.
    expectAll(t.parse(R"("lights": [{"type": "directional"}], "effects": [{"kind": "steam", "lighting": {"tableDims": 256}}])"),
              {"effects[0].lighting.tableDims: 256x256x256 needs 285212672 bytes a table (17 an entry), over the budget of 67108864 bytes of "
               "each shadow table"});
    EXPECT_TRUE(t.parse(R"("lights": [{"type": "directional"}], "effects": [{"kind": "steam", "lighting": {"tableDims": 158}}])").ok());
}

TEST(SceneFileBudgets, CloudsAndGroundFogAreBudgetedTogetherBeforeTheyAreBuilt) {
    const TempDir t("volumes");
    // A fully refined 513x33x513 cloud (4.0 GB): 5 tetrahedra a cell.
    expectAll(t.parse(R"("volumes": [{"kind": "clouds", "name": "big", "dims": [513, 33, 513]}])"),
              {"volumes[0]: the scene's volumes with clouds 'big' (513x33x513 points, up to 41943040 tetrahedra a frame, a 64x64x128 table) needs ",
               "bytes, over the budget of 2147483648 (raise Budgets::volumeBytes)"});
    // Many clouds: each fits, the sum does not; the one that crosses is named with the sum.
    const std::string small = R"({"kind": "clouds", "dims": [9, 9, 9], "tableScalars": 2, "tableLengths": 2})";
    auto clouds = [&](int n) { return R"("volumes": [)" + repeat(small, n) + "]"; };
    splatfx::Budgets one;
    one.volumeBytes = 1;
    const unsigned long long each = estimateOf(t.parse(clouds(1), one));
    ASSERT_GT(each, 0u);
    splatfx::Budgets three;
    three.volumeBytes = 3 * each;
    expectAll(t.parse(clouds(64), three),
              {"volumes[3]: the scene's volumes with clouds 'volume3' (9x9x9 points, up to 2560 tetrahedra a frame, a 2x2x2 table) needs " +
               std::to_string(4 * each) + " bytes, over the budget of " + std::to_string(3 * each) + " (raise Budgets::volumeBytes)"});
    auto fits = t.parse(clouds(3), three);
    ASSERT_TRUE(fits.ok()) << fits.error();
    EXPECT_EQ(fits->volumes.size(), 3u);
    // The largest table counts in full: 256 x 256 x 512 RGBA floats (64 such clouds were 7.0 GB).
    EXPECT_GT(estimateOf(t.parse(R"("volumes": [{"kind": "clouds", "dims": [9, 9, 9], "tableScalars": 256, "tableLengths": 512}])", one)),
              256ull * 256 * 512 * 16);
    // A 2048^2 ground fog at full resolution (inside its 4 Mi sample limit): 4.4 GB.
    t.pgm("dem.pgm", 2048, 2048, false);
    expectAll(t.parse(R"("volumes": [{"kind": "groundFog", "name": "valley", "heightmap": "dem.pgm", "fogTop": 1}])"),
              {"volumes[0]: the scene's volumes with groundFog 'valley' (2048x2048 points, up to 25141254 tetrahedra a frame, a 32x32x128 table)",
               "(raise Budgets::volumeBytes)"});
    EXPECT_TRUE(t.parse(R"("volumes": [{"kind": "clouds", "dims": [17, 9, 17]}])").ok());
}
