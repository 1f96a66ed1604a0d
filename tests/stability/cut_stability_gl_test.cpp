// The depth cut's hard cases (issue 15) through the GL renderer, each against
// the splat-exact reference with the same cut, and for continuity: a surface
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

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "../reference/gl_bounds.hpp"
#include "gl_fixture.hpp"
#include "splatfx/reference.hpp"

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

class CutStability : public test::GLTest {
protected:
    struct Frame {
        Image gl, ref;
        double worst = 0.0, bound = 0.0;
    };

    // Draws the splats over a host surface at view depth zSurface (a
    // constant window depth: a plane facing the camera; < 0: none), GL and
    // reference, and compares them.
    Frame draw(const std::vector<Splat>& splats, const Camera& cam, const Materials& mat, float zSurface, bool cut = true,
               float depthOverride = -1.0f) {
        Frame f;
        auto r = gl::Renderer::create({.sampling = gl::TextureSampling::Bilinear, .depthCut = cut});
        EXPECT_TRUE(r) << r.error();
        const Status up = r->upload(mat);
        EXPECT_TRUE(up) << up.error();
        // A reversed host draws into float depth (the engines' reverse-Z setup).
        auto fb = gl::Framebuffer::create(
            {.width = cam.viewport.x, .height = cam.viewport.y, .color = gl::Precision::F32, .floatDepth = cam.depth.reversed});
        EXPECT_TRUE(fb);
        const float depth = depthOverride >= 0.0f ? depthOverride : zSurface > 0.0f ? windowDepth(cam, zSurface) : float(cam.depth.farWindow());
        fb->clear(kBackground, depth);
        const Image depthImage = fb->readDepth();
        glClipControl(GL_LOWER_LEFT, cam.depth.clip == ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
        r->draw(splats, cam, {.framebuffer = fb->handle(), .width = cam.viewport.x, .height = cam.viewport.y});
        glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        if (cut) { EXPECT_TRUE(r->stats().cutHostDepth) << "the framebuffer depth texture must be read"; }
        f.gl = fb->read();
        SplatExactDesc rd;
        rd.host.background = kBackground;
        rd.host.depth = &depthImage;
        rd.depthCut = cut;
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
        const double zMax = std::max(double(zSurface), 1.0) * 2.0;
        const double depthErr = 4.0 * std::ldexp(zMax, -22) / minScale;
        const double cutErr = 2.0 * tableError(fp) + fp.kernel(0.0) / fp.exact(0.0) * depthErr;
        const double n = double(stats.maxOverlap);
        f.bound = n * std::log(2.0) * maxDensity * (test::windowErrorBound(mat, 0) + (cut ? cutErr : 0.0)) + std::ldexp(1.0, -11) +
                  n * std::ldexp(1.0, -24);
        for (size_t i = 0; i < f.gl.pixels.size(); ++i) {
            const float v = f.gl.pixels[i];
            EXPECT_TRUE(std::isfinite(v)) << "pixel value " << i;
            EXPECT_GE(v, 0.0f);
            EXPECT_LE(v, 1.0f);
            f.worst = std::max(f.worst, double(std::abs(v - f.ref.pixels[i])));
        }
        return f;
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

} // namespace
} // namespace splatfx
