// ScaledRenderer: pass-through at scale 1, closeness at reduced scale, and no
// bleeding onto nearer host geometry thanks to nearest-depth upsampling.
#include <algorithm>
#include <cmath>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/gl/scaled_renderer.hpp"

namespace splatfx {
namespace {

class ScaledRendererTest : public test::GLTest {
protected:
    Materials mat{Footprint{}};
    Grid grid = *Grid::box({5, 8, 4}, glm::vec3(0.5f));
    glm::ivec2 size{96, 72};
    Camera cam = Camera::lookAt({0, 2.0f, 7.0f}, {0, 1.8f, 0}, {0, 1, 0}, 0.8f, size);
    SplatBuilder builder;
    const glm::vec4 bg{0.05f, 0.05f, 0.1f, 1.0f};

    void SetUp() override {
        test::GLTest::SetUp();
        mat.addColorTable(ColorTable::fire());
        for (Voxel& v : grid.voxels) v.opacity = 0.35f;
        grid.colorByHeight();
        builder.begin(cam);
        builder.add(grid, mat, {.textured = false});
        builder.sort();
    }
    gl::Framebuffer makeTarget() {
        auto fb = gl::Framebuffer::create({.width = size.x, .height = size.y, .color = gl::Precision::F32});
        EXPECT_TRUE(fb);
        fb->clear(bg);
        return std::move(*fb);
    }
};

TEST_F(ScaledRendererTest, ScaleOneIsTheWrappedRendererBitForBit) {
    auto plain = gl::Renderer::create();
    auto scaled = gl::ScaledRenderer::create({.scale = 1});
    ASSERT_TRUE(plain && scaled);
    ASSERT_TRUE(plain->upload(mat) && scaled->upload(mat));
    gl::Framebuffer a = makeTarget(), b = makeTarget();
    plain->draw(builder.splats(), cam, {.framebuffer = a.handle(), .width = size.x, .height = size.y});
    scaled->draw(builder.splats(), cam, {.framebuffer = b.handle(), .width = size.x, .height = size.y});
    EXPECT_EQ(a.read().pixels, b.read().pixels);
}

TEST_F(ScaledRendererTest, ReducedScaleStaysWithinTheLocalVariationOfTheFullImage) {
    // Upsampled pixel p interpolates low-resolution samples taken at points
    // within `scale` pixels of p, so it cannot leave the range of the full
    // image over that neighbourhood (radius scale + 1 for the bilinear taps'
    // reach), except for F16 storage (2^-11 relative) and the half-texel
    // offset of the low-resolution pixel centres, which the +1 covers.
    auto plain = gl::Renderer::create();
    ASSERT_TRUE(plain && plain->upload(mat));
    gl::Framebuffer full = makeTarget();
    plain->draw(builder.splats(), cam, {.framebuffer = full.handle(), .width = size.x, .height = size.y});
    const Image ref = full.read();
    for (int scale : {2, 4}) {
        auto sr = gl::ScaledRenderer::create({.scale = scale});
        ASSERT_TRUE(sr) << sr.error();
        ASSERT_TRUE(sr->upload(mat));
        gl::Framebuffer fb = makeTarget();
        sr->draw(builder.splats(), cam, {.framebuffer = fb.handle(), .width = size.x, .height = size.y});
        const Image got = fb.read();
        int outside = 0;
        double meanErr = 0.0;
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x)
                for (int c = 0; c < 4; ++c) {
                    float lo = 1e9f, hi = -1e9f;
                    const int reach = scale + 1;
                    for (int j = std::max(0, y - reach); j <= std::min(size.y - 1, y + reach); ++j)
                        for (int i = std::max(0, x - reach); i <= std::min(size.x - 1, x + reach); ++i)
                            lo = std::min(lo, ref.at(i, j, c)), hi = std::max(hi, ref.at(i, j, c));
                    const float v = got.at(x, y, c), slack = 1e-3f * std::max(1.0f, std::abs(v));
                    outside += v < lo - slack || v > hi + slack;
                    meanErr += std::abs(v - ref.at(x, y, c));
                }
        EXPECT_EQ(outside, 0) << "scale " << scale;
        EXPECT_GT(meanErr, 0.0) << "a reduced scale cannot be exact";
    }
}

TEST_F(ScaledRendererTest, NearestDepthUpsamplingDoesNotBleedOntoNearerGeometry) {
    // Host geometry at the near plane covers the left 37 columns (not a
    // multiple of 2 or 4, so low-resolution blocks straddle its edge). The
    // full-resolution renderer leaves those pixels untouched; so must the
    // scaled one at every scale: each covered pixel finds a low-resolution
    // neighbour at its own depth, whose splats were all depth-tested away.
    for (int scale : {2, 4}) {
        auto sr = gl::ScaledRenderer::create({.scale = scale});
        ASSERT_TRUE(sr && sr->upload(mat));
        gl::Framebuffer fb = makeTarget();
        glBindFramebuffer(GL_FRAMEBUFFER, fb.handle());
        glEnable(GL_SCISSOR_TEST);
        glScissor(0, 0, 37, size.y);
        glClearDepth(0.0);
        glClear(GL_DEPTH_BUFFER_BIT);
        glDisable(GL_SCISSOR_TEST);
        glClearDepth(1.0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        sr->draw(builder.splats(), cam, {.framebuffer = fb.handle(), .width = size.x, .height = size.y});
        const Image got = fb.read();
        int bled = 0;
        float shown = 0.0f;
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x) {
                if (x < 37) bled += got.at(x, y, 0) != bg.r || got.at(x, y, 1) != bg.g;
                else shown = std::max(shown, got.at(x, y, 0) - bg.r);
            }
        EXPECT_EQ(bled, 0) << "scale " << scale;
        EXPECT_GT(shown, 0.1f) << "the effect must still show beside the geometry";
    }
}

TEST_F(ScaledRendererTest, RestoresTheHostState) {
    auto sr = gl::ScaledRenderer::create({.scale = 2});
    ASSERT_TRUE(sr && sr->upload(mat));
    gl::Framebuffer fb = makeTarget();
    glViewport(1, 2, 3, 4);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    sr->draw(builder.splats(), cam, {.framebuffer = fb.handle(), .width = size.x, .height = size.y});
    GLint vp[4];
    glGetIntegerv(GL_VIEWPORT, vp);
    GLboolean mask = GL_FALSE;
    glGetBooleanv(GL_DEPTH_WRITEMASK, &mask);
    EXPECT_EQ(vp[0], 1);
    EXPECT_EQ(vp[3], 4);
    EXPECT_FALSE(glIsEnabled(GL_BLEND));
    EXPECT_TRUE(glIsEnabled(GL_DEPTH_TEST));
    EXPECT_TRUE(mask);
}

// A host may delete its program while it is still bound: GL keeps it alive
// only until another program replaces it, which draw() does. Putting the old
// name back would then be GL_INVALID_VALUE (the fixture's TearDown fails the
// test on any GL error); the shared state guard binds 0 instead.
TEST_F(ScaledRendererTest, RestoringSurvivesAProgramTheHostDeleted) {
    for (int scale : {1, 2}) {
        auto sr = gl::ScaledRenderer::create({.scale = scale});
        ASSERT_TRUE(sr && sr->upload(mat));
        gl::Framebuffer fb = makeTarget();
        auto host = gl::linkProgram({"#version 450 core\nvoid main() { gl_Position = vec4(0, 0, 0, 1); }\n"},
                                    {"#version 450 core\nout vec4 o; void main() { o = vec4(1); }\n"}, "host");
        ASSERT_TRUE(host) << host.error();
        glUseProgram(*host);
        glDeleteProgram(*host); // flagged; still current
        ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));
        sr->draw(builder.splats(), cam, {.framebuffer = fb.handle(), .width = size.x, .height = size.y});
        EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR)) << "scale " << scale;
        GLint current = -1;
        glGetIntegerv(GL_CURRENT_PROGRAM, &current);
        EXPECT_EQ(current, 0) << "scale " << scale << ": the deleted program's name must not be rebound";
    }
}

TEST_F(ScaledRendererTest, RejectsAScaleItDoesNotSupport) {
    auto sr = gl::ScaledRenderer::create({.scale = 3});
    ASSERT_FALSE(sr);
    EXPECT_EQ(sr.error(), "ScaledRendererDesc::scale must be 1, 2 or 4 (got 3)");
}

} // namespace
} // namespace splatfx
