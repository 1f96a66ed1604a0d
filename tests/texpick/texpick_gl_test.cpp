// TexpickGLTest: the preview animation (headless EGL): one full cycle of
// cross-faded textured splats, and the command line writing it into the set.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include "gl_fixture.hpp"
#include "texpick.hpp"

namespace fs = std::filesystem;

namespace {

double meanAbsDiff(const splatfx::Image& a, const splatfx::Image& b) {
    double sum = 0.0;
    for (size_t i = 0; i < a.pixels.size(); ++i) sum += std::abs(a.pixels[i] - b.pixels[i]);
    return sum / double(a.pixels.size());
}

} // namespace

class TexpickGLTest : public splatfx::test::GLTest {};

TEST_F(TexpickGLTest, PreviewCyclesThroughTheSet) {
    const auto set = splatfx::TextureSet::turbulence({.count = 4, .size = 32, .seed = 3});
    auto frames = texpick::renderPreview(set, {.previewSize = 64});
    ASSERT_TRUE(frames) << frames.error();
    ASSERT_EQ(frames->size(), 12u); // 3 frames per texture, one full cycle
    const splatfx::Image& f0 = (*frames)[0];
    EXPECT_EQ(f0.width, 128);
    EXPECT_EQ(f0.height, 64);
    // Splats were drawn in both halves: the centre pixels are brighter than the background (0.02).
    EXPECT_GT(f0.at(32, 32, 0), 0.1f);
    EXPECT_GT(f0.at(96, 32, 0), 0.1f);
    // It animates: the renderer is deterministic, so identical splats give
    // bit-identical frames and any difference comes from the cycling. The
    // loop closes: the step from the last frame back to the first is a
    // regular cross-fade step, no larger than twice the previous one plus one
    // 8-bit level of rounding.
    EXPECT_GT(meanAbsDiff((*frames)[0], (*frames)[3]), 0.0);
    EXPECT_LE(meanAbsDiff((*frames)[11], (*frames)[0]), 2.0 * meanAbsDiff((*frames)[10], (*frames)[11]) + 1.0 / 255.0);
}

TEST_F(TexpickGLTest, CommandLineWritesThePreview) {
    const fs::path dir = fs::path(splatfx::test::outputDir()) / "out";
    fs::remove_all(dir);
    const std::string set = (dir / "turb").string();
    const char* argv[] = {"splatfx-texpick", "turbulence", "--out", set.c_str(), "--count", "4", "--preview-size", "64", "--quiet"};
    auto o = texpick::parseOptions(9, argv);
    ASSERT_TRUE(o) << o.error();
    ASSERT_EQ(texpick::run(*o), 0);
    ASSERT_TRUE(splatfx::loadTextureSet(set));
    auto in = OIIO::ImageInput::open(set + "/preview.gif");
    ASSERT_TRUE(in) << OIIO::geterror();
    EXPECT_EQ(in->spec().width, 128);
    EXPECT_EQ(in->spec().height, 64);
    int subimages = 0;
    while (in->seek_subimage(subimages, 0)) ++subimages;
    EXPECT_EQ(subimages, 12);
}
