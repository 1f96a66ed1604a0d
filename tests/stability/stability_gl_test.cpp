// Hard cases through the GL renderer (headless), each checked for finite,
// in-range output and agreement with the splat-exact reference.
//
// Every scene uses one constant colour c over a constant background b, so a
// pixel is c (1 - T) + b T with T = prod(1 - alpha_i): independent of the
// compositing order (per-splat sort vs the reference's per-pixel order).
// Then |T_gl - T_ref| <= sum |alpha_gl,i - alpha_ref,i| <= n ln2 density_max
// windowErrorBound (d alpha / d detail <= ln2 density), n = the most
// fragments on one pixel (SplatExactStats::maxOverlap), plus the RGBA16F
// colour row (2^-11 relative) and F32 blending (n * 2^-24).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "../reference/gl_bounds.hpp"
#include "gl_fixture.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/solver.hpp"

namespace splatfx {
namespace {

const glm::vec4 kColour{0.9f, 0.6f, 0.3f, 1.0f};
const glm::vec4 kBackground{0.1f, 0.15f, 0.2f, 1.0f};

class Stability : public test::GLTest {
protected:
    struct Result {
        Image gl, ref;
        double bound = 0.0, worst = 0.0;
        std::uint64_t splats = 0;
    };

    static Materials plain() {
        Materials m{Footprint{}};
        m.addColorTable(ColorTable::constant(kColour));
        return m;
    }

    // Builds, draws (F32 unless told) and compares; extraBound adds a case-specific term.
    Result run(const Grid& grid, const Camera& cam, const Materials& mat, SplatStyle style = {.textured = false},
               gl::Precision precision = gl::Precision::F32, double extraBound = 0.0) {
        Result r;
        SplatBuilder b;
        b.begin(cam);
        b.add(grid, mat, style);
        b.sort();
        r.splats = b.splats().size();
        // The bounds are derived for bilinear sampling (gl_bounds.hpp), so name it.
        auto renderer = gl::Renderer::create({.sampling = gl::TextureSampling::Bilinear});
        EXPECT_TRUE(renderer && renderer->upload(mat));
        auto fb = gl::Framebuffer::create({.width = cam.viewport.x, .height = cam.viewport.y, .color = precision});
        EXPECT_TRUE(fb);
        fb->clear(kBackground);
        renderer->draw(b.splats(), cam, {.framebuffer = fb->handle(), .width = cam.viewport.x, .height = cam.viewport.y});
        r.gl = fb->read();
        SplatExactStats stats;
        SplatExactDesc rd;
        rd.host.background = kBackground;
        // Textured layers hold the window already sampled at layerSize; against
        // them the reference reads the same layers in double (Stored), and the
        // bound is storage and filtering only.
        rd.window = style.textured ? ReferenceWindow::Stored : ReferenceWindow::Exact;
        auto ref = renderSplatExact(b.splats(), cam, mat, rd, &stats);
        EXPECT_TRUE(ref) << ref.error();
        r.ref = *ref;
        double maxDensity = 0.0;
        for (const Splat& s : b.splats()) maxDensity = std::max(maxDensity, double(s.density));
        double window = 0.0;
        if (style.textured) {
            for (std::uint32_t l = 0; l < mat.layerCount(); ++l) window = std::max(window, test::storedErrorBound(mat, l));
        } else {
            window = test::windowErrorBound(mat, 0);
        }
        const double n = double(stats.maxOverlap);
        r.bound = n * std::log(2.0) * maxDensity * window + std::ldexp(1.0, -11) + n * std::ldexp(1.0, -24) + extraBound;
        for (size_t i = 0; i < r.gl.pixels.size(); ++i) {
            const float v = r.gl.pixels[i];
            EXPECT_TRUE(std::isfinite(v)) << "pixel value " << i;
            EXPECT_GE(v, 0.0f);
            EXPECT_LE(v, 1.0f);
            EXPECT_TRUE(std::isfinite(r.ref.pixels[i]));
            r.worst = std::max(r.worst, double(std::abs(v - r.ref.pixels[i])));
        }
        std::printf("  %llu splats, overlap %llu: max |GL - reference| %.2e, derived bound %.2e\n", static_cast<unsigned long long>(r.splats),
                    static_cast<unsigned long long>(stats.maxOverlap), r.worst, r.bound);
        return r;
    }
    static double visible(const Image& img) {
        double peak = 0.0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) peak = std::max(peak, double(std::abs(img.at(x, y, 0) - kBackground.r)));
        return peak;
    }
};

TEST_F(Stability, SingleVoxel) {
    Grid g;
    g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.8f});
    const Result r = run(g, Camera::lookAt({0.5f, 0.4f, 4}, {0, 0, 0}, {0, 1, 0}, 0.9f, {48, 40}), plain());
    EXPECT_LE(r.worst, r.bound);
    EXPECT_GT(visible(r.ref), 0.3);
}

TEST_F(Stability, OneVoxelThickSheet) {
    Grid g = *Grid::box({12, 12, 1}, glm::vec3(0.5f));
    for (Voxel& v : g.voxels) v.opacity = 0.6f;
    for (const glm::vec3 eye : {glm::vec3(0, 3, 8), glm::vec3(8, 3, 0.01f)}) { // face-on-ish and edge-on
        const Result r = run(g, Camera::lookAt(eye, {0, 3, 0}, {0, 1, 0}, 0.9f, {64, 48}), plain());
        EXPECT_LE(r.worst, r.bound) << "eye " << eye.x;
        EXPECT_GT(visible(r.ref), 0.3);
    }
}

TEST_F(Stability, GridWithHoles) {
    Grid g = *Grid::box({8, 8, 8}, glm::vec3(0.5f));
    std::vector<Voxel> kept;
    for (const Voxel& v : g.voxels)
        if ((v.cell.x + v.cell.y + v.cell.z) % 2 == 0 && !(v.cell.x == 4 && v.cell.y > 1)) kept.push_back(v);
    g.voxels = kept;
    for (Voxel& v : g.voxels) v.opacity = 0.3f;
    const Result r = run(g, Camera::lookAt({3, 4, 7}, {0, 2, 0}, {0, 1, 0}, 0.8f, {64, 48}), plain());
    EXPECT_LE(r.worst, r.bound);
    EXPECT_GT(visible(r.ref), 0.3);
}

TEST_F(Stability, HundredThousandSplatsStackedOnOnePixel) {
    // N voxels on the same cell, each of opacity a = 1e-4: the centre pixel
    // should read 1 - (1 - a_gl)^N, a_gl being what one such splat gives on
    // this GL (measured with N = 1 in F32). F32: each blend rounds by at most
    // one ulp (2^-24), so the drift over N blends is at most N 2^-24 (6e-3 at
    // 1e5). U8 and F16 quantize every blend, so tiny increments may round
    // away: there alpha must stay in [0, 1], never decrease with N, and never
    // exceed the exact value by more than one quantum (1/255, 2^-11).
    const Materials mat = plain();
    const Camera cam = Camera::lookAt({0, 0, 6}, {0, 0, 0}, {0, 1, 0}, 0.2f, {5, 5});
    auto renderer = gl::Renderer::create();
    ASSERT_TRUE(renderer && renderer->upload(mat));
    auto centre = [&](int n, gl::Precision p) {
        Grid g;
        g.voxels.assign(size_t(n), Voxel{.cell = {0, 0, 0}, .opacity = 1e-4f});
        SplatBuilder b;
        b.begin(cam);
        b.add(g, mat, {.textured = false});
        b.sort();
        auto fb = gl::Framebuffer::create({.width = 5, .height = 5, .color = p});
        fb->clear({0, 0, 0, 0});
        renderer->draw(b.splats(), cam, {.framebuffer = fb->handle(), .width = 5, .height = 5});
        return double(fb->read().at(2, 2, 3));
    };
    const double one = centre(1, gl::Precision::F32);
    EXPECT_NEAR(one, 1e-4, 1e-4 * 0.05) << "one splat: opacity 1e-4 up to the 8-bit window (< 5 %)";
    for (gl::Precision p : {gl::Precision::F32, gl::Precision::F16, gl::Precision::U8}) {
        double prev = 0.0;
        for (int n : {1, 10, 100, 1000, 10000, 100000}) {
            const double a = centre(n, p), exact = 1.0 - std::pow(1.0 - one, n);
            ASSERT_TRUE(std::isfinite(a));
            EXPECT_GE(a, 0.0);
            EXPECT_LE(a, 1.0);
            EXPECT_GE(a, prev) << "monotone in N, n = " << n;
            if (p == gl::Precision::F32) {
                EXPECT_NEAR(a, exact, n * std::ldexp(1.0, -24) + 1e-7) << "n = " << n;
            } else {
                EXPECT_LE(a, exact + (p == gl::Precision::U8 ? 1.0 / 255 : std::ldexp(1.0, -11))) << "n = " << n;
            }
            prev = a;
        }
        if (p == gl::Precision::F32) { EXPECT_GT(prev, 0.99); }
    }
}

Grid boxOf(int n, float opacity) {
    Grid g = *Grid::box({n, n, n}, glm::vec3(0.5f));
    for (Voxel& v : g.voxels) v.opacity = opacity;
    return g;
}

TEST_F(Stability, CameraExactlyAtAVoxelCentre) {
    const Grid g = boxOf(5, 0.3f);
    const glm::vec3 eye = g.worldPosition({2, 2, 2});
    const Result r = run(g, Camera::lookAt(eye, eye + glm::vec3(0.3f, 0.1f, -1), {0, 1, 0}, 1.2f, {48, 40}), plain());
    EXPECT_LE(r.worst, r.bound);
    EXPECT_GT(visible(r.ref), 0.1);
}

TEST_F(Stability, CameraInsideTheVolume) {
    const Grid g = boxOf(7, 0.25f);
    const Result r = run(g, Camera::lookAt({0.2f, 1.3f, 0.1f}, {1, 1.5f, -3}, {0, 1, 0}, 1.2f, {48, 40}), plain());
    EXPECT_LE(r.worst, r.bound);
    EXPECT_GT(visible(r.ref), 0.1);
}

TEST_F(Stability, VoxelOnTheNearPlane) {
    // The voxel centre sits exactly at the near plane's distance: the depth
    // cut (issue 15) keeps the half of its kernel behind the near plane, so
    // every voxel draws and GL agrees with the reference's exact cut.
    Grid g;
    for (int z = 0; z < 4; ++z) g.voxels.push_back({.cell = {0, 0, -z}, .opacity = 0.7f});
    const float nearPlane = 0.5f;
    const Camera cam = Camera::lookAt({0, 0, nearPlane}, {0, 0, -1}, {0, 1, 0}, 1.0f, {40, 32}, nearPlane, 100.0f);
    const Result r = run(g, cam, plain());
    EXPECT_LE(r.worst, r.bound);
    EXPECT_EQ(r.splats, 4u) << "the voxel on the near plane is cut, not faded out";
    EXPECT_GT(visible(r.ref), 0.1);
}

TEST_F(Stability, CameraHundredThousandUnitsAway) {
    // A telephoto view from 1e5 units. The GL transforms in float: positions
    // of magnitude 1e5 carry an ulp of 2^-7 world units, i.e. this many pixels
    // at this zoom; the allowed error adds that shift times the largest
    // difference between neighbouring reference pixels.
    const Grid g = boxOf(4, 0.5f);
    const glm::ivec2 size{48, 40};
    const float dist = 1e5f, fov = 4.0f / dist;
    const Camera cam = Camera::lookAt({0, 1, dist}, {0, 1, 0}, {0, 1, 0}, fov, size, dist - 100.0f, dist + 100.0f);
    const double shiftPx = std::ldexp(1.0, -7) / (2.0 * dist * std::tan(0.5 * fov) / size.y);
    SplatBuilder b;
    b.begin(cam);
    b.add(g, plain(), {.textured = false});
    SplatExactDesc rd;
    rd.host.background = kBackground;
    auto ref = renderSplatExact(b.splats(), cam, plain(), rd);
    ASSERT_TRUE(ref);
    double grad = 0.0;
    for (int y = 0; y + 1 < size.y; ++y)
        for (int x = 0; x + 1 < size.x; ++x)
            for (int c = 0; c < 4; ++c)
                grad = std::max(
                    {grad, double(std::abs(ref->at(x + 1, y, c) - ref->at(x, y, c))), double(std::abs(ref->at(x, y + 1, c) - ref->at(x, y, c)))});
    const Result r = run(g, cam, plain(), {.textured = false}, gl::Precision::F32, 2.0 * shiftPx * grad);
    EXPECT_LE(r.worst, r.bound) << "shift " << shiftPx << " px";
    EXPECT_GT(visible(r.ref), 0.3);
}

TEST_F(Stability, ViewNearlyAlongAStretchedKernel) {
    // Stretch 20 along z seen 1e-3 rad off that axis: the ellipse degenerates
    // towards a disc with a huge chord; axes and density must stay finite, and
    // the splat's (clamped) density is what both renderers draw.
    Grid g;
    g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.4f, .stretch = {0, 0, 20}});
    g.voxels.push_back({.cell = {2, 0, 0}, .opacity = 0.4f, .stretch = {0, 20, 0}});
    const Camera cam = Camera::lookAt({0.03f, 0.0f, 30.0f}, {1, 0, 0}, {0, 1, 0}, 0.3f, {48, 40});
    const Result r = run(g, cam, plain());
    EXPECT_EQ(r.splats, 2u);
    EXPECT_LE(r.worst, r.bound);
    EXPECT_GT(visible(r.ref), 0.2);
}

Grid texturedBox() {
    Grid g = *Grid::box({4, 4, 2}, glm::vec3(0.5f));
    for (Voxel& v : g.voxels) v.opacity = 0.5f, v.texture = std::uint32_t(v.cell.x * 7 + v.cell.y);
    return g;
}
const Camera kTexCam = Camera::lookAt({0.5f, 1.5f, 5}, {0, 1, 0}, {0, 1, 0}, 0.8f, {48, 40});

TextureSet uniformSet(int count, float value) {
    TextureSet t = TextureSet::turbulence({.count = count, .size = 32});
    for (auto& layer : t.layers)
        for (size_t i = 0; i < layer.size(); i += 4) layer[i] = layer[i + 1] = layer[i + 2] = value;
    return t;
}

TEST_F(Stability, TextureSetOfOneTexture) {
    Materials mat = plain();
    const std::uint32_t set = mat.addTextureSet(TextureSet::turbulence({.count = 1, .size = 32}));
    const Result r = run(texturedBox(), kTexCam, mat, {.textureSet = set, .crossfade = true});
    EXPECT_LE(r.worst, r.bound);
    EXPECT_GT(visible(r.ref), 0.2);
}

TEST_F(Stability, TextureSetAllZeroDrawsNothing) {
    Materials mat = plain();
    const std::uint32_t set = mat.addTextureSet(uniformSet(3, 0.0f));
    const Result r = run(texturedBox(), kTexCam, mat, {.textureSet = set});
    EXPECT_EQ(mat.set(set).gain, 1.0f) << "no division by the zero mean";
    EXPECT_EQ(visible(r.gl), 0.0);
    EXPECT_EQ(visible(r.ref), 0.0);
}

TEST_F(Stability, TextureSetAllOneEqualsPlainSplatting) {
    // Detail 1 everywhere windowed by the footprint is the plain footprint
    // layer, with gain exactly 1: textured and untextured draws are identical.
    Materials mat = plain();
    const std::uint32_t set = mat.addTextureSet(uniformSet(3, 1.0f));
    EXPECT_EQ(mat.set(set).gain, 1.0f);
    const Result tex = run(texturedBox(), kTexCam, mat, {.textureSet = set});
    const Result flat = run(texturedBox(), kTexCam, mat, {.textured = false});
    EXPECT_EQ(tex.gl.pixels, flat.gl.pixels);
    EXPECT_LE(tex.worst, tex.bound);
}

// SplatVariation (issue 25) lives in the Splat list both paths read: jittered,
// turned, mirrored and scaled splats agree with the reference within the
// same derived bound, and the variation visibly changes the image.
TEST_F(Stability, VariedSplatsMatchTheReference) {
    Materials mat = plain();
    const std::uint32_t set = mat.addTextureSet(TextureSet::turbulence({.count = 4, .size = 32}));
    const SplatVariation varied{.jitter = 0.5f, .rotationRad = 3.14159265f, .mirror = true, .scaleLog2 = 0.3f, .seed = 5};
    const Result r = run(texturedBox(), kTexCam, mat, {.textureSet = set, .crossfade = true, .variation = varied});
    EXPECT_LE(r.worst, r.bound);
    EXPECT_GT(visible(r.ref), 0.2);
    const Result lattice = run(texturedBox(), kTexCam, mat, {.textureSet = set, .crossfade = true});
    double moved = 0.0;
    for (size_t i = 0; i < r.gl.pixels.size(); ++i) moved = std::max(moved, double(std::abs(r.gl.pixels[i] - lattice.gl.pixels[i])));
    // The derived bound is loose (it adds every overlapping splat's worst case); against the
    // two paths' actual disagreement the variation's change must stand an order of magnitude out.
    std::printf("  the variation changes a pixel by up to %.3f\n", moved);
    EXPECT_GT(moved, 10.0 * r.worst) << "the variation must change the picture well beyond the GL-vs-reference difference";
}

} // namespace
} // namespace splatfx
