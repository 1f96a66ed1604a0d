// TexpickTest: splatfx-texpick's selection modes, processing, output safety and
// error messages, on synthetic images whose answers are known. CPU only: every
// output here is written with --no-preview (the GL test covers the preview).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <regex>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "gl_fixture.hpp"
#include "texpick.hpp"

namespace fs = std::filesystem;
using texpick::Patch;

namespace {

constexpr double kPi = 3.14159265358979323846;

template <class F>
splatfx::Image grayImage(int w, int h, F f) {
    splatfx::Image im;
    im.width = w;
    im.height = h;
    im.channels = 1;
    im.pixels.resize(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) im.at(x, y, 0) = float(f(x, y));
    return im;
}

// Left half: one slow ripple (about 1/96 cycles per pixel, inside the lowest
// band); right half: a fine grid at radius sqrt(2)/4 = 0.354 cycles per pixel
// (inside the top band). Both have mean 0.5 and amplitude 0.3.
texpick::Source twoHalves() {
    return texpick::sourceFromImage(grayImage(512, 256,
                                              [](int x, int y) {
                                                  if (x < 256) return 0.5 + 0.3 * std::sin(2 * kPi * x / 96.0) * std::sin(2 * kPi * y / 96.0);
                                                  return 0.5 + 0.3 * std::sin(2 * kPi * (x + 0.5) / 4.0) * std::sin(2 * kPi * (y + 0.5) / 4.0);
                                              }),
                                    "two-halves");
}

// Smooth random texture: white noise blurred with sigma 6 px, so shifting a
// patch by a few pixels changes it gradually (what path mode relies on).
texpick::Source smoothNoise(int w, int h, std::uint32_t seed) {
    std::mt19937 rng(seed);
    cv::Mat m(h, w, CV_32F);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) m.at<float>(y, x) = float(rng() % 1000) / 999.0f;
    cv::GaussianBlur(m, m, cv::Size(0, 0), 6.0);
    cv::normalize(m, m, 0.05, 0.95, cv::NORM_MINMAX);
    return texpick::sourceFromImage(grayImage(w, h, [&](int x, int y) { return m.at<float>(y, x); }), "smooth-noise");
}

// A fresh, empty folder per test under the build tree.
fs::path scratch() {
    const fs::path dir = fs::path(splatfx::test::outputDir()) / "scratch";
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::vector<std::string> entries(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    return names;
}

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += x + " ";
    return s;
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

void writeBytes(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary);
    out << bytes;
}

// 8-bit PNG storage rounds to the nearest of 256 levels: at most half a level off.
constexpr float kEightBit = 0.5f / 255.0f + 1e-6f;

} // namespace

// [SECTION] Spectral mode

TEST(TexpickSpectral, HighBandPicksFromTheFineHalf) {
    const texpick::Source src = twoHalves();
    auto sel = texpick::pickSpectral(src, {.count = 4, .patch = 64, .bandLo = 0.25, .bandHi = 0.75});
    ASSERT_TRUE(sel) << sel.error();
    ASSERT_EQ(sel->patches.size(), 4u);
    for (const Patch& p : sel->patches) {
        EXPECT_GE(p.x, 256) << "patch at x = " << p.x << " is not wholly in the high-frequency (right) half";
        EXPECT_GT(texpick::bandFraction(src, p, 0.25, 0.75), 0.9);
    }
}

TEST(TexpickSpectral, LowBandPicksFromTheSmoothHalf) {
    const texpick::Source src = twoHalves();
    auto sel = texpick::pickSpectral(src, {.count = 4, .patch = 64, .bandLo = 0.0, .bandHi = 1.0 / 16});
    ASSERT_TRUE(sel) << sel.error();
    ASSERT_EQ(sel->patches.size(), 4u);
    for (const Patch& p : sel->patches) EXPECT_LE(p.x + p.size, 256) << "patch at x = " << p.x << " reaches into the fine half";
}

TEST(TexpickSpectral, SpreadPicksFromBothHalves) {
    const texpick::Source src = twoHalves();
    auto sel = texpick::pickSpectral(src, {.count = 4, .patch = 64, .spread = true});
    ASSERT_TRUE(sel) << sel.error();
    ASSERT_EQ(sel->patches.size(), 4u);
    int left = 0, right = 0;
    for (const Patch& p : sel->patches) {
        left += p.x + p.size <= 256;
        right += p.x >= 256;
    }
    EXPECT_GE(left, 1);
    EXPECT_GE(right, 1);
    // A band pick for comparison has all four in one half: its band energies barely vary.
    auto band = texpick::pickSpectral(src, {.count = 4, .patch = 64, .bandLo = 0.25, .bandHi = 0.75});
    ASSERT_TRUE(band);
    auto spreadOf = [](const texpick::Selection& s) {
        double total = 0.0;
        for (size_t b = 0; b + 1 < texpick::bandEdges().size(); ++b) {
            double mean = 0.0, var = 0.0;
            for (const auto& st : s.stats) mean += st.bandEnergy[b] / double(s.stats.size());
            for (const auto& st : s.stats) var += (st.bandEnergy[b] - mean) * (st.bandEnergy[b] - mean);
            total += var;
        }
        return total;
    };
    EXPECT_GT(spreadOf(*sel), spreadOf(*band));
}

TEST(TexpickSpectral, StatsSeparateTheHalvesAndSumToOne) {
    const texpick::Source src = twoHalves();
    const auto lo = texpick::analyze(src, {64, 64, 64}), hi = texpick::analyze(src, {320, 64, 64});
    const double sumLo = std::accumulate(lo.bandEnergy.begin(), lo.bandEnergy.end(), 0.0);
    const double sumHi = std::accumulate(hi.bandEnergy.begin(), hi.bandEnergy.end(), 0.0);
    // Fractions of one total: equal to 1 up to double rounding over 4096 bins.
    EXPECT_NEAR(sumLo, 1.0, 1e-9);
    EXPECT_NEAR(sumHi, 1.0, 1e-9);
    // The ripple sits at 1/96 cycles per pixel per axis (0.67 of a 1/64 bin);
    // the Hann window's main lobe reaches 2 bins either side, so its power
    // stays below 2.67 / 64 = 0.042 < 1/16: inside the two lowest bands.
    EXPECT_GT(lo.bandEnergy[0] + lo.bandEnergy[1], 0.9);
    // The grid is exactly on bin (16, 16); the window spreads it by 1 bin,
    // i.e. to radius >= 15 sqrt(2) / 64 = 0.33 > 1/4: all in the top band.
    EXPECT_GT(hi.bandEnergy.back(), 0.9);
    // The fine grid sits at sqrt(2)/4 cycles per pixel; the Hann window
    // spreads it over +-1 bin (1/64), so the centroid lies within that.
    EXPECT_NEAR(hi.centroid, std::sqrt(2.0) / 4, std::sqrt(2.0) / 64);
}

// [SECTION] Path mode

TEST(TexpickPath, LinearPatchesOverlapByTheStep) {
    const texpick::Source src = smoothNoise(256, 256, 5);
    auto sel = texpick::pickPath(src, {.points = {{40, 128}, {200, 128}}, .patch = 32, .step = 4});
    ASSERT_TRUE(sel) << sel.error();
    ASSERT_EQ(sel->patches.size(), 41u); // 160 px / 4 px + 1
    for (size_t k = 0; k + 1 < sel->patches.size(); ++k) {
        const Patch a = sel->patches[k], b = sel->patches[k + 1];
        EXPECT_EQ(b.x - a.x, 4);
        EXPECT_EQ(b.y, a.y);
    }
    // The textures themselves: texture k+1 is texture k moved 4 texels left,
    // so the 28 shared columns match exactly (no resampling, no contrast).
    auto made = texpick::makeSet(src, sel->patches, {.textureSize = 32, .contrast = texpick::Contrast::None});
    ASSERT_TRUE(made) << made.error();
    for (int k = 0; k + 1 < made->set.count(); ++k)
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x + 4 < 32; ++x)
                ASSERT_EQ(made->set.layers[size_t(k)][(size_t(y) * 32 + x + 4) * 4], made->set.layers[size_t(k + 1)][(size_t(y) * 32 + x) * 4])
                    << "texture " << k + 1 << " texel (" << x << ", " << y << ")";
}

TEST(TexpickPath, PiecewisePathIsFollowedInBothDirections) {
    const texpick::Source src = smoothNoise(256, 256, 6);
    const std::vector<cv::Point2d> pts{{40, 40}, {200, 40}, {200, 180}};
    auto sel = texpick::pickPath(src, {.points = pts, .patch = 32, .step = 6, .count = 40});
    ASSERT_TRUE(sel) << sel.error();
    ASSERT_EQ(sel->patches.size(), 40u);
    auto distToPath = [&](cv::Point2d c) {
        double best = 1e9;
        for (size_t i = 0; i + 1 < pts.size(); ++i) {
            const cv::Point2d d = pts[i + 1] - pts[i];
            const double t = std::clamp((c - pts[i]).dot(d) / d.dot(d), 0.0, 1.0);
            best = std::min(best, cv::norm(c - (pts[i] + t * d)));
        }
        return best;
    };
    int alongX = 0, alongY = 0;
    for (size_t k = 0; k < sel->patches.size(); ++k) {
        const cv::Point2d c(sel->patches[k].centerX(), sel->patches[k].centerY());
        // Centres are rounded to whole pixels: at most half a pixel off in x and in y.
        EXPECT_LE(distToPath(c), std::sqrt(0.5) + 1e-9) << "patch " << k;
        if (k == 0) continue;
        const cv::Point2d p(sel->patches[k - 1].centerX(), sel->patches[k - 1].centerY());
        // Consecutive centres are 6 px apart along the path; a chord across the
        // right-angle corner is at least 6 / sqrt(2), and rounding moves each
        // end by at most sqrt(0.5).
        EXPECT_LE(cv::norm(c - p), 6.0 + 2 * std::sqrt(0.5) + 1e-9);
        EXPECT_GE(cv::norm(c - p), 6.0 / std::sqrt(2.0) - 2 * std::sqrt(0.5) - 1e-9);
        alongX += c.x > p.x && c.y == p.y;
        alongY += c.y > p.y && c.x == p.x;
    }
    EXPECT_EQ(sel->patches.front(), (Patch{24, 24, 32}));
    // The first segment (160 px) holds 26 whole 6-px steps along x; of the
    // remaining 13 steps one crosses the corner, 12 run along y.
    EXPECT_EQ(alongX, 26);
    EXPECT_EQ(alongY, 12);
}

TEST(TexpickPath, LeavingTheImageIsAnError) {
    const texpick::Source src = smoothNoise(128, 96, 7);
    auto sel = texpick::pickPath(src, {.points = {{40, 40}, {120, 40}}, .patch = 32, .step = 4});
    ASSERT_FALSE(sel);
    EXPECT_EQ(sel.error(), "path: point 2 (120, 40) leaves the 128x96 image 'smooth-noise': a 32-px patch needs its "
                           "centre within [16, 112] x [16, 80]");
    auto tooMany = texpick::pickPath(src, {.points = {{40, 40}, {60, 40}}, .patch = 32, .step = 4, .count = 10});
    ASSERT_FALSE(tooMany);
    EXPECT_EQ(tooMany.error(), "path: 10 patches 4 px apart need a path 36 px long, but the path is 20 px; lower --count "
                               "or --step, or lengthen --path");
}

// [SECTION] Positions and random modes

TEST(TexpickPositions, ReproducesTheGivenPatchesExactly) {
    splatfx::Image rgb;
    rgb.width = 96;
    rgb.height = 80;
    rgb.channels = 3;
    rgb.pixels.resize(size_t(96) * 80 * 3);
    for (size_t i = 0; i < rgb.pixels.size(); ++i) rgb.pixels[i] = float((i * 37) % 251) / 250.0f;
    const texpick::Source src = texpick::sourceFromImage(rgb, "rgb");
    auto sel = texpick::pickPositions(src, {.centers = {{20, 30, 16}, {70, 50, 16}, {48, 40, 16}}});
    ASSERT_TRUE(sel) << sel.error();
    EXPECT_EQ(sel->patches[0], (Patch{12, 22, 16}));
    EXPECT_EQ(sel->patches[1], (Patch{62, 42, 16}));
    EXPECT_EQ(sel->patches[2], (Patch{40, 32, 16}));
    const texpick::ProcessDesc proc{.textureSize = 16, .color = true, .contrast = texpick::Contrast::None};
    auto made = texpick::makeSet(src, sel->patches, proc);
    ASSERT_TRUE(made) << made.error();
    for (int k = 0; k < 3; ++k)
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x)
                for (int c = 0; c < 3; ++c)
                    ASSERT_EQ(made->set.layers[size_t(k)][(size_t(y) * 16 + x) * 4 + size_t(c)],
                              rgb.at(sel->patches[size_t(k)].x + x, sel->patches[size_t(k)].y + y, c));

    // Written and read back by the SDK: the same texels up to 8-bit storage,
    // and the manifest records each patch where it was cut.
    const fs::path out = scratch() / "positions";
    texpick::Provenance prov{.sourceFile = "rgb", .method = "positions", .selection = &*sel, .process = &proc, .order = made->order};
    ASSERT_TRUE(texpick::writeOutput(out.string(), made->set, texpick::provenanceJson(prov), {.preview = false}, &src, &sel->patches));
    auto back = splatfx::loadTextureSet(out.string());
    ASSERT_TRUE(back) << back.error();
    ASSERT_EQ(back->count(), 3);
    EXPECT_TRUE(back->color);
    for (int k = 0; k < 3; ++k)
        for (size_t i = 0; i < back->layers[size_t(k)].size(); ++i)
            ASSERT_NEAR(back->layers[size_t(k)][i], made->set.layers[size_t(k)][i], kEightBit);
    std::ifstream in(out / "manifest.json");
    const auto m = nlohmann::json::parse(in);
    const auto& patches = m["provenance"]["patches"];
    ASSERT_EQ(patches.size(), 3u);
    EXPECT_EQ(patches[1]["x"], 62);
    EXPECT_EQ(patches[1]["y"], 42);
    EXPECT_EQ(patches[1]["size"], 16);
    EXPECT_EQ(m["provenance"]["provenanceVersion"], texpick::kProvenanceVersion);
    EXPECT_EQ(patches[1]["bandEnergy"].size(), texpick::bandEdges().size() - 1);
    EXPECT_TRUE(fs::exists(out / "contact.png"));
}

TEST(TexpickPositions, APatchLeavingTheImageIsAnError) {
    const texpick::Source src = smoothNoise(100, 80, 3);
    auto sel = texpick::pickPositions(src, {.centers = {{50, 40, 0}, {90, 40, 0}}, .defaultSize = 32});
    ASSERT_FALSE(sel);
    EXPECT_EQ(sel.error(), "position 2 (90, 40): its 32-px patch at (74, 24) leaves the 100x80 image 'smooth-noise'");
}

TEST(TexpickRandom, DeterministicPerSeed) {
    const texpick::Source src = smoothNoise(300, 200, 11);
    auto a = texpick::pickRandom(src, {.count = 8, .patch = 32, .seed = 42});
    auto b = texpick::pickRandom(src, {.count = 8, .patch = 32, .seed = 42});
    auto c = texpick::pickRandom(src, {.count = 8, .patch = 32, .seed = 43});
    ASSERT_TRUE(a && b && c);
    EXPECT_EQ(a->patches, b->patches);
    EXPECT_NE(a->patches, c->patches);
}

TEST(TexpickRandom, RejectsFlatPatches) {
    // Left half flat grey, right half textured.
    const texpick::Source noise = smoothNoise(256, 128, 9);
    const texpick::Source src =
        texpick::sourceFromImage(grayImage(256, 128, [&](int x, int y) { return x < 128 ? 0.5f : noise.luminance.at<float>(y, x); }), "half-flat");
    const texpick::Acceptance accept{.minStd = 0.03f};
    auto sel = texpick::pickRandom(src, {.count = 12, .patch = 32, .seed = 3, .accept = accept});
    ASSERT_TRUE(sel) << sel.error();
    // With uniform positions about 3/7 of tries land wholly in the flat half, so some must have been rejected.
    EXPECT_GT(sel->rejected, 0);
    for (size_t k = 0; k < sel->patches.size(); ++k) {
        EXPECT_GT(sel->patches[k].x + sel->patches[k].size, 128) << "patch " << k << " lies wholly in the flat half";
        // Relative thresholds (the default): minStd times the source's luminance range.
        EXPECT_GE(sel->stats[k].stddev, texpick::effectiveThresholds(src, accept).minStd);
    }
    const texpick::Source flat = texpick::sourceFromImage(grayImage(64, 64, [](int, int) { return 0.5; }), "flat");
    auto none = texpick::pickRandom(flat, {.count = 2, .patch = 16, .seed = 1, .maxTries = 50});
    ASSERT_FALSE(none);
    // Every try counted against the threshold that rejected it: a constant
    // image is judged as if it spanned one 8-bit step (0.03 / 255).
    EXPECT_EQ(none.error(), "random: only 0 of 2 16-px patches of 'flat' passed after 50 tries: of 50 candidates, 0 were rejected "
                            "by --min-coverage 0.9 (mean alpha; alpha read as coverage), 0 by --min-mean 0.03 (0.015 for this "
                            "source's luminance 0.5..0.5), 50 by --min-std 0.03 (0.000117647 for this source's luminance 0.5..0.5); "
                            "lower --min-std or use a smaller --patch");
}

// [SECTION] Processing

TEST(TexpickProcess, ContrastNormalizationHitsTheTarget) {
    const texpick::Source src = smoothNoise(128, 128, 4);
    auto made = texpick::makeSet(src, {{0, 0, 64}, {64, 64, 64}}, {.textureSize = 64, .contrast = texpick::Contrast::Patch, .contrastStd = 0.1f});
    ASSERT_TRUE(made) << made.error();
    for (const auto& layer : made->set.layers) {
        double sum = 0, sum2 = 0;
        for (size_t i = 0; i < layer.size(); i += 4) sum += layer[i], sum2 += double(layer[i]) * layer[i];
        const double n = double(layer.size() / 4), mean = sum / n;
        // Std 0.1 around 0.5 keeps every texel inside [0, 1] unless 4 std out, so clamping is negligible.
        EXPECT_NEAR(mean, 0.5, 1e-3);
        EXPECT_NEAR(std::sqrt(sum2 / n - mean * mean), 0.1, 1e-3);
    }
}

TEST(TexpickProcess, SmoothCycleRecoversACircularPath) {
    // 16 patches on a closed ring, shuffled: the smooth cycle must visit them
    // in ring order (either direction), because on this smooth texture the
    // difference between patches grows with their distance.
    const texpick::Source src = smoothNoise(200, 200, 21);
    std::vector<Patch> ring;
    for (int k = 0; k < 16; ++k) {
        const double a = 2 * kPi * k / 16;
        ring.push_back({int(std::lround(84 + 12 * std::cos(a))), int(std::lround(84 + 12 * std::sin(a))), 32});
    }
    std::vector<int> perm(16);
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), std::mt19937(5));
    std::vector<Patch> shuffled;
    for (int i : perm) shuffled.push_back(ring[size_t(i)]);
    auto made = texpick::makeSet(src, shuffled, {.textureSize = 32, .contrast = texpick::Contrast::None, .order = true});
    ASSERT_TRUE(made) << made.error();
    std::vector<int> identity(16);
    std::iota(identity.begin(), identity.end(), 0);
    for (int k = 0; k < 16; ++k) {
        const int here = perm[size_t(made->order[size_t(k)])], next = perm[size_t(made->order[size_t((k + 1) % 16)])];
        EXPECT_EQ(std::min((here - next + 16) % 16, (next - here + 16) % 16), 1)
            << "textures " << k << " and " << (k + 1) % 16 << " are ring patches " << here << " and " << next;
    }
    auto unordered = texpick::makeSet(src, shuffled, {.textureSize = 32, .contrast = texpick::Contrast::None});
    ASSERT_TRUE(unordered);
    EXPECT_LT(texpick::cycleCost(made->set, identity), texpick::cycleCost(unordered->set, identity));
}

// [SECTION] Bad input through the command line: clear messages, nothing left behind

class TexpickErrors : public ::testing::Test {
protected:
    void SetUp() override {
        dir = scratch();
        // A nested, not yet existing --out: a failed run must not leave the parents either.
        out = (dir / "new" / "deeper" / "set").string();
    }
    void expectNothingLeft() {
        EXPECT_FALSE(fs::exists(dir / "new")) << "a failed run left '" << (dir / "new").string() << "' behind";
        for (const auto& name : entries(dir)) EXPECT_EQ(name.find(".set"), std::string::npos) << name;
    }
    fs::path dir;
    std::string out;
};

TEST_F(TexpickErrors, MissingImage) {
    const std::string img = (dir / "nope.png").string();
    auto [rc, err] = runCli({"random", img, "--out", out, "--no-preview"});
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(err, "splatfx-texpick: cannot read image '" + img + "': no such file\n");
    expectNothingLeft();
}

TEST_F(TexpickErrors, EmptyImage) {
    const std::string img = (dir / "empty.png").string();
    writeBytes(img, "");
    auto [rc, err] = runCli({"random", img, "--out", out, "--no-preview"});
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(err, "splatfx-texpick: cannot read image '" + img + "': the file is empty\n");
    expectNothingLeft();
}

TEST_F(TexpickErrors, CorruptImage) {
    const std::string img = (dir / "corrupt.png").string();
    // A PNG signature followed by garbage: the header promises an image the data cannot deliver.
    writeBytes(img, std::string("\x89PNG\r\n\x1a\n", 8) + std::string(200, 'x'));
    auto [rc, err] = runCli({"random", img, "--out", out, "--no-preview"});
    EXPECT_EQ(rc, 1);
    // libpng prints its own complaints to stderr first; ours follows them.
    EXPECT_NE(err.find("splatfx-texpick: cannot read image '" + img + "': "), std::string::npos) << err;
    EXPECT_NE(err.find("(OpenCV cannot decode it either)"), std::string::npos) << err;
    expectNothingLeft();
}

TEST_F(TexpickErrors, UnreadableImageAFolder) {
    auto [rc, err] = runCli({"random", dir.string(), "--out", out, "--no-preview"});
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(err, "splatfx-texpick: cannot read image '" + dir.string() + "': it is a folder, not an image file\n");
    expectNothingLeft();
}

TEST_F(TexpickErrors, UnreadableImageNoPermission) {
    if (geteuid() == 0) GTEST_SKIP() << "running as root: file permissions cannot make a file unreadable";
    const std::string img = (dir / "locked.png").string();
    ASSERT_TRUE(splatfx::writeImage(img, grayImage(64, 64, [](int x, int) { return x / 64.0; })));
    fs::permissions(img, fs::perms::none);
    auto [rc, err] = runCli({"random", img, "--out", out, "--no-preview"});
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(err, "splatfx-texpick: cannot read image '" + img + "': the file cannot be opened (check its permissions)\n");
    expectNothingLeft();
}

TEST_F(TexpickErrors, TinyImage) {
    const std::string img = (dir / "tiny.png").string();
    ASSERT_TRUE(splatfx::writeImage(img, grayImage(20, 12, [](int x, int y) { return ((x + y) % 2) * 1.0; })));
    auto [rc, err] = runCli({"random", img, "--out", out, "--no-preview", "--patch", "64"});
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(err, "splatfx-texpick: image '" + img + "' is 20x12 pixels, too small for one 64-px patch; use --patch 12 or less\n");
    expectNothingLeft();
}

// Smaller than any patch: the advice must not name a patch size that cannot work.
TEST_F(TexpickErrors, ImageSmallerThanTheSmallestPatch) {
    const std::string img = (dir / "one.png").string();
    ASSERT_TRUE(splatfx::writeImage(img, grayImage(1, 1, [](int, int) { return 0.5; })));
    auto [rc, err] = runCli({"random", img, "--out", out, "--no-preview"});
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(err, "splatfx-texpick: image '" + img + "' is 1x1 pixels, smaller than the smallest patch (4 px); use a larger image\n");
    expectNothingLeft();
}

TEST_F(TexpickErrors, PathLeavingTheImage) {
    const std::string img = (dir / "small.png").string();
    ASSERT_TRUE(splatfx::writeImage(img, grayImage(100, 80, [](int x, int y) { return ((x / 3 + y / 5) % 2) * 0.8 + 0.1; })));
    auto [rc, err] = runCli({"path", img, "--out", out, "--no-preview", "--patch", "32", "--path", "20,20:90,40"});
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(err, "splatfx-texpick: path: point 2 (90, 40) leaves the 100x80 image '" + img +
                       "': a 32-px patch needs its centre within [16, 84] x [16, 64]\n");
    expectNothingLeft();
}

TEST_F(TexpickErrors, RefusesToReplaceAFolderThatIsNotATextureSet) {
    const std::string img = (dir / "ok.png").string();
    ASSERT_TRUE(splatfx::writeImage(img, grayImage(64, 64, [](int x, int y) { return ((x / 3 + y / 5) % 2) * 0.8 + 0.1; })));
    const fs::path precious = dir / "precious";
    fs::create_directories(precious);
    writeBytes(precious / "notes.txt", "keep me");
    auto [rc, err] = runCli({"random", img, "--out", precious.string(), "--no-preview", "--patch", "16", "--count", "2"});
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(err, "splatfx-texpick: refusing to replace '" + precious.string() +
                       "': it exists and is not a texture-set folder (no manifest.json); remove it or choose another --out\n");
    EXPECT_EQ(entries(precious), std::vector<std::string>{"notes.txt"});
}

TEST_F(TexpickErrors, AFailureHalfwayKeepsTheOldSetAndLeavesNoStaging) {
    const texpick::Source src = smoothNoise(64, 64, 2);
    auto made = texpick::makeSet(src, {{0, 0, 32}, {32, 32, 32}}, {});
    ASSERT_TRUE(made);
    const fs::path target = dir / "set";
    ASSERT_TRUE(texpick::writeOutput(target.string(), made->set, "{\"run\": 1}", {.preview = false}));
    const std::string before = [&] {
        std::ifstream in(target / "manifest.json");
        return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    // The second run fails after the textures and contact sheet are staged: the preview size is invalid.
    auto s = texpick::writeOutput(target.string(), made->set, "{\"run\": 2}", {.preview = true, .previewSize = 8});
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "nothing written to '" + target.string() + "': --preview-size must be between 32 and 2048 pixels, got 8");
    const std::string after = [&] {
        std::ifstream in(target / "manifest.json");
        return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    EXPECT_EQ(before, after);
    EXPECT_EQ(entries(dir), std::vector<std::string>{"set"}) << joined(entries(dir));
}

TEST_F(TexpickErrors, BadOptionsNameTheOption) {
    auto [rc, err] = runCli({"spectral", "x.png", "--out", out, "--band", "0.5:0.2"});
    EXPECT_EQ(rc, 2);
    EXPECT_EQ(err, "--band expects LO:HI cycles per pixel with 0 <= LO < HI (e.g. 0.125:0.75), got '0.5:0.2'\n");
    auto [rc2, err2] = runCli({"path", "x.png", "--out", out, "--path", "10,10"});
    EXPECT_EQ(rc2, 2);
    EXPECT_EQ(err2, "--path needs at least 2 points X,Y:X,Y, got '10,10'\n");
    expectNothingLeft();
}

// [SECTION] The SDK loads what texpick makes

TEST(TexpickSets, TurbulenceAndMergeLoad) {
    const fs::path dir = scratch();
    auto [rc, err] = runCli({"turbulence", "--out", (dir / "turb").string(), "--count", "4", "--size", "16", "--seed", "9", "--no-preview"});
    ASSERT_EQ(rc, 0) << err;
    auto [rc2, err2] = runCli({"turbulence", "--out", (dir / "turb2").string(), "--count", "3", "--size", "16", "--no-preview"});
    ASSERT_EQ(rc2, 0) << err2;
    auto [rc3, err3] = runCli({"merge", (dir / "turb").string(), (dir / "turb2").string(), "--out", (dir / "both").string(), "--no-preview"});
    ASSERT_EQ(rc3, 0) << err3;
    auto turb = splatfx::loadTextureSet((dir / "turb").string());
    auto both = splatfx::loadTextureSet((dir / "both").string());
    ASSERT_TRUE(turb) << turb.error();
    ASSERT_TRUE(both) << both.error();
    EXPECT_EQ(turb->count(), 4);
    EXPECT_EQ(both->count(), 7);
    // The saved turbulence is TextureSet::turbulence itself, up to 8-bit storage.
    const auto ref = splatfx::TextureSet::turbulence({.count = 4, .size = 16, .seed = 9});
    for (int k = 0; k < 4; ++k)
        for (size_t i = 0; i < ref.layers[size_t(k)].size(); ++i) ASSERT_NEAR(turb->layers[size_t(k)][i], ref.layers[size_t(k)][i], kEightBit);
    for (size_t i = 0; i < ref.layers[3].size(); ++i) ASSERT_EQ(both->layers[3][i], turb->layers[3][i]);
}

TEST(TexpickSets, WindowedSetRoundTrips) {
    const texpick::Source src = smoothNoise(64, 64, 8);
    const texpick::ProcessDesc proc{.textureSize = 16, .window = true};
    auto made = texpick::makeSet(src, {{0, 0, 32}, {16, 16, 32}}, proc);
    ASSERT_TRUE(made) << made.error();
    ASSERT_TRUE(made->set.isWindowed);
    const fs::path out = scratch() / "windowed";
    ASSERT_TRUE(texpick::writeOutput(out.string(), made->set, "{}", {.preview = false}));
    auto back = splatfx::loadTextureSet(out.string());
    ASSERT_TRUE(back) << back.error();
    EXPECT_TRUE(back->isWindowed);
    for (int k = 0; k < 2; ++k)
        for (size_t i = 0; i < back->layers[size_t(k)].size(); ++i)
            ASSERT_NEAR(back->layers[size_t(k)][i], made->set.layers[size_t(k)][i], kEightBit) << i;
}

TEST(TexpickSets, WindowedColourIsRefused) {
    // Texture-set version 1 stores a windowed colour set as RGBA PNG, which
    // does not read back as written (see docs/texpick.md), so texpick says so.
    const texpick::Source src = smoothNoise(64, 64, 8);
    auto made = texpick::makeSet(src, {{0, 0, 32}}, {.textureSize = 16, .color = true, .window = true});
    ASSERT_FALSE(made);
    EXPECT_EQ(made.error(), "--window with --color is not supported: texture-set version 1 cannot store a windowed colour "
                            "set faithfully; leave out --window (the renderer windows the set with the same footprint)");
}

TEST(TexpickSets, EveryShippedSetLoads) {
    // textures/<name>-<count>x<size>/: the name promises the count and size.
    const fs::path root = splatfx::test::sourcePath("textures");
    int sets = 0;
    const std::regex shape(".*-([0-9]+)x([0-9]+)$");
    for (const auto& e : fs::directory_iterator(root)) {
        if (!fs::exists(e.path() / "manifest.json")) continue;
        ++sets;
        auto set = splatfx::loadTextureSet(e.path().string());
        ASSERT_TRUE(set) << set.error();
        std::smatch m;
        const std::string name = e.path().filename().string();
        ASSERT_TRUE(std::regex_match(name, m, shape)) << name << " does not end in -<count>x<size>";
        EXPECT_EQ(set->count(), std::stoi(m[1])) << name;
        EXPECT_EQ(set->size, std::stoi(m[2])) << name;
        std::ifstream in(e.path() / "manifest.json");
        const auto j = nlohmann::json::parse(in);
        EXPECT_EQ(j["provenance"]["tool"], "splatfx-texpick") << name;
        EXPECT_EQ(j["provenance"]["provenanceVersion"], texpick::kProvenanceVersion) << name;
    }
    EXPECT_GE(sets, 7) << "expected the turbulence, photo and faces sets in " << root.string();
}

TEST(TexpickSets, ShippedTurbulenceRegenerates) {
    const fs::path dir = splatfx::test::sourcePath("textures/turbulence-8x32");
    std::ifstream in(dir / "manifest.json");
    ASSERT_TRUE(in) << "missing " << dir.string();
    const auto p = nlohmann::json::parse(in)["provenance"]["parameters"];
    const auto ref = splatfx::TextureSet::turbulence({.count = p["count"],
                                                      .size = p["size"],
                                                      .seed = p["seed"],
                                                      .octaves = p["octaves"],
                                                      .baseFrequency = p["baseFrequency"],
                                                      .loopRadius = p["loopRadius"]});
    auto set = splatfx::loadTextureSet(dir.string());
    ASSERT_TRUE(set) << set.error();
    ASSERT_EQ(set->count(), ref.count());
    for (int k = 0; k < ref.count(); ++k)
        for (size_t i = 0; i < ref.layers[size_t(k)].size(); ++i) ASSERT_NEAR(set->layers[size_t(k)][i], ref.layers[size_t(k)][i], kEightBit);
}

// A run killed at the swap leaves the previous set moved aside under a hidden
// name (its process gone); the next run puts it back before anything else, so
// even a next run that fails leaves the user with the old set, and a killed
// run's staging folder is removed. 4194305 is above Linux's largest pid.
TEST(TexpickOutput, KilledRunsAreRecoveredByTheNextRun) {
    const fs::path dir = fs::path(splatfx::test::outputDir()) / "recover";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const auto set = splatfx::TextureSet::turbulence({.count = 2, .size = 16, .seed = 4});
    ASSERT_TRUE(saveTextureSet(set, (dir / ".fire.texpick-old-4194305").string(), "{}"));
    fs::create_directories(dir / ".fire.texpick-4194306");
    std::ofstream(dir / ".fire.texpick-4194306" / "t000.png") << "half written";
    const splatfx::Status s = texpick::writeOutput((dir / "fire").string(), splatfx::TextureSet{}, "{}", {.contactSheet = false, .preview = false});
    ASSERT_FALSE(s) << "an empty set must fail to save";
    EXPECT_TRUE(fs::exists(dir / "fire" / "manifest.json")) << "the previous set must be back under its name";
    EXPECT_TRUE(splatfx::loadTextureSet((dir / "fire").string()));
    EXPECT_FALSE(fs::exists(dir / ".fire.texpick-4194306")) << "the killed run's staging folder must be gone";
    EXPECT_FALSE(fs::exists(dir / ".fire.texpick-old-4194305"));
}
