// A level of 1000 preset effects draws (issue 12): its materials hold only
// the distinct sets, fit the GL's layer limit, and the 990 effects out of
// view change no pixel of the frame.
#include <cmath>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

class MaterialsGL : public test::GLTest {};

// The README's scheduling level: fire, steam, smoke, fire-to-smoke in turn,
// each with its own dynamics seed; 10 in front of the camera, the rest far
// away all around it (beyond their 150-unit range or outside the frustum).
Result<Effect> levelEffect(Materials& m, int i) {
    glm::vec3 at{-20.0f + 4.5f * float(i), 0.0f, 0.0f};
    if (i >= 10) {
        const float angle = std::fmod(2.399963f * float(i), 6.2831853f) - 3.1415927f;
        const float r = 200.0f + 200.0f * float(i) / 1000.0f;
        at = {r * std::sin(angle), 0.0f, 40.0f - r * std::cos(angle)};
    }
    const std::uint32_t seed = std::uint32_t(i + 1);
    switch (i % 4) {
    case 0: return presets::fire(m, {.position = at, .seed = seed});
    case 1: return presets::steam(m, {.position = at, .seed = seed});
    case 2: return presets::smoke(m, {.dims = {6, 12, 6}, .position = at, .seed = seed});
    default: return presets::fireToSmoke(m, {.position = at, .seed = seed});
    }
}

Image drawFrame(Scene& scene, const Materials& m, gl::FrameRenderer& r, gl::Framebuffer& fb, const Camera& cam, double t) {
    Frame frame;
    EXPECT_TRUE(scene.prepare(t, cam, m, frame));
    r.render(frame, {.framebuffer = fb.handle(), .drawOpaque = [&] { fb.clear({0, 0, 0, 1}); }});
    return fb.read();
}

} // namespace

TEST_F(MaterialsGL, ThousandEffectLevelDrawsWithOnlyItsDistinctSets) {
    Materials m{Footprint{}};
    Scene level, onlySeen;
    for (int i = 0; i < 1000; ++i) {
        auto e = levelEffect(m, i);
        ASSERT_TRUE(e) << e.error();
        if (i < 10) onlySeen.add(*e, {.name = "seen " + std::to_string(i), .rangeWorld = 150.0f});
        level.add(std::move(*e), {.name = "effect " + std::to_string(i), .rangeWorld = 150.0f});
    }
    // The distinct content: fire (8 textures, contrast 2.5), steam (16),
    // smoke (8, base frequency 2), fire-to-smoke's fire (8) and smoke (8,
    // textureSeed + 1); plus the footprint layer. Tables: fire, steam, smoke.
    EXPECT_EQ(m.setCount(), 5u);
    EXPECT_EQ(m.layerCount(), 1u + 8u + 16u + 8u + 8u + 8u);
    EXPECT_EQ(m.colorTableCount(), 3u);

    auto r = gl::FrameRenderer::create();
    ASSERT_TRUE(r) << r.error();
    const Status up = r->upload(m);
    ASSERT_TRUE(up) << up.error();
    auto fb = gl::Framebuffer::create({.width = 64, .height = 48});
    ASSERT_TRUE(fb) << fb.error();
    const Camera cam = Camera::lookAt({0, 6, 40}, {0, 4, 0}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.1f, 1000.0f);
    Image a, b;
    for (int f = 0; f < 3; ++f) { // a few frames so the smoke solvers have emitted
        a = drawFrame(level, m, *r, *fb, cam, f / 60.0);
        b = drawFrame(onlySeen, m, *r, *fb, cam, f / 60.0);
    }
    EXPECT_EQ(level.counters().needed, 10u);
    ASSERT_GT(level.counters().splats, 0u);
    // Something was drawn: some pixels are well above the black background
    // (an 8-bit target: 1/255 is one step).
    int lit = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) lit += (a.at(x, y, 0) + a.at(x, y, 1) + a.at(x, y, 2)) > 10.0f / 255.0f;
    EXPECT_GT(lit, 64 * 48 / 50) << "the 10 effects in view should cover more than 2% of the frame";
    // The unseen 990 add nothing: the frame equals that of the 10 alone, pixel for pixel.
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_EQ(a.pixels, b.pixels);
}

TEST_F(MaterialsGL, TooManyDistinctLayersNameTheSets) {
    GLint maxLayers = 0;
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
    ASSERT_GT(maxLayers, 0);
    // Distinct 8-layer sets until the limit is passed (small layers: cheap).
    Materials m{Footprint{}, {.layerSize = 4}};
    for (int s = 0; int(m.layerCount()) <= maxLayers; ++s) {
        TextureSet set;
        set.size = 4;
        for (int i = 0; i < 8; ++i) {
            std::vector<float> px(4 * 4 * 4, 1.0f);
            px[3 + 4 * 5] = float(s * 8 + i + 1) / float(8 * maxLayers); // one texel differs per layer
            set.layers.push_back(std::move(px));
        }
        ASSERT_TRUE(m.addTextureSet(set, "generated " + std::to_string(s)));
    }
    auto r = gl::Renderer::create();
    ASSERT_TRUE(r) << r.error();
    const Status up = r->upload(m);
    ASSERT_FALSE(up);
    EXPECT_NE(up.error().find(std::to_string(m.layerCount()) + " texture layers"), std::string::npos) << up.error();
    EXPECT_NE(up.error().find("allows " + std::to_string(maxLayers)), std::string::npos) << up.error();
    EXPECT_NE(up.error().find("set 0 ('generated 0') 8 layers"), std::string::npos) << up.error();
    EXPECT_NE(up.error().find("more sets"), std::string::npos) << up.error();
}
