// Only what the scene calls for, in every system (issue 24 item 4): in the
// mixed scheduling level (tools/bench/mixed_level.hpp: effects, gases,
// clouds, ground fog, fog terms; lit and shadow-casting; a few in view, one
// caster out of view shadowing it) no pixel of the in-view result changes
// when the out-of-view content is removed: the level and a scene holding only
// what the view needs draw the same image, bit for bit, frame after frame.
#include <string>
#include <vector>

#include "gl_fixture.hpp"
#include "mixed_level.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"

using namespace splatfx;

namespace {

class MixedLevelGL : public test::GLTest {};

constexpr int kCount = 80; // 7 in view or casting into it; the rest around, 2 cloud decks and 2 fog layers among them

} // namespace

TEST_F(MixedLevelGL, OutOfViewContentChangesNoPixelInView) {
    Materials m{Footprint{}};
    Scene level, needed;
    ASSERT_TRUE(bench::buildMixedLevel(level, m, kCount, [](int) { return true; }));
    auto fog = Fog::create(bench::mixedFog(kCount));
    ASSERT_TRUE(fog) << fog.error();
    level.setFog(*fog);
    const Camera cam = bench::mixedCamera({160, 120});
    Frame frameLevel, frameNeeded;
    ASSERT_TRUE(level.prepare(0.0, cam, m, frameLevel));
    // The level schedules every kind by the view: the in-view items are drawn, the plume left of
    // the view only casts, the rest cost nothing; far fog terms are dropped.
    for (int i = 0; i < 6; ++i) EXPECT_TRUE(level.status(EffectId(i)).needed) << "item " << i;
    EXPECT_TRUE(level.status(6).castsIntoView) << "the plume out of view shadows it";
    EXPECT_GE(level.counters().castOnly, 1u);
    EXPECT_GT(level.counters().fogTermsSkipped, 0u);
    EXPECT_GT(level.counters().tetrahedra, 0u) << "clouds and ground fog in view";
    std::vector<bool> keep(kCount);
    std::size_t kept = 0;
    for (int i = 0; i < kCount; ++i) kept += keep[std::size_t(i)] = level.status(EffectId(i)).needed || level.status(EffectId(i)).castsIntoView;
    EXPECT_LT(kept, std::size_t(kCount) / 4);
    ASSERT_TRUE(bench::buildMixedLevel(needed, m, kCount, [&](int i) { return bool(keep[std::size_t(i)]); }));
    ASSERT_NE(frameLevel.fog(), nullptr);
    needed.setFog(*Fog::create(frameLevel.fog()->desc()));
    ASSERT_TRUE(needed.setFogCulling({.enabled = false})); // already the kept terms
    ASSERT_TRUE(needed.prepare(0.0, cam, m, frameNeeded));

    auto fb = gl::Framebuffer::create({.width = 160, .height = 120, .color = gl::Precision::F32});
    auto rLevel = gl::FrameRenderer::create();
    auto rNeeded = gl::FrameRenderer::create();
    ASSERT_TRUE(fb && rLevel && rNeeded);
    ASSERT_TRUE(rLevel->upload(m));
    ASSERT_TRUE(rNeeded->upload(m));
    auto draw = [&](gl::FrameRenderer& r, const Frame& f) {
        r.render(f, {.framebuffer = fb->handle(), .drawOpaque = [&] { fb->clear({0.02f, 0.02f, 0.04f, 1.0f}); }});
        return fb->read();
    };
    for (double t : {0.25, 0.5, 1.0}) {
        ASSERT_TRUE(level.prepare(t, cam, m, frameLevel));
        ASSERT_TRUE(needed.prepare(t, cam, m, frameNeeded));
        EXPECT_EQ(frameLevel.splats().size(), frameNeeded.splats().size()) << t;
        EXPECT_EQ(frameLevel.volumes().size(), frameNeeded.volumes().size()) << t;
        ASSERT_TRUE(frameLevel.shadow().valid);
        EXPECT_EQ(frameLevel.shadow().depth, frameNeeded.shadow().depth) << "the scene shadow on the host's surfaces, at " << t;
        const Image a = draw(*rLevel, frameLevel);
        const Image b = draw(*rNeeded, frameNeeded);
        // The same splats, tetrahedra, lit colours and fog reach the same passes: tolerance 0.
        std::size_t lit = 0;
        for (int y = 0; y < 120; ++y)
            for (int x = 0; x < 160; ++x) {
                for (int c = 0; c < 4; ++c) ASSERT_EQ(a.at(x, y, c), b.at(x, y, c)) << "pixel " << x << "," << y << " at t = " << t;
                lit += a.at(x, y, 0) > 0.05f;
            }
        EXPECT_GT(lit, 160u * 120u / 20u) << "the view should show the level's content";
    }
}
