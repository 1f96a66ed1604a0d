// The fog in the frame (issue 14, item 3), GL-free: Scene hands its fog to
// every Frame, and the splat-exact reference composites splats in fog as one
// medium, checked against the closed form of a constant fog.
#include <cmath>

#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

namespace splatfx {
namespace {

TEST(FogFrame, SceneHandsItsFogToEveryFrameAndClearsIt) {
    Scene scene;
    Materials mat{Footprint{}};
    Frame frame;
    const Camera cam = Camera::lookAt({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.9f, {16, 16});
    EXPECT_TRUE(scene.prepare(0.0, cam, mat, frame));
    EXPECT_EQ(frame.fog(), nullptr);
    scene.setFog(*Fog::create(paperFig6Fog()));
    EXPECT_TRUE(scene.prepare(0.1, cam, mat, frame));
    ASSERT_NE(frame.fog(), nullptr);
    EXPECT_EQ(frame.fog(), scene.fog());
    EXPECT_DOUBLE_EQ(frame.fog()->density({0, 0, 0}, 0.0), Fog::create(paperFig6Fog())->density({0, 0, 0}, 0.0));
    frame.begin(0.2, cam); // begin() keeps the fog (a setting, not content)
    EXPECT_NE(frame.fog(), nullptr);
    scene.clearFog();
    EXPECT_TRUE(scene.prepare(0.3, cam, mat, frame));
    EXPECT_EQ(frame.fog(), nullptr);
}

// One splat seen through a constant fog k over a transparent background: the
// fogged layer is f (a c) + (1 - f) a C_fog with f = exp(-k |X - eye|), X the
// ray's crossing of the splat plane; alpha is unchanged. The emission of the
// fog between the eye and X, integral_0^s k e^{-k u} C du = (1 - f) C, is what
// the second term is, so this is the exact emission-absorption answer.
TEST(FogFrame, ReferenceMatchesTheClosedFormOfAConstantFog) {
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::constant({0.9f, 0.6f, 0.3f, 1.0f}));
    Grid g;
    g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.7f});
    const glm::ivec2 size{24, 20};
    const Camera cam = Camera::lookAt({0.4f, 0.3f, 5.0f}, {0, 0, 0}, {0, 1, 0}, 0.5f, size, 0.05f, 40.0f);
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    ASSERT_EQ(b.splats().size(), 1u);
    const double k = 0.3;
    FogDesc fd;
    fd.terms.push_back(FogTerm::constant(k));
    fd.colour = {0.2, 0.5, 0.9};
    const Fog fog = *Fog::create(fd);

    SplatExactDesc rd; // transparent black background
    auto plain = renderSplatExact(b.splats(), cam, mat, rd);
    ASSERT_TRUE(plain);
    rd.fog = &fog;
    rd.fogHost = false;
    rd.fogTolerance = 1e-12;
    auto fogged = renderSplatExact(b.splats(), cam, mat, rd);
    ASSERT_TRUE(fogged);

    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    const glm::dvec3 eye(cam.eye()), c(b.splats()[0].center);
    const glm::dvec3 n = glm::cross(glm::dvec3(b.splats()[0].axisU), glm::dvec3(b.splats()[0].axisV));
    int covered = 0;
    for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) {
            const double a = plain->at(x, y, 3);
            if (a <= 0.0) continue;
            ++covered;
            const glm::dvec4 h = inv * glm::dvec4((x + 0.5) / size.x * 2 - 1, (size.y - 1 - y + 0.5) / size.y * 2 - 1, -1.0, 1.0);
            const glm::dvec3 dir = glm::normalize(glm::dvec3(h) / h.w - eye);
            const double s = glm::dot(c - eye, n) / glm::dot(dir, n);
            const double f = std::exp(-k * s);
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(fogged->at(x, y, ch), f * plain->at(x, y, ch) + (1 - f) * a * fd.colour[ch], 1e-6) << x << "," << y;
            EXPECT_FLOAT_EQ(fogged->at(x, y, 3), float(a));
        }
    EXPECT_GT(covered, 20);

    // With the host fogged: no depth image means sky, fogged to the far plane
    // (40 units: e^{-12}, essentially the fog colour) under the splat.
    rd.fogHost = true;
    rd.host.background = {1.0f, 1.0f, 1.0f, 1.0f};
    auto withHost = renderSplatExact(b.splats(), cam, mat, rd);
    ASSERT_TRUE(withHost);
    EXPECT_NEAR(withHost->at(0, 0, 0), fd.colour.x + std::exp(-k * 40.0) * (1 - fd.colour.x), 2e-3);
}

} // namespace
} // namespace splatfx
