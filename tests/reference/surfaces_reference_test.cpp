// (issue 15) The reference's transparent surfaces: panes and boxes
// composited per pixel in exact depth order with the splats, each splat cut
// into sections at the surfaces with its exact share of the kernel integral.
#include <cmath>

#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/splatfx.hpp"

namespace splatfx {
namespace {

const glm::vec4 kColour{0.9f, 0.6f, 0.3f, 1.0f};
const glm::ivec2 kSize{15, 11};

struct Lone {
    Materials mat{Footprint{}};
    Camera cam = Camera::lookAt({0.0f, 0.0f, 8.0f}, {0, 0, 0}, {0, 1, 0}, 0.5f, kSize);
    SplatBuilder b;
    Lone() {
        mat.addColorTable(ColorTable::constant(kColour));
        mat.addTextureSet(TextureSet::turbulence({.count = 4}));
        Grid g;
        g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.6f});
        b.begin(cam);
        b.add(g, mat, {.textured = false});
    }
    Image render(std::vector<ReferenceSurface> surfaces, bool cut = true) const {
        return *renderSplatExact(b.splats(), cam, mat, {.depthCut = cut, .surfaces = std::move(surfaces)});
    }
};

// A pane at world z, covering the view.
ReferenceSurface pane(double z, glm::dvec4 c) { return ReferenceSurface::quad({-9, -9, z}, {9, -9, z}, {9, 9, z}, {-9, 9, z}, c); }

glm::dvec4 px(const Image& img, int x, int y) { return {img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2), img.at(x, y, 3)}; }
glm::dvec4 over(glm::dvec4 f, glm::dvec4 b) { return f + (1.0 - f.a) * b; }

// Float output: the comparisons hold to float rounding of values <= 1.
constexpr double kFloat = 1e-6;

TEST(ReferenceSurfaces, APaneWhollyInFrontOrBehindComposesAsTheClosedForm) {
    Lone s;
    const Image alone = s.render({});
    const glm::dvec4 p{0.1, 0.2, 0.05, 0.4};
    const Image front = s.render({pane(3.0, p)}), back = s.render({pane(-3.0, p)});
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const glm::dvec4 a = px(alone, x, y);
            const glm::dvec4 wf = over(p, a), wb = over(a, p);
            for (int c = 0; c < 4; ++c) {
                EXPECT_NEAR(px(front, x, y)[c], wf[c], kFloat);
                EXPECT_NEAR(px(back, x, y)[c], wb[c], kFloat);
            }
        }
}

// A pane through the kernel's centre, seen head-on: on the centre pixel the
// symmetric kernel puts half its optical depth on each side (exactBefore(r,
// 0) = exact(r) / 2), so each half has alpha 1 - sqrt(1 - alpha) and the
// pixel is front half over pane over back half.
TEST(ReferenceSurfaces, APaneThroughTheCentreSplitsTheKernelInHalves) {
    Lone s;
    const Image alone = s.render({});
    const glm::dvec4 p{0.05, 0.1, 0.2, 0.3};
    const Image cutImg = s.render({pane(0.0, p)});
    const glm::dvec4 a = px(alone, 7, 5);
    ASSERT_GT(a.a, 0.3);
    const double ah = 1.0 - std::sqrt(1.0 - a.a);
    const glm::dvec4 half = glm::dvec4(glm::dvec3(a) / a.a * ah, ah);
    const glm::dvec4 want = over(half, over(p, half));
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(px(cutImg, 7, 5)[c], want[c], kFloat) << c;
    // Alpha does not depend on the order: 1 - (1 - a)(1 - p.a) everywhere.
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) EXPECT_NEAR(px(cutImg, x, y).a, 1.0 - (1.0 - px(alone, x, y).a) * (1.0 - p.a), kFloat);
    // Without the cut the whole splat sits at its plane (the pane at the same depth: behind it, side 2 first).
    const Image plain = s.render({pane(0.001, p)}, false);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(px(plain, 7, 5)[c], over(p, a)[c], kFloat) << c;
}

// A zero surface changes nothing; an opaque one in front hides everything; a
// box around the splat is two layers, one in front and one behind.
TEST(ReferenceSurfaces, ZeroOpaqueAndBoxSurfaces) {
    Lone s;
    const Image alone = s.render({});
    const Image zero = s.render({pane(1.0, glm::dvec4(0.0))});
    for (std::size_t i = 0; i < alone.pixels.size(); ++i) EXPECT_EQ(zero.pixels[i], alone.pixels[i]);
    const glm::dvec4 wall{0.3, 0.2, 0.1, 1.0};
    const Image hidden = s.render({pane(2.0, wall)});
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(px(hidden, 7, 5)[c], wall[c], kFloat);
    const glm::dvec4 g{0.02, 0.04, 0.06, 0.1};
    const Image boxed = s.render({ReferenceSurface::box({-3, -3, -3}, {3, 3, 3}, g)});
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(px(boxed, 7, 5)[c], over(g, over(px(alone, 7, 5), g))[c], kFloat) << c;
}

} // namespace
} // namespace splatfx
