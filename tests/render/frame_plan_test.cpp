// gl::planFrame: every ordering and fallback decision of a frame, on the CPU
// (no context). Each test is one pass combination the frame renderer can run;
// the GL tests (frame_renderer_gl_test, fragment_lists_gl_test, tetra_gl_test,
// fog_frame_gl_test) check that running those steps draws what the passes draw.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "scenes.hpp"
#include "splatfx/gl/frame_plan.hpp"

using namespace splatfx;
using gl::StepKind;
using gl::StepRange;
using gl::StepTarget;

namespace {

constexpr glm::ivec2 kSize{96, 72};

// The campfire's splats, optionally with two tetrahedra (one far behind the
// fire, one between it and the eye) and a fog.
struct TestFrame {
    Materials materials{Footprint{}};
    std::uint32_t set = materials.addTextureSet(TextureSet::turbulence({.count = 4, .size = 16, .seed = 3}));
    std::uint32_t colours = materials.addColorTable(ColorTable::fire());
    TransferFunction transfer = *TransferFunction::create(
        {{.scalar = 0.0f, .color = {1, 1, 1}, .extinctionPerWorld = 1.0f}, {.scalar = 1.0f, .color = {1, 1, 1}, .extinctionPerWorld = 1.0f}});
    PreIntegrationTable table = *PreIntegrationTable::create(transfer, {.scalarResolution = 4, .lengthResolution = 4});
    Frame frame;

    explicit TestFrame(bool tetrahedra, bool fog = false) {
        const Camera cam = test::campfireCamera(kSize);
        frame.begin(0.0, cam);
        frame.builder().add(test::campfireGrid(3), materials, {.textureSet = set, .colorTable = colours});
        if (tetrahedra) {
            FrameVolume& v = frame.volumes().emplace_back();
            v.table = &table;
            auto tet = [](glm::vec3 c) {
                Tetrahedron t;
                t.position = {c + glm::vec3(-1, -1, -1), c + glm::vec3(1, -1, 1), c + glm::vec3(-1, 1, 1), c + glm::vec3(1, 1, -1)};
                return t;
            };
            v.lod.tets = {tet({0.0f, 4.6f, -40.0f}), tet({0.0f, 4.6f, 10.0f})}; // back to front
        }
        if (fog) {
            FogDesc d;
            d.terms.push_back(FogTerm::constant(0.05));
            frame.setFog(std::make_shared<const Fog>(*Fog::create(d)));
        }
        frame.end();
    }
};

std::vector<StepKind> kinds(const gl::FramePlan& plan) {
    std::vector<StepKind> k;
    for (const gl::PlanStep& s : plan.steps) k.push_back(s.kind);
    return k;
}

std::string show(const gl::FramePlan& plan) {
    std::string out;
    for (const gl::PlanStep& s : plan.steps) out += "  " + gl::describe(s) + "\n";
    return out;
}

const gl::HostDepth kDepth{.texture = 7, .samples = 1, .copied = false, .missing = {}};
void opaque() {}
void transparent() {}

} // namespace

TEST(FramePlan, FullResolutionSplatsAreOneRangeBetweenTheShadowUploadAndUnbind) {
    TestFrame f(false);
    const gl::FramePlan p = gl::planFrame(f.frame, {.framebuffer = 3}, {}, kDepth);
    EXPECT_EQ(kinds(p), (std::vector{StepKind::UploadShadow, StepKind::Splats, StepKind::UnbindShadow})) << show(p);
    EXPECT_EQ(p.steps[1].begin, 0u);
    EXPECT_EQ(p.steps[1].end, f.frame.splats().size());
    EXPECT_EQ(p.target.depthTexture, 7u);
    EXPECT_EQ(p.target.width, kSize.x);
    EXPECT_EQ(p.target.height, kSize.y);
    EXPECT_TRUE(p.steps[1].note.empty());
}

TEST(FramePlan, TheHostsHooksRunBeforeAndAfterTheVolumes) {
    TestFrame f(false);
    const gl::FramePlan p = gl::planFrame(f.frame, {.drawOpaque = opaque, .drawTransparent = transparent}, {}, kDepth);
    EXPECT_EQ(kinds(p),
              (std::vector{StepKind::UploadShadow, StepKind::HostOpaque, StepKind::Splats, StepKind::HostTransparent, StepKind::UnbindShadow}))
        << show(p);
}

TEST(FramePlan, ReducedResolutionDrawsEverySplatInOneReducedPass) {
    TestFrame f(false);
    const gl::FramePlan p = gl::planFrame(f.frame, {.drawOpaque = opaque}, {.resolutionScale = 2}, kDepth);
    EXPECT_EQ(kinds(p), (std::vector{StepKind::UploadShadow, StepKind::HostOpaque, StepKind::ReducedSplats, StepKind::UnbindShadow})) << show(p);
    EXPECT_TRUE(p.reduced);
}

// Splats and tetrahedra in Frame::drawOrder, each batch one step, covering
// every splat and every tetrahedron exactly once.
TEST(FramePlan, TetrahedraInterleaveWithTheSplatsInTheFramesDrawOrder) {
    TestFrame f(true);
    ASSERT_GE(f.frame.drawOrder().size(), 3u) << "the test frame must interleave";
    const gl::FramePlan p = gl::planFrame(f.frame, {}, {.volumeLayer = false}, kDepth);
    ASSERT_GE(p.steps.size(), 2u + f.frame.drawOrder().size());
    EXPECT_EQ(p.steps[1].kind, StepKind::PrepareTetrahedra) << show(p);
    std::size_t splats = 0, tets = 0;
    for (std::size_t i = 0; i < f.frame.drawOrder().size(); ++i) {
        const DrawBatch& b = f.frame.drawOrder()[i];
        const gl::PlanStep& s = p.steps[2 + i];
        EXPECT_EQ(s.kind, b.kind == DrawBatch::Kind::Tetrahedra ? StepKind::Tetrahedra : StepKind::Splats) << show(p);
        EXPECT_EQ(s.begin, b.begin);
        EXPECT_EQ(s.end, b.end);
        EXPECT_EQ(s.target, StepTarget::Host);
        (b.kind == DrawBatch::Kind::Tetrahedra ? tets : splats) += b.end - b.begin;
    }
    EXPECT_EQ(splats, f.frame.splats().size());
    EXPECT_EQ(tets, 2u);
}

// FrameRendererDesc::volumeLayer (the default): at full resolution the same
// batches in the same order, all into the layer, composited once.
TEST(FramePlan, TetrahedraAtFullResolutionGoIntoTheVolumeLayerInTheSameOrder) {
    TestFrame f(true);
    const gl::FramePlan p = gl::planFrame(f.frame, {}, {}, kDepth);
    const std::size_t n = f.frame.drawOrder().size();
    ASSERT_GE(p.steps.size(), 4u + n) << show(p);
    EXPECT_EQ(p.steps[2].kind, StepKind::ReducedBegin) << show(p);
    EXPECT_EQ(p.steps[3 + n].kind, StepKind::ReducedComposite) << show(p);
    EXPECT_FALSE(p.reduced);
    for (std::size_t i = 0; i < n; ++i) {
        const DrawBatch& b = f.frame.drawOrder()[i];
        const gl::PlanStep& s = p.steps[3 + i];
        EXPECT_EQ(s.kind, b.kind == DrawBatch::Kind::Tetrahedra ? StepKind::Tetrahedra : StepKind::Splats) << show(p);
        EXPECT_EQ(s.begin, b.begin);
        EXPECT_EQ(s.end, b.end);
        EXPECT_EQ(s.target, StepTarget::Reduced) << show(p);
    }
    // Without tetrahedra the splats go straight into the host, as before.
    TestFrame splatsOnly(false);
    for (const gl::PlanStep& s : gl::planFrame(splatsOnly.frame, {}, {}, kDepth).steps) EXPECT_NE(s.kind, StepKind::ReducedBegin);
}

// At reduced resolution the splats are composited in one pass: every
// tetrahedron first (full resolution), then the splats; or, with
// reduceTetrahedra, both into the reduced image in one order.
TEST(FramePlan, ReducedResolutionWithTetrahedraEitherDrawsThemFirstOrReducesThemToo) {
    TestFrame f(true);
    const gl::FramePlan apart = gl::planFrame(f.frame, {}, {.resolutionScale = 2}, kDepth);
    std::vector<StepKind> expected{StepKind::UploadShadow, StepKind::PrepareTetrahedra, StepKind::Tetrahedra,
                                   StepKind::Tetrahedra,   StepKind::ReducedSplats,     StepKind::UnbindShadow};
    EXPECT_EQ(kinds(apart), expected) << show(apart);

    const gl::FramePlan together = gl::planFrame(f.frame, {}, {.resolutionScale = 4, .reduceTetrahedra = true}, kDepth);
    ASSERT_EQ(together.steps.size(), 5u + f.frame.drawOrder().size()) << show(together);
    EXPECT_EQ(together.steps[2].kind, StepKind::ReducedBegin);
    EXPECT_EQ(together.steps[3 + f.frame.drawOrder().size()].kind, StepKind::ReducedComposite);
    for (std::size_t i = 0; i < f.frame.drawOrder().size(); ++i) EXPECT_EQ(together.steps[3 + i].target, StepTarget::Reduced) << show(together);
}

TEST(FramePlan, AFogIsDrawnOverTheHostImageRightAfterTheOpaquePass) {
    TestFrame f(false, true);
    const gl::FramePlan p = gl::planFrame(f.frame, {.drawOpaque = opaque}, {}, kDepth);
    EXPECT_EQ(kinds(p), (std::vector{StepKind::UploadShadow, StepKind::HostOpaque, StepKind::HostFog, StepKind::Splats, StepKind::UnbindShadow}))
        << show(p);
    EXPECT_TRUE(p.fogHost);
    EXPECT_NE(p.fog, nullptr);
    EXPECT_TRUE(p.fogNote.empty());
    // FrameRendererDesc::fogHost = false: only the volumes are fogged, and that is no fallback.
    const gl::FramePlan off = gl::planFrame(f.frame, {.drawOpaque = opaque}, {.fogHost = false}, kDepth);
    EXPECT_FALSE(off.fogHost);
    EXPECT_TRUE(off.fogNote.empty());
    EXPECT_NE(off.fog, nullptr);
}

// No host depth to read (none handed over, none that could be copied): the
// host image cannot be fogged, and the plan says so instead of skipping it silently.
TEST(FramePlan, AFogWithoutAHostDepthTextureIsNotedNotSkippedSilently) {
    TestFrame f(false, true);
    const gl::FramePlan p = gl::planFrame(f.frame, {.framebuffer = 0, .drawOpaque = opaque}, {}, {});
    const std::vector<StepKind> k = kinds(p);
    EXPECT_EQ(std::count(k.begin(), k.end(), StepKind::HostFog), 0) << show(p);
    EXPECT_FALSE(p.fogHost);
    EXPECT_NE(p.fogNote.find("no host depth to read"), std::string::npos) << p.fogNote;
    // The frame renderer's reason, when it has one, is the note's.
    const gl::FramePlan why =
        gl::planFrame(f.frame, {.framebuffer = 0, .drawOpaque = opaque}, {}, {.texture = 0, .samples = 0, .copied = false, .missing = "no depth buffer"});
    EXPECT_NE(why.fogNote.find("no depth buffer"), std::string::npos) << why.fogNote;
}

// A window's default framebuffer (or a renderbuffer) is copied into a texture:
// the copy comes after the host has drawn its depth and before anything reads it.
TEST(FramePlan, ACopiedHostDepthIsCopiedAfterTheOpaquePassAndBeforeItIsRead) {
    TestFrame f(false, true);
    const gl::HostDepth copied{.texture = 3, .samples = 0, .copied = true, .missing = {}};
    const gl::FramePlan p = gl::planFrame(f.frame, {.framebuffer = 0, .drawOpaque = opaque}, {}, copied);
    const std::vector<StepKind> k = kinds(p);
    const auto opaqueAt = std::find(k.begin(), k.end(), StepKind::HostOpaque), copyAt = std::find(k.begin(), k.end(), StepKind::CopyHostDepth);
    ASSERT_NE(copyAt, k.end()) << show(p);
    EXPECT_EQ(copyAt, opaqueAt + 1) << show(p);
    EXPECT_TRUE(p.fogHost);
    EXPECT_EQ(p.target.depthTexture, 3u);
    // Without an opaque hook (the host drew before render()) the copy comes before any pass.
    const gl::FramePlan before = gl::planFrame(f.frame, {.framebuffer = 0}, {}, copied);
    const std::vector<StepKind> kb = kinds(before);
    const auto copyBefore = std::find(kb.begin(), kb.end(), StepKind::CopyHostDepth);
    ASSERT_NE(copyBefore, kb.end()) << show(before);
    EXPECT_LT(copyBefore - kb.begin(), std::find(kb.begin(), kb.end(), StepKind::HostFog) - kb.begin()) << show(before);
    // A depth texture the host hands over is never copied.
    const std::vector<StepKind> given = kinds(gl::planFrame(f.frame, {.framebuffer = 0, .drawOpaque = opaque}, {}, kDepth));
    EXPECT_EQ(std::count(given.begin(), given.end(), StepKind::CopyHostDepth), 0);
}

// A multisampled host depth is read one sample at a time: the host fog and
// the splats run once per sample, each after the step that copies that
// sample's depth (and restricts the drawing to it), every pass handed the
// single-sample texture; the last step copies each pixel's nearest sample
// and ends the restriction. Nothing falls back, so nothing is noted.
TEST(FramePlan, AMultisampledHostDepthRunsTheFogAndTheVolumesOncePerSample) {
    TestFrame f(false, true);
    const gl::HostDepth ms{.texture = 9, .samples = 4, .copied = false, .missing = {}, .sampleTexture = 11};
    const gl::FramePlan p = gl::planFrame(f.frame, {.framebuffer = 5, .drawOpaque = opaque}, {}, ms);
    EXPECT_EQ(p.target.depthTexture, 11u);
    EXPECT_EQ(p.samples, 4);
    EXPECT_TRUE(p.fogHost);
    EXPECT_TRUE(p.fogNote.empty()) << p.fogNote;
    std::vector<StepKind> expected{StepKind::UploadShadow, StepKind::HostOpaque};
    for (int s = 0; s < 4; ++s)
        for (StepKind k : {StepKind::HostDepthSample, StepKind::HostFog, StepKind::Splats}) expected.push_back(k);
    for (StepKind k : {StepKind::HostDepthSample, StepKind::UnbindShadow}) expected.push_back(k);
    EXPECT_EQ(kinds(p), expected) << show(p);
    for (int s = 0; s < 4; ++s) EXPECT_EQ(p.steps[2 + 3 * std::size_t(s)].sample, s);
    EXPECT_EQ(p.steps[14].sample, -1);
    for (const gl::PlanStep& s : p.steps) EXPECT_TRUE(s.note.empty()) << show(p);
    // A copied multisampled depth buffer (a window's, a renderbuffer) is copied once, before the first sample.
    const gl::FramePlan c = gl::planFrame(f.frame, {.drawOpaque = opaque}, {}, {.texture = 9, .samples = 8, .copied = true, .missing = {}, .sampleTexture = 11});
    const std::vector<StepKind> kc = kinds(c);
    EXPECT_EQ(kc[2], StepKind::CopyHostDepth) << show(c);
    EXPECT_EQ(std::count(kc.begin(), kc.end(), StepKind::HostDepthSample), 9) << show(c);
}

// Without the texture the samples are read into, no pass is handed the
// multisampled depth: the fog and the depth cut say so.
TEST(FramePlan, AMultisampledHostDepthWithoutASampleTextureIsNeverHandedToAPassAndEveryFallbackIsNoted) {
    TestFrame f(false, true);
    const gl::FramePlan p = gl::planFrame(f.frame, {.framebuffer = 5}, {}, {.texture = 9, .samples = 4, .copied = false, .missing = {}});
    EXPECT_EQ(p.target.depthTexture, 0u);
    EXPECT_EQ(p.samples, 0);
    EXPECT_FALSE(p.fogHost);
    EXPECT_NE(p.fogNote.find("multisampled (4 samples)"), std::string::npos) << p.fogNote;
    const auto splats = std::find_if(p.steps.begin(), p.steps.end(), [](const gl::PlanStep& s) { return s.kind == StepKind::Splats; });
    ASSERT_NE(splats, p.steps.end());
    EXPECT_NE(splats->note.find("depth cut off"), std::string::npos) << show(p);
}

// A list frame on a multisampled host: the splats take the ordered blend
// under the surfaces (drawn per sample; the list sections are per pixel);
// the lists run once, after the per-sample volumes, against each pixel's
// nearest sample, and the step that copies it says so.
TEST(FramePlan, ListFramesOnAMultisampledHostReadTheNearestSampleAndSaySo) {
    TestFrame f(false);
    const gl::FramePlan p = gl::planFrame(f.frame, {.drawTransparent = transparent, .transparentToLists = true}, {},
                                          {.texture = 9, .samples = 4, .copied = false, .missing = {}, .sampleTexture = 11});
    EXPECT_TRUE(p.lists && !p.splatsInLists);
    EXPECT_NE(p.listsNote.find("multisampled host (4 samples)"), std::string::npos) << p.listsNote;
    const std::vector<StepKind> k = kinds(p);
    EXPECT_EQ(std::count(k.begin(), k.end(), StepKind::Splats), 4) << show(p);
    const auto nearest = std::find_if(p.steps.begin(), p.steps.end(), [](const gl::PlanStep& s) { return s.kind == StepKind::HostDepthSample && s.sample == -1; });
    ASSERT_NE(nearest, p.steps.end()) << show(p);
    EXPECT_NE(nearest->note.find("nearest sample"), std::string::npos) << nearest->note;
    EXPECT_LT(nearest - p.steps.begin(), std::find(k.begin(), k.end(), StepKind::ListsCollect) - k.begin()) << show(p);
}

// The order-exact path: surfaces collected, splats split into runs behind,
// between and in front of them; only the middle run is sectioned; the front
// run is drawn after the resolve.
TEST(FramePlan, ListFramesSectionOnlyTheSplatsThatMeetASurface) {
    TestFrame f(false);
    const gl::FramePlan p = gl::planFrame(f.frame, {.drawTransparent = transparent, .transparentToLists = true}, {}, kDepth);
    EXPECT_EQ(kinds(p), (std::vector{StepKind::UploadShadow, StepKind::ListsCollect, StepKind::ListsSplit, StepKind::Splats, StepKind::ListsSections,
                                     StepKind::ListsResolve, StepKind::Splats, StepKind::UnbindShadow}))
        << show(p);
    EXPECT_EQ(p.steps[3].range, StepRange::ListsBehind);
    EXPECT_EQ(p.steps[4].range, StepRange::ListsBetween);
    EXPECT_EQ(p.steps[6].range, StepRange::ListsFront);
    EXPECT_TRUE(p.lists && p.splatsInLists);
    EXPECT_TRUE(p.listsNote.empty());
}

// Fogged sections are not implemented: with a fog the splats that meet a
// surface take the ordinary (ordered) pass before the resolve, and the step says so.
TEST(FramePlan, ListFramesWithAFogDrawTheMeetingSplatsOrderedAndSaySo) {
    TestFrame f(false, true);
    const gl::FramePlan p = gl::planFrame(f.frame, {.drawTransparent = transparent, .transparentToLists = true}, {}, kDepth);
    const std::vector<StepKind> k = kinds(p);
    EXPECT_EQ(std::count(k.begin(), k.end(), StepKind::ListsSections), 0) << show(p);
    const auto ordered =
        std::find_if(p.steps.begin(), p.steps.end(), [](const gl::PlanStep& s) { return s.range == StepRange::ListsBehindAndBetween; });
    ASSERT_NE(ordered, p.steps.end()) << show(p);
    EXPECT_NE(ordered->note.find("fogged sections not implemented"), std::string::npos);
}

// What the lists cannot draw takes the ordered blend under the surfaces, with the reason.
TEST(FramePlan, ListFramesTheSplatsCannotJoinNameTheReason) {
    TestFrame plain(false), clouds(true);
    const gl::HostTarget host{.drawTransparent = transparent, .transparentToLists = true};
    struct Case {
        const Frame& frame;
        gl::FrameRendererDesc desc;
        gl::HostDepth depth;
        const char* reason;
    };
    const Case cases[] = {{plain.frame, {.resolutionScale = 2}, kDepth, "reduced resolution"},
                          {clouds.frame, {}, kDepth, "tetrahedra in the frame"},
                          {plain.frame, {}, {}, "no host depth to read"},
                          {plain.frame, {}, {.texture = 9, .samples = 8, .copied = false, .missing = {}}, "multisampled (8 samples)"}};
    for (const Case& c : cases) {
        const gl::FramePlan p = gl::planFrame(c.frame, host, c.desc, c.depth);
        EXPECT_TRUE(p.lists && !p.splatsInLists) << c.reason;
        EXPECT_NE(p.listsNote.find(c.reason), std::string::npos) << p.listsNote;
        const std::vector<StepKind> k = kinds(p);
        EXPECT_EQ(std::count(k.begin(), k.end(), StepKind::ListsSections), 0) << show(p);
        // The volumes come before the surfaces are collected, and the lists are still resolved.
        const auto collect = std::find(k.begin(), k.end(), StepKind::ListsCollect);
        ASSERT_NE(collect, k.end());
        EXPECT_EQ(std::find(collect, k.end(), StepKind::Splats), k.end()) << show(p);
        EXPECT_NE(std::find(collect, k.end(), StepKind::ListsResolve), k.end()) << show(p);
    }
}

// transparentToLists without a transparent hook: nothing to collect, no list steps.
TEST(FramePlan, ListsWithoutATransparentHookAreNotUsed) {
    TestFrame f(false);
    const gl::FramePlan p = gl::planFrame(f.frame, {.transparentToLists = true}, {}, kDepth);
    EXPECT_FALSE(p.lists);
    EXPECT_EQ(kinds(p), (std::vector{StepKind::UploadShadow, StepKind::Splats, StepKind::UnbindShadow})) << show(p);
}

TEST(FramePlan, DescribeNamesEachStepItsRangeAndItsTarget) {
    EXPECT_EQ(gl::describe({.kind = StepKind::Tetrahedra, .target = StepTarget::Reduced, .volume = 1, .begin = 0, .end = 840}),
              "Tetrahedra volume 1 [0, 840) into the reduced image");
    EXPECT_EQ(gl::describe({.kind = StepKind::Splats, .range = StepRange::ListsFront}), "Splats (in front of every surface)");
}
