// The splat-exact reference: conventions, ordering and input checks (CPU only).
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/splatfx.hpp"

namespace splatfx {
namespace {

const glm::vec4 kColour{0.9f, 0.6f, 0.3f, 1.0f};

struct Scene {
    Materials mat{Footprint{}};
    std::uint32_t set = 0;
    Scene() {
        mat.addColorTable(ColorTable::constant(kColour));
        set = mat.addTextureSet(TextureSet::turbulence({.count = 4}));
    }
};

TEST(SplatExact, CentrePixelOfALoneSplatHasTheVoxelsOpacity) {
    // A cubic voxel far from the near plane: fade 1, chord 1, gain 1 (untextured),
    // so at the splat centre alpha = 1 - 2^-tau = opacity. The centre pixel of an
    // odd viewport looks exactly at the look-at target. Float density: 1e-6.
    Scene s;
    Grid g;
    g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.4f});
    const Camera cam = Camera::lookAt({0.5f, 0.3f, 8.0f}, {0, 0, 0}, {0, 1, 0}, 0.5f, {15, 11});
    SplatBuilder b;
    b.begin(cam);
    b.add(g, s.mat, {.textured = false});
    auto img = renderSplatExact(b.splats(), cam, s.mat);
    ASSERT_TRUE(img) << img.error();
    EXPECT_NEAR(img->at(7, 5, 3), 0.4, 1e-6);
    EXPECT_NEAR(img->at(7, 5, 0), kColour.r * 0.4, 1e-6);
}

TEST(SplatExact, PixelCentresAreSymmetricAboutTheViewAxis) {
    // Camera on the voxel's axis: the image of an isotropic voxel must be
    // mirror-symmetric in x and y about the viewport centre. Sampling at pixel
    // corners instead of centres (a +0.5 slip) would break it by about
    // |dF/dpixel| * 0.5 ~ 5e-2 here; float axes allow ~1e-6.
    Scene s;
    Grid g;
    g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.7f});
    const Camera cam = Camera::lookAt({0, 0, 6.0f}, {0, 0, 0}, {0, 1, 0}, 0.6f, {16, 12});
    SplatBuilder b;
    b.begin(cam);
    b.add(g, s.mat, {.textured = false});
    auto img = renderSplatExact(b.splats(), cam, s.mat);
    ASSERT_TRUE(img);
    double worst = 0.0;
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 16; ++x) {
            worst = std::max(worst, double(std::abs(img->at(x, y, 3) - img->at(15 - x, y, 3))));
            worst = std::max(worst, double(std::abs(img->at(x, y, 3) - img->at(x, 11 - y, 3))));
        }
    EXPECT_LT(worst, 1e-6);
    EXPECT_GT(img->at(7, 5, 3), 0.5f);
}

TEST(SplatExact, OrderComesFromEachPixelNotFromTheList) {
    // The reference sorts per pixel by where the ray meets each splat plane, so
    // any permutation of the list renders the same image (exactly: the same
    // doubles are summed in the same per-pixel order).
    Scene s;
    Grid g = *Grid::box({4, 5, 3}, glm::vec3(0.5f));
    std::mt19937 rng(3);
    for (Voxel& v : g.voxels) v.opacity = std::uniform_real_distribution<float>(0.1f, 0.9f)(rng), v.texture = rng();
    const Camera cam = Camera::lookAt({2, 3, 5}, {0, 1, 0}, {0, 1, 0}, 0.8f, {32, 24});
    SplatBuilder b;
    b.begin(cam);
    b.add(g, s.mat, {.textureSet = s.set});
    b.sort();
    auto sorted = renderSplatExact(b.splats(), cam, s.mat);
    std::vector<Splat> shuffled = b.splats();
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    auto other = renderSplatExact(shuffled, cam, s.mat);
    ASSERT_TRUE(sorted && other);
    EXPECT_EQ(sorted->pixels, other->pixels);
    EXPECT_GT(*std::max_element(sorted->pixels.begin(), sorted->pixels.end()), 0.3f);
}

TEST(SplatExact, ExactWindowRecoversTheStoredLayer) {
    // The Exact window divides the sampled window out of the stored layer and
    // multiplies the exact one back; at texel centres inside the support that
    // must give back the stored alpha up to the table's interpolation error
    // (256 entries: |F''| h^2 / 8 ~ 1e-5 of F(0)) and float rounding. Checked
    // through whole images: Exact and Stored windows differ by at most 1e-3 in
    // alpha on a textured scene whose layers match layerSize.
    Scene s;
    Grid g = *Grid::box({3, 3, 3}, glm::vec3(0.5f));
    for (Voxel& v : g.voxels) v.opacity = 0.5f, v.texture = std::uint32_t(v.cell.x + 3 * v.cell.y);
    const Camera cam = Camera::lookAt({0, 1, 5}, {0, 0.5f, 0}, {0, 1, 0}, 0.8f, {40, 30});
    SplatBuilder b;
    b.begin(cam);
    b.add(g, s.mat, {.textureSet = s.set});
    auto exact = renderSplatExact(b.splats(), cam, s.mat, {.window = ReferenceWindow::Exact});
    auto stored = renderSplatExact(b.splats(), cam, s.mat, {.window = ReferenceWindow::Stored});
    ASSERT_TRUE(exact && stored);
    double worst = 0.0;
    for (size_t i = 3; i < exact->pixels.size(); i += 4) worst = std::max(worst, double(std::abs(exact->pixels[i] - stored->pixels[i])));
    // Bilinear sampling of the window between texel centres differs from the
    // exact window by up to |F''| (2R/32)^2 / 8 of F(0) (~4e-3 for CrawfisMax
    // at 32 texels), times d alpha / d detail <= ln 2 * density (~1.3 here).
    EXPECT_LT(worst, 1e-2);
    EXPECT_GT(worst, 0.0) << "the two windows are different approximations";
}

TEST(SplatExact, RejectsAHostImageOfTheWrongSize) {
    Scene s;
    Image bg;
    bg.width = 3;
    bg.height = 3;
    bg.channels = 4;
    bg.pixels.assign(36, 0.0f);
    const Camera cam = Camera::lookAt({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.7f, {4, 4});
    auto r = renderSplatExact({}, cam, s.mat, {.host = {.backgroundImage = &bg}});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), "renderSplatExact: host.backgroundImage is 3x3x4; expected 4x4 with at least 4 channel(s)");
}

TEST(SplatExact, SkipsSplatsWithLayersOrRowsItDoesNotHave) {
    Scene s;
    Splat sp;
    sp.axisU = {1, 0, 0};
    sp.axisV = {0, 1, 0};
    sp.density = 1.0f;
    sp.layer = 99.0f;
    SplatExactStats stats;
    auto r = renderSplatExact({sp}, Camera::lookAt({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.7f, {4, 4}), s.mat, {}, &stats);
    ASSERT_TRUE(r);
    EXPECT_EQ(stats.skippedSplats, 1u);
    EXPECT_EQ(*std::max_element(r->pixels.begin(), r->pixels.end()), 0.0f);
}

} // namespace
} // namespace splatfx
