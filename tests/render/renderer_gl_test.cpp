#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "image_compare.hpp"
#include "scenes.hpp"
#include "splatfx/gl/program.hpp"

using namespace splatfx;

namespace {

struct FireMaterials {
    Materials materials{Footprint{}};
    std::uint32_t set = 0, table = 0;
    FireMaterials(std::uint32_t seed) {
        set = materials.addTextureSet(TextureSet::turbulence({.count = 8, .size = 32, .seed = seed}));
        table = materials.addColorTable(ColorTable::fire());
    }
};

Image renderCampfire(std::uint32_t seed, glm::ivec2 size, const gl::RendererDesc& desc = {}, const SplatVariation& variation = {}) {
    FireMaterials f(seed);
    auto fb = gl::Framebuffer::create({.width = size.x, .height = size.y});
    EXPECT_TRUE(fb) << fb.error();
    auto r = gl::Renderer::create(desc);
    EXPECT_TRUE(r) << r.error();
    const Status up = r->upload(f.materials);
    EXPECT_TRUE(up) << up.error();
    fb->clear({0.02f, 0.02f, 0.04f, 1.0f});
    const Camera cam = test::campfireCamera(size);
    SplatBuilder b;
    b.begin(cam);
    b.add(test::campfireGrid(seed), f.materials, {.textureSet = f.set, .colorTable = f.table, .variation = variation});
    b.sort();
    r->draw(b.splats(), cam, {.framebuffer = fb->handle(), .width = size.x, .height = size.y});
    return fb->read();
}

// A minimal host: one opaque, depth-writing quad in the plane z = zPlane.
class HostQuad {
public:
    HostQuad() {
        const char* vs = "#version 450 core\nuniform mat4 uMvp; const vec2 k[4] = vec2[4](vec2(0,-4),vec2(4,-4),vec2(0,12),vec2(4,12));\n"
                         "uniform float uZ; void main(){ gl_Position = uMvp * vec4(k[gl_VertexID], uZ, 1.0); }";
        const char* fs = "#version 450 core\nout vec4 o; void main(){ o = vec4(0.1, 0.5, 0.9, 1.0); }";
        auto linked = gl::linkProgram({vs}, {fs}, "HostQuad");
        if (linked) program = *linked;
        else ADD_FAILURE() << linked.error(); // the stand-in host must draw, or the depth tests prove nothing
        glCreateVertexArrays(1, &vao);
    }
    ~HostQuad() {
        glDeleteProgram(program);
        glDeleteVertexArrays(1, &vao);
    }
    // Covers x in [0, 4], y in [-4, 12] (the right half of the fire) at depth z.
    void draw(const Camera& cam, float z) {
        glUseProgram(program);
        const glm::mat4 mvp = cam.proj * cam.view;
        glUniformMatrix4fv(glGetUniformLocation(program, "uMvp"), 1, GL_FALSE, glm::value_ptr(mvp));
        glUniform1f(glGetUniformLocation(program, "uZ"), z);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glDisable(GL_BLEND);
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    }
    GLuint program = 0, vao = 0;
};

} // namespace

class RendererGL : public test::GLTest {};

void expectGolden(const Image& actual, const std::string& name) {
    const std::string goldenPath = test::sourcePath("tests/golden/" + name);
    if (std::getenv("SPLATFX_UPDATE_GOLDEN")) { ASSERT_TRUE(writeImage(goldenPath, actual)); }
    auto golden = readImage(goldenPath);
    ASSERT_TRUE(golden) << golden.error();
    // The tolerances live beside the golden, each explained there.
    auto limits = test::loadGoldenThresholds(test::sourcePath("tests/golden/campfire_160x120.json")); // shared by both goldens
    ASSERT_TRUE(limits) << limits.error();
    const test::ImageDiff d = test::compareImages(actual, *golden, limits->pixelThreshold);
    ASSERT_TRUE(d.sameSize);
    std::printf("golden diff: mean %.3f/255 max %.1f/255 over %.2f%%\n", d.meanAbs * 255, d.maxAbs * 255, d.fractionOver * 100);
    const bool ok = test::withinThresholds(d, *limits);
    EXPECT_TRUE(ok) << "mean " << d.meanAbs * 255 << "/255, max " << d.maxAbs * 255 << "/255, over " << d.fractionOver * 100 << "% -- "
                    << test::writeFailureImages(actual, d);
}

// The paper's lattice: every splat on its voxel, textures upright.
TEST_F(RendererGL, CampfireMatchesGoldenImage) {
    // Bilinear sampling, named: the default (Auto) depends on the GL.
    expectGolden(renderCampfire(1, {160, 120}, {.sampling = gl::TextureSampling::Bilinear}), "campfire_160x120.png");
}

// The presets' default SplatVariation (jittered, turned and mirrored splats),
// with the same tolerances (the same kinds of splats on the same pixels).
TEST_F(RendererGL, VariedCampfireMatchesGoldenImage) {
    expectGolden(renderCampfire(1, {160, 120}, {.sampling = gl::TextureSampling::Bilinear}, SplatVariation::recommended(1)),
                 "campfire_varied_160x120.png");
}

// Upsampled layers sampled nearest stand in for bilinear sampling: the same
// picture to within a fraction of an 8-bit step on average, and closer the
// finer the resampling.
TEST_F(RendererGL, UpsampledSamplingApproachesBilinear) {
    const glm::ivec2 size{160, 120};
    const Image bilinear = renderCampfire(1, size, {.sampling = gl::TextureSampling::Bilinear});
    const Image nearest = renderCampfire(1, size, {.sampling = gl::TextureSampling::Nearest});
    double previous = 1.0;
    for (int factor : {2, 4, 8}) {
        const Image up = renderCampfire(1, size, {.sampling = gl::TextureSampling::Upsampled, .upsample = factor});
        const double mean = test::compareImages(up, bilinear, 2.0 / 255.0).meanAbs;
        std::printf("upsampled %dx vs bilinear: mean %.3f/255\n", factor, mean * 255);
        EXPECT_LT(mean, 0.5 / 255) << factor << "x";
        EXPECT_LT(mean, previous) << factor << "x";
        previous = mean;
    }
    const double nearestMean = test::compareImages(nearest, bilinear, 2.0 / 255.0).meanAbs;
    std::printf("nearest vs bilinear: mean %.3f/255\n", nearestMean * 255);
    EXPECT_LT(previous, nearestMean);
}

// Auto: upsampled on CPU rasterizers, by 4x or 2x within the memory budget,
// bilinear on GPUs and for layers too large to upsample within it.
TEST_F(RendererGL, AutoSamplingFollowsTheRasterizerAndTheBudget) {
    const std::string name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const bool cpu = name.find("llvmpipe") != std::string::npos || name.find("softpipe") != std::string::npos;
    struct Case {
        int layerSize, count, factor; // factor expected on a CPU rasterizer (1: bilinear)
    };
    // Layers = the set plus the plain footprint (layer 0).
    for (const Case c : {Case{16, 8, 4}, Case{32, 7, 4}, Case{32, 8, 2}, Case{64, 7, 2}, Case{64, 8, 1}}) {
        Materials m{Footprint{}, {.layerSize = c.layerSize}};
        m.addTextureSet(TextureSet::turbulence({.count = c.count, .size = c.layerSize}));
        auto r = gl::Renderer::create();
        ASSERT_TRUE(r) << r.error();
        ASSERT_TRUE(r->upload(m));
        const int expected = cpu ? c.factor : 1;
        EXPECT_EQ(r->upsampleFactor(), expected) << c.layerSize << "^2 x " << c.count;
        EXPECT_EQ(r->sampling(), expected > 1 ? gl::TextureSampling::Upsampled : gl::TextureSampling::Bilinear);
    }
}

TEST_F(RendererGL, SameSeedGivesIdenticalPixels) {
    const Image a = renderCampfire(3, {96, 72});
    const Image b = renderCampfire(3, {96, 72});
    const Image c = renderCampfire(4, {96, 72});
    EXPECT_EQ(a.pixels, b.pixels);
    EXPECT_NE(a.pixels, c.pixels);
}

TEST_F(RendererGL, TexturedSplatsShowDetailTraditionalDoNot) {
    // Fig. 1: the same grid drawn traditional is smooth, textured is detailed.
    // Measure high-frequency energy (mean |Laplacian| of luminance).
    auto render = [](bool textured) {
        FireMaterials f(1);
        auto fb = gl::Framebuffer::create({.width = 160, .height = 120});
        auto r = gl::Renderer::create();
        const Status up = r->upload(f.materials);
        EXPECT_TRUE(up) << up.error();
        fb->clear({0, 0, 0, 1});
        const Camera cam = test::campfireCamera({160, 120});
        SplatBuilder b;
        b.begin(cam);
        b.add(test::campfireGrid(1), f.materials, {.textureSet = f.set, .colorTable = f.table, .textured = textured});
        b.sort();
        r->draw(b.splats(), cam, {.framebuffer = fb->handle(), .width = 160, .height = 120});
        const Image img = fb->read();
        double lap = 0.0;
        auto lum = [&](int x, int y) { return img.at(x, y, 0) + img.at(x, y, 1) + img.at(x, y, 2); };
        for (int y = 1; y < 119; ++y)
            for (int x = 1; x < 159; ++x) lap += std::abs(4 * lum(x, y) - lum(x - 1, y) - lum(x + 1, y) - lum(x, y - 1) - lum(x, y + 1));
        return lap;
    };
    EXPECT_GT(render(true), 3.0 * render(false));
}

TEST_F(RendererGL, OpaqueObjectInsideTheFireHidesExactlyTheSplatsBehindIt) {
    // Orthographic view down -z: every splat plane is parallel to the host's
    // quad at z = 0.25 (between two voxel layers, so none is coplanar), so each splat is wholly in front of it or wholly behind.
    // Drawing all splats with the depth test must then equal drawing only the
    // front splats with no depth test at all, bit for bit. This is the plain
    // test (RendererDesc::depthCut = false); the cut is tested in cut_gl_test.cpp.
    const glm::ivec2 size(120, 160);
    FireMaterials f(1);
    Grid g = test::campfireGrid(1);
    const glm::mat4 view = glm::lookAt(glm::vec3(0, 4.75f, 20), glm::vec3(0, 4.75f, 0), glm::vec3(0, 1, 0));
    const Camera cam = Camera::fromMatrices(view, glm::ortho(-4.0f, 4.0f, -5.5f, 5.5f, 1.0f, 40.0f), size);
    SplatBuilder b;
    b.begin(cam);
    b.add(g, f.materials, {.textureSet = f.set, .colorTable = f.table});
    b.sort();
    std::vector<Splat> front;
    for (const Splat& s : b.splats())
        if (s.center.z > 0.25f) front.push_back(s);
    ASSERT_GT(front.size(), 10u);
    ASSERT_LT(front.size(), b.splats().size() - 10);

    auto r = gl::Renderer::create({.depthCut = false});
    ASSERT_TRUE(r->upload(f.materials));
    auto rNoDepth = gl::Renderer::create({.depthTest = false, .depthCut = false});
    ASSERT_TRUE(rNoDepth->upload(f.materials));
    HostQuad quad;
    const gl::PassTarget target{.framebuffer = 0, .width = size.x, .height = size.y};

    auto fbA = gl::Framebuffer::create({.width = size.x, .height = size.y});
    fbA->clear({0, 0, 0, 1});
    glBindFramebuffer(GL_FRAMEBUFFER, fbA->handle());
    glViewport(0, 0, size.x, size.y);
    quad.draw(cam, 0.25f);
    r->draw(b.splats(), cam, {.framebuffer = fbA->handle(), .width = size.x, .height = size.y});
    const Image a = fbA->read();

    auto fbB = gl::Framebuffer::create({.width = size.x, .height = size.y});
    fbB->clear({0, 0, 0, 1});
    glBindFramebuffer(GL_FRAMEBUFFER, fbB->handle());
    quad.draw(cam, 0.25f);
    auto fbC = gl::Framebuffer::create({.width = size.x, .height = size.y});
    fbC->clear({0, 0, 0, 1});
    rNoDepth->draw(b.splats(), cam, {.framebuffer = fbC->handle(), .width = size.x, .height = size.y});
    rNoDepth->draw(front, cam, {.framebuffer = fbB->handle(), .width = size.x, .height = size.y});
    const Image expectedQuad = fbB->read(), expectedOpen = fbC->read();
    (void)target;

    int quadPixels = 0;
    for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) {
            // The quad covers world x >= 0: the right half of the image.
            const bool covered = x >= size.x / 2;
            const Image& e = covered ? expectedQuad : expectedOpen;
            quadPixels += covered;
            for (int c = 0; c < 4; ++c)
                ASSERT_EQ(a.at(x, y, c), e.at(x, y, c)) << "pixel " << x << "," << y << (covered ? " (behind quad)" : " (open)");
        }
    EXPECT_GT(quadPixels, 0);
}

TEST_F(RendererGL, CameraInsideTheVolumeGivesFiniteInRangePixels) {
    FireMaterials f(1);
    const glm::ivec2 size(96, 96);
    auto fb = gl::Framebuffer::create({.width = size.x, .height = size.y, .color = gl::Precision::F32});
    auto r = gl::Renderer::create();
    ASSERT_TRUE(r->upload(f.materials));
    const Grid g = test::campfireGrid(1);
    int visible = 0;
    // Eye at a voxel centre, between voxels, and looking along each axis.
    for (glm::vec3 eye : {glm::vec3(0, 2.5f, 0), glm::vec3(0.25f, 3.1f, 0.2f)})
        for (glm::vec3 look : {glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0.01f)}) {
            const Camera cam = Camera::lookAt(eye, eye + look, {0, 1, 0}, 1.4f, size, 0.01f, 100.0f);
            SplatBuilder b;
            b.begin(cam);
            b.add(g, f.materials, {.textureSet = f.set, .colorTable = f.table});
            b.sort();
            fb->clear({0, 0, 0, 0});
            r->draw(b.splats(), cam, {.framebuffer = fb->handle(), .width = size.x, .height = size.y});
            const Image img = fb->read();
            for (float v : img.pixels) {
                ASSERT_TRUE(std::isfinite(v));
                ASSERT_GE(v, 0.0f);
                ASSERT_LE(v, 1.0f + 1e-6f);
            }
            for (size_t p = 3; p < img.pixels.size(); p += 4) visible += img.pixels[p] > 0.01f;
        }
    EXPECT_GT(visible, 100); // the fire is seen from inside, not culled away
}

// A program the host deleted while bound lives only until draw() replaces
// it; restoring must not rebind the dead name (GL_INVALID_VALUE).
TEST_F(RendererGL, RestoringSurvivesAProgramTheHostDeleted) {
    FireMaterials f(1);
    auto fb = gl::Framebuffer::create({.width = 32, .height = 32});
    auto r = gl::Renderer::create();
    ASSERT_TRUE(fb && r && r->upload(f.materials));
    std::optional<HostQuad> quad{std::in_place};
    glUseProgram(quad->program);
    quad.reset(); // deletes its program (flagged, still current) and vertex array
    ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));
    const Camera cam = test::campfireCamera({32, 32});
    SplatBuilder b;
    b.begin(cam);
    b.add(test::campfireGrid(1), f.materials, {.textureSet = f.set, .colorTable = f.table});
    b.sort();
    r->draw(b.splats(), cam, {.framebuffer = fb->handle(), .width = 32, .height = 32});
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
    GLint current = -1;
    glGetIntegerv(GL_CURRENT_PROGRAM, &current);
    EXPECT_EQ(current, 0);
}

TEST_F(RendererGL, HostStateIsUnchangedAfterDraw) {
    while (glGetError() != GL_NO_ERROR) {} // start from a clean error state
    FireMaterials f(1);
    auto host = gl::Framebuffer::create({.width = 64, .height = 64});
    auto r = gl::Renderer::create();
    ASSERT_TRUE(r->upload(f.materials));
    HostQuad quad; // gives us a host program and vertex array to leave bound
    GLuint tex0 = 0, tex1 = 0, buffer = 0;
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &tex0);
    glCreateTextures(GL_TEXTURE_2D, 1, &tex1);
    glCreateBuffers(1, &buffer);
    glBindFramebuffer(GL_FRAMEBUFFER, host->handle());
    glUseProgram(quad.program);
    glBindVertexArray(quad.vao);
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, tex0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, tex1);
    glActiveTexture(GL_TEXTURE3);
    glViewport(3, 5, 17, 19);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_COLOR, GL_DST_ALPHA, GL_ZERO, GL_SRC_ALPHA);
    glBlendEquationSeparate(GL_FUNC_SUBTRACT, GL_MAX);
    glDisable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glEnable(GL_CULL_FACE);
    glColorMask(GL_TRUE, GL_FALSE, GL_TRUE, GL_FALSE);

    ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR)) << "host setup";
    const Camera cam = test::campfireCamera({64, 64});
    SplatBuilder b;
    b.begin(cam);
    b.add(test::campfireGrid(1), f.materials, {.textureSet = f.set, .colorTable = f.table});
    b.sort();
    r->draw(b.splats(), cam, {.framebuffer = host->handle(), .width = 64, .height = 64});
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR)) << "draw";

    auto geti = [](GLenum e) {
        GLint v = 0;
        glGetIntegerv(e, &v);
        return v;
    };
    EXPECT_EQ(geti(GL_DRAW_FRAMEBUFFER_BINDING), GLint(host->handle()));
    EXPECT_EQ(geti(GL_CURRENT_PROGRAM), GLint(quad.program));
    EXPECT_EQ(geti(GL_VERTEX_ARRAY_BINDING), GLint(quad.vao));
    EXPECT_EQ(geti(GL_ARRAY_BUFFER_BINDING), GLint(buffer));
    EXPECT_EQ(geti(GL_ACTIVE_TEXTURE), GL_TEXTURE3);
    GLint vp[4];
    glGetIntegerv(GL_VIEWPORT, vp);
    EXPECT_EQ(glm::ivec4(vp[0], vp[1], vp[2], vp[3]), glm::ivec4(3, 5, 17, 19));
    EXPECT_TRUE(glIsEnabled(GL_BLEND));
    EXPECT_FALSE(glIsEnabled(GL_DEPTH_TEST));
    EXPECT_TRUE(glIsEnabled(GL_CULL_FACE));
    EXPECT_EQ(geti(GL_BLEND_SRC_RGB), GL_SRC_COLOR);
    EXPECT_EQ(geti(GL_BLEND_DST_RGB), GL_DST_ALPHA);
    EXPECT_EQ(geti(GL_BLEND_SRC_ALPHA), GL_ZERO);
    EXPECT_EQ(geti(GL_BLEND_DST_ALPHA), GL_SRC_ALPHA);
    EXPECT_EQ(geti(GL_BLEND_EQUATION_RGB), GL_FUNC_SUBTRACT);
    EXPECT_EQ(geti(GL_BLEND_EQUATION_ALPHA), GL_MAX);
    EXPECT_EQ(geti(GL_DEPTH_FUNC), GL_GREATER);
    GLboolean mask = GL_FALSE, color[4];
    glGetBooleanv(GL_DEPTH_WRITEMASK, &mask);
    glGetBooleanv(GL_COLOR_WRITEMASK, color);
    EXPECT_TRUE(mask);
    EXPECT_TRUE(color[0] && !color[1] && color[2] && !color[3]);
    glActiveTexture(GL_TEXTURE0);
    EXPECT_EQ(geti(GL_TEXTURE_BINDING_2D_ARRAY), GLint(tex0));
    glActiveTexture(GL_TEXTURE1);
    EXPECT_EQ(geti(GL_TEXTURE_BINDING_2D), GLint(tex1));
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));

    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glActiveTexture(GL_TEXTURE0);
    glDeleteTextures(1, &tex0);
    glDeleteTextures(1, &tex1);
    glDeleteBuffers(1, &buffer);
}
