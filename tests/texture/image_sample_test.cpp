// TextureSet::sampleImage (King et al. 1999, sec. 4 / Fig. 11), CPU only: each
// texture is one window of the source, whole and in place; the windows are a
// function of the seed; bad input is refused with a message naming it.
#include <gtest/gtest.h>

#include "splatfx/texture_set.hpp"

namespace {

// R and G encode a pixel's position exactly (multiples of 1/64 and 1/32 are
// exact in float), B is constant, so a window is identified by its texels.
splatfx::Image ramp(int w, int h) {
    splatfx::Image img;
    img.width = w;
    img.height = h;
    img.channels = 3;
    img.pixels.resize(std::size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            img.at(x, y, 0) = float(x) / float(w);
            img.at(x, y, 1) = float(y) / float(h);
            img.at(x, y, 2) = 0.5f;
        }
    return img;
}

struct Window {
    int x0, y0;
};

// The window's corner, checked texel by texel to be a whole, unmoved window of `ramp`.
Window windowOf(const std::vector<float>& layer, int size, int w, int h) {
    const int x0 = int(layer[0] * float(w) + 0.5f), y0 = int(layer[1] * float(h) + 0.5f);
    EXPECT_GE(x0, 0);
    EXPECT_GE(y0, 0);
    EXPECT_LE(x0 + size, w);
    EXPECT_LE(y0 + size, h);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const std::size_t p = (std::size_t(y) * size + x) * 4;
            // The values are copied unchanged (in [0, 1], alpha 1): exact equality holds.
            EXPECT_EQ(layer[p + 0], float(x0 + x) / float(w));
            EXPECT_EQ(layer[p + 1], float(y0 + y) / float(h));
            EXPECT_EQ(layer[p + 2], 0.5f);
        }
    return {x0, y0};
}

} // namespace

TEST(ImageSample, EveryTextureIsAWholeWindowOfTheImage) {
    const splatfx::Image img = ramp(64, 32);
    auto set = splatfx::TextureSet::sampleImage(img, {.count = 12, .size = 8, .seed = 5, .keepColor = true});
    ASSERT_TRUE(set) << set.error();
    EXPECT_EQ(set->count(), 12);
    EXPECT_EQ(set->size, 8);
    EXPECT_TRUE(set->color);
    int distinct = 0;
    std::vector<Window> seen;
    for (const auto& layer : set->layers) {
        const Window w = windowOf(layer, 8, 64, 32);
        bool again = false;
        for (const Window& s : seen) again |= s.x0 == w.x0 && s.y0 == w.y0;
        distinct += again ? 0 : 1;
        seen.push_back(w);
    }
    // 57 x 25 possible corners: 12 draws nearly always differ; at least half must.
    EXPECT_GE(distinct, 6);
}

TEST(ImageSample, WindowsFollowTheSeed) {
    const splatfx::Image img = ramp(64, 64);
    auto a = splatfx::TextureSet::sampleImage(img, {.count = 6, .size = 8, .seed = 1, .keepColor = true});
    auto b = splatfx::TextureSet::sampleImage(img, {.count = 6, .size = 8, .seed = 1, .keepColor = true});
    auto c = splatfx::TextureSet::sampleImage(img, {.count = 6, .size = 8, .seed = 2, .keepColor = true});
    ASSERT_TRUE(a && b && c);
    EXPECT_EQ(a->layers, b->layers);
    EXPECT_NE(a->layers, c->layers);
}

TEST(ImageSample, AWindowAsLargeAsTheImageIsTheImage) {
    const splatfx::Image img = ramp(16, 16);
    auto set = splatfx::TextureSet::sampleImage(img, {.count = 3, .size = 16, .keepColor = true});
    ASSERT_TRUE(set) << set.error();
    for (const auto& layer : set->layers) {
        const Window w = windowOf(layer, 16, 16, 16);
        EXPECT_EQ(w.x0, 0);
        EXPECT_EQ(w.y0, 0);
    }
}

TEST(ImageSample, BadInputIsRefusedWithAMessage) {
    const splatfx::Image img = ramp(20, 10);
    auto small = splatfx::TextureSet::sampleImage(img, {.size = 16, .sourceName = "image 'wood.jpg'"});
    ASSERT_FALSE(small);
    EXPECT_EQ(small.error(), "image 'wood.jpg' is 20x10, smaller than the sample size 16");
    auto none = splatfx::TextureSet::sampleImage(img, {.count = 0, .size = 8});
    ASSERT_FALSE(none);
    EXPECT_NE(none.error().find("ImageSampleDesc.count"), std::string::npos) << none.error();
    auto zero = splatfx::TextureSet::sampleImage(img, {.size = 0});
    ASSERT_FALSE(zero);
    EXPECT_NE(zero.error().find("ImageSampleDesc.size"), std::string::npos) << zero.error();
    splatfx::Image broken = img;
    broken.pixels.resize(7);
    auto mismatch = splatfx::TextureSet::sampleImage(broken, {.size = 8});
    ASSERT_FALSE(mismatch);
    EXPECT_NE(mismatch.error().find("the image holds 7 values"), std::string::npos) << mismatch.error();
    // Below the texture-set minimum size: fromImages' own refusal comes through.
    auto tiny = splatfx::TextureSet::sampleImage(img, {.size = 2});
    ASSERT_FALSE(tiny);
    EXPECT_NE(tiny.error().find("outside"), std::string::npos) << tiny.error();
}
