// One medium with the splats (issue 14, items 2-3): gl::FrameRenderer fogs the
// host image from its depth texture and every splat fragment, against the
// splat-exact reference integrating the same fog numerically along each ray.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/reference.hpp"

namespace splatfx {
namespace {

constexpr double kEps = 5.9604644775390625e-08; // 2^-24: float rounding, relative
constexpr glm::ivec2 kSize{64, 48};
const glm::vec4 kBackground{0.1f, 0.2f, 0.3f, 1.0f};

// A fog at the scale of the test scene (a few units): a constant, a cosine
// layer and a point equipotential next to the splats. Density 0.02 to 0.66.
Fog testFog() {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.06));
    d.terms.push_back(FogTerm::cosine(0.04, 1.3, {1.0, 0.2, 0.0}, 0.2));
    d.terms.push_back(FogTerm::point(0.6, {0.3, 0.0, 0.5}, 1.0, 3.0));
    d.colour = {0.7, 0.75, 0.8};
    return *Fog::create(d);
}

Camera testCamera() { return Camera::lookAt({0.4f, 0.3f, 5.0f}, {0, 0, 0}, {0, 1, 0}, 0.9f, kSize, 0.05f, 30.0f); }

// Float evaluation error of the optical depth on segments up to lengthMax
// (the shader's own arithmetic, derived per term as in fog_glsl_gl_test):
// each term's integral is amplitude * L * (a cos/atan of an argument of size
// A, rounded to 2^-24 A, plus the device's own error, under 2^-20 on
// llvmpipe, fog_glsl_gl_test measures it), with 16 roundings for the sums and
// products around it; plus the rounding of the endpoint (the interpolated or
// unprojected position, relative error `positionRel`) times the density there.
double tauFloatBound(const Fog& fog, double lengthMax, double densityMax, double positionRel) {
    double b = 0.0;
    for (const FogTerm& t : fog.desc().terms) {
        const double amp = std::abs(t.weight) * (t.kind == FogTermKind::Point ? 1.0 / t.c : 1.0);
        const double arg = t.kind == FogTermKind::Cosine ? glm::length(t.wave) * (lengthMax + 10.0) + std::abs(t.phase) : 4.0;
        b += amp * lengthMax * (arg * kEps + std::ldexp(1.0, -20) + 16.0 * kEps);
    }
    return b + densityMax * lengthMax * positionRel;
}

struct Splats {
    Materials materials{Footprint{}};
    Frame frame;
    Splats() {
        materials.addColorTable(ColorTable::constant({0.9f, 0.5f, 0.2f, 1.0f}));
        Grid g;
        for (int z = -1; z <= 1; ++z)
            for (int x = -1; x <= 1; ++x) g.voxels.push_back({.cell = {x, 0, z}, .opacity = 0.5f});
        g.spacing = glm::vec3(0.6f);
        frame.begin(0.0, testCamera());
        frame.builder().add(g, materials, {.textured = false});
        frame.end();
    }
};

// The host: background colour; depth 0.995 (7.5 units, behind the splats) on
// the left 20 columns, sky (1.0) elsewhere.
void drawHost() {
    glClearColor(kBackground.r, kBackground.g, kBackground.b, kBackground.a);
    glClearDepth(1.0);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, 20, kSize.y);
    glClearDepth(0.995);
    glClear(GL_DEPTH_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
    glClearDepth(1.0);
}

double maxDiff(const Image& a, const Image& b) {
    double w = 0.0;
    for (size_t i = 0; i < a.pixels.size(); ++i) w = std::max(w, double(std::abs(a.pixels[i] - b.pixels[i])));
    return w;
}

class FogFrameGL : public test::GLTest {};

TEST_F(FogFrameGL, SplatsAndHostInFogAgreeWithTheReferenceWithinSplatErrorPlusFogError) {
    Splats s;
    ASSERT_GT(s.frame.splats().size(), 5u);
    auto fr = gl::FrameRenderer::create({.splats = {.sampling = gl::TextureSampling::Bilinear}});
    ASSERT_TRUE(fr) << fr.error();
    ASSERT_TRUE(fr->upload(s.materials));
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fb);
    const Fog fog = testFog();

    auto drawGL = [&](const Fog* f) {
        s.frame.setFog(f ? std::make_shared<const Fog>(*f) : nullptr);
        fr->render(s.frame, {.framebuffer = fb->handle(), .drawOpaque = drawHost});
        return fb->read();
    };
    const Image glPlain = drawGL(nullptr);
    EXPECT_FALSE(fr->stats().fog.host || fr->stats().fog.splats);
    const Image depth = fb->readDepth();
    const Image glFog = drawGL(&fog);
    EXPECT_TRUE(fr->stats().fog.host && fr->stats().fog.splats) << fr->stats().fog.error;

    SplatExactDesc rd;
    rd.host.background = kBackground;
    rd.host.depth = &depth;
    auto refPlain = renderSplatExact(s.frame.splats(), s.frame.camera(), s.materials, rd);
    ASSERT_TRUE(refPlain) << refPlain.error();
    rd.fog = &fog;
    rd.fogTolerance = 1e-9;
    SplatExactStats st;
    auto refFog = renderSplatExact(s.frame.splats(), s.frame.camera(), s.materials, rd, &st);
    ASSERT_TRUE(refFog) << refFog.error();
    EXPECT_EQ(st.fogUnconverged, 0u);
    EXPECT_GT(st.fragments, 0u);

    // The splat-only error, measured on the same frame.
    const double splatError = maxDiff(glPlain, *refPlain);
    // Fogging replaces each premultiplied layer (c, a) by the convex
    // combination f (c, a) + (1 - f) (a C_fog, a) with C_fog <= 1, so the
    // splats' own errors (in colour and alpha) pass through at most unchanged;
    // what fog adds is |df| <= |dtau| per layer and for the host point, each
    // weighting a colour of at most 1: twice the float bound of tau plus the
    // quadrature's own error. Positions: the rasterizer's interpolated
    // world position and the unprojected host point (at most 75x the depth's
    // rounding for the far plane of this camera: (f + n) / ((f + n) - z (f - n))).
    const double lengthMax = 30.0 * 1.2, densityMax = 0.06 + 0.04 + 0.6;
    const double tauBound = tauFloatBound(fog, lengthMax, densityMax, 75.0 * 8.0 * kEps);
    const double bound = splatError + 2.0 * tauBound + 2.0 * st.fogMaxErrorEstimate + 1e-6;
    const double fogError = maxDiff(glFog, *refFog);
    EXPECT_LT(2.0 * tauBound, 0.01) << "the fog's share of the bound must stay small";
    EXPECT_GT(maxDiff(*refFog, *refPlain), 0.2) << "the fog must change the picture";
    EXPECT_GT(st.fogMaxOpticalDepth, 1.0);
    EXPECT_LE(fogError, bound) << "splat-only error " << splatError << ", fog share " << 2.0 * tauBound;
    RecordProperty("splat_error", std::to_string(splatError));
    RecordProperty("fog_error", std::to_string(fogError));
}

// A host depth texture with every hard value: a surface, sky (1.0), NaN,
// beyond 1 and below 0; per pixel against the reference's host fog.
// The host fog alone: a depth texture holding `depthAt(x, y)` (GL rows,
// bottom first) under `camera`, fogged by the frame renderer, and the
// splat-exact reference of the same (its depth is what the texture holds: a
// driver may clamp out-of-range values on upload).
struct HostFogRun {
    Image got, want, depth;
    SplatExactStats reference;
};
template <class DepthAt>
HostFogRun renderHostFog(const Camera& camera, const Fog& fog, DepthAt depthAt) {
    HostFogRun run;
    const glm::ivec2 size = camera.viewport; // the image: the camera's viewport
    GLuint fbo = 0, colour = 0, depthTex = 0;
    glCreateFramebuffers(1, &fbo);
    glCreateTextures(GL_TEXTURE_2D, 1, &colour);
    glTextureStorage2D(colour, 1, GL_RGBA32F, size.x, size.y);
    glCreateTextures(GL_TEXTURE_2D, 1, &depthTex);
    glTextureStorage2D(depthTex, 1, GL_DEPTH_COMPONENT32F, size.x, size.y);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, colour, 0);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depthTex, 0);
    EXPECT_EQ(glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
    std::vector<float> d(size_t(size.x) * size.y);
    for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) d[size_t(y) * size.x + x] = depthAt(x, y);
    glTextureSubImage2D(depthTex, 0, 0, 0, size.x, size.y, GL_DEPTH_COMPONENT, GL_FLOAT, d.data());
    std::vector<float> held(d.size());
    glGetTextureImage(depthTex, 0, GL_DEPTH_COMPONENT, GL_FLOAT, GLsizei(held.size() * 4), held.data());
    run.depth.width = size.x, run.depth.height = size.y, run.depth.channels = 1;
    run.depth.pixels.resize(held.size());
    for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) run.depth.pixels[size_t(y) * size.x + x] = held[size_t(size.y - 1 - y) * size.x + x];

    Frame frame;
    frame.begin(0.0, camera);
    frame.end();
    frame.setFog(std::make_shared<const Fog>(fog));
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::constant(glm::vec4(1.0f)));
    auto fr = gl::FrameRenderer::create();
    EXPECT_TRUE(fr) << fr.error();
    if (!fr) return run;
    EXPECT_TRUE(fr->upload(mat));
    const float clear[4] = {kBackground.r, kBackground.g, kBackground.b, kBackground.a};
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, clear);
    glClipControl(GL_LOWER_LEFT, camera.depth.clip == ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE); // the host's state
    fr->render(frame, {.framebuffer = fbo, .depthTexture = depthTex});
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    EXPECT_TRUE(fr->stats().fog.host) << fr->stats().fog.error;
    run.got.width = size.x, run.got.height = size.y, run.got.channels = 4;
    std::vector<float> raw(size_t(size.x) * size.y * 4);
    glGetTextureImage(colour, 0, GL_RGBA, GL_FLOAT, GLsizei(raw.size() * 4), raw.data());
    run.got.pixels.resize(raw.size());
    for (int y = 0; y < size.y; ++y)
        std::copy_n(raw.begin() + std::ptrdiff_t(size_t(size.y - 1 - y) * size.x * 4), size.x * 4,
                    run.got.pixels.begin() + std::ptrdiff_t(size_t(y) * size.x * 4));
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &colour);
    glDeleteTextures(1, &depthTex);

    SplatExactDesc rd;
    rd.host.background = kBackground;
    rd.host.depth = &run.depth;
    rd.fog = &fog;
    auto ref = renderSplatExact({}, frame.camera(), mat, rd, &run.reference);
    EXPECT_TRUE(ref) << ref.error();
    if (ref) run.want = std::move(*ref);
    return run;
}

TEST_F(FogFrameGL, HostFogHandlesSkyNaNAndOutOfRangeDepth) {
    // Columns in bands: a ramp of surfaces, 1.0, NaN, 1.5, -0.5 (GL bottom row first).
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Fog fog = testFog();
    const HostFogRun run = renderHostFog(testCamera(), fog, [&](int x, int y) {
        const int band = x / 13;
        return band == 0 ? 0.9f + 0.1f * float(y) / kSize.y : band == 1 ? 1.0f : band == 2 ? nan : band == 3 ? 1.5f : -0.5f;
    });
    ASSERT_FALSE(run.want.pixels.empty());
    // No splats: only the host fog's float error (as above; the unprojection
    // blends 1 / view depth between its values at depth 0 and 1, each point's
    // relative error a few roundings: 8 eps).
    const double bound = 2.0 * tauFloatBound(fog, 36.0, 0.7, 8.0 * kEps) + 2.0 * run.reference.fogMaxErrorEstimate + 1e-6;
    EXPECT_LE(maxDiff(run.got, run.want), bound);
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 26; x < kSize.x; ++x) {
            const float dv = run.depth.at(x, y, 0);
            if (std::isnan(dv) || dv < 0.0f || dv > 1.0f) {
                ASSERT_NEAR(run.got.at(x, y, 0), fog.desc().colour.x, 1e-6) << "invalid depth is fully fogged at " << x << "," << y;
            }
        }
    for (float v : run.got.pixels) ASSERT_TRUE(std::isfinite(v));
}

// Engines' near / far ratios, in every depth convention (issue 26): the sky
// (the far plane's depth, or no point at all under an infinite far plane:
// fully fogged) and surfaces out to the far plane keep their fog distance. A
// float inverse projection loses it there (its w at the far plane is the
// difference of two terms of size 1 / (2 near) whose sum is 1 / far: at near
// 0.01, far 1e5 the sky's fog distance was off by 22 % against POV-Ray's
// media); every pass blends 1 / view depth between its values at window
// depth 0 and 1 instead (host_depth.glsl), so its error stays a few roundings
// at any ratio, against the double-precision reference reading the same
// stored depths. The far plane is the one the (float) projection matrix
// itself implies, the one the GPU's depth values follow.
TEST_F(FogFrameGL, HostFogKeepsTheSkyAtLargeFarOverNear) {
    const DepthConvention conventions[] = {{}, {.clip = ClipDepth::ZeroToOne}, {.reversed = true}, {.clip = ClipDepth::ZeroToOne, .reversed = true},
                                           {.clip = ClipDepth::ZeroToOne, .reversed = true, .infiniteFar = true}};
    for (const DepthConvention& dc : conventions)
        for (const glm::vec2 nearFar : {glm::vec2(0.05f, 1e4f), glm::vec2(0.01f, 1e5f), glm::vec2(0.1f, 3e5f), glm::vec2(0.001f, 1e4f)}) {
            const glm::ivec2 size = kSize;
            SCOPED_TRACE(describe(dc) + ", near " + std::to_string(nearFar.x) + ", far " + std::to_string(nearFar.y));
            // About one optical depth at the far plane (or the farthest surface): neither clear nor saturated.
            FogDesc fd;
            fd.terms.push_back(FogTerm::constant(0.7 / nearFar.y));
            fd.terms.push_back(FogTerm::cosine(0.3 / nearFar.y, 3.0 / nearFar.y, {1.0, 0.3, 0.0}, 0.4));
            fd.colour = {0.7, 0.75, 0.8};
            const Fog fog = *Fog::create(fd);
            const Camera cam = Camera::lookAt({0.4f, 0.3f, 5.0f}, {0, 0, 0}, {0, 1, 0}, 0.9f, size, nearFar.x, nearFar.y, dc);
            // Window depth of view depth z under the camera's float matrix, rounded to float as a depth buffer holds it.
            auto windowOf = [&](double z) {
                const glm::dvec4 c = glm::dmat4(cam.proj) * glm::dvec4(0.0, 0.0, -z, 1.0);
                const double ndc = c.z / c.w;
                return float(dc.clip == ClipDepth::ZeroToOne ? ndc : 0.5 * ndc + 0.5);
            };
            // Sky on the right half; on the left, surfaces from 0.5 far to within 1e-4 of it.
            const HostFogRun run = renderHostFog(cam, fog, [&](int x, int y) {
                if (x >= size.x / 2) return float(dc.farWindow());
                const double t = double(y + 1) / size.y;
                return windowOf(double(nearFar.y) * (x % 2 ? 1.0 - 1e-4 * t : 1.0 - 0.5 * t));
            });
            ASSERT_FALSE(run.want.pixels.empty());
            EXPECT_EQ(run.reference.fogUnconverged, 0u);
            const double densityMax = 1.0 / nearFar.y, lengthMax = 1.2 * nearFar.y;
            const double bound = 2.0 * tauFloatBound(fog, lengthMax, densityMax, 8.0 * kEps) + 2.0 * run.reference.fogMaxErrorEstimate + 1e-6;
            const double err = maxDiff(run.got, run.want);
            std::printf("%s, far/near %.0e: max |GL - reference| %.2e (bound %.2e)\n", describe(dc).c_str(), double(nearFar.y / nearFar.x), err, bound);
            EXPECT_LE(err, bound);
            // The sky: the far-plane point's fog, or full fog without a far plane; never the background.
            if (dc.infiniteFar) { EXPECT_NEAR(run.got.at(size.x - 1, 0, 0), fog.desc().colour.x, 1e-6); }
        }
}

// Reduced fog textures: each pixel's upsampled f is a convex combination of the
// four texels around it that lie on its own surface (each evaluated at one
// full-resolution pixel), so it must lie within the range of the per-pixel f
// at those pixels: across the silhouette between a near surface and the sky
// nothing bleeds. Only where none of the four is on its surface does it take
// one of the others.
TEST_F(FogFrameGL, ReducedFogTextureStaysWithinTheSameSurfacesPerPixelRange) {
    const Fog fog = testFog();
    Frame frame;
    frame.begin(0.0, testCamera());
    frame.end();
    frame.setFog(std::make_shared<const Fog>(fog));
    Materials mat{Footprint{}};
    mat.addColorTable(ColorTable::constant(glm::vec4(1.0f)));
    // Near surface (depth 0.99, about 3.7 units) on a disc, sky around it.
    auto host = [] {
        glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
        glClearDepth(1.0);
        glDepthMask(GL_TRUE);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glEnable(GL_SCISSOR_TEST);
        glScissor(17, 9, 23, 25);
        glClearDepth(0.99);
        glClear(GL_DEPTH_BUFFER_BIT);
        glDisable(GL_SCISSOR_TEST);
        glClearDepth(1.0);
    };
    auto render = [&](glm::ivec2 texSize) {
        auto fr = gl::FrameRenderer::create({.fogTextureSize = texSize});
        EXPECT_TRUE(fr) << fr.error();
        EXPECT_TRUE(fr->upload(mat));
        auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
        fr->render(frame, {.framebuffer = fb->handle(), .drawOpaque = host});
        EXPECT_TRUE(fr->stats().fog.host) << fr->stats().fog.error;
        return std::make_pair(fb->read(), fb->readDepth());
    };
    const auto [perPixel, depth] = render({0, 0});
    for (glm::ivec2 tex : {glm::ivec2{32, 24}, glm::ivec2{16, 16}, glm::ivec2{8, 6}}) {
        const Image got = render(tex).first;
        // f = 1 - alpha (the background is black with alpha 1: alpha stays 1; use red / C_fog.r).
        auto fOf = [&](const Image& im, int x, int y) { return 1.0 - im.at(x, y, 0) / fog.desc().colour.x; };
        double worstExcess = 0.0;
        int fallbacks = 0;
        for (int y = 0; y < kSize.y; ++y)
            for (int x = 0; x < kSize.x; ++x) {
                const float dv = depth.at(x, y, 0);
                // The four texels the upsampling reads (GL rows bottom first) and
                // the full-resolution pixel each one was evaluated at.
                const double gx = (x + 0.5) / kSize.x * tex.x - 0.5, gy = (kSize.y - 1 - y + 0.5) / kSize.y * tex.y - 0.5;
                double lo = 1e9, hi = -1e9, loAll = 1e9, hiAll = -1e9;
                for (int j = 0; j < 2; ++j)
                    for (int i = 0; i < 2; ++i) {
                        const int tx = std::clamp(int(std::floor(gx)) + i, 0, tex.x - 1), ty = std::clamp(int(std::floor(gy)) + j, 0, tex.y - 1);
                        const int px = int(std::floor((tx + 0.5) / tex.x * kSize.x));
                        const int py = kSize.y - 1 - int(std::floor((ty + 0.5) / tex.y * kSize.y));
                        const double fs = fOf(perPixel, px, py);
                        loAll = std::min(loAll, fs), hiAll = std::max(hiAll, fs);
                        if (depth.at(px, py, 0) == dv) lo = std::min(lo, fs), hi = std::max(hi, fs);
                    }
                if (lo > hi) lo = loAll, hi = hiAll, ++fallbacks; // no texel on this surface: the nearest in distance
                const double f = fOf(got, x, y);
                worstExcess = std::max(worstExcess, std::max(lo - f, f - hi));
            }
        EXPECT_LT(fallbacks, kSize.x * kSize.y / 10) << tex.x << "x" << tex.y;
        // 1e-5: float rounding of f and of the blend (colour <= 1).
        EXPECT_LE(worstExcess, 1e-5) << tex.x << "x" << tex.y;
    }
}

// RendererDesc::fogPerSplat: f at each splat's centre. For a constant fog k,
// f depends only on the distance from the eye, which differs between a
// fragment and its splat's centre by at most the drawn half-diagonal R, so
// each layer's f moves by at most k R, and the composite (weights summing to
// at most 1, colours <= 1) by at most that on top of the splat-only error.
TEST_F(FogFrameGL, PerSplatFogStaysWithinTheFogsVariationAcrossASplat) {
    Splats s;
    FogDesc fd;
    const double k = 0.15;
    fd.terms.push_back(FogTerm::constant(k));
    fd.colour = {0.7, 0.75, 0.8};
    const Fog fog = *Fog::create(fd);
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fb);
    auto draw = [&](bool perSplat, const Fog* f) {
        auto fr = gl::FrameRenderer::create({.splats = {.sampling = gl::TextureSampling::Bilinear, .fogPerSplat = perSplat}});
        EXPECT_TRUE(fr) << fr.error();
        EXPECT_TRUE(fr->upload(s.materials));
        s.frame.setFog(f ? std::make_shared<const Fog>(*f) : nullptr);
        fr->render(s.frame, {.framebuffer = fb->handle(), .drawOpaque = drawHost});
        return fb->read();
    };
    const Image plain = draw(false, nullptr);
    const Image depth = fb->readDepth();
    const Image perFragment = draw(false, &fog);
    const Image perSplat = draw(true, &fog);
    SplatExactDesc rd;
    rd.host.background = kBackground;
    rd.host.depth = &depth;
    auto refPlain = renderSplatExact(s.frame.splats(), s.frame.camera(), s.materials, rd);
    rd.fog = &fog;
    SplatExactStats st;
    auto refFog = renderSplatExact(s.frame.splats(), s.frame.camera(), s.materials, rd, &st);
    ASSERT_TRUE(refPlain && refFog);
    double radius = 0.0;
    for (const Splat& sp : s.frame.splats())
        radius = std::max(radius,
                          double(gl::RendererDesc{}.footprintCut) * std::sqrt(double(glm::dot(sp.axisU, sp.axisU) + glm::dot(sp.axisV, sp.axisV))));
    const double splatError = maxDiff(plain, *refPlain);
    const double floatBound = 2.0 * tauFloatBound(fog, 36.0, k, 75.0 * 8.0 * kEps) + 2.0 * st.fogMaxErrorEstimate + 1e-6;
    EXPECT_LE(maxDiff(perFragment, *refFog), splatError + floatBound);
    EXPECT_LE(maxDiff(perSplat, *refFog), splatError + floatBound + k * radius) << "R = " << radius;
    EXPECT_GT(maxDiff(perSplat, perFragment), 1e-4) << "the knob must change what is drawn";
    EXPECT_LT(k * radius, 0.5) << "the bound must mean something";
}

TEST_F(FogFrameGL, FogTextureSizeIsValidated) {
    auto bad = gl::FrameRenderer::create({.fogTextureSize = {256, 0}});
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("fogTextureSize"), std::string::npos);
    EXPECT_FALSE(gl::FrameRenderer::create({.fogTextureSize = {-1, 4}}));
}

} // namespace
} // namespace splatfx
