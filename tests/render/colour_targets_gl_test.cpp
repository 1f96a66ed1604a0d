// Hosts whose colour target is not linear RGBA8: an sRGB target with
// GL_FRAMEBUFFER_SRGB on (GL decodes the destination, blends in linear and
// encodes the result: splatfx's colours, tables and textures are linear) and
// an RGBA16F target. Each is held against the same frame drawn into RGBA32F,
// within the rounding its own format makes at each write.
#include <algorithm>
#include <cmath>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/gl/frame_renderer.hpp"

namespace splatfx {
namespace {

constexpr glm::ivec2 kSize{48, 32};

double srgbToLinear(double s) { return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4); }

// Three voxels one behind the other along the view and a fog: each pixel is
// written by the host's clear, at most three splats and the fog pass, five
// writes at most.
struct Scene {
    Materials materials{Footprint{}};
    Frame frame;
    Scene() {
        materials.addColorTable(ColorTable::constant({0.9f, 0.35f, 0.1f, 1.0f}));
        Grid g;
        for (int z = -1; z <= 1; ++z) g.voxels.push_back({.cell = {0, 0, z}, .opacity = 0.55f});
        g.spacing = glm::vec3(0.8f);
        frame.begin(0.0, Camera::lookAt({0.0f, 0.0f, 4.0f}, {0, 0, 0}, {0, 1, 0}, 0.9f, kSize, 0.05f, 30.0f));
        frame.builder().add(g, materials, {.textured = false});
        frame.end();
        FogDesc fog;
        fog.terms.push_back(FogTerm::constant(0.05));
        fog.colour = {0.6, 0.65, 0.7};
        frame.setFog(std::make_shared<const Fog>(*Fog::create(fog)));
    }
};
constexpr int kWrites = 5;

struct Target {
    GLuint fbo = 0, color = 0, depth = 0;
    explicit Target(GLenum colorFormat) {
        glCreateFramebuffers(1, &fbo);
        glCreateTextures(GL_TEXTURE_2D, 1, &color);
        glTextureStorage2D(color, 1, colorFormat, kSize.x, kSize.y);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
        glCreateTextures(GL_TEXTURE_2D, 1, &depth);
        glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT24, kSize.x, kSize.y);
        glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
    }
    ~Target() {
        glDeleteFramebuffers(1, &fbo);
        glDeleteTextures(1, &color);
        glDeleteTextures(1, &depth);
    }
    // RGBA as stored (sRGB codes / 255 for an sRGB texture: no decoding on read-back).
    std::vector<float> read() const {
        std::vector<float> px(std::size_t(kSize.x) * kSize.y * 4);
        glGetTextureImage(color, 0, GL_RGBA, GL_FLOAT, GLsizei(px.size() * sizeof(float)), px.data());
        return px;
    }
};

std::vector<float> draw(gl::FrameRenderer& fr, Scene& s, const Target& t, bool srgb) {
    fr.render(s.frame, {.framebuffer = t.fbo, .depthTexture = t.depth, .drawOpaque = [srgb] {
                            if (srgb) glEnable(GL_FRAMEBUFFER_SRGB);
                            glClearColor(0.2f, 0.3f, 0.45f, 1.0f);
                            glClearDepth(1.0);
                            glDepthMask(GL_TRUE);
                            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                        }});
    glDisable(GL_FRAMEBUFFER_SRGB);
    return t.read();
}

class ColourTargetsGL : public test::GLTest {};

TEST_F(ColourTargetsGL, AnSrgbTargetBlendsInLinearAndEncodesOnce) {
    Scene s;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(s.materials));
    const Target linear(GL_RGBA32F), srgb(GL_SRGB8_ALPHA8);
    const std::vector<float> want = draw(*fr, s, linear, false);
    ASSERT_TRUE(fr->stats().fog.host) << fr->stats().fog.error;
    const std::vector<float> got = draw(*fr, s, srgb, true);
    double worst = 0.0, meanAbs = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
        if (i % 4 == 3) continue; // alpha is stored linear
        const double lin = srgbToLinear(got[i]);
        // Each write rounds to the nearest sRGB code: at most half a code, in linear half
        // a code times the decoding's slope there (largest at 1: 2.4 / 1.055^2.4 ... about
        // 2.3 / 255 per code); an error made by one write is passed on by later blends
        // scaled by (1 - alpha) <= 1, so kWrites of them at most.
        const double s1 = std::min(1.0, double(got[i]) + 1.0 / 255.0), s0 = std::max(0.0, double(got[i]) - 1.0 / 255.0);
        const double slope = (srgbToLinear(s1) - srgbToLinear(s0)) / (s1 - s0) * 1.2; // the slope nearby, with the next code's increase
        const double bound = kWrites * 0.5 / 255.0 * std::max(slope, 2.3);
        const double e = std::abs(lin - want[i]);
        worst = std::max(worst, e / bound);
        meanAbs += e, ++n;
        EXPECT_LE(e, bound) << "value " << i;
    }
    meanAbs /= n;
    // Blending the codes as if they were linear (GL_FRAMEBUFFER_SRGB off) misses by far more: the
    // same frame's mid-tones are 0.1 and more off; the test's bound is below that.
    const std::vector<float> raw = draw(*fr, s, srgb, false);
    double rawWorst = 0.0;
    for (std::size_t i = 0; i < raw.size(); ++i)
        if (i % 4 != 3) rawWorst = std::max(rawWorst, std::abs(srgbToLinear(raw[i]) - double(want[i])));
    EXPECT_GT(rawWorst, 5.0 * meanAbs + 0.02) << "the sRGB target must differ from blending codes in linear arithmetic";
    std::printf("[ sRGB target ] worst error / bound %.2f, mean |error| %.4f; with GL_FRAMEBUFFER_SRGB off the worst is %.3f\n", worst, meanAbs,
                rawWorst);
}

TEST_F(ColourTargetsGL, AnRgba16fTargetKeepsTheBlendInHalfFloat) {
    Scene s;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr && fr->upload(s.materials));
    const Target full(GL_RGBA32F), half(GL_RGBA16F);
    const std::vector<float> want = draw(*fr, s, full, false), got = draw(*fr, s, half, false);
    for (std::size_t i = 0; i < got.size(); ++i) {
        // Half float: 11 significant bits. Each write rounds its value (every colour on the way is
        // at most 1) by at most half an ulp, 2^-11 at 1; a later blend passes it on scaled by <= 1.
        const double bound = kWrites * std::ldexp(1.0, -11);
        EXPECT_NEAR(got[i], want[i], bound) << "value " << i;
    }
}

} // namespace
} // namespace splatfx
