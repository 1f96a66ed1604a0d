// Depth conventions (issue 26): reverse-Z, [0, 1] clip depth, infinite far.
// CPU: the projections and the one unprojection against closed forms. GL: the
// golden frame (and a frame with a host surface, the depth cut, the host fog
// and the reduced-resolution splats) in all four conventions gives the same
// 8-bit image as OpenGL's default.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "scenes.hpp"
#include "splatfx/depth_convention.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/program.hpp"

using namespace splatfx;

namespace {

const DepthConvention kFour[] = {{},
                                 {.clip = ClipDepth::ZeroToOne},
                                 {.reversed = true},
                                 {.clip = ClipDepth::ZeroToOne, .reversed = true}};

// Window depth of view depth z under `cam`, in double.
double windowOf(const Camera& cam, double z) {
    const glm::dvec4 c = glm::dmat4(cam.proj) * glm::dvec4(0.0, 0.0, -z, 1.0);
    return cam.depth.clip == ClipDepth::ZeroToOne ? c.z / c.w : 0.5 * c.z / c.w + 0.5;
}

TEST(DepthConvention, ProjectionsPutNearAndFarWhereTheConventionSays) {
    for (DepthConvention dc : kFour)
        for (bool inf : {false, true}) {
            dc.infiniteFar = inf;
            SCOPED_TRACE(describe(dc));
            const Camera cam = Camera::lookAt({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8f, {64, 48}, 0.1f, 1000.0f, dc);
            EXPECT_NEAR(windowOf(cam, 0.1), dc.nearWindow(), 1e-6);
            EXPECT_NEAR(windowOf(cam, inf ? 1e30 : 1000.0), dc.farWindow(), 1e-6);
            EXPECT_NEAR(cam.nearPlane(), 0.1f, 1e-6f);
            EXPECT_EQ(conventionOfProjection(cam.proj, dc.clip), dc);
            // The one unprojection: view depth back from window depth, at the near plane and far out.
            const DepthUnprojection u = depthUnprojection(cam);
            for (double z : {0.1, 1.0, 37.0, 999.0}) EXPECT_NEAR(u.viewDepth(windowOf(cam, z)) / z, 1.0, 1e-9) << z;
            if (inf) { EXPECT_EQ(u.viewDepth(dc.farWindow()), INFINITY); }
        }
    EXPECT_EQ(perspectiveProjection(0.8f, 1.5f, 0.1f, 100.0f), glm::perspective(0.8f, 1.5f, 0.1f, 100.0f)) << "the default is glm's";
}

TEST(DepthConvention, UnprojectionKeepsFarOverNearOf1e7) {
    // 1 / view depth is blended between its two ends, both >= 0: relative
    // error of a few roundings at any ratio (float: the uniforms and the blend).
    for (DepthConvention dc : kFour) {
        const Camera cam = Camera::lookAt({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8f, {64, 48}, 0.001f, 1e4f, dc);
        const DepthUnprojection u = depthUnprojection(cam);
        const float a = float(u.ends.x), b = float(u.ends.y);
        for (double z : {1.0, 1e2, 5e3, 9.999e3}) {
            const float d = float(windowOf(cam, z));
            const double exact = u.viewDepth(double(d)); // what the stored depth means, in double
            const float m = (1.0f - d) * a + d * b;     // host_depth.glsl, in float
            EXPECT_NEAR(double(1.0f / m) / exact, 1.0, 8.0 * 5.96e-8) << describe(dc) << " z " << z;
        }
    }
}

// A host surface: a depth-writing quad at world z = zPlane over the right part of the view.
class HostQuad {
public:
    HostQuad() {
        const char* vs = "#version 450 core\nuniform mat4 uMvp; uniform float uZ; const vec2 k[4] = vec2[4](vec2(0.5,-4),vec2(6,-4),vec2(0.5,12),vec2(6,12));\n"
                         "void main(){ gl_Position = uMvp * vec4(k[gl_VertexID], uZ, 1.0); }";
        const char* fs = "#version 450 core\nout vec4 o; void main(){ o = vec4(0.1, 0.5, 0.9, 1.0); }";
        auto linked = gl::linkProgram({vs}, {fs}, "HostQuad");
        if (linked) program = *linked;
        else ADD_FAILURE() << linked.error();
        glCreateVertexArrays(1, &vao);
    }
    ~HostQuad() {
        glDeleteProgram(program);
        glDeleteVertexArrays(1, &vao);
    }
    // The host's frame: clear (depth to the far plane's value), the quad with its convention's test.
    void draw(const Camera& cam, float z) {
        glClearColor(0.02f, 0.02f, 0.04f, 1.0f);
        glClearDepth(cam.depth.farWindow());
        glDepthMask(GL_TRUE);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glClearDepth(1.0);
        glUseProgram(program);
        const glm::mat4 mvp = cam.proj * cam.view;
        glUniformMatrix4fv(glGetUniformLocation(program, "uMvp"), 1, GL_FALSE, glm::value_ptr(mvp));
        glUniform1f(glGetUniformLocation(program, "uZ"), z);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(cam.depth.reversed ? GL_GREATER : GL_LESS);
        glDisable(GL_BLEND);
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    }
    GLuint program = 0, vao = 0;
};

struct Campfire {
    Materials materials{Footprint{}};
    std::uint32_t set = 0, table = 0;
    Campfire() {
        set = materials.addTextureSet(TextureSet::turbulence({.count = 8, .size = 32, .seed = 1}));
        table = materials.addColorTable(ColorTable::fire());
    }
};

// The golden frame (tests/golden/campfire_160x120) under convention `dc`,
// through the frame renderer: without a host surface (the golden itself), or
// with the quad through the fire, the depth cut, optionally fog and a reduced
// resolution. Reversed conventions draw into float depth, as engines do.
Image render(const DepthConvention& dc, bool host, const Fog* fog, int scale) {
    const glm::ivec2 size{160, 120};
    Campfire c;
    const Camera cam = Camera::lookAt({0.0f, 4.8f, 15.0f}, {0.0f, 4.6f, 0.0f}, {0, 1, 0}, 0.7853982f, size, 0.05f, 1000.0f, dc);
    Frame frame;
    frame.begin(0.0, cam);
    frame.builder().add(test::campfireGrid(1), c.materials, {.textureSet = c.set, .colorTable = c.table});
    frame.end();
    if (fog) frame.setFog(std::make_shared<const Fog>(*fog));
    auto fb = gl::Framebuffer::create({.width = size.x, .height = size.y, .floatDepth = dc.reversed});
    EXPECT_TRUE(fb) << fb.error();
    auto fr = gl::FrameRenderer::create({.splats = {.sampling = gl::TextureSampling::Bilinear}, .resolutionScale = scale});
    EXPECT_TRUE(fr) << fr.error();
    EXPECT_TRUE(fr->upload(c.materials));
    HostQuad quad;
    glClipControl(GL_LOWER_LEFT, dc.clip == ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    fb->clear({0.02f, 0.02f, 0.04f, 1.0f}, float(dc.farWindow()));
    fr->render(frame, {.framebuffer = fb->handle(), .drawOpaque = [&] {
                           if (host) quad.draw(cam, 0.3f);
                       }});
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    EXPECT_TRUE(fr->stats().notes.empty()) << fr->stats().notes.front();
    if (fog) { EXPECT_TRUE(fr->stats().fog.host) << fr->stats().fog.error; }
    return fb->read();
}

class DepthConventionGL : public test::GLTest {};

// The tolerance: each image is read from an RGBA8 target, so a channel is the
// float result rounded to 1/255. The four conventions compute the same
// float values up to a few roundings (the view depth of the cut, the fog
// distance: relative 1e-6, far below 1/255), which can move a value across a
// rounding boundary: one 8-bit step, never two. Stated per channel as max <= 1/255.
TEST_F(DepthConventionGL, GoldenFramesAreTheSameInAllFourConventions) {
    FogDesc fd;
    fd.terms.push_back(FogTerm::constant(0.02));
    fd.terms.push_back(FogTerm::cosine(0.02, 0.7, {1.0, 0.3, 0.0}, 0.4));
    fd.colour = {0.5, 0.55, 0.6};
    const Fog fog = *Fog::create(fd);
    auto golden = readImage(test::sourcePath("tests/golden/campfire_160x120.png"));
    ASSERT_TRUE(golden) << golden.error();
    auto limits = test::loadGoldenThresholds(test::sourcePath("tests/golden/campfire_160x120.json"));
    ASSERT_TRUE(limits) << limits.error();
    struct Case {
        const char* name;
        bool host;
        const Fog* fog;
        int scale;
    };
    for (const Case& k : {Case{"golden", false, nullptr, 1}, Case{"host quad, cut", true, nullptr, 1}, Case{"host quad, cut, fog", true, &fog, 1},
                          Case{"host quad, cut, fog, 1/2 resolution", true, &fog, 2}}) {
        const Image base = render(kFour[0], k.host, k.fog, k.scale);
        if (!k.host) {
            const test::ImageDiff d = test::compareImages(base, *golden, limits->pixelThreshold);
            EXPECT_TRUE(test::withinThresholds(d, *limits)) << "the frame renderer's golden frame, mean " << d.meanAbs * 255;
        }
        for (const DepthConvention& dc : kFour) {
            const Image img = render(dc, k.host, k.fog, k.scale);
            const test::ImageDiff d = test::compareImages(img, base, 0.5 / 255.0);
            std::printf("%s, %s: max %.1f/255, mean %.4f/255\n", k.name, describe(dc).c_str(), d.maxAbs * 255, d.meanAbs * 255);
            EXPECT_LE(d.maxAbs, 1.0 / 255.0 + 1e-6) << k.name << ", " << describe(dc) << " -- " << test::writeFailureImages(img, d);
        }
    }
}

// The helper reads glClipControl; a camera that disagrees with the context
// (or with its own projection) is said in FrameRenderStats::notes.
TEST_F(DepthConventionGL, ContextConventionIsReadAndAMismatchIsANote) {
    const DepthConvention rz{.clip = ClipDepth::ZeroToOne, .reversed = true, .infiniteFar = true};
    const Camera cam = Camera::lookAt({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8f, {32, 24}, 0.1f, 100.0f, rz);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    auto got = gl::depthConventionOfContext(cam.proj);
    ASSERT_TRUE(got) << got.error();
    EXPECT_EQ(*got, rz);
    glClipControl(GL_UPPER_LEFT, GL_ZERO_TO_ONE);
    got = gl::depthConventionOfContext(cam.proj);
    ASSERT_FALSE(got);
    EXPECT_NE(got.error().find("GL_UPPER_LEFT"), std::string::npos) << got.error();
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);

    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::constant(glm::vec4(1.0f)));
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr) << fr.error();
    ASSERT_TRUE(fr->upload(mat));
    auto fb = gl::Framebuffer::create({.width = 32, .height = 24, .floatDepth = true});
    ASSERT_TRUE(fb);
    auto notesOf = [&](const Camera& c) {
        Frame frame;
        frame.begin(0.0, c);
        frame.end();
        fr->render(frame, {.framebuffer = fb->handle()});
        std::string all;
        for (const std::string& n : fr->stats().notes) all += n + "\n";
        return all;
    };
    EXPECT_NE(notesOf(cam).find("glClipControl depth mode is GL_NEGATIVE_ONE_TO_ONE"), std::string::npos) << "[0,1] camera, [-1,1] context";
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    EXPECT_EQ(notesOf(cam), "") << "matching";
    EXPECT_EQ(fr->stats().depthConvention, "[0,1] reversed infinite far");
    Camera lying = cam;
    lying.depth.reversed = false;
    EXPECT_NE(notesOf(lying).find("projection is reversed"), std::string::npos);
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
}

} // namespace
