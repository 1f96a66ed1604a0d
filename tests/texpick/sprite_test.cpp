// TexpickSprites (issue 18, item 4): game particle sprites as sources. A soft
// radial puff whose alpha is density and a dark, low-contrast sprite (its
// brightest texel 68/255) both give a set with the default thresholds; the
// same sources under the old reading (alpha as a cut-out, absolute
// thresholds) give nothing, and the error says which threshold rejected how
// many patches. Sprites are generated here (see docs/texpick.md for why no
// packaged game sprite is used) and go through real PNG files.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gl_fixture.hpp"
#include "texpick.hpp"

namespace fs = std::filesystem;

namespace {

// Deterministic value noise in [0, 1]: bilinear between hashed lattice values
// `cell` pixels apart, summed over three octaves (a puff's inner structure).
double latticeValue(int x, int y, std::uint32_t seed) {
    std::uint32_t h = std::uint32_t(x) * 73856093u ^ std::uint32_t(y) * 19349663u ^ seed * 83492791u;
    h ^= h >> 13, h *= 0x5bd1e995u, h ^= h >> 15;
    return (h & 0xffffu) / 65535.0;
}
double valueNoise(double x, double y, double cell, std::uint32_t seed) {
    const double u = x / cell, v = y / cell;
    const int i = int(std::floor(u)), j = int(std::floor(v));
    const double fu = u - i, fv = v - j;
    const double a = latticeValue(i, j, seed), b = latticeValue(i + 1, j, seed), c = latticeValue(i, j + 1, seed),
                 d = latticeValue(i + 1, j + 1, seed);
    return (a * (1 - fu) + b * fu) * (1 - fv) + (c * (1 - fu) + d * fu) * fv;
}
double fractal(double x, double y, std::uint32_t seed) {
    return (4.0 * valueNoise(x, y, 16, seed) + 2.0 * valueNoise(x, y, 8, seed + 1) + valueNoise(x, y, 4, seed + 2)) / 7.0;
}

fs::path scratch(const std::string& name) {
    const fs::path dir = fs::path(splatfx::test::outputDir()) / ("sprites-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// A smoke puff as games ship it: white RGB, alpha = density, a Gaussian
// falloff from the centre times fractal noise, 128x128.
splatfx::Image softPuff() {
    splatfx::Image im;
    im.width = im.height = 128;
    im.channels = 4;
    im.pixels.resize(128 * 128 * 4);
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x) {
            const double r2 = ((x - 63.5) * (x - 63.5) + (y - 63.5) * (y - 63.5)) / (40.0 * 40.0);
            const double a = std::exp(-r2) * (0.35 + 0.65 * fractal(x, y, 7));
            for (int c = 0; c < 3; ++c) im.at(x, y, c) = 1.0f;
            im.at(x, y, 3) = float(a);
        }
    return im;
}

// A dark, low-contrast additive sprite (no alpha: black is empty): grey
// 68/255 at its brightest, a broad glow with faint structure, 128x128.
splatfx::Image darkSprite() {
    splatfx::Image im;
    im.width = im.height = 128;
    im.channels = 3;
    im.pixels.resize(128 * 128 * 3);
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x) {
            const double r2 = ((x - 63.5) * (x - 63.5) + (y - 63.5) * (y - 63.5)) / (70.0 * 70.0);
            const double v = 68.0 / 255.0 * std::exp(-r2) * (0.6 + 0.4 * fractal(x, y, 3));
            for (int c = 0; c < 3; ++c) im.at(x, y, c) = float(v);
        }
    // The brightest texel exactly 68/255, as in the reported sprite.
    for (int c = 0; c < 3; ++c) im.at(64, 64, c) = 68.0f / 255.0f;
    return im;
}

std::string writePng(const fs::path& dir, const std::string& name, const splatfx::Image& im) {
    const std::string path = (dir / name).string();
    EXPECT_TRUE(splatfx::writeImage(path, im, splatfx::Alpha::Straight));
    return path;
}

// Runs the command line as a user would; returns the exit code and stderr.
std::pair<int, std::string> runCli(std::vector<std::string> args) {
    args.insert(args.begin(), "splatfx-texpick");
    std::vector<const char*> argv;
    for (const auto& a : args) argv.push_back(a.c_str());
    testing::internal::CaptureStderr();
    testing::internal::CaptureStdout();
    int rc = 2;
    auto o = texpick::parseOptions(int(argv.size()), argv.data());
    if (o) rc = texpick::run(*o);
    else std::fprintf(stderr, "%s\n", o.error().c_str());
    testing::internal::GetCapturedStdout();
    return {rc, testing::internal::GetCapturedStderr()};
}

} // namespace

TEST(TexpickSprites, SoftPuffAlphaIsReadAsDensityOnce) {
    const fs::path dir = scratch("puff");
    const splatfx::Image puff = softPuff();
    auto src = texpick::loadSource(writePng(dir, "puff.png", puff));
    ASSERT_TRUE(src) << src.error();
    EXPECT_EQ(src->alpha, texpick::AlphaUse::Density);
    EXPECT_GT(src->softAlphaFraction, 0.9) << "a radial falloff is soft almost everywhere";
    // The file stores straight alpha in 8 bits: each texel's luminance is
    // white x alpha, multiplied once (a premultiplied read multiplied again
    // would give alpha^2), exact to the 8-bit quantization of alpha (1/510).
    double worst = 0.0;
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x) {
            worst = std::max(worst, std::abs(double(src->luminance.at<float>(y, x)) - puff.at(x, y, 3)));
            ASSERT_EQ(src->coverage.at<float>(y, x), 1.0f) << "density alpha is never a cut-out";
        }
    EXPECT_LE(worst, 0.5 / 255.0 + 1e-6);

    // The defaults pick a set; forcing the alpha to be a cut-out rejects
    // every patch on coverage, and says so.
    auto sel = texpick::pickRandom(*src, {.count = 8, .patch = 32, .seed = 1});
    ASSERT_TRUE(sel) << sel.error();
    EXPECT_EQ(sel->rejectedCoverage, 0);
    auto cut = texpick::loadSource((dir / "puff.png").string(), {.alpha = texpick::AlphaUse::Coverage});
    ASSERT_TRUE(cut);
    EXPECT_EQ(cut->alpha, texpick::AlphaUse::Coverage);
    auto none = texpick::pickRandom(*cut, {.count = 8, .patch = 32, .seed = 1, .maxTries = 400});
    ASSERT_FALSE(none);
    EXPECT_NE(none.error().find("of 400 candidates, 400 were rejected by --min-coverage 0.9 (mean alpha; alpha read as coverage)"), std::string::npos)
        << none.error();
    EXPECT_NE(none.error().find("give --alpha density"), std::string::npos) << none.error();
}

TEST(TexpickSprites, DarkLowContrastSpriteWorksWithTheDefaults) {
    const fs::path dir = scratch("dark");
    const std::string path = writePng(dir, "dark.png", darkSprite());
    auto src = texpick::loadSource(path);
    ASSERT_TRUE(src) << src.error();
    EXPECT_NEAR(src->luminanceMax, 68.0 / 255.0, 1e-6) << "grey: the Rec. 709 weights sum to 1";
    auto sel = texpick::pickRandom(*src, {.count = 8, .patch = 32, .seed = 2});
    ASSERT_TRUE(sel) << sel.error();
    const texpick::Thresholds t = texpick::effectiveThresholds(*src, {});
    EXPECT_NEAR(t.minStd, 0.03 * (src->luminanceMax - src->luminanceMin), 1e-9);
    EXPECT_NEAR(t.minMean, 0.03 * src->luminanceMax, 1e-9);
    for (const texpick::SpectralStats& st : sel->stats) {
        EXPECT_GE(st.stddev, t.minStd);
        EXPECT_LT(st.stddev, 0.03) << "the sprite is below the old absolute threshold everywhere (why this test exists)";
    }
    // The old absolute thresholds find every patch flat, and the message says
    // it was --min-std, with the count.
    texpick::Acceptance absolute;
    absolute.relative = false;
    auto none = texpick::pickSpectral(*src, {.count = 8, .patch = 32, .accept = absolute});
    ASSERT_FALSE(none);
    EXPECT_NE(none.error().find("of 169 candidates, 0 were rejected by --min-coverage 0.9 (mean alpha; alpha read as coverage), "), std::string::npos)
        << none.error();
    // Most of the 169 candidates fail --min-std (a few bright-centre ones pass it and then crowd each other out).
    std::smatch hit;
    const std::string err = none.error();
    ASSERT_TRUE(std::regex_search(err, hit, std::regex("0 by --min-mean 0\\.03 \\(absolute\\), ([0-9]+) by --min-std 0\\.03 \\(absolute\\)"))) << err;
    EXPECT_GT(std::stoi(hit[1].str()), 169 / 2) << err;
    EXPECT_NE(err.find("; lower --min-std"), std::string::npos) << err;

    // The command line with nothing but the defaults writes the set and
    // records how its thresholds were read.
    const fs::path out = dir / "set";
    const auto [rc, cliErr] = runCli({"random", path, "--out", out.string(), "--no-preview"});
    ASSERT_EQ(rc, 0) << cliErr;
    std::ifstream in(out / "manifest.json");
    const nlohmann::json m = nlohmann::json::parse(in);
    const nlohmann::json& p = m["provenance"]["parameters"];
    EXPECT_EQ(p["thresholds"], "relative");
    EXPECT_EQ(p["alpha"], "coverage");
    EXPECT_NEAR(p["luminanceRange"][1].get<double>(), 68.0 / 255.0, 1e-6);
}

// Which threshold rejected how many: a hard cut-out (left half outside it)
// beside a flat grey half, on the spectral grid (32-px patches every 8 px:
// 13 x 5 = 65 candidates). Patches starting left of x = 64 have under 90%
// coverage (8 columns: 40); the other 25 lie in flat grey.
TEST(TexpickSprites, NothingPassesSaysWhichThresholdRejectedHowMany) {
    splatfx::Image im;
    im.width = 128, im.height = 64, im.channels = 4;
    im.pixels.assign(size_t(128) * 64 * 4, 0.0f);
    for (int y = 0; y < 64; ++y)
        for (int x = 64; x < 128; ++x) {
            for (int c = 0; c < 3; ++c) im.at(x, y, c) = 0.5f;
            im.at(x, y, 3) = 1.0f;
        }
    const texpick::Source src = texpick::sourceFromImage(im, "half-cut");
    EXPECT_EQ(src.alpha, texpick::AlphaUse::Coverage) << "hard alpha is a cut-out";
    auto none = texpick::pickSpectral(src, {.count = 2, .patch = 32, .stride = 8});
    ASSERT_FALSE(none);
    EXPECT_EQ(none.error(),
              "spectral: only 0 of 2 32-px patches of 'half-cut' are usable: of 65 candidates, 40 were rejected by --min-coverage 0.9 "
              "(mean alpha; alpha read as coverage), 0 by --min-mean 0.03 (0.015 for this source's luminance 0..0.5), 25 by --min-std 0.03 "
              "(0.015 for this source's luminance 0..0.5), 0 by --min-distance 16; lower --min-coverage, or give --alpha density if the "
              "alpha is the gas's density (a sprite)");
}

TEST(TexpickSprites, ShippedTranslucentStampIsASprite) {
    // textures/sources/fire.png: a Tux Paint stamp of translucent flames.
    auto src = texpick::loadSource(std::string(SPLATFX_SOURCE_DIR) + "/textures/sources/fire.png");
    ASSERT_TRUE(src) << src.error();
    EXPECT_EQ(src->alpha, texpick::AlphaUse::Density);
    auto forced = texpick::loadSource(std::string(SPLATFX_SOURCE_DIR) + "/textures/sources/fire.png", {.alpha = texpick::AlphaUse::Coverage});
    ASSERT_TRUE(forced);
    EXPECT_EQ(forced->alpha, texpick::AlphaUse::Coverage);
    EXPECT_DOUBLE_EQ(forced->softAlphaFraction, src->softAlphaFraction);
}

TEST(TexpickSprites, AlphaFlagIsParsedStrictly) {
    const char* good[] = {"splatfx-texpick", "random", "x.png", "--out", "o", "--alpha", "density", "--absolute-thresholds"};
    auto o = texpick::parseOptions(8, good);
    ASSERT_TRUE(o) << o.error();
    EXPECT_EQ(o->source.alpha, texpick::AlphaUse::Density);
    EXPECT_FALSE(o->accept.relative);
    const char* bad[] = {"splatfx-texpick", "random", "x.png", "--out", "o", "--alpha", "opacity"};
    auto b = texpick::parseOptions(7, bad);
    ASSERT_FALSE(b);
    EXPECT_EQ(b.error(), "--alpha expects auto, coverage or density, got 'opacity'");
}
