// gl::FrameRenderer: the frame's passes in their order, and no change to what the splat pass draws.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "scenes.hpp"

using namespace splatfx;

namespace {

constexpr glm::ivec2 kSize{96, 72};
const glm::vec4 kBackground{0.02f, 0.02f, 0.04f, 1.0f};

struct Fire {
    Materials materials{Footprint{}};
    std::uint32_t set = 0, table = 0;
    Frame frame;
    Fire() {
        set = materials.addTextureSet(TextureSet::turbulence({.count = 8, .size = 32, .seed = 3}));
        table = materials.addColorTable(ColorTable::fire());
        frame.begin(0.0, test::campfireCamera(kSize));
        frame.builder().add(test::campfireGrid(3), materials, {.textureSet = set, .colorTable = table});
        frame.end();
    }
};

class FrameRendererGL : public test::GLTest {};

// The opaque hook: a background and a depth buffer cleared to `depth`.
auto clearTo(glm::vec4 colour, double depth) {
    return [colour, depth] {
        glClearColor(colour.r, colour.g, colour.b, colour.a);
        glClearDepth(depth);
        glDepthMask(GL_TRUE);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    };
}

} // namespace

// At full resolution the frame renderer adds nothing to the splat pass: the
// same splats give the same pixels as gl::Renderer drawing them directly.
TEST_F(FrameRendererGL, FullResolutionDrawsExactlyWhatTheSplatPassDraws) {
    Fire f;
    auto bare = gl::Renderer::create();
    auto framed = gl::FrameRenderer::create();
    ASSERT_TRUE(bare && framed);
    ASSERT_TRUE(bare->upload(f.materials));
    ASSERT_TRUE(framed->upload(f.materials));
    auto a = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    auto b = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    ASSERT_TRUE(a && b);
    a->clear(kBackground);
    bare->draw(f.frame.splats(), f.frame.camera(), {.framebuffer = a->handle(), .width = kSize.x, .height = kSize.y});
    framed->render(f.frame, {.framebuffer = b->handle(), .drawOpaque = clearTo(kBackground, 1.0)});
    const test::ImageDiff d = test::compareImages(b->read(), a->read(), 0.0);
    ASSERT_TRUE(d.sameSize);
    EXPECT_EQ(d.maxAbs, 0.0) << test::writeFailureImages(b->read(), d);
    EXPECT_EQ(framed->stats().splats, f.frame.splats().size());
}

// The opaque pass runs first and its depth cuts the volumes: a depth of 0
// everywhere (geometry at the near plane) hides every splat; a depth of 1
// (nothing drawn) hides none.
TEST_F(FrameRendererGL, OpaquePassRunsFirstAndItsDepthHidesTheVolumes) {
    Fire f;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(f.materials));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    ASSERT_TRUE(fb);
    const glm::vec4 wall{0.1f, 0.5f, 0.9f, 1.0f};
    Frame empty;
    empty.begin(0.0, f.frame.camera());
    empty.end();
    fr->render(empty, {.framebuffer = fb->handle(), .drawOpaque = clearTo(wall, 1.0)});
    const Image wallAlone = fb->read(); // the wall as this framebuffer stores it (8-bit)
    fr->render(f.frame, {.framebuffer = fb->handle(), .drawOpaque = clearTo(wall, 0.0)});
    const Image hidden = fb->read();
    fr->render(f.frame, {.framebuffer = fb->handle(), .drawOpaque = clearTo(wall, 1.0)});
    const Image shown = fb->read();
    double hiddenChange = 0.0, shownChange = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            hiddenChange = std::max(hiddenChange, double(std::abs(hidden.at(x, y, 0) - wallAlone.at(x, y, 0))));
            shownChange = std::max(shownChange, double(std::abs(shown.at(x, y, 0) - wallAlone.at(x, y, 0))));
        }
    EXPECT_EQ(hiddenChange, 0.0) << "splats were drawn in front of geometry at the near plane";
    EXPECT_GT(shownChange, 0.2) << "with nothing in front the fire must show over the wall";
}

// The transparent pass runs after the volumes: when it is called, the fire is
// already in the framebuffer.
TEST_F(FrameRendererGL, TransparentPassRunsAfterTheVolumes) {
    Fire f;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(f.materials));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    ASSERT_TRUE(fb);
    std::vector<float> seen(std::size_t(kSize.x) * kSize.y * 4, 0.0f);
    bool called = false;
    fr->render(f.frame, {.framebuffer = fb->handle(), .drawOpaque = clearTo(kBackground, 1.0), .drawTransparent = [&] {
                             called = true;
                             glReadPixels(0, 0, kSize.x, kSize.y, GL_RGBA, GL_FLOAT, seen.data());
                         }});
    ASSERT_TRUE(called);
    float brightest = 0.0f;
    for (std::size_t i = 0; i < seen.size(); i += 4) brightest = std::max(brightest, seen[i]);
    EXPECT_GT(brightest, 0.2f) << "the volumes had not been drawn when the transparent pass ran";
}

// Reduced resolution is the depth-aware ScaledRenderer, chosen by one field.
TEST_F(FrameRendererGL, ReducedResolutionIsTheScaledSplatPass) {
    Fire f;
    auto scaled = gl::ScaledRenderer::create({.scale = 2});
    auto framed = gl::FrameRenderer::create({.resolutionScale = 2});
    ASSERT_TRUE(scaled && framed);
    ASSERT_TRUE(scaled->upload(f.materials));
    ASSERT_TRUE(framed->upload(f.materials));
    auto a = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    auto b = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    ASSERT_TRUE(a && b);
    a->clear(kBackground);
    scaled->draw(f.frame.splats(), f.frame.camera(), {.framebuffer = a->handle(), .width = kSize.x, .height = kSize.y});
    framed->render(f.frame, {.framebuffer = b->handle(), .drawOpaque = clearTo(kBackground, 1.0)});
    const test::ImageDiff d = test::compareImages(b->read(), a->read(), 0.0);
    EXPECT_EQ(d.maxAbs, 0.0) << test::writeFailureImages(b->read(), d);
    EXPECT_EQ(framed->stats().resolutionScale, 2);
}

TEST_F(FrameRendererGL, RejectsAResolutionScaleItCannotDraw) {
    auto fr = gl::FrameRenderer::create({.resolutionScale = 3});
    ASSERT_FALSE(fr);
    EXPECT_NE(fr.error().find("FrameRendererDesc::resolutionScale must be 1, 2 or 4, got 3"), std::string::npos) << fr.error();
}

// A Scene's frame: one effect drawn traditional by its own options, another
// textured, both in one sorted list, drawn through the frame renderer.
TEST_F(FrameRendererGL, SceneFrameDrawsEachEffectItsOwnWay) {
    Materials m{Footprint{}};
    Scene scene;
    auto a = presets::fire(m, {.dims = {5, 10, 5}});
    auto b = presets::fire(m, {.dims = {5, 10, 5}, .position = {6, 0, 0}});
    ASSERT_TRUE(a && b);
    const EffectId textured = scene.add(std::move(*a), {.name = "textured"});
    const EffectId plain = scene.add(std::move(*b), {.name = "plain", .draw = {.textured = false}});
    const Camera cam = Camera::lookAt({3, 3, 18}, {3, 3, 0}, {0, 1, 0}, 0.9f, kSize);
    Frame frame;
    EXPECT_TRUE(scene.prepare(0.25, cam, m, frame));
    ASSERT_EQ(frame.counters().needed, 2u);
    EXPECT_EQ(frame.counters().drawn, 2u);
    std::uint64_t plainLayers = 0;
    for (const Splat& s : frame.splats()) plainLayers += s.layer == 0 ? 1 : 0; // layer 0: the plain footprint
    EXPECT_EQ(plainLayers, scene.status(plain).splatsDrawn) << "only the traditional effect draws the plain footprint";
    EXPECT_GT(scene.status(textured).splatsDrawn, 0u);
    for (std::size_t i = 1; i < frame.splats().size(); ++i)
        ASSERT_GE(frame.splats()[i - 1].depth, frame.splats()[i].depth) << "one back-to-front order across effects";
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(m));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    ASSERT_TRUE(fb);
    fr->render(frame, {.framebuffer = fb->handle(), .drawOpaque = clearTo(kBackground, 1.0)});
    EXPECT_EQ(fr->stats().splats, frame.splats().size());
}

// Its GL objects are names in the context it was created in: with another
// context current it makes no GL call (upload fails, render draws nothing and
// says why in stats().notes), and a hook that makes another context current
// ends the frame there instead of drawing into that context's objects.
TEST_F(FrameRendererGL, AnotherContextCurrentIsRefusedAndNoted) {
    Fire f;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(f.materials));
    ASSERT_TRUE(fr->checkContext());
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    ASSERT_TRUE(fb);
    {
        auto other = HeadlessContext::create(); // current from here
        ASSERT_TRUE(other) << other.error();
        const Status wrong = fr->checkContext();
        ASSERT_FALSE(wrong);
        EXPECT_NE(wrong.error().find("is not the one it was created in"), std::string::npos) << wrong.error();
        const Status upload = fr->upload(f.materials);
        EXPECT_FALSE(upload);
        fr->render(f.frame, {.framebuffer = fb->handle()});
        ASSERT_EQ(fr->stats().notes.size(), 1u);
        EXPECT_EQ(fr->stats().notes[0], "frame not drawn: " + wrong.error());
        EXPECT_EQ(fr->stats().drawCalls, 0u);
        EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR)); // nothing reached this context
        // Back in its own context, a hook that switches to the other one: the frame stops after the hook.
        SetUp();
        fr->render(f.frame, {.framebuffer = fb->handle(), .drawOpaque = [&] { other->makeCurrent(); }});
        ASSERT_FALSE(fr->stats().notes.empty());
        EXPECT_NE(fr->stats().notes.back().find("frame cut short after the host's opaque hook"), std::string::npos) << fr->stats().notes.back();
        EXPECT_EQ(fr->stats().drawCalls, 0u);
        EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
    } // `other` destroyed while current: none is current after it
    SetUp();
    fr->render(f.frame, {.framebuffer = fb->handle(), .drawOpaque = clearTo(kBackground, 1.0)});
    EXPECT_TRUE(fr->stats().notes.empty());
    EXPECT_GT(fr->stats().drawCalls, 0u);
}
