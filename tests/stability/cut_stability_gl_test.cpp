// The depth cut's and the fragment lists' hard cases (issues 15, 24) through
// the GL renderer, each against the splat-exact reference with the same cut
// (and, for the lists, the same transparent surfaces; their bound is derived
// above ListStability), and for continuity: a surface
// moved by 2 eps across a coincidence (voxel centres, a splat plane) must
// change the image no more than a move of 2 eps elsewhere does (the cut image
// is a smooth function of the surface depth, so equal moves give equal
// changes up to curvature; factor 2), while the plain test pops.
//
// Scenes: one constant colour over a constant background (as
// stability_gl_test.cpp), so the error bound is per fragment:
//   n ln2 density_max (window error + cut error) + RGBA16F row + F32 blending,
// with the cut error per fragment (in units of the detail) bounded by
//   2 x (table error of fractionBefore, sampled 8x per cell, plus llvmpipe's
//   8-bit filter weights: 1/256 of the largest step per axis)
//   + (h(0) / F(0)) x (depth-linearization error) / l_min,
// since detail x d(share)/ds <= h(r) / F(0) <= h(0) / F(0) (footprint.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

#include "../reference/gl_bounds.hpp"
#include "gl_fixture.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/transparency.hpp"
#include "transparent_glass.hpp"

namespace splatfx {
namespace {

const glm::vec4 kColour{0.9f, 0.6f, 0.3f, 1.0f};
const glm::vec4 kBackground{0.1f, 0.15f, 0.2f, 1.0f};

Materials plain() {
    Materials m{Footprint{}};
    m.addColorTable(ColorTable::constant(kColour));
    return m;
}

Grid block(int n, float spacing, float opacity) {
    Grid g = *Grid::box({n, n, n}, glm::vec3(spacing));
    for (Voxel& v : g.voxels) v.opacity = opacity;
    return g;
}

// Window depth of view depth z for this camera's projection and depth convention.
float windowDepth(const Camera& cam, float z) {
    const glm::vec4 c = cam.proj * glm::vec4(0.0f, 0.0f, -z, 1.0f);
    return cam.depth.clip == ClipDepth::ZeroToOne ? c.z / c.w : 0.5f * c.z / c.w + 0.5f;
}

// Largest table error of fractionBefore, in share units (see the header).
double tableError(const Footprint& fp) {
    const double R = fp.radius();
    const int rows = fp.partialRows(), cols = fp.partialCols();
    double worst = 0.0;
    for (int i = 0; i <= (rows - 1) * 8; ++i)
        for (int j = 0; j <= (cols - 1) * 8; ++j) {
            const double r = std::min(R * i / ((rows - 1) * 8.0), R * (1.0 - 1e-3)), sigma = -1.0 + 2.0 * j / ((cols - 1) * 8.0);
            const double c = std::sqrt(R * R - r * r);
            worst = std::max(worst, std::abs(double(fp.fractionBefore(float(r), float(sigma * c))) - fp.exactFractionBefore(r, sigma * c)));
        }
    double step = 0.0;
    const std::vector<float>& t = fp.partialTable();
    for (int i = 0; i < rows; ++i)
        for (int j = 0; j < cols; ++j) {
            const float v = t[size_t(i) * cols + j];
            if (j + 1 < cols) step = std::max(step, double(std::abs(t[size_t(i) * cols + j + 1] - v)));
            if (i + 1 < rows) step = std::max(step, double(std::abs(t[size_t(i + 1) * cols + j] - v)));
        }
    return worst + 2.0 * step / 256.0 + 1e-6;
}

// The host's opaque geometry: world-space triangles drawn into the bound
// framebuffer's depth with the depth test of the camera's convention, in
// the background colour by default (so only the depth changes).
// The largest slope of the bilinear table in s (kernel units), times the
// exact window F(r) / F(0): the most detail x d(share)/ds of a GL fragment.
// The lookup is bilinear in (r, sigma), so its slope in s is largest on cell
// edges; sampled 8x per cell in r and once per cell in sigma (linear there).
double glTableSlope(const Footprint& fp) {
    const double R = fp.radius(), F0 = fp.exact(0.0);
    const int rows = fp.partialRows(), cols = fp.partialCols();
    double worst = 0.0;
    for (int i = 0; i <= (rows - 1) * 8; ++i) {
        const double r = std::min(R * i / ((rows - 1) * 8.0), R * (1.0 - 1e-3)), chord = std::sqrt(R * R - r * r);
        for (int j = 0; j + 1 < cols; ++j) {
            const double s0 = chord * (-1.0 + 2.0 * (j + 0.25) / (cols - 1)), s1 = chord * (-1.0 + 2.0 * (j + 0.75) / (cols - 1));
            const double slope = std::abs(double(fp.fractionBefore(float(r), float(s1))) - fp.fractionBefore(float(r), float(s0))) / (s1 - s0);
            worst = std::max(worst, slope * fp.exact(r) / F0);
        }
    }
    return worst;
}

class OpaqueTriangles {
public:
    OpaqueTriangles() {
        const char* vs = "#version 450 core\nlayout(location = 0) in vec3 aPosition;\nuniform mat4 uViewProj;\n"
                         "void main() { gl_Position = uViewProj * vec4(aPosition, 1.0); }\n";
        const char* fs = "#version 450 core\nuniform vec4 uColour;\nout vec4 oColour;\nvoid main() { oColour = uColour; }\n";
        auto prog = gl::linkProgram({vs}, {fs}, "opaque host triangles");
        EXPECT_TRUE(prog) << prog.error();
        if (prog) mProgram = *prog;
        glCreateVertexArrays(1, &mVao);
        glCreateBuffers(1, &mVbo);
    }
    ~OpaqueTriangles() {
        if (mProgram) glDeleteProgram(mProgram);
        glDeleteVertexArrays(1, &mVao);
        glDeleteBuffers(1, &mVbo);
    }
    void draw(const std::vector<glm::vec3>& triangles, const Camera& cam, glm::vec4 colour = kBackground) const {
        glNamedBufferData(mVbo, GLsizeiptr(triangles.size() * sizeof(glm::vec3)), triangles.data(), GL_DYNAMIC_DRAW);
        glVertexArrayVertexBuffer(mVao, 0, mVbo, 0, sizeof(glm::vec3));
        glVertexArrayAttribFormat(mVao, 0, 3, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(mVao, 0, 0);
        glEnableVertexArrayAttrib(mVao, 0);
        const glm::mat4 vp = cam.proj * cam.view;
        glUseProgram(mProgram);
        glUniformMatrix4fv(glGetUniformLocation(mProgram, "uViewProj"), 1, GL_FALSE, &vp[0][0]);
        glUniform4f(glGetUniformLocation(mProgram, "uColour"), colour.r, colour.g, colour.b, colour.a);
        glDisable(GL_BLEND);
        glDisable(GL_CULL_FACE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(cam.depth.reversed ? GL_GEQUAL : GL_LEQUAL);
        glDepthMask(GL_TRUE);
        glBindVertexArray(mVao);
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(triangles.size()));
        glBindVertexArray(0);
        glUseProgram(0);
        glDisable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
    }

private:
    GLuint mProgram = 0, mVao = 0, mVbo = 0;
};

// The quad a, b, c, d as two triangles.
std::vector<glm::vec3> quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) { return {a, b, c, a, c, d}; }

class CutStability : public test::GLTest {
protected:
    struct Frame {
        Image gl, ref, depth;
        double worst = 0.0, bound = 0.0;
        double n = 0.0, density = 0.0, minScale = 0.0; // most fragments on a pixel, largest density, smallest ray scale
        gl::DrawStats stats{};
    };

    // The host under the splats: a plane facing the camera at view depth
    // zSurface (a constant window depth; < 0: none), or the window depth
    // `depth` when >= 0, then `opaque` drawn into the cleared depth (the
    // host's geometry; colour kBackground, so the background stays constant).
    struct Host {
        float zSurface = -1.0f;
        float depth = -1.0f;
        std::function<void()> opaque{};
        bool cut = true;
        int floatDepth = -1; // -1: the convention's (float when reversed)
        double zMax = 0.0;   // largest finite view depth of the host surface, for the bound; 0: from zSurface
        gl::RendererDesc renderer{.sampling = gl::TextureSampling::Bilinear};
    };

    // Draws the splats over the host, GL and reference, and compares them.
    Frame drawOver(const std::vector<Splat>& splats, const Camera& cam, const Materials& mat, const Host& host) {
        Frame f;
        gl::RendererDesc rdesc = host.renderer;
        rdesc.depthCut = host.cut;
        auto r = gl::Renderer::create(rdesc);
        EXPECT_TRUE(r) << r.error();
        const Status up = r->upload(mat);
        EXPECT_TRUE(up) << up.error();
        // A reversed host draws into float depth (the engines' reverse-Z setup).
        const bool floatDepth = host.floatDepth < 0 ? cam.depth.reversed : host.floatDepth != 0;
        auto fb = gl::Framebuffer::create({.width = cam.viewport.x, .height = cam.viewport.y, .color = gl::Precision::F32, .floatDepth = floatDepth});
        EXPECT_TRUE(fb);
        const float depth = host.depth >= 0.0f ? host.depth : host.zSurface > 0.0f ? windowDepth(cam, host.zSurface) : float(cam.depth.farWindow());
        fb->clear(kBackground, depth);
        glClipControl(GL_LOWER_LEFT, cam.depth.clip == ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
        if (host.opaque) {
            glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
            glViewport(0, 0, cam.viewport.x, cam.viewport.y);
            host.opaque();
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
        }
        const Image depthImage = fb->readDepth();
        r->draw(splats, cam, {.framebuffer = fb->handle(), .width = cam.viewport.x, .height = cam.viewport.y});
        glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        if (host.cut && rdesc.depthTest) { EXPECT_TRUE(r->stats().cutHostDepth) << "the framebuffer depth texture must be read"; }
        f.stats = r->stats();
        f.gl = fb->read();
        f.depth = depthImage;
        SplatExactDesc rd;
        rd.host.background = kBackground;
        if (rdesc.depthTest) rd.host.depth = &depthImage;
        rd.depthCut = host.cut;
        rd.threads = 2;
        SplatExactStats stats;
        auto ref = renderSplatExact(splats, cam, mat, rd, &stats);
        EXPECT_TRUE(ref) << ref.error();
        f.ref = *ref;
        double maxDensity = 0.0, minScale = 1e30;
        for (const Splat& s : splats) {
            maxDensity = std::max(maxDensity, double(s.density));
            minScale = std::min(minScale, double(splatRayScale(s, mat.footprint().radius())));
        }
        const Footprint& fp = mat.footprint();
        // Depth linearization in float (GLSL): view depth to ~2^-22 relative, twice (surface, fragment).
        const double zMax = std::max(host.zMax > 0.0 ? host.zMax : double(host.zSurface), 1.0) * 2.0;
        const double depthErr = 4.0 * std::ldexp(zMax, -22) / minScale;
        const double cutErr = 2.0 * tableError(fp) + fp.kernel(0.0) / fp.exact(0.0) * depthErr;
        f.n = double(stats.maxOverlap);
        f.density = maxDensity;
        f.minScale = minScale;
        f.bound = f.n * std::log(2.0) * maxDensity * (test::windowErrorBound(mat, 0) + (host.cut ? cutErr : 0.0)) + std::ldexp(1.0, -11) +
                  f.n * std::ldexp(1.0, -24);
        for (size_t i = 0; i < f.gl.pixels.size(); ++i) {
            const float v = f.gl.pixels[i];
            EXPECT_TRUE(std::isfinite(v)) << "pixel value " << i;
            EXPECT_GE(v, 0.0f);
            EXPECT_LE(v, 1.0f);
            f.worst = std::max(f.worst, double(std::abs(v - f.ref.pixels[i])));
        }
        return f;
    }

    // Over a plane facing the camera at view depth zSurface (< 0: none), or the window depth depthOverride.
    Frame draw(const std::vector<Splat>& splats, const Camera& cam, const Materials& mat, float zSurface, bool cut = true,
               float depthOverride = -1.0f) {
        return drawOver(splats, cam, mat, {.zSurface = zSurface, .depth = depthOverride, .cut = cut});
    }

    static double maxDiff(const Image& a, const Image& b) {
        double m = 0.0;
        for (size_t i = 0; i < a.pixels.size(); ++i) m = std::max(m, double(std::abs(a.pixels[i] - b.pixels[i])));
        return m;
    }
    static double visible(const Image& img) {
        double peak = 0.0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) peak = std::max(peak, double(std::abs(img.at(x, y, 0) - kBackground.r)));
        return peak;
    }

    // The continuity check around zCoincident (see the header), GL and reference.
    void continuity(const std::vector<Splat>& splats, const Camera& cam, const Materials& mat, float zCoincident, float eps, bool plainPops = true) {
        const Frame below = draw(splats, cam, mat, zCoincident - eps), above = draw(splats, cam, mat, zCoincident + eps),
                    further = draw(splats, cam, mat, zCoincident + 3.0f * eps);
        for (const Frame* f : {&below, &above, &further}) EXPECT_LE(f->worst, f->bound) << "GL against the reference";
        const double across = maxDiff(below.gl, above.gl), beside = maxDiff(above.gl, further.gl);
        const double acrossRef = maxDiff(below.ref, above.ref), besideRef = maxDiff(above.ref, further.ref);
        std::printf("  across the coincidence %.3e (reference %.3e), beside it %.3e (reference %.3e)\n", across, acrossRef, beside, besideRef);
        EXPECT_GT(beside, 1e-4) << "the surface must cut visible splats";
        // The GL error at each of the two frames can add to the difference.
        EXPECT_LE(across, 2.0 * beside + 2.0 * below.bound) << "the cut must not pop";
        EXPECT_LE(acrossRef, 2.0 * besideRef) << "the reference must not pop";
        // The plain test pops there: a whole layer of splats appears at once.
        if (!plainPops) return;
        const Frame plainBelow = draw(splats, cam, mat, zCoincident - eps, false), plainAbove = draw(splats, cam, mat, zCoincident + eps, false);
        const double plainAcross = maxDiff(plainBelow.gl, plainAbove.gl);
        std::printf("  plain depth test across it %.3e\n", plainAcross);
        EXPECT_GT(plainAcross, 4.0 * across) << "the plain test was expected to pop here (else this case proves nothing)";
    }
};

TEST_F(CutStability, SurfaceExactlyThroughVoxelCentres) {
    const Materials mat = plain();
    const Grid g = block(6, 0.3f, 0.35f);
    // Looking down -z at a voxel centre from 4 units: the surface at view
    // depth 4 is the plane through that voxel layer's centres.
    const glm::vec3 centre = g.worldPosition({3, 3, 3});
    const Camera cam = Camera::lookAt(centre + glm::vec3(0.0f, 0.0f, 4.0f), centre, {0, 1, 0}, 0.7f, {48, 40}, 0.5f, 50.0f);
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    b.sort();
    // The surface through the centres of the layer containing `centre` (view depth 4 on the axis).
    continuity(b.splats(), cam, mat, 4.0f, 0.003f);
}

TEST_F(CutStability, SurfaceCoplanarWithASplatPlane) {
    // Orthographic: every splat plane faces the camera, so a surface at a
    // voxel layer's depth is coplanar with that layer's splats.
    const Materials mat = plain();
    const Grid g = block(6, 0.3f, 0.35f);
    const glm::vec3 centre = g.worldPosition({3, 3, 3});
    const glm::mat4 view = glm::lookAt(centre + glm::vec3(0.0f, 0.0f, 4.0f), centre, glm::vec3(0, 1, 0));
    const Camera cam = Camera::fromMatrices(view, glm::ortho(-1.2f, 1.2f, -1.0f, 1.0f, 0.5f, 50.0f), {48, 40});
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    b.sort();
    continuity(b.splats(), cam, mat, 4.0f, 0.003f);
}

TEST_F(CutStability, DepthEqualToTheNearPlane) {
    // A surface at the near plane (window depth 0) hides everything: the
    // share between the near plane and the surface is empty.
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.5f);
    const glm::vec3 centre = g.worldPosition({2, 2, 2});
    const Camera cam = Camera::lookAt(centre + glm::vec3(0.1f, 0.2f, 0.35f), centre, {0, 1, 0}, 1.2f, {40, 32}, 0.2f, 50.0f);
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    b.sort();
    ASSERT_GT(b.splats().size(), 10u);
    const Frame f = draw(b.splats(), cam, mat, 0.2f, true, 0.0f);
    for (int y = 0; y < f.ref.height; ++y)
        for (int x = 0; x < f.ref.width; ++x)
            for (int c = 0; c < 4; ++c) ASSERT_EQ(f.ref.at(x, y, c), kBackground[c]) << "reference at " << x << "," << y;
    EXPECT_LE(f.worst, f.bound) << "GL must show the background too";
    // Without the surface the block is visible (so the test proves something).
    const Frame open = draw(b.splats(), cam, mat, -1.0f);
    EXPECT_GT(visible(open.ref), 0.1);
    EXPECT_LE(open.worst, open.bound);
}

TEST_F(CutStability, CameraInsideAKernelWithASurfaceInsideItToo) {
    // The eye 0.12 voxel units from a voxel centre (inside its support, R =
    // 1.6 voxel units), looking slightly off the centre; the surface at view
    // depth 0.2, also inside that kernel's support (0.3 x 1.6 = 0.48).
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.4f);
    const glm::vec3 c = g.worldPosition({2, 2, 2});
    const glm::vec3 eye = c + glm::vec3(0.02f, -0.01f, 0.03f);
    const Camera cam = Camera::lookAt(eye, eye + glm::vec3(0.15f, 0.1f, -1.0f), {0, 1, 0}, 1.2f, {40, 32}, 0.02f, 50.0f);
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    b.sort();
    ASSERT_GT(b.splats().size(), 10u);
    // No splat plane lies at depth 0.2, so the plain test has nothing to pop there.
    continuity(b.splats(), cam, mat, 0.2f, 0.003f, false);
    const Frame open = draw(b.splats(), cam, mat, -1.0f);
    EXPECT_LE(open.worst, open.bound) << "the camera inside a kernel, no surface";
}

// The engines' convention (issue 26): reverse-Z, [0, 1] clip depth, float
// depth. The same coincidence cases: the cut must not pop, the plain test
// (GEQUAL now) must, GL against the reference with the same bound.
constexpr DepthConvention kReverseZ{.clip = ClipDepth::ZeroToOne, .reversed = true};

TEST_F(CutStability, SurfaceExactlyThroughVoxelCentresReverseZ) {
    const Materials mat = plain();
    const Grid g = block(6, 0.3f, 0.35f);
    const glm::vec3 centre = g.worldPosition({3, 3, 3});
    const Camera cam = Camera::lookAt(centre + glm::vec3(0.0f, 0.0f, 4.0f), centre, {0, 1, 0}, 0.7f, {48, 40}, 0.5f, 50.0f, kReverseZ);
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    b.sort();
    continuity(b.splats(), cam, mat, 4.0f, 0.003f);
}

TEST_F(CutStability, CameraInsideAKernelWithASurfaceInsideItTooReverseZInfiniteFar) {
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.4f);
    const glm::vec3 c = g.worldPosition({2, 2, 2});
    const glm::vec3 eye = c + glm::vec3(0.02f, -0.01f, 0.03f);
    DepthConvention dc = kReverseZ;
    dc.infiniteFar = true;
    const Camera cam = Camera::lookAt(eye, eye + glm::vec3(0.15f, 0.1f, -1.0f), {0, 1, 0}, 1.2f, {40, 32}, 0.02f, 50.0f, dc);
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    b.sort();
    ASSERT_GT(b.splats().size(), 10u);
    continuity(b.splats(), cam, mat, 0.2f, 0.003f, false);
    const Frame open = draw(b.splats(), cam, mat, -1.0f);
    EXPECT_LE(open.worst, open.bound) << "the camera inside a kernel, no surface, sky at infinity";
}

// ---- Issue 24: the depth cut's further edges ----

std::vector<Splat> built(const Grid& g, const Camera& cam, const Materials& mat) {
    SplatBuilder b;
    b.begin(cam);
    b.add(g, mat, {.textured = false});
    b.sort();
    return b.splats();
}

TEST_F(CutStability, SkyDepthWithTheFarPlaneThroughTheKernels) {
    // The host's sky (window depth 1: the far plane) with the far plane
    // through the block's middle layer: each kernel it crosses keeps its share
    // in front of the far plane, including those whose splat plane lies beyond
    // it (GL clipped their polygons whole until the vertex stage moved them in
    // front of the far plane: 8x the error of the same cut by a surface).
    // The far plane at view depth 4 is the same cut as a host surface at view
    // depth 4 with the far plane beyond it, so GL's error against the
    // reference must be that frame's (factor 2 for the depths' different
    // rounding, as in continuity()), besides the per-fragment bound.
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.5f);
    const glm::vec3 centre = g.worldPosition({2, 2, 2});
    const glm::vec3 eye = centre + glm::vec3(0.05f, 0.03f, 4.0f);
    const Camera cam = Camera::lookAt(eye, centre, {0, 1, 0}, 0.7f, {32, 24}, 0.5f, 4.0f);
    const std::vector<Splat> splats = built(g, cam, mat);
    ASSERT_GT(splats.size(), 50u);
    const Frame f = drawOver(splats, cam, mat, {.zMax = 4.0});
    EXPECT_LE(f.worst, f.bound) << "sky at the far plane, the cut on";
    EXPECT_GT(f.stats.cutHost, 0u) << "the far plane meets the kernels: the host-depth variant must draw them";
    const Camera open = Camera::lookAt(eye, centre, {0, 1, 0}, 0.7f, {32, 24}, 0.5f, 50.0f);
    const std::vector<Splat> openSplats = built(g, open, mat);
    const Frame surface = draw(openSplats, open, mat, 4.0f);
    std::printf("  far plane at 4: error %.3e; a surface at 4, far 50: %.3e\n", f.worst, surface.worst);
    EXPECT_LE(f.worst, 2.0 * surface.worst + std::ldexp(1.0, -11));
    // The far plane does cut: the block seen with the far plane beyond it is denser.
    const Frame whole = draw(openSplats, open, mat, -1.0f);
    EXPECT_GT(maxDiff(whole.ref, f.ref), 0.05);
    // Orthographic (the polygons are shifted along the view, not scaled about the eye).
    const glm::mat4 view = glm::lookAt(eye, centre, glm::vec3(0, 1, 0));
    const Camera ortho = Camera::fromMatrices(view, glm::ortho(-1.0f, 1.0f, -0.8f, 0.8f, 0.5f, 4.0f), {32, 24});
    const Camera orthoOpen = Camera::fromMatrices(view, glm::ortho(-1.0f, 1.0f, -0.8f, 0.8f, 0.5f, 50.0f), {32, 24});
    const Frame o = drawOver(built(g, ortho, mat), ortho, mat, {.zMax = 4.0});
    const Frame oSurface = draw(built(g, orthoOpen, mat), orthoOpen, mat, 4.0f);
    std::printf("  orthographic: far plane at 4: error %.3e; a surface at 4, far 50: %.3e\n", o.worst, oSurface.worst);
    EXPECT_LE(o.worst, o.bound);
    EXPECT_LE(o.worst, 2.0 * oSurface.worst + std::ldexp(1.0, -11));
}

TEST_F(CutStability, SurfaceAMicronFromASplatPlane) {
    // Orthographic, float depth: the surface 1e-6 in front of and behind a
    // splat layer's plane (a few float steps of its window depth). The cut
    // share is continuous in the surface depth, so the image moves by at most
    // its slope times the move: per fragment ln2 density x detail x
    // d(share)/ds x ds, with detail x d(share)/ds <= h(0)/F(0) for the exact
    // fraction (the reference) and, for GL, the largest slope of the
    // bilinear table (glTableSlope) times the window (plus its 8-bit error),
    // over ds = (the depths' difference, read back, + GL's float rounding of
    // both view depths) / l. The plain test pops by a whole layer there.
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.35f);
    const glm::vec3 centre = g.worldPosition({2, 2, 2});
    const glm::mat4 view = glm::lookAt(centre + glm::vec3(0.0f, 0.0f, 4.0f), centre, glm::vec3(0, 1, 0));
    const Camera cam = Camera::fromMatrices(view, glm::ortho(-1.0f, 1.0f, -0.8f, 0.8f, 0.5f, 50.0f), {25, 20});
    const std::vector<Splat> splats = built(g, cam, mat);
    const float eps = 1e-6f;
    const Frame below = drawOver(splats, cam, mat, {.zSurface = 4.0f - eps, .floatDepth = 1, .zMax = 4.0});
    const Frame above = drawOver(splats, cam, mat, {.zSurface = 4.0f + eps, .floatDepth = 1, .zMax = 4.0});
    EXPECT_LE(below.worst, below.bound);
    EXPECT_LE(above.worst, above.bound);
    const DepthUnprojection un = depthUnprojection(cam);
    const double dz = std::abs(un.viewDepth(above.depth.at(0, 0, 0)) - un.viewDepth(below.depth.at(0, 0, 0)));
    EXPECT_GT(dz, 0.0) << "float depth must resolve the move";
    EXPECT_LE(dz, 4.0 * eps);
    const Footprint& fp = mat.footprint();
    const double perFragment = std::log(2.0) * below.density / below.minScale;
    const double refBound = below.n * perFragment * fp.kernel(0.0) / fp.exact(0.0) * dz + 2.0 * std::ldexp(1.0, -24);
    // GL: the table's slope; the two view depths rounded in float (2^-22 relative, each, twice);
    // exp2 within (3 + 2|x|) ulps (GLSL 4.50), x <= density <= 1, and one F32 blend, per fragment and frame.
    const double glBound = below.n * perFragment * (1.0 + test::windowErrorBound(mat, 0)) * glTableSlope(fp) * (dz + 4.0 * std::ldexp(8.0, -22)) +
                           below.n * 2.0 * 6.0 * std::ldexp(1.0, -24);
    const double across = maxDiff(below.gl, above.gl), acrossRef = maxDiff(below.ref, above.ref);
    std::printf("  view depth moved %.3e: GL %.3e (bound %.3e), reference %.3e (bound %.3e)\n", dz, across, glBound, acrossRef, refBound);
    EXPECT_LE(acrossRef, refBound);
    EXPECT_LE(across, glBound);
    const Frame plainBelow = drawOver(splats, cam, mat, {.zSurface = 4.0f - eps, .cut = false, .floatDepth = 1, .zMax = 4.0});
    const Frame plainAbove = drawOver(splats, cam, mat, {.zSurface = 4.0f + eps, .cut = false, .floatDepth = 1, .zMax = 4.0});
    EXPECT_GT(maxDiff(plainBelow.gl, plainAbove.gl), 0.02) << "the plain test pops a layer here (else the case proves nothing)";
}

TEST_F(CutStability, GrazingFloorThroughTheBlock) {
    // A floor through the block seen 4 degrees above grazing: along a pixel
    // column the host depth runs from the near plane to 20, so every 16 x 16
    // tile's depth range (which decides which splats are cut, which skipped
    // as hidden) spans many voxels; each pixel must still be cut at its own
    // depth.
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.4f);
    const glm::vec3 c = g.worldPosition({2, 2, 2});
    const Camera cam = Camera::lookAt(c + glm::vec3(0.03f, 0.28f, 4.0f), c, {0, 1, 0}, 0.7f, {40, 32}, 0.5f, 20.0f);
    const float y = c.y - 0.05f;
    OpaqueTriangles floor;
    const std::vector<glm::vec3> tris = quad({c.x - 30, y, c.z + 3.9f}, {c.x + 30, y, c.z + 3.9f}, {c.x + 30, y, c.z - 30}, {c.x - 30, y, c.z - 30});
    const Frame f = drawOver(built(g, cam, mat), cam, mat, {.opaque = [&] { floor.draw(tris, cam); }, .zMax = 20.0});
    EXPECT_LE(f.worst, f.bound);
    double lo = 1.0, hi = 0.0;
    for (float d : f.depth.pixels) lo = std::min(lo, double(d)), hi = std::max(hi, double(d));
    EXPECT_LT(lo, hi) << "the floor must cover part of the image";
    EXPECT_GT(f.stats.cutHost, 0u);
    const Frame open = draw(built(g, cam, mat), cam, mat, -1.0f);
    EXPECT_GT(maxDiff(open.ref, f.ref), 0.05) << "the floor must cut the block";
}

TEST_F(CutStability, SilhouetteEdgeAcrossTheSplats) {
    // A depth discontinuity through the block: an opaque wall through the
    // middle layer on the left of x = c.x + 0.07 (not on a pixel or voxel
    // boundary), the sky on the right. Splats across the edge are cut on its
    // left and whole on its right, pixel by pixel; the edge tiles' depth range
    // spans the wall to the far plane.
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.45f);
    const glm::vec3 c = g.worldPosition({2, 2, 2});
    const Camera cam = Camera::lookAt(c + glm::vec3(0.0f, 0.0f, 4.0f), c, {0, 1, 0}, 0.7f, {40, 32}, 0.5f, 50.0f);
    const float x = c.x + 0.07f;
    OpaqueTriangles wall;
    const std::vector<glm::vec3> tris = quad({x - 20, c.y - 20, c.z}, {x, c.y - 20, c.z}, {x, c.y + 20, c.z}, {x - 20, c.y + 20, c.z});
    const Frame f = drawOver(built(g, cam, mat), cam, mat, {.opaque = [&] { wall.draw(tris, cam); }, .zMax = 4.0});
    EXPECT_LE(f.worst, f.bound);
    // Mirror pixels about the block's centre column: cut on the left, whole on the right.
    const int row = f.ref.height / 2;
    // (Red: the gas's colour over the dark background; alpha is 1 everywhere.)
    EXPECT_GT(f.ref.at(f.ref.width / 2 + 6, row, 0) - f.ref.at(f.ref.width / 2 - 7, row, 0), 0.05f);
}

TEST_F(CutStability, SplatLargerThanTheScreenCutBySurface) {
    // One kernel of support radius 3.2 seen from 6 units with a 0.3 rad field
    // of view (0.9 units of half height): its polygon covers the screen many
    // times over (the tiles it covers clamped to the screen), the texture
    // magnified ~40x; a surface 0.4 in front of its centre cuts it everywhere.
    const Materials mat = plain();
    Grid g = *Grid::box({1, 1, 1}, glm::vec3(2.0f));
    g.voxels[0].opacity = 0.6f;
    const glm::vec3 c = g.worldPosition({0, 0, 0});
    const Camera cam = Camera::lookAt(c + glm::vec3(0.1f, 0.05f, 6.0f), c + glm::vec3(0.1f, 0.05f, 0.0f), {0, 1, 0}, 0.3f, {40, 32}, 0.5f, 50.0f);
    const std::vector<Splat> splats = built(g, cam, mat);
    ASSERT_EQ(splats.size(), 1u);
    const Frame f = draw(splats, cam, mat, 5.6f);
    EXPECT_LE(f.worst, f.bound);
    EXPECT_EQ(f.stats.cutHost, 1u);
    EXPECT_EQ(f.stats.cutGeneral, 0u) << "the eye is outside the support";
    const Frame open = draw(splats, cam, mat, -1.0f);
    EXPECT_LE(open.worst, open.bound);
    EXPECT_GT(std::abs(open.ref.at(0, 0, 0) - f.ref.at(0, 0, 0)), 0.02f) << "cut in the corner too";
}

TEST_F(CutStability, SplatCentreExactlyOnTheNearPlane) {
    // One voxel whose centre is at view depth 1 = the near plane: the ray
    // through the centre (pixel (16, 12) of 33 x 25) keeps exactly half of
    // the kernel's line integral (the fraction before s = 0 is 1/2 by
    // symmetry; the table's two columns around sigma = 0 average to 1/2):
    // alpha = 1 - 2^(-density / 2), over the background.
    const Materials mat = plain();
    Grid g = *Grid::box({1, 1, 1}, glm::vec3(0.4f));
    g.voxels[0].opacity = 0.7f;
    const glm::vec3 c = g.worldPosition({0, 0, 0});
    const Camera cam = Camera::lookAt(c + glm::vec3(0.0f, 0.0f, 1.0f), c, {0, 1, 0}, 1.0f, {33, 25}, 1.0f, 50.0f);
    const std::vector<Splat> splats = built(g, cam, mat);
    ASSERT_EQ(splats.size(), 1u);
    const Frame f = draw(splats, cam, mat, -1.0f);
    EXPECT_LE(f.worst, f.bound);
    EXPECT_EQ(f.stats.cutNear + f.stats.cutGeneral, 1u) << "the near plane crosses the kernel";
    const double a = 1.0 - std::exp2(-0.5 * double(splats[0].density));
    for (int ch = 0; ch < 4; ++ch) {
        const double want = double(kColour[ch]) * a + (1.0 - a) * double(kBackground[ch]); // kColour.a = 1
        // The reference: exactFractionBefore(0, 0) = 1/2 exactly; the pixel ray meets the centre to float rounding of the camera.
        EXPECT_NEAR(f.ref.at(16, 12, ch), want, 1e-5) << "reference, channel " << ch;
        EXPECT_NEAR(f.gl.at(16, 12, ch), want, f.bound + 1e-5) << "GL, channel " << ch;
    }
}

TEST_F(CutStability, FloatDepthWithNearOneThousandthAndFarOneHundredThousand) {
    // OpenGL's default [-1, 1] convention, not reversed, into a 32-bit float
    // depth buffer with far / near = 1e8: the surface at view depth 4 through
    // the voxel centres has window depth 1 - 2.5e-4. A 4x4 inverse projection
    // in float would lose ~6e-4 of view depth there (f + n - ndc (f - n)
    // subtracts terms of 1e5: 80x the bound's linearization term); the
    // cut's unprojection blends 1 / depth (depth_convention.hpp) and must
    // agree with the reference to float rounding (the bound's 2^-22 relative).
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.35f);
    const glm::vec3 c = g.worldPosition({2, 2, 2});
    const Camera cam = Camera::lookAt(c + glm::vec3(0.02f, 0.01f, 4.0f), c, {0, 1, 0}, 0.7f, {40, 32}, 1e-3f, 1e5f);
    const std::vector<Splat> splats = built(g, cam, mat);
    const Frame f = drawOver(splats, cam, mat, {.zSurface = 4.0f, .floatDepth = 1, .zMax = 4.0});
    EXPECT_LE(f.worst, f.bound);
    EXPECT_GT(f.stats.cutHost, 0u);
    EXPECT_NEAR(f.depth.at(20, 16, 0), 1.0 - 2.5e-4, 1e-6);
}

TEST_F(CutStability, D24DepthWhereOneCodeIsAFiftiethOfAVoxel) {
    // A 24-bit fixed depth with near 0.01: at view depth 30 one depth code
    // spans z^2 / near x 2^-24 = 5.4e-3 world units, 1/55 of the voxel
    // spacing. GL reads the code from the depth texture, the reference the
    // same code read back as float: they must agree to the bound (one code's
    // difference would move the cut by 0.018 kernel units, 100x the bound's
    // linearization term).
    const Materials mat = plain();
    const Grid g = block(5, 0.3f, 0.35f);
    const glm::vec3 c = g.worldPosition({2, 2, 2});
    const Camera cam = Camera::lookAt(c + glm::vec3(0.01f, 0.02f, 30.0f), c, {0, 1, 0}, 0.06f, {40, 32}, 0.01f, 1000.0f);
    const std::vector<Splat> splats = built(g, cam, mat);
    const Frame f = drawOver(splats, cam, mat, {.zSurface = 30.0f, .floatDepth = 0, .zMax = 30.0});
    EXPECT_LE(f.worst, f.bound);
    EXPECT_GT(f.stats.cutHost, 0u);
    const DepthUnprojection un = depthUnprojection(cam);
    const double d = f.depth.at(20, 16, 0), code = std::ldexp(1.0, -24);
    const double step = un.viewDepth(d + code) - un.viewDepth(d);
    EXPECT_GT(step, 3e-3);
    EXPECT_LT(step, 8e-3);
    const Frame open = draw(splats, cam, mat, -1.0f);
    EXPECT_GT(maxDiff(open.ref, f.ref), 0.05) << "the surface must cut the block";
}

TEST_F(CutStability, StretchedKernelsReachInFrontOfTheSurface) {
    // Voxels stretched 4x along the view (stretch 3): their centres 0.5
    // behind the surface, their supports reaching 1.92 in front of it (an
    // unstretched one reaches 0.48). The part in front is drawn; the splats
    // must not be skipped as hidden behind the surface (the classifier's reach
    // is the ray scale's, stretch included).
    const Materials mat = plain();
    Grid g = block(3, 0.3f, 0.6f);
    for (Voxel& v : g.voxels) v.stretch = {0.0f, 0.0f, 3.0f};
    const glm::vec3 c = g.worldPosition({1, 1, 1});
    const Camera cam = Camera::lookAt(c + glm::vec3(0.02f, 0.01f, 4.0f), c, {0, 1, 0}, 0.7f, {40, 32}, 0.5f, 50.0f);
    const std::vector<Splat> splats = built(g, cam, mat);
    const Frame f = draw(splats, cam, mat, 3.5f - 0.3f); // in front of the front layer's centres by 0.5
    EXPECT_LE(f.worst, f.bound);
    EXPECT_EQ(f.stats.cutHidden, 0u);
    EXPECT_GT(visible(f.ref), 0.05) << "the stretched kernels' front parts must show";
}

// ---- Issue 24: the fragment lists' edges (transparent surfaces among the splats) ----
//
// The block (5^3, spacing 0.3, opacity 0.4, one colour) seen from 2.5 in
// front of it, panes of the integration snippet (tests/common/
// transparent_glass.hpp) across it, GL's lists against the reference with
// the same panes as ReferenceSurface quads. The bound (as in
// tests/render/fragment_lists_gl_test.cpp): the same frame's error without a
// pane (the ordinary pass), plus per splat fragment and cut 2 ln2 tau delta
// (a cut's table lookup off by delta moves ln2 tau delta of optical depth
// from one section to the next, across a pane), n fragments on a pixel,
// plus the sections' and the resolve's RGBA16F rounding ((n + 2) 2^-12) and
// each pane's half colour (2^-11).

// The lists' background: transparent black, so that alpha is the scene's own.
const glm::vec4 kListBackground{0.0f};

class ListStability : public test::GLTest {
protected:
    struct Run {
        Image gl, ref, depth;
        gl::FrameRenderStats stats;
        double worst = 0.0;
    };
    struct Options {
        std::vector<glm::vec3> opaque{}; // the host's opaque triangles (depth), drawn after the clear
        int fragmentsPerPixel = 8;
        const std::vector<ReferenceSurface>* reference = nullptr; // the reference's surfaces; default the panes
    };

    Materials mat = plain();
    splatfx::Frame frame;
    Camera cam;
    double n = 0.0, tau = 0.0, delta = 0.0, base = 0.0;

    // The block seen from `eye` (looking down -z), and the no-pane error.
    void scene(const Grid& g, glm::vec3 eye, glm::ivec2 size = {40, 32}) {
        cam = Camera::lookAt(eye, eye + glm::vec3(0.0f, 0.0f, -1.0f), {0, 1, 0}, 1.2f, size, 0.2f, 50.0f);
        frame.begin(0.0, cam);
        frame.builder().add(g, mat, {.textured = false});
        frame.end();
        SplatExactStats st;
        EXPECT_TRUE(renderSplatExact(frame.splats(), cam, mat, {.threads = 2}, &st));
        n = double(st.maxOverlap);
        for (const Splat& sp : frame.splats()) tau = std::max(tau, double(sp.density));
        delta = tableError(mat.footprint());
        base = run({}).worst;
    }
    double bound(int cuts, int panes) const {
        return base + n * 2.0 * cuts * std::log(2.0) * tau * delta + (n + 2.0) * std::ldexp(1.0, -12) + panes * std::ldexp(1.0, -11);
    }
    static ReferenceSurface surface(const test::Pane& p) {
        return ReferenceSurface::quad({p.centre.x - p.half, p.centre.y - p.half, p.z}, {p.centre.x + p.half, p.centre.y - p.half, p.z},
                                      {p.centre.x + p.half, p.centre.y + p.half, p.z}, {p.centre.x - p.half, p.centre.y + p.half, p.z},
                                      glm::dvec4(p.premultiplied));
    }
    test::Pane pane(float z, glm::vec4 premultiplied, float half = 1.5f) const {
        return {.z = z, .premultiplied = premultiplied, .half = half, .centre = {cam.eye().x, cam.eye().y}};
    }

    Run run(const std::vector<test::Pane>& panes) { return run(panes, Options{}); }
    Run run(const std::vector<test::Pane>& panes, const Options& o) {
        Run out;
        test::Glass glass;
        EXPECT_TRUE(glass.error().empty()) << glass.error();
        OpaqueTriangles opaque;
        auto fr = gl::FrameRenderer::create({.splats = {.sampling = gl::TextureSampling::Bilinear}, .fragmentsPerPixel = o.fragmentsPerPixel});
        EXPECT_TRUE(fr && fr->upload(mat));
        auto fb = gl::Framebuffer::create({.width = cam.viewport.x, .height = cam.viewport.y, .color = gl::Precision::F32});
        EXPECT_TRUE(fb);
        if (!fr || !fb || !glass.error().empty()) return out;
        fr->render(frame, {.framebuffer = fb->handle(),
                           .drawOpaque =
                               [&] {
                                   glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
                                   glClearDepth(1.0);
                                   glDepthMask(GL_TRUE);
                                   glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                                   if (!o.opaque.empty()) opaque.draw(o.opaque, cam, kListBackground);
                               },
                           .drawTransparent = [&] { glass.draw(panes, cam); },
                           .transparentToLists = true});
        out.stats = fr->stats();
        out.gl = fb->read();
        out.depth = fb->readDepth();
        std::vector<ReferenceSurface> surfaces;
        for (const test::Pane& p : panes) surfaces.push_back(surface(p));
        SplatExactDesc rd;
        rd.host = {.background = kListBackground, .depth = &out.depth};
        rd.threads = 2;
        rd.surfaces = o.reference ? *o.reference : surfaces;
        auto ref = renderSplatExact(frame.splats(), cam, mat, rd);
        EXPECT_TRUE(ref) << ref.error();
        if (!ref) return out;
        out.ref = *ref;
        for (std::size_t i = 0; i < out.gl.pixels.size(); ++i) {
            const float v = out.gl.pixels[i];
            EXPECT_TRUE(std::isfinite(v) && v >= 0.0f && v <= 1.0f) << "pixel value " << i << ": " << v;
            out.worst = std::max(out.worst, std::abs(double(v) - double(out.ref.pixels[i])));
        }
        return out;
    }
};

Grid listBlock() { return block(5, 0.3f, 0.4f); }
glm::vec3 listEye(const Grid& g) { return g.worldPosition({2, 2, 4}) + glm::vec3(0.05f, 0.03f, 2.5f); }

TEST_F(ListStability, PaneExactlyAtTheHostDepth) {
    // An opaque wall through the block's middle layer and a transparent pane
    // on the same plane, drawn by two programs: their depths agree only to
    // rounding (GL promises no more without `invariant`), so the hook's
    // LEQUAL test keeps the pane on some pixels and hides it on others. Each
    // pixel must be one of the two exact images: the pane stored (the gas cut
    // at the wall, no section behind the pane: before(wall) - before(pane)
    // is 0, not the gas counted twice) or the pane hidden (the gas cut at
    // the wall alone). The reference's crossing and the read-back depth are
    // also equal only to rounding, so its pane lies 1e-4 in front of the
    // wall: the gas in that sliver adds at most n ln2 tau (h(0) / F(0)) 1e-4 / l.
    const Grid g = listBlock();
    scene(g, listEye(g));
    const float z = g.worldPosition({2, 2, 2}).z;
    const test::Pane glassPane = pane(z, {0.1f, 0.2f, 0.3f, 0.4f});
    const float h = glassPane.half;
    const glm::vec2 c = glassPane.centre;
    test::Pane shifted = glassPane;
    shifted.z = z + 1e-4f;
    const std::vector<glm::vec3> wall = quad({c.x - h, c.y - h, z}, {c.x + h, c.y - h, z}, {c.x + h, c.y + h, z}, {c.x - h, c.y + h, z});
    const std::vector<ReferenceSurface> inFront{surface(shifted)}, none{};
    const Run stored = run({glassPane}, {.opaque = wall, .reference = &inFront});
    const Run hidden = run({glassPane}, {.opaque = wall, .reference = &none});
    ASSERT_EQ(stored.gl.pixels, hidden.gl.pixels) << "the same GL frame twice";
    const Footprint& fp = mat.footprint();
    const double tol = bound(1, 1) + n * std::log(2.0) * tau * fp.kernel(0.0) / fp.exact(0.0) * 1e-4 / 0.3;
    double worst = 0.0;
    int shown = 0;
    for (int y = 0; y < cam.viewport.y; ++y)
        for (int x = 0; x < cam.viewport.x; ++x) {
            double a = 0.0, b = 0.0;
            for (int ch = 0; ch < 4; ++ch) {
                a = std::max(a, std::abs(double(stored.gl.at(x, y, ch)) - double(stored.ref.at(x, y, ch))));
                b = std::max(b, std::abs(double(hidden.gl.at(x, y, ch)) - double(hidden.ref.at(x, y, ch))));
            }
            shown += a < b;
            worst = std::max(worst, std::min(a, b));
        }
    std::printf("  pane shown on %d of %llu stored pixels; error %.3e (bound %.3e; no pane %.3e)\n", shown,
                (unsigned long long)stored.stats.lists.nodes, worst, tol, base);
    EXPECT_GT(stored.stats.lists.nodes, 0u);
    EXPECT_GE(std::uint64_t(shown), stored.stats.lists.nodes * 9 / 10) << "a stored pane must show";
    EXPECT_LE(worst, tol);
    // Tighter: the frame without the pane has one cut lookup per fragment
    // (the wall's), with it two (the wall's and the pane's), each off by at
    // most delta, and the window's error is the same: at most twice the
    // no-pane error, plus the pane's half colour and the sections' rounding.
    // (The section pass used to test the drawn polygons against the host
    // depth: splats whose plane lay behind the wall lost their part in front
    // of it, 10x this error.)
    EXPECT_LE(worst, 2.0 * base + std::ldexp(1.0, -11) + (n + 2.0) * std::ldexp(1.0, -12));
}

TEST_F(ListStability, TwoPanesAtTheSameDepth) {
    // Two panes on one plane through the block: an order tie. Which is
    // composited first is the lists' choice; either is right, so each pixel
    // must lie between the two orders' references (each channel, within the
    // bound), alpha the same in both (1 - (1 - a1)(1 - a2), order-free), and
    // the gas between them, a section of zero share, must add nothing.
    const Grid g = listBlock();
    scene(g, listEye(g));
    const float z = g.worldPosition({2, 2, 2}).z;
    const test::Pane a = pane(z, {0.3f, 0.05f, 0.0f, 0.35f}), b = pane(z, {0.0f, 0.1f, 0.4f, 0.5f});
    const std::vector<ReferenceSurface> ab{surface(a), surface(b)}, ba{surface(b), surface(a)};
    const Run first = run({a, b}, {.reference = &ab});
    const Run second = run({a, b}, {.reference = &ba});
    const double tol = bound(2, 2);
    double outside = 0.0, orders = 0.0;
    for (std::size_t i = 0; i < first.gl.pixels.size(); ++i) {
        const double lo = std::min(first.ref.pixels[i], second.ref.pixels[i]), hi = std::max(first.ref.pixels[i], second.ref.pixels[i]);
        const double v = first.gl.pixels[i];
        outside = std::max(outside, std::max(lo - v, v - hi));
        orders = std::max(orders, hi - lo);
    }
    std::printf("  outside the two orders %.3e (bound %.3e); the orders differ by %.3e\n", outside, tol, orders);
    EXPECT_GT(orders, 0.05) << "the two orders must differ (else the tie proves nothing)";
    EXPECT_LE(outside, tol);
    EXPECT_EQ(first.stats.lists.sectionOverflow, 0u);
}

TEST_F(ListStability, EightPanesThroughOneKernelOverflowTheSections) {
    // Eight panes through one large kernel (support radius 1.6): nine
    // sections, one more than kTransparentMaxSections. With seven, every
    // section is exact; with eight, the gas behind the 8th is merged into the
    // last section and counted (lists.sectionOverflow), never dropped: alpha,
    // which does not depend on the order, stays within the bound, and every
    // channel in [0, 1]. The node budget is raised so only the sections
    // overflow.
    Grid g = *Grid::box({1, 1, 1}, glm::vec3(1.0f));
    g.voxels[0].opacity = 0.9f;
    const glm::vec3 c = g.worldPosition({0, 0, 0});
    scene(g, c + glm::vec3(0.05f, 0.03f, 3.0f));
    std::vector<test::Pane> panes;
    for (int k = 0; k < 8; ++k) panes.push_back(pane(c.z + 0.9f - 0.25f * float(k), {0.02f * float(k), 0.05f, 0.1f, 0.15f}));
    const std::vector<test::Pane> seven(panes.begin(), panes.begin() + 7);
    const Run exact = run(seven, {.fragmentsPerPixel = 16});
    EXPECT_EQ(exact.stats.lists.sections, kTransparentMaxSections);
    EXPECT_EQ(exact.stats.lists.sectionOverflow, 0u);
    EXPECT_EQ(exact.stats.lists.overflowPixels, 0u);
    EXPECT_LE(exact.worst, bound(7, 7)) << "seven surfaces: every section exact";
    const Run over = run(panes, {.fragmentsPerPixel = 16});
    EXPECT_EQ(over.stats.lists.overflowPixels, 0u);
    EXPECT_GT(over.stats.lists.sectionOverflow, 0u) << "must be reported, not silent";
    double alpha = 0.0;
    for (int y = 0; y < cam.viewport.y; ++y)
        for (int x = 0; x < cam.viewport.x; ++x) alpha = std::max(alpha, std::abs(double(over.gl.at(x, y, 3)) - double(over.ref.at(x, y, 3))));
    std::printf("  seven: error %.3e (bound %.3e); eight: alpha error %.3e (bound %.3e), colour %.3e\n", exact.worst, bound(7, 7), alpha, bound(8, 8),
                over.worst);
    EXPECT_LE(alpha, bound(8, 8));
}

TEST_F(ListStability, PixelsWithPanesButNoSplats) {
    // A block covering the left of the image, two panes over all of it: on
    // pixels no splat reaches, the lists
    // must still composite both panes in depth order over the background:
    // front over (back over background), closed form, to the panes' half
    // colours (2^-11 each) and the resolve's RGBA16F (2^-12). The background
    // is transparent black, so the closed form is the panes' alone.
    Grid g = listBlock();
    const glm::vec3 eye = g.worldPosition({4, 2, 4}) + glm::vec3(0.55f, 0.03f, 1.2f);
    scene(g, eye, {48, 24});
    const test::Pane back = pane(g.worldPosition({2, 2, 0}).z - 0.5f, {0.05f, 0.3f, 0.1f, 0.4f}, 3.0f);
    const test::Pane front = pane(g.worldPosition({2, 2, 2}).z, {0.3f, 0.1f, 0.05f, 0.35f}, 3.0f);
    const Run r = run({front, back});
    EXPECT_LE(r.worst, bound(2, 2));
    // Where both panes cover a pixel: front over (back over background).
    const glm::dvec4 want = glm::dvec4(front.premultiplied) + (1.0 - double(front.premultiplied.a)) * glm::dvec4(back.premultiplied);
    const Image none = *renderSplatExact(frame.splats(), cam, mat, {.host = {.background = kListBackground}, .threads = 2});
    int empty = 0;
    double worst = 0.0;
    for (int y = 0; y < cam.viewport.y; ++y)
        for (int x = 0; x < cam.viewport.x; ++x) {
            bool gas = false;
            for (int ch = 0; ch < 4; ++ch) gas = gas || none.at(x, y, ch) != 0.0f;
            if (gas || std::abs(double(r.ref.at(x, y, 3)) - want.a) > 1e-6) continue; // gas, or not under both panes
            ++empty;
            for (int ch = 0; ch < 4; ++ch) worst = std::max(worst, std::abs(double(r.gl.at(x, y, ch)) - want[ch]));
        }
    EXPECT_GT(empty, cam.viewport.x * cam.viewport.y / 4) << "a quarter of the pixels at least must have both panes and no splat";
    EXPECT_LE(worst, 2.0 * std::ldexp(1.0, -11) + std::ldexp(1.0, -12));
    EXPECT_GT(r.stats.lists.splatsSectioned, 0u) << "the front pane cuts the block";
}

TEST_F(ListStability, GasSectionOneHundredthOfAVoxelThick) {
    // Two panes 0.003 apart (1/100 of the spacing) through the block: the
    // section between them is the difference of two nearly equal table
    // lookups. It must stay >= 0 (a negative share would give a negative
    // alpha) and agree with the reference's to the bound.
    const Grid g = listBlock();
    scene(g, listEye(g));
    const float z = g.worldPosition({2, 2, 2}).z + 0.1f;
    const Run r = run({pane(z, {0.1f, 0.2f, 0.3f, 0.4f}), pane(z - 0.003f, {0.3f, 0.2f, 0.1f, 0.4f})});
    std::printf("  error %.3e (bound %.3e; no pane %.3e)\n", r.worst, bound(2, 2), base);
    EXPECT_LE(r.worst, bound(2, 2));
    EXPECT_GT(r.stats.lists.splatsSectioned, 0u);
}

// Particles (King et al. 1999, sec. 6) go into the grid's one splat list: a
// particle between two voxels in depth is drawn between them, and a host
// surface cuts it with the same exact share of its kernel as a voxel, GL
// against the reference with CutStability's bound (its derivation holds for
// splats of different colours: compositing is 1-Lipschitz in each fragment's
// alpha, and the colour rows' 2^-11 error is weighted by alphas summing to <= 1).
TEST_F(CutStability, AParticleBetweenTwoGridSplatsIsSortedAndCutLikeThem) {
    Materials mat = plain();                                       // row 0: the grid's colour
    mat.addColorTable(ColorTable::constant({0.2f, 0.9f, 0.4f, 1.0f})); // row 1: the particle's
    const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.9f, {64, 48});
    Grid g;
    g.spacing = glm::vec3(0.6f);
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-0.1f, 0.0f, -3.0f));
    g.voxels = {{.cell = {0, 0, 0}, .opacity = 0.6f}, {.cell = {0, 0, -3}, .opacity = 0.6f}}; // view depths 3 and 4.8
    const Particle p{.position = {0.15f, 0.1f, -3.9f}, .sizeWorld = 0.6f, .opacity = 0.7f, .colorCoord = 0.0f};
    auto build = [&](bool asVoxel) {
        SplatBuilder b;
        b.begin(cam);
        if (asVoxel) { // the same splat from a one-voxel grid of the particle's size, for the cut comparison
            Grid v;
            v.spacing = glm::vec3(p.sizeWorld);
            v.transform = glm::translate(glm::mat4(1.0f), p.position);
            v.voxels = {{.cell = {0, 0, 0}, .opacity = p.opacity}};
            b.add(v, mat, {.colorTable = 1, .textured = false});
        } else {
            b.add(std::span<const Particle>(&p, 1), mat, {.splat = {.colorTable = 1, .textured = false}});
        }
        b.add(g, mat, {.textured = false});
        b.sort(SortMode::Exact);
        return b.splats();
    };
    const std::vector<Splat> splats = build(false);
    ASSERT_EQ(splats.size(), 3u);
    EXPECT_EQ(splats[1].colorRow, 1.0f) << "the particle must sort between the voxels";
    EXPECT_GT(splats[0].depth, splats[1].depth);
    EXPECT_GT(splats[1].depth, splats[2].depth);

    // The reference of another list over the same host as frame f (its depth image), with or without the cut.
    auto reference = [&](const std::vector<Splat>& list, const Frame& f, bool withCut) {
        SplatExactDesc rd;
        rd.host.background = kBackground;
        rd.host.depth = &f.depth;
        rd.depthCut = withCut;
        auto img = renderSplatExact(list, cam, mat, rd);
        EXPECT_TRUE(img) << img.error();
        return *img;
    };
    const Frame open = draw(splats, cam, mat, -1.0f);
    std::printf("  no surface: error %.3e (bound %.3e)\n", open.worst, open.bound);
    EXPECT_LE(open.worst, open.bound);
    EXPECT_GT(visible(open.gl), 0.3);
    // The reference orders each pixel's fragments by depth itself; GL draws in
    // list order. Drawn in the wrong order (the particle last, in front of the
    // near voxel) GL must land more than twice the bound away, or the agreement
    // above would say nothing of the order.
    std::vector<Splat> wrong = splats;
    std::swap(wrong[1], wrong[2]);
    const Frame misordered = draw(wrong, cam, mat, -1.0f);
    EXPECT_GT(misordered.worst, 2.0 * misordered.bound);

    // A host surface through the particle's centre (view depth 3.9): the far voxel
    // keeps only its tail in front, the particle about half, the near voxel all.
    const Frame cut = draw(splats, cam, mat, 3.9f);
    std::printf("  surface through the particle: error %.3e (bound %.3e)\n", cut.worst, cut.bound);
    EXPECT_LE(cut.worst, cut.bound);
    EXPECT_GT(maxDiff(reference(splats, cut, false), cut.ref), 2.0 * cut.bound) << "the cut must differ from the all-or-nothing test here";
    // Cut exactly like a voxel of its size at its place: the two splats agree to
    // float rounding (ParticleSplats.AParticleAtAVoxelCentreDrawsAsThatVoxel); the
    // reference images then agree to a few 1e-7 (the splat parameters' relative
    // rounding times the image's slope, below 1); 1e-5 leaves room.
    EXPECT_LE(maxDiff(reference(build(true), cut, true), cut.ref), 1e-5);
}

// A particle centred on the near plane: half its kernel is in front of the
// plane, and the cut keeps exactly the other half (GL against the reference).
TEST_F(CutStability, AParticleCentredOnTheNearPlane) {
    const Materials mat = plain();
    const Camera cam = Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.9f, {64, 48});
    const std::vector<Particle> ps = {{.position = {0.0f, 0.0f, -cam.nearPlane()}, .sizeWorld = 0.05f, .opacity = 0.8f},
                                      {.position = {0.02f, 0.01f, -0.3f}, .sizeWorld = 0.08f, .opacity = 0.5f}};
    SplatBuilder b;
    b.begin(cam);
    b.add(ps, mat, {.splat = {.textured = false}});
    b.sort();
    ASSERT_EQ(b.splats().size(), 2u);
    const Frame f = draw(b.splats(), cam, mat, -1.0f);
    std::printf("  near plane: error %.3e (bound %.3e)\n", f.worst, f.bound);
    EXPECT_LE(f.worst, f.bound);
    EXPECT_GT(visible(f.gl), 0.1);
}

} // namespace
} // namespace splatfx
