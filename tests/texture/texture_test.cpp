#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/texture_set_io.hpp"

using splatfx::Footprint;
using splatfx::loadTextureSet;
using splatfx::TextureSet;
namespace fs = std::filesystem;

TEST(TextureSet, TurbulenceIsDeterministicPerSeed) {
    const auto a = TextureSet::turbulence({.seed = 7});
    const auto b = TextureSet::turbulence({.seed = 7});
    const auto c = TextureSet::turbulence({.seed = 8});
    ASSERT_EQ(a.count(), 8);
    EXPECT_EQ(a.size, 32);
    EXPECT_EQ(a.layers, b.layers);
    EXPECT_NE(a.layers, c.layers);
    for (const auto& layer : a.layers)
        for (float v : layer) {
            EXPECT_GE(v, 0.0f);
            EXPECT_LE(v, 1.0f);
        }
}

TEST(TextureSet, ConsecutiveTexturesAreCoherentAndTheCycleCloses) {
    // Textures lie on a loop through noise space: neighbours (including last
    // -> first) must differ less than textures half a cycle apart.
    const auto set = TextureSet::turbulence({.count = 8, .seed = 3});
    auto dist = [&](int i, int j) {
        double d = 0.0;
        for (size_t t = 0; t < set.layers[0].size(); t += 4) d += std::abs(set.layers[size_t(i)][t] - set.layers[size_t(j)][t]);
        return d;
    };
    for (int i = 0; i < 8; ++i) EXPECT_LT(dist(i, (i + 1) % 8), dist(i, (i + 4) % 8)) << "texture " << i;
}

TEST(TextureSet, WindowingKeepsDetailInsideTheFootprint) {
    const Footprint fp;
    const auto raw = TextureSet::turbulence({.size = 32, .seed = 2});
    const auto win = raw.windowed(fp);
    const auto w = fp.image(32);
    int inside = 0;
    for (int p = 0; p < 32 * 32; ++p) {
        const float detail = raw.layers[0][size_t(p) * 4]; // grayscale: R = G = B = luminance
        const float a = win.layers[0][size_t(p) * 4 + 3];
        if (w[size_t(p)] == 0.0f) {
            EXPECT_EQ(a, 0.0f); // nothing outside the footprint
        } else {
            ++inside;
            // Figure 2: windowed = detail * footprint, to float rounding of the luminance weights.
            EXPECT_NEAR(a, detail * w[size_t(p)], 1e-6f);
        }
        EXPECT_EQ(win.layers[0][size_t(p) * 4], 1.0f); // grayscale sets carry no colour
    }
    EXPECT_GT(inside, 32 * 32 / 2);
}

TEST(TextureSet, SaveAndLoadRoundTrip) {
    const std::string dir = splatfx::test::outputDir() + "/set";
    const auto set = TextureSet::turbulence({.count = 3, .size = 16, .seed = 5});
    ASSERT_TRUE(saveTextureSet(set, dir, R"({"method": "test"})"));
    auto back = loadTextureSet(dir);
    ASSERT_TRUE(back) << back.error();
    ASSERT_EQ(back->count(), 3);
    ASSERT_EQ(back->size, 16);
    // 8-bit PNG: values agree to half a quantization step.
    for (int k = 0; k < 3; ++k)
        for (size_t i = 0; i < set.layers[0].size(); i += 4) EXPECT_NEAR(back->layers[size_t(k)][i], set.layers[size_t(k)][i], 0.5 / 255 + 1e-6);
}

TEST(TextureSetBadInput, MissingFolderIsNamed) {
    auto set = loadTextureSet("/nonexistent/fire-set");
    ASSERT_FALSE(set);
    EXPECT_EQ(set.error(), "texture set '/nonexistent/fire-set': no such folder");
}

TEST(TextureSetBadInput, MissingTextureFileIsNamed) {
    const std::string dir = splatfx::test::outputDir() + "/missing";
    fs::remove_all(dir);
    ASSERT_TRUE(saveTextureSet(TextureSet::turbulence({.count = 2, .size = 8}), dir));
    fs::remove(dir + "/t001.png");
    auto set = loadTextureSet(dir);
    ASSERT_FALSE(set);
    EXPECT_NE(set.error().find("t001.png': no such file"), std::string::npos) << set.error();
}

TEST(TextureSetBadInput, CorruptAndZeroSizeImagesAreNamed) {
    const std::string dir = splatfx::test::outputDir() + "/corrupt";
    fs::remove_all(dir);
    ASSERT_TRUE(saveTextureSet(TextureSet::turbulence({.count = 2, .size = 8}), dir));
    { std::ofstream(dir + "/t000.png", std::ios::trunc); } // zero bytes
    auto empty = loadTextureSet(dir);
    ASSERT_FALSE(empty);
    EXPECT_NE(empty.error().find("t000.png': the file is empty"), std::string::npos) << empty.error();

    { std::ofstream(dir + "/t000.png", std::ios::trunc) << "\x89PNG\r\n\x1a\n this is not really a png"; }
    auto corrupt = loadTextureSet(dir);
    ASSERT_FALSE(corrupt);
    EXPECT_NE(corrupt.error().find("cannot read image '" + dir + "/t000.png'"), std::string::npos) << corrupt.error();
}

TEST(TextureSetBadInput, MalformedManifestNamesTheField) {
    const std::string dir = splatfx::test::outputDir() + "/manifest";
    fs::create_directories(dir);
    { std::ofstream(dir + "/manifest.json") << R"({"format": "splatfx-texture-set", "version": 2, "textures": []})"; }
    auto v = loadTextureSet(dir);
    ASSERT_FALSE(v);
    EXPECT_NE(v.error().find("field 'version' must be 1"), std::string::npos) << v.error();
    { std::ofstream(dir + "/manifest.json") << "{ not json"; }
    auto j = loadTextureSet(dir);
    ASSERT_FALSE(j);
    EXPECT_NE(j.error().find("not valid JSON"), std::string::npos) << j.error();
}

TEST(Materials, TexturedSetsCarryTheFootprintsMeanOpacity) {
    splatfx::Materials m{Footprint{}};
    const auto id = m.addTextureSet(TextureSet::turbulence({}));
    const auto& r = m.set(id);
    double plain = 0.0, textured = 0.0;
    for (size_t t = 3; t < m.layer(0).size(); t += 4) plain += m.layer(0)[t];
    for (std::uint32_t l = r.first; l < r.first + r.count; ++l)
        for (size_t t = 3; t < m.layer(l).size(); t += 4) textured += m.layer(l)[t] / r.count;
    EXPECT_NEAR(textured * r.gain, plain, 1e-3 * plain);
    EXPECT_GT(r.gain, 1.0f); // detail below 1 somewhere needs a gain above 1
}

TEST(TextureSet, WindowedColourSetsRoundTrip) {
    // Windowed colour sets keep colour in RGB and opacity in A (unassociated).
    const std::string dir = splatfx::test::outputDir() + "/colour";
    TextureSet set = TextureSet::turbulence({.count = 2, .size = 16, .seed = 9});
    set.color = true;
    for (auto& layer : set.layers)
        for (size_t i = 0; i < layer.size(); i += 4) layer[i + 1] *= 0.5f, layer[i + 2] *= 0.25f; // warm tint
    const TextureSet win = set.windowed(Footprint{});
    ASSERT_TRUE(saveTextureSet(win, dir));
    auto back = loadTextureSet(dir);
    ASSERT_TRUE(back) << back.error();
    ASSERT_TRUE(back->color && back->isWindowed);
    for (int k = 0; k < 2; ++k)
        for (size_t i = 0; i < win.layers[0].size(); i += 4) {
            const float a = win.layers[size_t(k)][i + 3];
            // Straight alpha: colour and alpha are each stored once in 8 bits,
            // so both come back within half a quantization step.
            EXPECT_NEAR(back->layers[size_t(k)][i + 3], a, 0.5 / 255 + 1e-6);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(back->layers[size_t(k)][i + size_t(c)], win.layers[size_t(k)][i + size_t(c)], 0.5 / 255 + 1e-6);
        }
}

// Manifest entries stay inside their folder, and every field a manifest
// states is checked against the files (issue 13): a lying manifest is an
// error naming the field, never a set built from the wrong files.
TEST(TextureSetBadInput, LyingOrEscapingManifestsAreRefused) {
    const std::string dir = splatfx::test::outputDir() + "/lying";
    fs::remove_all(dir);
    ASSERT_TRUE(saveTextureSet(TextureSet::turbulence({.count = 2, .size = 8}), dir, "{}"));
    const std::string good = [&] {
        std::ifstream in(dir + "/manifest.json");
        return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    ASSERT_TRUE(loadTextureSet(dir));
    auto withManifest = [&](const std::string& text) {
        std::ofstream(dir + "/manifest.json") << text;
        return loadTextureSet(dir);
    };
    auto replaced = [&](const std::string& from, const std::string& to) {
        std::string s = good;
        const auto at = s.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        return s.replace(at, from.size(), to);
    };
    const struct {
        std::string manifest, message;
    } cases[] = {
        {replaced("\"t000.png\"", "\"../../etc/passwd\""), "must be a file name inside the set's folder"},
        {replaced("\"t000.png\"", "\"/etc/passwd\""), "must be a file name inside the set's folder"},
        {replaced("\"size\": 8", "\"size\": 16"), "is 8x8, but field 'size' says 16"},
        {replaced("\"size\": 8", "\"size\": 8, \"count\": 5"), "field 'count' says 5 but 'textures' lists 2"},
        {replaced("\"windowed\": false", "\"windowed\": \"yes\""), "field 'windowed' must be true or false"},
    };
    for (const auto& c : cases) {
        auto r = withManifest(c.manifest);
        ASSERT_FALSE(r) << c.manifest;
        EXPECT_NE(r.error().find(c.message), std::string::npos) << r.error();
    }
}
