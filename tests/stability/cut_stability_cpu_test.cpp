// The depth cut's and the fragment lists' hard cases that need no GL: the
// double-precision reference itself at its edges (issue 24).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/splatfx.hpp"

namespace splatfx {
namespace {

const glm::vec4 kColour{0.9f, 0.6f, 0.3f, 1.0f};

struct Scene {
    Materials mat{Footprint{}};
    Grid grid = *Grid::box({4, 4, 4}, glm::vec3(0.3f));
    Camera cam;
    std::vector<Splat> splats;
    Scene() {
        mat.addColorTable(ColorTable::constant(kColour));
        for (Voxel& v : grid.voxels) v.opacity = 0.5f;
        const glm::vec3 c = grid.worldPosition({2, 2, 2});
        cam = Camera::lookAt(c + glm::vec3(0.03f, 0.02f, 2.0f), c, {0, 1, 0}, 1.0f, {24, 20}, 0.2f, 50.0f);
        SplatBuilder b;
        b.begin(cam);
        b.add(grid, mat, {.textured = false});
        b.sort();
        splats = b.splats();
    }
    Image render(const SplatExactDesc& d) const {
        auto img = renderSplatExact(splats, cam, mat, d);
        EXPECT_TRUE(img) << img.error();
        return img ? *img : Image{};
    }
};

TEST(CutStabilityCpu, SectionsAtSevenSurfacesMultiplyBackToTheWholeFragment) {
    // Seven panes across the block (one through a layer of splat centres,
    // two at one depth, one exactly at the host depth): every fragment is
    // cut into up to eight sections, whose shares must telescope to its whole
    // share between the near plane and the host (no gas lost or counted twice
    // at a cut, whatever the clamps do). Alpha does not depend on the order,
    // so on every pixel all seven panes cross, 1 - alpha with the panes =
    // (1 - alpha without them) x prod (1 - a_k): closed form, to the float
    // rounding of the two stored alphas (2^-24 each, 1 - a_k exact in double).
    const Scene s;
    const glm::vec3 c = s.grid.worldPosition({2, 2, 2});
    const double zHost = c.z - 0.2;
    Image depth;
    depth.width = s.cam.viewport.x, depth.height = s.cam.viewport.y, depth.channels = 1;
    // The host: a plane facing the camera at world z = zHost, as window depth (OpenGL's default convention).
    const glm::vec4 clip = s.cam.proj * s.cam.view * glm::vec4(c.x, c.y, float(zHost), 1.0f);
    depth.pixels.assign(std::size_t(depth.width) * depth.height, 0.5f * clip.z / clip.w + 0.5f);
    const double zs[7] = {c.z + 0.45, double(s.grid.worldPosition({2, 2, 3}).z), c.z + 0.15, c.z - 0.05, c.z - 0.05, c.z - 0.13, zHost};
    std::vector<ReferenceSurface> panes;
    double keep = 1.0;
    for (int k = 0; k < 7; ++k) {
        const double a = 0.05 + 0.03 * k, h = 4.0;
        panes.push_back(ReferenceSurface::quad({c.x - h, c.y - h, zs[k]}, {c.x + h, c.y - h, zs[k]}, {c.x + h, c.y + h, zs[k]},
                                               {c.x - h, c.y + h, zs[k]}, {0.2 * a, 0.5 * a, 0.9 * a, a}));
        keep *= 1.0 - a;
    }
    SplatExactDesc without{.host = {.depth = &depth}, .threads = 2};
    SplatExactDesc with = without;
    with.surfaces = panes;
    const Image a = s.render(without), b = s.render(with);
    // The last pane lies at the host depth up to the float rounding of both: on or just behind it.
    double worst = 0.0, gas = 0.0;
    const double keepSix = keep / (1.0 - (0.05 + 0.03 * 6));
    for (int y = 0; y < depth.height; ++y)
        for (int x = 0; x < depth.width; ++x) {
            const double t = 1.0 - double(a.at(x, y, 3));
            gas = std::max(gas, 1.0 - t);
            const double got = 1.0 - double(b.at(x, y, 3));
            worst = std::max(worst, std::min(std::abs(got - t * keep), std::abs(got - t * keepSix)));
        }
    EXPECT_GT(gas, 0.5) << "the gas in front of the host must be visible";
    EXPECT_LE(worst, 2.0 * std::ldexp(1.0, -24));
}

TEST(CutStabilityCpu, HostDepthNaNOrBeyondOneIsNoSurface) {
    // A float depth buffer can hold NaN (a broken host shader) or, cleared by
    // hand, values outside [0, 1]. The reference must stay finite: NaN and
    // values above 1 are no surface (the far plane cuts, as the sky's 1 does),
    // finite values below 0 lie in front of the near plane (nothing left, as 0).
    const Scene s;
    Image depth;
    depth.width = s.cam.viewport.x, depth.height = s.cam.viewport.y, depth.channels = 1;
    auto with = [&](float d) {
        depth.pixels.assign(std::size_t(depth.width) * depth.height, d);
        return s.render({.host = {.depth = &depth}, .threads = 2});
    };
    const Image sky = with(1.0f), zero = with(0.0f);
    const Image open = s.render({.threads = 2});
    for (const float d : {std::numeric_limits<float>::quiet_NaN(), 1.5f, std::numeric_limits<float>::infinity()}) {
        const Image img = with(d);
        for (std::size_t i = 0; i < img.pixels.size(); ++i) {
            ASSERT_TRUE(std::isfinite(img.pixels[i])) << "depth " << d;
            ASSERT_EQ(img.pixels[i], open.pixels[i]) << "depth " << d;
            ASSERT_EQ(img.pixels[i], sky.pixels[i]) << "depth " << d;
        }
    }
    for (const float d : {-0.5f, -1e30f}) {
        const Image img = with(d);
        for (std::size_t i = 0; i < img.pixels.size(); ++i) ASSERT_EQ(img.pixels[i], zero.pixels[i]) << "depth " << d;
    }
    double peak = 0.0;
    for (float v : zero.pixels) peak = std::max(peak, double(v));
    EXPECT_EQ(peak, 0.0) << "host depth 0 (the near plane) hides everything";
    for (float v : open.pixels) peak = std::max(peak, double(v));
    EXPECT_GT(peak, 0.3);
}

} // namespace
} // namespace splatfx
