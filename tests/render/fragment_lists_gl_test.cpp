// (issue 15) The order-exact transparency path: host surfaces through
// transparentGlsl() (the docs/integration.md snippet), splats sorted among
// them per pixel, the fragment budget and its overflow, and the hard cases.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "scenes.hpp"
#include "splatfx/transparency.hpp"
#include "transparent_glass.hpp"

using namespace splatfx;
using splatfx::test::Glass;
using splatfx::test::Pane;

namespace {

constexpr glm::ivec2 kSize{96, 72};
const glm::vec4 kBackground{0.02f, 0.02f, 0.04f, 1.0f};

struct Fire {
    Materials materials{Footprint{}};
    Frame frame;
    Fire() {
        const std::uint32_t set = materials.addTextureSet(TextureSet::turbulence({.count = 8, .size = 32, .seed = 3}));
        const std::uint32_t table = materials.addColorTable(ColorTable::fire());
        frame.begin(0.0, test::campfireCamera(kSize));
        frame.builder().add(test::campfireGrid(3), materials, {.textureSet = set, .colorTable = table});
        frame.end();
    }
    // The fire's z extent in world space (campfireGrid: 5 cells of 0.5, centred at 0).
    static constexpr float kFront = 1.25f, kBack = -1.25f;
};

auto clearTo(glm::vec4 colour) {
    return [colour] {
        glClearColor(colour.r, colour.g, colour.b, colour.a);
        glClearDepth(1.0);
        glDepthMask(GL_TRUE);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    };
}

glm::vec4 over(glm::vec4 front, glm::vec4 back) { return front + (1.0f - front.a) * back; }

// Readback is 8-bit (gl::Framebuffer's default RGBA8): one half step of
// rounding per read, and the list stores premultiplied colours as halves
// (relative error 2^-11, below 1/255 for values <= 1).
constexpr double kEightBit = 1.0 / 255.0;

// The splats' sections are composited in RGBA16F targets and the resolve
// writes RGBA16F: every blend rounds each channel (<= 1) by at most half an
// ulp, 2^-12, and later blends only attenuate earlier errors (factor <= 1),
// so a pixel with m splat fragments differs from an F32 ordered blend by at
// most (m + 2) 2^-12 (+2: the resolve's image and the surface's half colour).
// m is the most fragments on one pixel, from the reference's count.
double halfTolerance(const Frame& frame, const Materials& materials) {
    SplatExactStats st;
    auto ref = renderSplatExact(frame.splats(), frame.camera(), materials, {.threads = 2}, &st);
    return ref ? double(st.maxOverlap + 2) * std::ldexp(1.0, -12) : 0.0;
}

class FragmentListsGL : public test::GLTest {};

} // namespace

// The frame flags the path: without transparentToLists (or with no hook) the
// frame is today's ordered blend, pixel for pixel and with no list stats.
TEST_F(FragmentListsGL, WithoutTransparentSurfacesTheFrameTakesTheOrderedPath) {
    Fire f;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(f.materials));
    auto a = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    auto b = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    ASSERT_TRUE(a && b);
    fr->render(f.frame, {.framebuffer = a->handle(), .drawOpaque = clearTo(kBackground)});
    fr->render(f.frame, {.framebuffer = b->handle(), .drawOpaque = clearTo(kBackground), .transparentToLists = true});
    EXPECT_FALSE(fr->stats().lists.used);
    const test::ImageDiff d = test::compareImages(b->read(), a->read(), 0.0);
    EXPECT_EQ(d.maxAbs, 0.0) << test::writeFailureImages(b->read(), d);
}

// A pane wholly in front of the fire gives what the ordered blend gives (the
// pane after the splats); wholly behind, what drawing the pane first gives.
// Both orders are unambiguous, so the lists must reproduce them.
TEST_F(FragmentListsGL, PanesInFrontOfAndBehindTheFireSortLikeTheUnambiguousOrder) {
    Fire f;
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(f.materials));
    auto lists = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    auto ordered = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(lists && ordered);
    const double tol = halfTolerance(f.frame, f.materials);
    ASSERT_GT(tol, 0.0);
    const Camera& cam = f.frame.camera();
    const glm::vec4 tint{0.05f, 0.15f, 0.2f, 0.35f};
    // A blending copy of the pane for the ordered reference: the snippet's
    // shader with no lists bound would be undefined, so draw it through the
    // lists path with an empty frame instead (pane over whatever is there).
    Frame empty;
    empty.begin(0.0, cam);
    empty.end();
    for (const float z : {Fire::kFront + 2.0f, Fire::kBack - 2.0f}) {
        const bool inFront = z > 0.0f;
        const std::vector<Pane> pane{{.z = z, .premultiplied = tint}};
        fr->render(f.frame, {.framebuffer = lists->handle(),
                             .drawOpaque = clearTo(kBackground),
                             .drawTransparent = [&] { glass.draw(pane, cam); },
                             .transparentToLists = true});
        EXPECT_TRUE(fr->stats().lists.used && fr->stats().lists.splats);
        EXPECT_EQ(fr->stats().lists.fallback, 0u);
        EXPECT_EQ(fr->stats().lists.overflowPixels, 0u);
        EXPECT_GE(fr->stats().lists.nodes, std::uint64_t(kSize.x) * kSize.y); // the pane covers every pixel
        const Image got = lists->read();
        // Every splat lies wholly behind (or in front of) the pane: none
        // needs a section; all take the ordinary splat pass, before (after)
        // the resolve (FragmentListPass::split).
        EXPECT_EQ(fr->stats().lists.sections, 0);
        EXPECT_EQ(fr->stats().lists.splatsSectioned, 0u);
        EXPECT_EQ(inFront ? fr->stats().lists.splatsBehind : fr->stats().lists.splatsFront, f.frame.splats().size());
        if (inFront) {
            fr->render(f.frame, {.framebuffer = ordered->handle(), .drawOpaque = clearTo(kBackground)});
            fr->render(empty, {.framebuffer = ordered->handle(), .drawTransparent = [&] { glass.draw(pane, cam); }, .transparentToLists = true});
        } else {
            fr->render(empty, {.framebuffer = ordered->handle(),
                               .drawOpaque = clearTo(kBackground),
                               .drawTransparent = [&] { glass.draw(pane, cam); },
                               .transparentToLists = true});
            fr->render(f.frame, {.framebuffer = ordered->handle()});
        }
        // F32 targets: the two differ only by the sections' half rounding.
        const test::ImageDiff d = test::compareImages(got, ordered->read(), tol);
        EXPECT_LE(d.maxAbs, tol) << (inFront ? "in front: " : "behind: ") << test::writeFailureImages(got, d);
    }
}

// The engines' depth conventions (issue 26): the lists sort by a key that
// grows with distance in every convention (1 - depth reversed), the sections
// cut at it and the hook's test follows the convention. Three panes drawn out
// of order around and through the fire: the same 8-bit image in all four
// conventions (reversed ones with float depth) as in OpenGL's default. Each
// channel is rounded to 1/255 on readback; the conventions differ only in the
// depths' last bits, which can move a value across one rounding boundary:
// one step, never two.
TEST_F(FragmentListsGL, PanesAroundTheFireAreTheSameInAllFourConventions) {
    const DepthConvention conventions[] = {
        {}, {.clip = ClipDepth::ZeroToOne}, {.reversed = true}, {.clip = ClipDepth::ZeroToOne, .reversed = true}};
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    const std::vector<Pane> panes{{.z = Fire::kBack - 1.0f, .premultiplied = {0.02f, 0.1f, 0.05f, 0.3f}},
                                  {.z = Fire::kFront + 1.5f, .premultiplied = {0.05f, 0.15f, 0.2f, 0.35f}},
                                  {.z = 0.1f, .premultiplied = {0.1f, 0.05f, 0.02f, 0.25f}}};
    Image base;
    for (const DepthConvention& dc : conventions) {
        Materials materials{Footprint{}};
        const std::uint32_t set = materials.addTextureSet(TextureSet::turbulence({.count = 8, .size = 32, .seed = 3}));
        const std::uint32_t table = materials.addColorTable(ColorTable::fire());
        const Camera cam = Camera::lookAt({0.0f, 4.8f, 15.0f}, {0.0f, 4.6f, 0.0f}, {0, 1, 0}, 0.7853982f, kSize, 0.05f, 1000.0f, dc);
        Frame frame;
        frame.begin(0.0, cam);
        frame.builder().add(test::campfireGrid(3), materials, {.textureSet = set, .colorTable = table});
        frame.end();
        auto fr = gl::FrameRenderer::create();
        ASSERT_TRUE(fr && fr->upload(materials));
        auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .floatDepth = dc.reversed});
        ASSERT_TRUE(fb);
        glClipControl(GL_LOWER_LEFT, dc.clip == ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
        fr->render(frame, {.framebuffer = fb->handle(),
                           .drawOpaque =
                               [&] {
                                   glClearColor(kBackground.r, kBackground.g, kBackground.b, kBackground.a);
                                   glClearDepth(dc.farWindow());
                                   glDepthMask(GL_TRUE);
                                   glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                                   glClearDepth(1.0);
                               },
                           .drawTransparent = [&] { glass.draw(panes, cam); },
                           .transparentToLists = true});
        glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        EXPECT_TRUE(fr->stats().notes.empty()) << fr->stats().notes.front();
        EXPECT_TRUE(fr->stats().lists.used && fr->stats().lists.splats);
        EXPECT_GT(fr->stats().lists.splatsSectioned, 0u) << "the middle pane must cut the fire into sections";
        const Image got = fb->read();
        if (base.pixels.empty()) {
            base = got;
            continue;
        }
        const test::ImageDiff d = test::compareImages(got, base, 0.5 / 255.0);
        std::printf("%s: max %.1f/255, mean %.4f/255\n", describe(dc).c_str(), d.maxAbs * 255, d.meanAbs * 255);
        EXPECT_LE(d.maxAbs, kEightBit + 1e-6) << describe(dc) << " -- " << test::writeFailureImages(got, d);
    }
}

// Three panes at once, drawn out of depth order: one in front of the fire,
// two behind it: each splat finds its section from the surfaces of its pixel
// (two sections in use need the 4-target variant). Against the ordered blend
// in the unambiguous order (both far panes, the fire, the front pane).
TEST_F(FragmentListsGL, ThreePanesAroundTheFireSortPerSplat) {
    Fire f;
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(f.materials));
    auto lists = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    auto ordered = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(lists && ordered);
    const double tol = halfTolerance(f.frame, f.materials) + 3 * std::ldexp(1.0, -12); // + three half pane colours
    const Camera& cam = f.frame.camera();
    const std::vector<Pane> panes{{.z = Fire::kBack - 3.0f, .premultiplied = glm::vec4(0.2f, 0.05f, 0.0f, 0.3f)},
                                  {.z = Fire::kFront + 2.0f, .premultiplied = glm::vec4(0.0f, 0.1f, 0.2f, 0.35f)},
                                  {.z = Fire::kBack - 1.0f, .premultiplied = glm::vec4(0.05f, 0.2f, 0.05f, 0.25f)}};
    fr->render(f.frame, {.framebuffer = lists->handle(),
                         .drawOpaque = clearTo(kBackground),
                         .drawTransparent = [&] { glass.draw(panes, cam); },
                         .transparentToLists = true});
    EXPECT_TRUE(fr->stats().lists.splats);
    EXPECT_EQ(fr->stats().lists.sections, 4);
    const Image got = lists->read();
    Frame empty;
    empty.begin(0.0, cam);
    empty.end();
    fr->render(empty, {.framebuffer = ordered->handle(),
                       .drawOpaque = clearTo(kBackground),
                       .drawTransparent =
                           [&] {
                               glass.draw({panes[0], panes[2]}, cam);
                           },
                       .transparentToLists = true});
    fr->render(f.frame, {.framebuffer = ordered->handle()});
    fr->render(empty, {.framebuffer = ordered->handle(), .drawTransparent = [&] { glass.draw({panes[1]}, cam); }, .transparentToLists = true});
    const test::ImageDiff d = test::compareImages(got, ordered->read(), tol);
    EXPECT_LE(d.maxAbs, tol) << test::writeFailureImages(got, d);
}

// 64 layers on every pixel, drawn in a scrambled order: the resolve sorts them
// (closed form: front-to-back "over" of the 64 colours by depth). With a
// budget of 8 the pool (8 per pixel) fills: the other 56 layers of each pixel
// are blended directly and counted, never dropped; alpha is still exact (the
// product of (1 - a_i) does not depend on the order) and colour within [0, 1].
TEST_F(FragmentListsGL, SixtyFourLayersOnOnePixel) {
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    const Camera cam = test::campfireCamera(kSize);
    std::vector<Pane> panes;
    for (int i = 0; i < 64; ++i) {
        const int k = (i * 37) % 64; // a permutation of 0..63: drawn out of depth order
        const float a = 0.05f + 0.01f * float(k % 7);
        const glm::vec3 c{0.5f + 0.5f * std::sin(float(k)), 0.5f + 0.5f * std::cos(float(k) * 1.3f), float(k) / 63.0f};
        panes.push_back({.z = 5.0f - 0.15f * float(k), .premultiplied = glm::vec4(c * a, a)});
    }
    std::vector<Pane> sorted = panes; // front (largest z: nearest the eye at z = 15) first
    std::sort(sorted.begin(), sorted.end(), [](const Pane& a, const Pane& b) { return a.z > b.z; });
    glm::vec4 expect = kBackground;
    for (auto it = sorted.rbegin(); it != sorted.rend(); ++it) expect = over(it->premultiplied, expect);
    Frame empty;
    empty.begin(0.0, cam);
    empty.end();
    Materials materials{Footprint{}};
    materials.addTextureSet(TextureSet::turbulence({.count = 1, .size = 16, .seed = 1}));
    const std::uint64_t pixels = std::uint64_t(kSize.x) * kSize.y;
    for (const int budget : {72, 8}) {
        auto fr = gl::FrameRenderer::create({.fragmentsPerPixel = budget});
        ASSERT_TRUE(fr && fr->upload(materials));
        auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
        ASSERT_TRUE(fb);
        fr->render(empty, {.framebuffer = fb->handle(),
                           .drawOpaque = clearTo(kBackground),
                           .drawTransparent = [&] { glass.draw(panes, cam); },
                           .transparentToLists = true});
        const Image img = fb->read();
        const gl::FrameRenderStats& s = fr->stats();
        double maxErr = 0.0, maxAlphaErr = 0.0;
        bool sane = true;
        for (int y = 0; y < kSize.y; ++y)
            for (int x = 0; x < kSize.x; ++x) {
                for (int ch = 0; ch < 4; ++ch) {
                    const double v = img.at(x, y, ch);
                    sane = sane && std::isfinite(v) && v >= 0.0 && v <= 1.0;
                    maxErr = std::max(maxErr, std::abs(v - double(expect[ch])));
                }
                maxAlphaErr = std::max(maxAlphaErr, std::abs(double(img.at(x, y, 3)) - double(expect.a)));
            }
        EXPECT_TRUE(sane);
        // Half-float colours: each of 64 layers rounds its premultiplied
        // colour (<= 0.11) by at most 2^-11 relative: 64 * 0.11 * 2^-11 < 0.0035;
        // plus one 8-bit step of the readback.
        const double tol = kEightBit + 64 * 0.11 * std::ldexp(1.0, -11);
        EXPECT_LE(maxAlphaErr, tol) << budget;
        EXPECT_EQ(s.lists.nodes + s.lists.fallback, 64 * pixels) << budget; // every fragment stored or blended
        if (budget >= 64) {
            EXPECT_LE(maxErr, tol) << test::writeFailureImages(img, test::compareImages(img, img, 0.0));
            EXPECT_EQ(s.lists.fallback, 0u);
            EXPECT_EQ(s.lists.overflowPixels, 0u);
            EXPECT_EQ(s.lists.maxSurfaces, 64u);
        } else {
            // The pool is shared: it fills after 8 per pixel on average, some
            // pixels holding more than 8 (those merge their farthest).
            EXPECT_EQ(s.lists.nodes, pixels * std::uint64_t(budget));
            EXPECT_EQ(s.lists.fallback, pixels * std::uint64_t(64 - budget));
        }
    }
}

// More nodes on a pixel than its budget while the pool has room: 16 small
// panes over the image centre with a budget of 4 per pixel. The centre pixel
// keeps 3 nodes exactly and merges the rest into its farthest slot: counted,
// alpha exact, colour within [0, 1].
TEST_F(FragmentListsGL, MorePixelNodesThanTheBudgetMergeTheFarthest) {
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    Camera cam = test::campfireCamera(kSize);
    cam = Camera::lookAt({0.0f, 0.0f, 15.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, 0.7853982f, kSize);
    std::vector<Pane> panes;
    double transmit = 1.0;
    for (int i = 0; i < 16; ++i) {
        const int k = (i * 5) % 16;
        const float a = 0.1f + 0.02f * float(k % 5);
        panes.push_back({.z = 2.0f - 0.2f * float(k),
                         .premultiplied = glm::vec4(0.3f * a, 0.6f * a, float(k) / 15.0f * a, a),
                         .half = 1.0f,
                         .centre = {0.0f, 0.0f}});
        transmit *= 1.0 - double(a);
    }
    Frame empty;
    empty.begin(0.0, cam);
    empty.end();
    Materials materials{Footprint{}};
    materials.addTextureSet(TextureSet::turbulence({.count = 1, .size = 16, .seed = 1}));
    auto fr = gl::FrameRenderer::create({.fragmentsPerPixel = 4});
    ASSERT_TRUE(fr && fr->upload(materials));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    ASSERT_TRUE(fb);
    fr->render(empty, {.framebuffer = fb->handle(),
                       .drawOpaque = clearTo(glm::vec4(0.0f)),
                       .drawTransparent = [&] { glass.draw(panes, cam); },
                       .transparentToLists = true});
    const gl::FrameRenderStats& s = fr->stats();
    EXPECT_EQ(s.lists.fallback, 0u);
    EXPECT_GT(s.lists.overflowPixels, 0u);
    EXPECT_GE(s.lists.mergedNodes, 12u * s.lists.overflowPixels / 2); // most overflowing pixels hold all 16
    const Image img = fb->read();
    const int cx = kSize.x / 2, cy = kSize.y / 2;
    EXPECT_NEAR(img.at(cx, cy, 3), 1.0 - transmit, kEightBit + 16 * std::ldexp(1.0, -11));
    for (int ch = 0; ch < 3; ++ch) EXPECT_TRUE(img.at(cx, cy, ch) >= 0.0f && img.at(cx, cy, ch) <= 1.0f);
}

// A zero surface stores nothing and changes nothing; a fully opaque surface
// in front of the fire hides it (the pane's colour exactly); behind the fire
// the fire composites over it.
TEST_F(FragmentListsGL, ZeroAlphaAndFullyOpaqueSurfaces) {
    Fire f;
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(f.materials));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    auto plain = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fb && plain);
    const double tol = halfTolerance(f.frame, f.materials);
    ASSERT_GT(tol, 0.0);
    const Camera& cam = f.frame.camera();
    fr->render(f.frame, {.framebuffer = plain->handle(), .drawOpaque = clearTo(kBackground)});
    const Image fire = plain->read();

    std::vector<Pane> zero{{.z = 0.0f, .premultiplied = glm::vec4(0.0f)}};
    fr->render(f.frame, {.framebuffer = fb->handle(),
                         .drawOpaque = clearTo(kBackground),
                         .drawTransparent = [&] { glass.draw(zero, cam); },
                         .transparentToLists = true});
    EXPECT_EQ(fr->stats().lists.nodes, 0u); // nothing stored
    test::ImageDiff d = test::compareImages(fb->read(), fire, tol);
    EXPECT_LE(d.maxAbs, tol) << "zero pane changed the image: " << test::writeFailureImages(fb->read(), d);

    const glm::vec4 wall{0.7f, 0.2f, 0.1f, 1.0f};
    std::vector<Pane> front{{.z = Fire::kFront + 1.0f, .premultiplied = wall}};
    fr->render(f.frame, {.framebuffer = fb->handle(),
                         .drawOpaque = clearTo(kBackground),
                         .drawTransparent = [&] { glass.draw(front, cam); },
                         .transparentToLists = true});
    const Image hidden = fb->read();
    double worst = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x)
            for (int ch = 0; ch < 4; ++ch) worst = std::max(worst, std::abs(double(hidden.at(x, y, ch)) - double(wall[ch])));
    EXPECT_LE(worst, std::ldexp(1.0, -10)) << "an opaque pane in front must hide the fire"; // the pane's half colour

    std::vector<Pane> back{{.z = Fire::kBack - 1.0f, .premultiplied = wall}};
    fr->render(f.frame, {.framebuffer = fb->handle(),
                         .drawOpaque = clearTo(kBackground),
                         .drawTransparent = [&] { glass.draw(back, cam); },
                         .transparentToLists = true});
    const Image behind = fb->read();
    // The fire over the wall: the ordered blend of the fire over an opaque clear of the wall's colour.
    fr->render(f.frame, {.framebuffer = plain->handle(), .drawOpaque = clearTo(wall)});
    d = test::compareImages(behind, plain->read(), tol);
    EXPECT_LE(d.maxAbs, tol) << "fire over an opaque pane behind it: " << test::writeFailureImages(behind, d);
}

// A budget of one node per pixel with two panes over the whole image, one
// through the middle of the fire and one behind it: the pool holds one node per
// pixel, and every fragment that finds it full is blended by the include at
// once (counted, never dropped); the splats need no nodes. Which pane a pixel's
// node goes to depends on the order the GPU runs fragments in (the pool is one
// counter for the whole image), but the pane drawn first (through the fire)
// takes the nodes of at least the first tiles run, so some splats are cut into
// sections whatever that order. The image stays sane: finite, in [0, 1], and
// its alpha is the exact alpha of fire and both panes (the product of
// transmittances does not depend on the order).
TEST_F(FragmentListsGL, BudgetOfOneFragmentPerPixel) {
    Fire f;
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    auto fr = gl::FrameRenderer::create({.fragmentsPerPixel = 1});
    ASSERT_TRUE(fr && fr->upload(f.materials));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    auto ordered = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fb && ordered);
    const double tol = halfTolerance(f.frame, f.materials);
    const Camera& cam = f.frame.camera();
    const std::vector<Pane> panes{{.z = 0.0f, .premultiplied = glm::vec4(0.05f, 0.1f, 0.15f, 0.3f)},
                                  {.z = Fire::kBack - 1.0f, .premultiplied = glm::vec4(0.2f, 0.1f, 0.0f, 0.4f)}};
    const glm::vec4 clear{0.0f};
    fr->render(
        f.frame,
        {.framebuffer = fb->handle(), .drawOpaque = clearTo(clear), .drawTransparent = [&] { glass.draw(panes, cam); }, .transparentToLists = true});
    const gl::FrameRenderStats s = fr->stats();
    const std::uint64_t pixels = std::uint64_t(kSize.x) * kSize.y;
    EXPECT_EQ(s.lists.nodes, pixels);
    EXPECT_EQ(s.lists.fallback, pixels);
    EXPECT_GE(s.lists.sections, 2);
    // Pool, heads and counts, the resolved RGBA16F image, the section targets,
    // the sorted depths (R32F, one layer fewer than sections), the counters.
    EXPECT_EQ(s.lists.bytes,
              std::size_t(pixels) * (kTransparentNodeBytes + kTransparentHeadBytesPerPixel + 8 +
                                     std::size_t(s.lists.sections) * kTransparentSectionBytesPerPixel + 4 * std::size_t(s.lists.sections - 1)) +
                  48 +
                  (16 + 4) * std::size_t((kSize.x + 15) / 16) *
                      std::size_t((kSize.y + 15) / 16)); // + per 16 x 16 tile the survey (RGBA32UI) and, with sections, the host depth (R32F)
    const Image got = fb->read();
    // The alpha of the three in any order: the blend of pane, fire, pane.
    Frame empty;
    empty.begin(0.0, cam);
    empty.end();
    auto one = gl::FrameRenderer::create({.fragmentsPerPixel = 1});
    ASSERT_TRUE(one && one->upload(f.materials));
    one->render(empty, {.framebuffer = ordered->handle(),
                        .drawOpaque = clearTo(clear),
                        .drawTransparent = [&] { glass.draw({panes[1]}, cam); },
                        .transparentToLists = true});
    one->render(f.frame, {.framebuffer = ordered->handle()});
    one->render(empty, {.framebuffer = ordered->handle(), .drawTransparent = [&] { glass.draw({panes[0]}, cam); }, .transparentToLists = true});
    const Image want = ordered->read();
    bool sane = true;
    double alphaErr = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            for (int ch = 0; ch < 4; ++ch) sane = sane && std::isfinite(got.at(x, y, ch)) && got.at(x, y, ch) >= 0.0f && got.at(x, y, ch) <= 1.0f;
            alphaErr = std::max(alphaErr, std::abs(double(got.at(x, y, 3)) - double(want.at(x, y, 3))));
        }
    EXPECT_TRUE(sane);
    EXPECT_LE(alphaErr, tol);
}

// One splat with a pane through its kernel, just in front of its plane and
// just behind it: the splat is cut into the part in front of the pane and
// the part behind (Ebert & Parent's sections), each with its share of the
// kernel's line integral. Against the reference with the same pane: the GL
// image may differ from it by what it differs without the pane, plus what
// the partial table's interpolation moves the two shares.
TEST_F(FragmentListsGL, SplatStraddlingAPaneIsCutIntoSections) {
    Materials materials{Footprint{}};
    materials.addTextureSet(TextureSet::turbulence({.count = 1, .size = 32, .seed = 5}));
    materials.addColorTable(ColorTable::constant({0.9f, 0.6f, 0.3f, 1.0f}));
    const Camera cam = Camera::lookAt({0.0f, 0.0f, 6.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, 0.7853982f, kSize);
    Grid g = *Grid::box({1, 1, 1}, glm::vec3(2.0f));
    g.voxels[0].opacity = 0.9f;
    Frame frame;
    frame.begin(0.0, cam);
    frame.builder().add(g, materials, {.textured = false});
    frame.end();
    ASSERT_EQ(frame.splats().size(), 1u);
    const glm::vec3 centre = frame.splats()[0].center;
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(materials));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fb);
    // The partial table's largest error against the exact fraction.
    const Footprint& fp = materials.footprint();
    double delta = 0.0;
    for (int i = 0; i <= 200; ++i)
        for (int j = 0; j <= 200; ++j) {
            const double r = fp.radius() * i / 200.0, sg = -1.0 + 2.0 * j / 200.0;
            const double sMax = std::sqrt(std::max(fp.radius() * fp.radius() - r * r, 0.0));
            delta = std::max(delta, std::abs(double(fp.fractionBefore(float(r), float(sg * sMax))) - fp.exactFractionBefore(r, sg * sMax)));
        }
    // A share off by delta moves a section's alpha 1 - 2^(-tau f) by at most
    // ln2 tau delta (and its colour, <= 1 times that); two sections.
    const double tau = frame.splats()[0].density;
    auto errorAgainstReference = [&](const std::vector<Pane>& panes) {
        fr->render(frame, {.framebuffer = fb->handle(),
                           .drawOpaque = clearTo(glm::vec4(0.0f)),
                           .drawTransparent = [&] { glass.draw(panes, cam); },
                           .transparentToLists = true});
        std::vector<ReferenceSurface> surfaces;
        for (const Pane& p : panes)
            surfaces.push_back(ReferenceSurface::quad(
                {p.centre.x - p.half, p.centre.y - p.half, p.z}, {p.centre.x + p.half, p.centre.y - p.half, p.z},
                {p.centre.x + p.half, p.centre.y + p.half, p.z}, {p.centre.x - p.half, p.centre.y + p.half, p.z}, glm::dvec4(p.premultiplied)));
        auto ref = renderSplatExact(frame.splats(), cam, materials, {.threads = 2, .surfaces = surfaces});
        const Image got = fb->read();
        double worst = 0.0;
        for (std::size_t i = 0; i < got.pixels.size(); ++i) worst = std::max(worst, std::abs(double(got.pixels[i]) - double(ref->pixels[i])));
        return worst;
    };
    const glm::vec4 tint{0.1f, 0.2f, 0.3f, 0.4f};
    const double base = errorAgainstReference({{.z = 40.0f, .premultiplied = glm::vec4(0.0f)}}); // no visible pane
    for (const float dz : {0.3f, -0.3f}) {
        const double err = errorAgainstReference({{.z = centre.z + dz, .premultiplied = tint}});
        EXPECT_TRUE(fr->stats().lists.cut);
        EXPECT_EQ(fr->stats().lists.splatsSectioned, 1u); // the pane meets its kernel: sections, not the ordinary pass
        EXPECT_EQ(fr->stats().lists.sections, 2);
        EXPECT_LE(err, base + 2.0 * std::log(2.0) * tau * delta + 4.0 * std::ldexp(1.0, -12)) << "pane at z = centre + " << dz;
    }
}

// With a fog, splats that lie wholly behind (or in front of) every surface
// they cover take the ordinary splat pass, which fogs every fragment: a pane
// in front of the fogged fire gives what the ordered blend gives (fire, then
// pane), up to the pane's half colour. Splats that meet a surface are not
// sectioned (fogged sections are not implemented): they take the ordered
// blend under the surfaces, and the frame says so; the surfaces are still
// sorted in the lists, never dropped.
TEST_F(FragmentListsGL, WithAFogSplatsClearOfTheSurfacesAreExactAndTheRestSaySo) {
    Fire f;
    Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    FogDesc fd;
    fd.terms.push_back(FogTerm::constant(0.02));
    auto fog = Fog::create(fd);
    ASSERT_TRUE(fog) << fog.error();
    f.frame.setFog(std::make_shared<const Fog>(*fog));
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(f.materials));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    auto ordered = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fb && ordered);
    const Camera& cam = f.frame.camera();
    const glm::vec4 tint{0.05f, 0.1f, 0.15f, 0.3f};
    const std::vector<Pane> front{{.z = Fire::kFront + 1.0f, .premultiplied = tint}};
    fr->render(f.frame, {.framebuffer = fb->handle(),
                         .drawOpaque = clearTo(kBackground),
                         .drawTransparent = [&] { glass.draw(front, cam); },
                         .transparentToLists = true});
    gl::FrameRenderStats s = fr->stats();
    EXPECT_TRUE(s.lists.used && s.lists.splats && s.fog.splats);
    EXPECT_TRUE(s.lists.note.empty()) << s.lists.note;
    EXPECT_EQ(s.lists.splatsBehind, f.frame.splats().size());
    EXPECT_EQ(s.lists.nodes, std::uint64_t(kSize.x) * kSize.y);
    const Image got = fb->read();
    Frame empty;
    empty.begin(0.0, cam);
    empty.end();
    fr->render(f.frame, {.framebuffer = ordered->handle(), .drawOpaque = clearTo(kBackground)});
    fr->render(empty, {.framebuffer = ordered->handle(), .drawTransparent = [&] { glass.draw(front, cam); }, .transparentToLists = true});
    // The same ordinary pass in both; the pane's colour is stored as halves
    // in the lists (2^-11 relative, colour <= 1) and composited once.
    const test::ImageDiff d = test::compareImages(got, ordered->read(), std::ldexp(1.0, -11));
    EXPECT_LE(d.maxAbs, std::ldexp(1.0, -11)) << test::writeFailureImages(got, d);

    const std::vector<Pane> through{{.z = 0.0f, .premultiplied = tint}};
    fr->render(f.frame, {.framebuffer = fb->handle(),
                         .drawOpaque = clearTo(kBackground),
                         .drawTransparent = [&] { glass.draw(through, cam); },
                         .transparentToLists = true});
    s = fr->stats();
    EXPECT_NE(s.lists.note.find("fog"), std::string::npos) << s.lists.note;
    EXPECT_EQ(s.lists.splatsSectioned, 0u);
    EXPECT_LT(s.lists.splatsBehind + s.lists.splatsFront, f.frame.splats().size()); // some meet the pane
    EXPECT_EQ(s.lists.nodes, std::uint64_t(kSize.x) * kSize.y);
    EXPECT_GT(s.splats, 0u);
}

// The camera inside the gas with a pane in front of it: the kernels around
// the eye cross the eye plane, and the one holding the eye is cut by a pane
// at view depth 0.2 (inside its support: 0.3 x 1.6 = 0.48). Such splats take
// the general (screen-covering) variant of the section pass, as in the splat
// pass (before, they were not drawn in the lists). Against the exact
// reference with the same pane, the error may exceed the error of the same
// frame without a visible pane (the ordinary pass: every splat behind no
// surface) by what the sections add per fragment: two more partial-table
// lookups (each off by at most delta, which moves a section's alpha by at
// most ln2 tau delta), for each of the n fragments on a pixel, plus the
// sections' and the resolve's half rounding ((n + 2) 2^-12) and the pane's
// half colour (2^-11).
namespace {

// Renders the 5^3 block (spacing 0.3, opacity 0.4, one colour) seen by cam
// with one pane at each view depth in turn (the camera looks along -z),
// against the exact reference with the same pane; the bound as explained
// above. Returns the stats of the last frame.
gl::FrameRenderStats blockAgainstReference(const Camera& cam, const std::vector<float>& depths, const char* what) {
    Materials materials{Footprint{}};
    materials.addColorTable(ColorTable::constant({0.9f, 0.6f, 0.3f, 1.0f}));
    Grid g = *Grid::box({5, 5, 5}, glm::vec3(0.3f));
    for (Voxel& v : g.voxels) v.opacity = 0.4f;
    Frame frame;
    frame.begin(0.0, cam);
    frame.builder().add(g, materials, {.textured = false});
    frame.end();
    EXPECT_GT(frame.splats().size(), 10u);
    Glass glass;
    EXPECT_TRUE(glass.error().empty()) << glass.error();
    auto fr = gl::FrameRenderer::create();
    EXPECT_TRUE(fr && fr->upload(materials));
    auto fb = gl::Framebuffer::create({.width = cam.viewport.x, .height = cam.viewport.y, .color = gl::Precision::F32});
    EXPECT_TRUE(fb);
    if (!fr || !fb || !glass.error().empty()) return {};
    const Footprint& fp = materials.footprint();
    double delta = 0.0;
    for (int i = 0; i <= 200; ++i)
        for (int j = 0; j <= 200; ++j) {
            const double r = fp.radius() * i / 200.0, sg = -1.0 + 2.0 * j / 200.0;
            const double sMax = std::sqrt(std::max(fp.radius() * fp.radius() - r * r, 0.0));
            delta = std::max(delta, std::abs(double(fp.fractionBefore(float(r), float(sg * sMax))) - fp.exactFractionBefore(r, sg * sMax)));
        }
    double tau = 0.0;
    for (const Splat& s : frame.splats()) tau = std::max(tau, double(s.density));
    SplatExactStats st;
    EXPECT_TRUE(renderSplatExact(frame.splats(), cam, materials, {.threads = 2}, &st));
    const double n = double(st.maxOverlap);
    const glm::vec4 clear{0.1f, 0.15f, 0.2f, 1.0f};
    const glm::vec3 eye = cam.eye();
    auto errorAgainstReference = [&](const std::vector<Pane>& panes) {
        fr->render(frame, {.framebuffer = fb->handle(),
                           .drawOpaque = clearTo(clear),
                           .drawTransparent = [&] { glass.draw(panes, cam); },
                           .transparentToLists = true});
        std::vector<ReferenceSurface> surfaces;
        for (const Pane& p : panes)
            surfaces.push_back(ReferenceSurface::quad(
                {p.centre.x - p.half, p.centre.y - p.half, p.z}, {p.centre.x + p.half, p.centre.y - p.half, p.z},
                {p.centre.x + p.half, p.centre.y + p.half, p.z}, {p.centre.x - p.half, p.centre.y + p.half, p.z}, glm::dvec4(p.premultiplied)));
        auto ref = renderSplatExact(frame.splats(), cam, materials, {.host = {.background = clear}, .threads = 2, .surfaces = surfaces});
        const Image got = fb->read();
        double worst = 0.0;
        for (std::size_t i = 0; i < got.pixels.size(); ++i) {
            EXPECT_TRUE(std::isfinite(got.pixels[i]));
            worst = std::max(worst, std::abs(double(got.pixels[i]) - double(ref->pixels[i])));
        }
        return worst;
    };
    // A pane behind the camera: stored nowhere, every splat in the ordinary pass.
    const double base = errorAgainstReference({{.z = eye.z + 5.0f, .premultiplied = glm::vec4(0.0f), .half = 1.0f, .centre = {eye.x, eye.y}}});
    const double bound = base + n * 2.0 * std::log(2.0) * tau * delta + (n + 2.0) * std::ldexp(1.0, -12) + std::ldexp(1.0, -11);
    const glm::vec4 tint{0.1f, 0.2f, 0.3f, 0.4f};
    gl::FrameRenderStats s;
    for (const float depth : depths) {
        const double err = errorAgainstReference({{.z = eye.z - depth, .premultiplied = tint, .half = 1.0f, .centre = {eye.x, eye.y}}});
        s = fr->stats();
        EXPECT_TRUE(s.lists.splats);
        EXPECT_GT(s.lists.splatsSectioned, 0u) << what << depth;
        std::printf("  %s, pane at view depth %.2f: error %.3e (bound %.3e; no pane %.3e), general %llu, sectioned %llu\n", what, depth, err, bound,
                    base, (unsigned long long)s.lists.general, (unsigned long long)s.lists.splatsSectioned);
        EXPECT_LE(err, bound) << what << ", pane at view depth " << depth;
    }
    return s;
}

} // namespace

TEST_F(FragmentListsGL, CameraInsideTheGasInFrontOfAPaneIsExact) {
    const Grid g = *Grid::box({5, 5, 5}, glm::vec3(0.3f));
    const glm::vec3 eye = g.worldPosition({2, 2, 2}) + glm::vec3(0.02f, -0.01f, 0.03f);
    const Camera cam = Camera::lookAt(eye, eye + glm::vec3(0.0f, 0.0f, -1.0f), {0, 1, 0}, 1.2f, {40, 32}, 0.02f, 50.0f);
    // Through the eye's kernel; beyond it, among the others.
    const gl::FrameRenderStats s = blockAgainstReference(cam, {0.6f, 0.2f}, "camera inside");
    EXPECT_GT(s.lists.general, 0u) << "the eye's kernel is cut by the pane: sections, general variant";
}

// The camera just outside the gas with the near plane through the front
// kernels and a pane through the block: the sectioned splats need the near
// cut or not (the cheaper variant), interleaved in the back-to-front order;
// the runs of variants must still cover every splat once, in order.
TEST_F(FragmentListsGL, SectionVariantsWithAndWithoutTheNearCutAreExact) {
    const Grid g = *Grid::box({5, 5, 5}, glm::vec3(0.3f));
    const glm::vec3 front = g.worldPosition({2, 2, 4});
    const glm::vec3 eye = front + glm::vec3(0.05f, 0.03f, 0.35f); // 0.35 in front of the front layer: inside its kernels' reach (0.48)
    const Camera cam = Camera::lookAt(eye, eye + glm::vec3(0.0f, 0.0f, -1.0f), {0, 1, 0}, 1.2f, {40, 32}, 0.2f, 50.0f);
    blockAgainstReference(cam, {0.5f, 0.95f}, "near plane through the front kernels");
}
