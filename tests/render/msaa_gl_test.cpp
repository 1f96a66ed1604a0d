// Multisampled host targets (4x and 8x MSAA): gl::FrameRenderer runs the
// host fog and the volumes once per sample, each against that sample's depth
// and drawing into that sample only (FrameRenderStats::msaa). So every sample
// of a pixel holds what a single-sampled frame holds at that pixel with that
// sample's surface: the host here draws a wall (a triangle with slanted edges
// at one depth, inside the volumes) over a background, and the resolved
// (glBlitFramebuffer) multisampled frame must equal, pixel by pixel,
//   c F_wall + (1 - c) F_open,
// c the pixel's wall coverage (the resolved image of the host's wall alone,
// drawn white over black), F_wall and F_open the single-sampled frames with
// the wall everywhere and nowhere. Inside the wall and outside it (c = 0 or
// 1) that is the single-sampled frame of the same host, which is checked too.
// The fragment lists read each pixel's nearest sample instead (a note says
// so): exact where c is 0 or 1, between F_wall and the nearest-sample frame
// at the wall's edges.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "scenes.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/gl/frame_plan.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/volume.hpp"
#include "transparent_glass.hpp"

namespace splatfx {
namespace {

constexpr glm::ivec2 kSize{64, 48};
constexpr GLenum kColour = GL_RGBA8;

// The host's opaque pass: a background, and a wall at one window depth (a
// triangle whose slanted edges cross pixels partially, the whole viewport, or none).
enum class Wall { None, Triangle, Full };

class Host {
public:
    Host() {
        const char* vs = R"(#version 450 core
uniform vec2 uCorner[3];
uniform float uZ;
void main() { gl_Position = vec4(uCorner[gl_VertexID], uZ, 1.0); })";
        const char* fs = R"(#version 450 core
uniform vec4 uColour;
out vec4 oColour;
void main() { oColour = uColour; })";
        auto p = gl::linkProgram({vs}, {fs}, "msaa test host");
        if (p) mProgram = *p;
        else mError = p.error();
        glCreateVertexArrays(1, &mVao);
    }
    ~Host() {
        if (mProgram) glDeleteProgram(mProgram);
        glDeleteVertexArrays(1, &mVao);
    }
    const std::string& error() const { return mError; }
    // Clears to the background and draws the wall at ndc z `z`.
    void draw(Wall wall, float z, glm::vec2 jitter = {0, 0}, glm::vec4 background = {0.1f, 0.2f, 0.3f, 1.0f},
              glm::vec4 colour = {0.55f, 0.5f, 0.4f, 1.0f}) const {
        glClearColor(background.r, background.g, background.b, background.a);
        glClearDepth(1.0);
        glDepthMask(GL_TRUE);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        if (wall == Wall::None) return;
        const float tri[6] = {-0.83f + jitter.x, -0.91f + jitter.y, 0.71f + jitter.x, -0.37f + jitter.y, -0.12f + jitter.x, 0.87f + jitter.y};
        const float full[6] = {-1.0f, -1.0f, 3.0f, -1.0f, -1.0f, 3.0f};
        glUseProgram(mProgram);
        glUniform2fv(glGetUniformLocation(mProgram, "uCorner"), 3, wall == Wall::Full ? full : tri);
        glUniform1f(glGetUniformLocation(mProgram, "uZ"), z);
        glUniform4f(glGetUniformLocation(mProgram, "uColour"), colour.r, colour.g, colour.b, colour.a);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glBindVertexArray(mVao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glUseProgram(0);
    }

private:
    GLuint mProgram = 0, mVao = 0;
    std::string mError;
};

// An RGBA8 target with a DEPTH_COMPONENT32F depth: single-sampled textures,
// or `samples` > 1: multisampled, the depth a texture or (depthRenderbuffer)
// a renderbuffer; read() resolves it with glBlitFramebuffer.
struct Target {
    GLuint fbo = 0, color = 0, depth = 0, resolveFbo = 0, resolved = 0;
    int samples = 0;
    bool renderbuffer = false;
    explicit Target(int samplesIn, bool depthRenderbuffer = false) : samples(samplesIn), renderbuffer(depthRenderbuffer) {
        glCreateFramebuffers(1, &fbo);
        if (samples > 1) {
            glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &color);
            glTextureStorage2DMultisample(color, samples, kColour, kSize.x, kSize.y, GL_TRUE);
            if (renderbuffer) {
                glCreateRenderbuffers(1, &depth);
                glNamedRenderbufferStorageMultisample(depth, samples, GL_DEPTH_COMPONENT32F, kSize.x, kSize.y);
                glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
            } else {
                glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &depth);
                glTextureStorage2DMultisample(depth, samples, GL_DEPTH_COMPONENT32F, kSize.x, kSize.y, GL_TRUE);
                glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
            }
            glCreateFramebuffers(1, &resolveFbo);
            glCreateTextures(GL_TEXTURE_2D, 1, &resolved);
            glTextureStorage2D(resolved, 1, kColour, kSize.x, kSize.y);
            glNamedFramebufferTexture(resolveFbo, GL_COLOR_ATTACHMENT0, resolved, 0);
        } else {
            glCreateTextures(GL_TEXTURE_2D, 1, &color);
            glTextureStorage2D(color, 1, kColour, kSize.x, kSize.y);
            glCreateTextures(GL_TEXTURE_2D, 1, &depth);
            glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT32F, kSize.x, kSize.y);
            glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
        }
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
    }
    ~Target() {
        glDeleteFramebuffers(1, &fbo);
        glDeleteTextures(1, &color);
        if (renderbuffer) glDeleteRenderbuffers(1, &depth);
        else glDeleteTextures(1, &depth);
        if (resolveFbo) glDeleteFramebuffers(1, &resolveFbo);
        if (resolved) glDeleteTextures(1, &resolved);
    }
    bool complete() const { return glCheckNamedFramebufferStatus(fbo, GL_DRAW_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE; }
    std::vector<float> read() const {
        GLuint from = color;
        if (samples > 1) {
            glBlitNamedFramebuffer(fbo, resolveFbo, 0, 0, kSize.x, kSize.y, 0, 0, kSize.x, kSize.y, GL_COLOR_BUFFER_BIT, GL_NEAREST);
            from = resolved;
        }
        std::vector<float> px(std::size_t(kSize.x) * kSize.y * 4);
        glGetTextureImage(from, 0, GL_RGBA, GL_FLOAT, GLsizei(px.size() * sizeof(float)), px.data());
        return px;
    }
};

int maxSamples() {
    GLint colour = 0, depth = 0;
    glGetIntegerv(GL_MAX_COLOR_TEXTURE_SAMPLES, &colour);
    glGetIntegerv(GL_MAX_DEPTH_TEXTURE_SAMPLES, &depth);
    return std::min(colour, depth);
}

// The campfire's splats, optionally the 16x16x8 cloud box around them and a fog.
struct Scene {
    Materials materials{Footprint{}};
    std::uint32_t set = materials.addTextureSet(TextureSet::turbulence({.count = 4, .size = 16, .seed = 3}));
    std::uint32_t colors = materials.addColorTable(ColorTable::fire());
    bool fog = false, clouds = false;
    std::optional<LodVolume> volume;
    std::optional<TransferFunction> transfer;
    std::optional<PreIntegrationTable> table;
    LodFrame lod;
    float wallZ = 0.0f; // ndc z of a wall through the fire's middle

    Scene(bool fogIn, bool cloudsIn) : fog(fogIn), clouds(cloudsIn) {
        const Camera cam = test::campfireCamera(kSize);
        const glm::vec4 c = cam.proj * cam.view * glm::vec4(0.0f, 4.6f, 0.0f, 1.0f);
        wallZ = c.z / c.w;
        if (clouds) {
            auto field = makeCloudVolume({.dims = {17, 17, 9}, .seed = 5, .featureCells = 6.0f, .coverage = 0.6f});
            transfer.emplace(*makeCloudTransfer({.maxExtinctionPerWorld = 2.0f}));
            table.emplace(*PreIntegrationTable::create(*transfer, {.scalarResolution = 32, .lengthResolution = 64, .maxLengthWorld = 28.0f}));
            volume.emplace(*LodVolume::create(*field, {.originWorld = {-8.0f, 0.0f, -4.0f}}));
            // Refined once for the unshifted camera: every frame draws the same tetrahedra.
            if (!volume->update(cam, {.detailC = 20.0f}, &*transfer, lod)) lod.tets.clear();
        }
    }
    // The frame, its image shifted by jitterNdc (ndc): the single-sampled
    // frames whose pixel centres sit where a sample of the multisampled one does.
    void build(Frame& frame, glm::vec2 jitterNdc) {
        Camera cam = test::campfireCamera(kSize);
        glm::mat4 shift(1.0f);
        shift[3][0] = jitterNdc.x, shift[3][1] = jitterNdc.y;
        cam.proj = shift * cam.proj;
        frame.begin(0.0, cam);
        frame.builder().add(test::campfireGrid(3), materials, {.textureSet = set, .colorTable = colors});
        if (clouds) {
            FrameVolume& fv = frame.volumes().emplace_back();
            fv.table = &*table;
            fv.lod = lod;
        }
        frame.end();
        if (fog) {
            FogDesc d;
            d.terms.push_back(FogTerm::constant(0.03));
            d.terms.push_back(FogTerm::point(0.2, {0.0, 3.0, 2.0}, 1.0, 4.0));
            d.colour = {0.7, 0.75, 0.8};
            frame.setFog(std::make_shared<const Fog>(*Fog::create(d)));
        }
    }
};

class MsaaGL : public test::GLTest {};

// The single-sampled frame with the triangle (F), the resolved multisampled
// one, the wall's coverage c of each pixel (its resolved image drawn white over
// black), the mean of the single-sampled frames shifted onto each sample's
// position, and the multisampled frame's stats.
struct Frames {
    std::vector<float> single, msaa, coverage, shiftedMean;
    gl::FrameRenderStats stats;
};

Frames renderFrames(gl::FrameRenderer& fr, Scene& s, const Host& host, int samples, bool renderbuffer,
                    const std::function<void(const Camera&)>& transparent = {}) {
    Frames out;
    auto draw = [&](Target& t, glm::vec2 jitter) {
        Frame frame;
        s.build(frame, jitter);
        std::function<void()> hook;
        if (transparent) hook = [&] { transparent(frame.camera()); };
        fr.render(frame, {.framebuffer = t.fbo,
                          .drawOpaque = [&] { host.draw(Wall::Triangle, s.wallZ, jitter); },
                          .drawTransparent = hook,
                          .transparentToLists = bool(transparent)});
        return t.read();
    };
    Target ms(samples, renderbuffer);
    EXPECT_TRUE(ms.complete());
    out.msaa = draw(ms, {0, 0});
    out.stats = fr.stats();
    glBindFramebuffer(GL_FRAMEBUFFER, ms.fbo);
    glViewport(0, 0, kSize.x, kSize.y);
    host.draw(Wall::Triangle, s.wallZ, {0, 0}, {0, 0, 0, 0}, {1, 1, 1, 1});
    std::vector<glm::vec2> positions(std::size_t(samples), glm::vec2(0.5f));
    for (int i = 0; i < samples; ++i) glGetMultisamplefv(GL_SAMPLE_POSITION, GLuint(i), &positions[std::size_t(i)].x);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    out.coverage = ms.read();

    Target t(1);
    out.single = draw(t, {0, 0});
    out.shiftedMean.assign(out.single.size(), 0.0f);
    for (const glm::vec2 o : positions) {
        // What the multisampled frame sees at p + o, the shifted one sees at its pixel centre p + 0.5.
        const std::vector<float> f = draw(t, 2.0f * (glm::vec2(0.5f) - o) / glm::vec2(kSize));
        for (std::size_t i = 0; i < f.size(); ++i) out.shiftedMean[i] += f[i] / float(samples);
    }
    return out;
}

constexpr double kBound = 2.0 / 255.0 + 1e-6;
struct Diff {
    double worst = 0.0;       // |msaa - mean of the shifted frames|, every pixel
    double meanSingle = 0.0;  // mean |msaa - single| (what anti-aliasing and the sample positions change)
    int edgePixels = 0;       // pixels the wall covers partly
};

Diff compare(const Frames& f, int samples) {
    Diff d;
    for (std::size_t p = 0; p < f.msaa.size() / 4; ++p) {
        const double c = std::round(f.coverage[p * 4] * samples) / samples;
        if (c > 0.0 && c < 1.0) ++d.edgePixels;
        for (int k = 0; k < 4; ++k) {
            const std::size_t i = p * 4 + std::size_t(k);
            d.worst = std::max(d.worst, double(std::abs(f.msaa[i] - f.shiftedMean[i])));
            d.meanSingle += std::abs(f.msaa[i] - f.single[i]) / double(f.msaa.size());
        }
    }
    return d;
}

// Each sample is shaded at its own position against its own depth, so it
// holds what the single-sampled frame shifted to put a pixel centre there
// holds: the same blends of the same inputs into RGBA8, up to the last float
// bits of the interpolation (the rasterizer's barycentrics at a sample, not
// at a pixel centre), which can turn one 8-bit rounding of a blend the other
// way in a sample (1/255, scaled by the layers over it, never more). The mean
// of the shifted frames is taken in float, the multisampled one is averaged
// and rounded once by the resolve (1/255 either way: GL does not fix the
// rounding). Bound: 2/255 at every pixel (kBound, with 1e-6 for the float
// read-back). An RGBA32F run of the same frames (no 8-bit rounding) leaves
// 1.5/255 on the cut and 0.5/255 on the fog: the splats' cut and the fog
// build their ray from gl_FragCoord, which need not move to the sample
// under sample shading, so part of the bound is that sub-pixel shift, not
// rounding.

// With tetrahedra the volumes go through the full-resolution volume layer (the
// default), a single-sampled float texture: each sample's run draws it with the
// image shifted onto that sample's positions (FrameRenderStats::msaa.layerPerSample)
// and composites it into that sample, one 8-bit rounding as in the single-sampled
// frame. Drawn at pixel centres instead, every sample got the same volumes:
// 11.5/255 from the shifted frames' mean on llvmpipe. With the layer off
// (`layer` false) the tetrahedra are drawn into each sample, the ray from the
// sample's window position: the entry point interpolated there (even
// `sample`-qualified) left 18.8/255 on llvmpipe. Either way kBound: the single-
// sampled frames are drawn with the same renderer (layer or not), so each sample
// takes the same blends rounded the same way, a last-bit difference flipping a
// rounding by one step that the blends over it scale by (1 - alpha) <= 1 and do
// not grow past one step (a difference under one step rounds to at most one).
void expectPerSample(const char* what, int samples, bool fog, bool clouds, bool layer = true) {
    Scene s(fog, clouds);
    Host host;
    ASSERT_TRUE(host.error().empty()) << host.error();
    auto fr = gl::FrameRenderer::create({.volumeLayer = layer});
    ASSERT_TRUE(fr) << fr.error();
    ASSERT_TRUE(fr->upload(s.materials));
    {
        for (bool renderbuffer : {false, true}) {
            SCOPED_TRACE(std::string(what) + ", " + std::to_string(samples) + "x, depth " + (renderbuffer ? "renderbuffer" : "texture"));
            const Frames f = renderFrames(*fr, s, host, samples, renderbuffer);
            EXPECT_EQ(f.stats.msaa.samples, samples);
            EXPECT_TRUE(f.stats.msaa.perSample);
            EXPECT_EQ(f.stats.msaa.layerPerSample, clouds && layer);
            EXPECT_EQ(f.stats.msaa.sampleCopies, samples + 1);
            EXPECT_EQ(f.stats.hostDepthCopied, renderbuffer);
            EXPECT_TRUE(f.stats.notes.empty()) << f.stats.notes.front();
            if (fog) {
                EXPECT_TRUE(f.stats.fog.host) << f.stats.fog.error;
            }
            if (clouds) {
                EXPECT_GT(f.stats.tetrahedra.drawn, 0u);
            }
            const Diff d = compare(f, samples);
            EXPECT_GT(d.edgePixels, 20) << "the wall's edges must cross pixels partially";
            EXPECT_LE(d.worst, kBound) << "each sample must hold the single-sampled frame shifted onto it";
            std::printf("%s %dx (%s depth): worst %.4f (x255 %.2f) against the shifted frames' mean, mean |msaa - 1x| %.4f, %d edge pixels\n",
                        what, samples, renderbuffer ? "renderbuffer" : "texture", d.worst, d.worst * 255.0, d.meanSingle, d.edgePixels);
        }
    }
}

// GL 4.5 guarantees 4 samples (GL_MAX_SAMPLES >= 4); 8 is the driver's choice and
// llvmpipe offers 4: the 8x cases say so and are skipped there (tools/gpu-check.sh
// runs them on a GPU). GTEST_SKIP returns from the test body, hence a macro.
#define SPLATFX_SKIP_WITHOUT_SAMPLES(n)                                                                                               \
    if (maxSamples() < (n))                                                                                                           \
    GTEST_SKIP() << (n) << "x MSAA needs GL_MAX_COLOR_TEXTURE_SAMPLES and GL_MAX_DEPTH_TEXTURE_SAMPLES >= " << (n) << "; this driver " \
                 << "offers " << maxSamples() << " (llvmpipe: 4). tools/gpu-check.sh runs it on a GPU"

TEST_F(MsaaGL, TheDepthCutRunsPerSample) { expectPerSample("cut", 4, false, false); }
TEST_F(MsaaGL, TheHostFogAndTheFoggedSplatsRunPerSample) { expectPerSample("fog", 4, true, false); }
TEST_F(MsaaGL, TheTetrahedraAndTheSplatsRunPerSample) { expectPerSample("clouds", 4, false, true); }
TEST_F(MsaaGL, TheTetrahedraRunPerSampleWithoutTheVolumeLayer) { expectPerSample("clouds, no layer", 4, false, true, false); }
TEST_F(MsaaGL, TheDepthCutRunsPerSampleAt8x) {
    SPLATFX_SKIP_WITHOUT_SAMPLES(8);
    expectPerSample("cut", 8, false, false);
}
TEST_F(MsaaGL, TheHostFogAndTheFoggedSplatsRunPerSampleAt8x) {
    SPLATFX_SKIP_WITHOUT_SAMPLES(8);
    expectPerSample("fog", 8, true, false);
}
TEST_F(MsaaGL, TheTetrahedraAndTheSplatsRunPerSampleAt8x) {
    SPLATFX_SKIP_WITHOUT_SAMPLES(8);
    expectPerSample("clouds", 8, false, true);
}

// Glass among gas: the host's surfaces go through the fragment lists once a
// frame, shaded at pixel centres against each pixel's nearest sample; the
// splats stay out of the list sections (per pixel) and are drawn per sample
// under the surfaces, in the ordered blend. Both are said in the notes; what
// the frame shows is not held to the single-sampled (order-exact) frame here.
void expectListsSayWhatRuns(int samples) {
    Scene s(false, false);
    Host host;
    ASSERT_TRUE(host.error().empty()) << host.error();
    test::Glass glass;
    ASSERT_TRUE(glass.error().empty()) << glass.error();
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr) << fr.error();
    ASSERT_TRUE(fr->upload(s.materials));
    const std::vector<test::Pane> panes{{.z = 2.0f, .premultiplied = {0.05f, 0.12f, 0.1f, 0.25f}},
                                        {.z = -1.5f, .premultiplied = {0.15f, 0.05f, 0.05f, 0.3f}}};
    {
        SCOPED_TRACE(std::to_string(samples) + "x");
        Target ms(samples);
        Frame frame;
        s.build(frame, {0, 0});
        fr->render(frame, {.framebuffer = ms.fbo,
                           .drawOpaque = [&] { host.draw(Wall::Triangle, s.wallZ); },
                           .drawTransparent = [&] { glass.draw(panes, frame.camera()); },
                           .transparentToLists = true});
        const gl::FrameRenderStats& st = fr->stats();
        EXPECT_TRUE(st.lists.used);
        EXPECT_FALSE(st.lists.splats);
        EXPECT_GT(st.lists.nodes, 0u);
        EXPECT_TRUE(st.msaa.perSample && st.msaa.listsNearest);
        EXPECT_NE(st.lists.note.find("multisampled host (" + std::to_string(samples) + " samples)"), std::string::npos) << st.lists.note;
        ASSERT_EQ(st.notes.size(), 2u);
        EXPECT_TRUE(std::any_of(st.notes.begin(), st.notes.end(), [](const std::string& n) { return n.find("nearest sample") != std::string::npos; }));
    }
}

TEST_F(MsaaGL, GlassAmongGasSaysWhatRuns) { expectListsSayWhatRuns(4); }
TEST_F(MsaaGL, GlassAmongGasSaysWhatRunsAt8x) {
    SPLATFX_SKIP_WITHOUT_SAMPLES(8);
    expectListsSayWhatRuns(8);
}

// The reduced-resolution layer (resolutionScale 2 or 4) is drawn at its own texel
// centres in every sample's run, not shifted onto the sample positions as the
// full-resolution layer is: a multisampled host is told so in stats().notes, once;
// a single-sampled host, or full resolution, has no such line.
TEST_F(MsaaGL, TheReducedLayerOnAMultisampledHostIsNoted) {
    Scene s(false, false);
    Host host;
    ASSERT_TRUE(host.error().empty()) << host.error();
    const std::string reduced = "the reduced layer is drawn at its own texel centres in every sample's run";
    for (int scale : {1, 2, 4})
        for (int samples : {1, 4}) {
            SCOPED_TRACE("resolutionScale " + std::to_string(scale) + ", " + std::to_string(samples) + " samples");
            auto fr = gl::FrameRenderer::create({.resolutionScale = scale});
            ASSERT_TRUE(fr) << fr.error();
            ASSERT_TRUE(fr->upload(s.materials));
            Target t(samples);
            ASSERT_TRUE(t.complete());
            Frame frame;
            s.build(frame, {0, 0});
            fr->render(frame, {.framebuffer = t.fbo, .drawOpaque = [&] { host.draw(Wall::Triangle, s.wallZ); }});
            const gl::FrameRenderStats& st = fr->stats();
            EXPECT_EQ(st.resolutionScale, scale);
            EXPECT_EQ(st.msaa.perSample, samples > 1);
            const auto n = std::count_if(st.notes.begin(), st.notes.end(), [&](const std::string& l) { return l.find(reduced) != std::string::npos; });
            if (scale > 1 && samples > 1) {
                ASSERT_EQ(n, 1) << "one line for every sample's run";
                const auto line = std::find_if(st.notes.begin(), st.notes.end(), [&](const std::string& l) { return l.find(reduced) != std::string::npos; });
                EXPECT_NE(line->find("resolutionScale " + std::to_string(scale)), std::string::npos) << *line;
                EXPECT_NE(line->find("(" + std::to_string(st.msaa.samples) + " samples)"), std::string::npos) << *line;
            } else {
                EXPECT_EQ(n, 0);
            }
        }
}

// gl::Framebuffer's MSAA and sRGB fields (what splatfx-render --msaa / --srgb
// draw into): bad values are refused with the field named; a multisampled one
// resolves on read() to its clear colour.
TEST_F(MsaaGL, FramebufferRefusesBadSampleCounts) {
    auto three = gl::Framebuffer::create({.width = 8, .height = 8, .samples = 3});
    ASSERT_FALSE(three);
    EXPECT_EQ(three.error(), "FramebufferDesc::samples must be 0, 1, 2, 4, 8 or 16, got 3");
    auto many = gl::Framebuffer::create({.width = 8, .height = 8, .samples = 32});
    ASSERT_FALSE(many);
    EXPECT_NE(many.error().find("FramebufferDesc::samples must be"), std::string::npos) << many.error();
    GLint maxSamples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
    if (maxSamples < 16) {
        auto above = gl::Framebuffer::create({.width = 8, .height = 8, .samples = 16});
        ASSERT_FALSE(above);
        EXPECT_NE(above.error().find("above this driver's GL_MAX_SAMPLES"), std::string::npos) << above.error();
    }
    auto srgbFloat = gl::Framebuffer::create({.width = 8, .height = 8, .color = gl::Precision::F16, .srgb = true});
    ASSERT_FALSE(srgbFloat);
    EXPECT_EQ(srgbFloat.error(), "FramebufferDesc::srgb needs color Precision::U8 (GL_SRGB8_ALPHA8)");
    auto ms = gl::Framebuffer::create({.width = 8, .height = 8, .samples = 4});
    ASSERT_TRUE(ms) << ms.error();
    ms->clear({0.25f, 0.5f, 0.75f, 1.0f});
    const Image img = ms->read();
    ASSERT_EQ(img.pixels.size(), 8u * 8u * 4u);
    // Every sample holds the clear colour: the mean is it, within the 8-bit step.
    EXPECT_NEAR(img.pixels[0], 0.25f, 0.5f / 255.0f + 1e-6f);
    EXPECT_NEAR(img.pixels[2], 0.75f, 0.5f / 255.0f + 1e-6f);
    EXPECT_TRUE(ms->readDepth().pixels.empty());
}

} // namespace
} // namespace splatfx
