// [clouds, issue 17] The projected-tetrahedra pass against the CPU references
// on the same emitted mesh: outside the cloud, with the host's depth cutting
// it, and with the camera inside it (near-plane clipping).
#include <algorithm>
#include <cmath>
#include <limits>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "gl_fixture.hpp"
#include "splatfx/cloud.hpp"
#include "splatfx/gl/frame_plan.hpp"
#include "scenes.hpp"

using namespace splatfx;

namespace {

constexpr glm::ivec2 kSize{64, 48};

struct TestCloud {
    ScalarVolume field;
    std::optional<LodVolume> volume;
    std::optional<TransferFunction> transfer;
    std::optional<PreIntegrationTable> table;
    float maxExtinction = 2.0f;
    explicit TestCloud(CloudModel model = CloudModel::DensityTableLightLength) {
        auto f = makeCloudVolume({.dims = {17, 17, 9}, .seed = 5, .featureCells = 6.0f, .coverage = 0.6f, .model = model});
        field = *f;
        volume.emplace(*LodVolume::create(field, {.spacingWorld = 1.0f}));
        transfer.emplace(*makeCloudTransfer({.maxExtinctionPerWorld = maxExtinction}, model));
        // The longest segment: the cube's diagonal (length scales are <= 1).
        table.emplace(
            *PreIntegrationTable::create(*transfer, {.scalarResolution = 32, .lengthResolution = 64, .maxLengthWorld = std::sqrt(3.0f) * 16.0f}));
    }
};

// The ray through a pixel centre (x right, y top row first), from the eye (unit direction).
glm::dvec3 pixelRay(const Camera& cam, int x, int y) {
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    const double nx = (x + 0.5) / cam.viewport.x * 2.0 - 1.0, ny = 1.0 - (y + 0.5) / cam.viewport.y * 2.0;
    glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
    return glm::normalize(glm::dvec3(b) / b.w - glm::dvec3(a) / a.w);
}

// What the GL pass computes for one ray, on the CPU in double: each
// tetrahedron the ray crosses is one table lookup of (front scalar, back
// scalar, length x mean length scale), composited front to back. `bound`
// receives the derived worst case of |GL - this| (see below).
// With a fog (and `transfer`), each segment is fogged as the fog
// variant does (f at the opacity centroid, closed-form f in double) and three
// more figures per ray are summed over the segments: `tableError`, 2 x the
// largest channel of |lookup - exact segment integral| (a layer error e moves
// the composite by <= 2e), and `placement`, 2 alpha_i (f(entry) - f(exit)):
// the most that putting the segment's fog in front of or behind its matter
// can change the pixel (colours <= 1; docs/fog.md, "Tetrahedra").
struct FogModel {
    const Fog* fog = nullptr;
    const TransferFunction* transfer = nullptr;
    double tableError = 0.0, placement = 0.0;
    glm::dvec4 exactSegments{0.0}; // the same fogged composite of the exact segment integrals (no table)
};

glm::dvec4 passModel(const std::vector<Tetrahedron>& tets, const PreIntegrationTable& table, glm::dvec3 o, glm::dvec3 d, double tFar, double& bound,
                     FogModel* fm = nullptr) {
    struct Piece {
        double t0, t1;
        std::size_t tet;
    };
    std::vector<Piece> pieces;
    static constexpr int kFaces[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};
    for (std::size_t i = 0; i < tets.size(); ++i) {
        double lo = 0.0, hi = tFar;
        for (const auto& f : kFaces) {
            const auto& p = tets[i].position;
            const glm::dvec3 a(p[std::size_t(f[0])]), b(p[std::size_t(f[1])]), c(p[std::size_t(f[2])]), q(p[std::size_t(f[3])]);
            glm::dvec3 n = glm::cross(b - a, c - a);
            if (glm::dot(n, q - a) < 0.0) n = -n;
            const double num = glm::dot(n, o - a), den = glm::dot(n, d);
            if (den == 0.0) {
                if (num < 0.0) hi = lo - 1.0;
                continue;
            }
            if (den > 0.0) lo = std::max(lo, -num / den);
            else hi = std::min(hi, -num / den);
        }
        if (hi > lo) pieces.push_back({lo, hi, i});
    }
    std::sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) { return a.t0 < b.t0; });
    const glm::ivec3 n = table.dims();
    const auto& data = table.data();
    glm::dvec4 acc(0.0);
    bound = 1e-5; // F32 framebuffer blending, once
    for (const Piece& pc : pieces) {
        const Tetrahedron& t = tets[pc.tet];
        const auto [lo, hi] = std::minmax_element(t.scalar.begin(), t.scalar.end());
        if (table.zeroOpacity(*lo, *hi)) continue; // the pass skips these: their table entries are zero
        const glm::dvec3 p0(t.position[0]);
        const glm::dmat3 inv =
            glm::inverse(glm::dmat3(glm::dvec3(t.position[1]) - p0, glm::dvec3(t.position[2]) - p0, glm::dvec3(t.position[3]) - p0));
        auto at = [&](double tt, const std::array<float, 4>& v) {
            const glm::dvec3 l = inv * (o + d * tt - p0);
            return (1.0 - l.x - l.y - l.z) * v[0] + l.x * v[1] + l.y * v[2] + l.z * v[3];
        };
        const double sf = at(pc.t0, t.scalar), sb = at(pc.t1, t.scalar);
        const double len = (pc.t1 - pc.t0) * std::max(0.5 * (at(pc.t0, t.lengthScale) + at(pc.t1, t.lengthScale)), 0.0);
        glm::dvec4 c(table.lookup(float(sf), float(sb), float(len)));
        if (fm && fm->fog) {
            const glm::dvec4 exactSeg = integrateSegment(*fm->transfer, sf, sb, pc.t1 - pc.t0, at(pc.t0, t.lengthScale), at(pc.t1, t.lengthScale));
            double e = 0.0;
            for (int ch = 0; ch < 4; ++ch) e = std::max(e, std::abs(c[ch] - exactSeg[ch]));
            fm->tableError += 2.0 * e;
            const double a = std::clamp(c.a, 0.0, 1.0), tau = -std::log(std::max(1.0 - a, 1e-30));
            const double w = tau < 1e-2 ? 0.5 - tau / 12.0 : 1.0 / tau - 1.0 / std::expm1(std::min(tau, 80.0));
            const double f = fm->fog->transmittance(o, o + d * (pc.t0 + w * (pc.t1 - pc.t0)), 0.0);
            fm->placement += 2.0 * a * (fm->fog->transmittance(o, o + d * pc.t0, 0.0) - fm->fog->transmittance(o, o + d * pc.t1, 0.0));
            c = glm::dvec4(f * glm::dvec3(c) + (1.0 - f) * c.a * fm->fog->desc().colour, c.a);
            // The exact segment, fogged by the same rule at its own centroid.
            const double ae = std::clamp(exactSeg.a, 0.0, 1.0), te = -std::log(std::max(1.0 - ae, 1e-30));
            const double we = te < 1e-2 ? 0.5 - te / 12.0 : 1.0 / te - 1.0 / std::expm1(std::min(te, 80.0));
            const double fe = fm->fog->transmittance(o, o + d * (pc.t0 + we * (pc.t1 - pc.t0)), 0.0);
            fm->exactSegments += (1.0 - fm->exactSegments.a) * glm::dvec4(fe * glm::dvec3(exactSeg) + (1.0 - fe) * ae * fm->fog->desc().colour, ae);
            // The shader's f in float: tau <= 4 here, summed from a few terms
            // with ~2^-20 relative error each, so |df| <= 2^-16; it moves the
            // layer by alpha df, the composite by twice that.
            bound += 2.0 * a * std::ldexp(1.0, -16);
        }
        acc += (1.0 - acc.a) * c;
        // Bound of one GL lookup against the float trilinear one: GL filters
        // with as few as 8 bits of sub-texel weight (the D3D/GL hardware
        // minimum), i.e. each of the 3 weights off by up to 2^-9, so the value
        // is off by at most 3 * 2^-9 * (max - min of the 8 texels of the cell).
        // A segment error e changes the composite by at most 2e (its colour,
        // and its alpha times what lies behind, <= 1).
        const glm::dvec3 g = glm::clamp(glm::dvec3(sf, sb, len / table.maxLengthWorld()), 0.0, 1.0) * glm::dvec3(n - 1);
        const glm::ivec3 c0 = glm::min(glm::ivec3(glm::floor(g)), n - 2);
        double spread = 0.0;
        for (int ch = 0; ch < 4; ++ch) {
            double vmin = 1e30, vmax = -1e30;
            for (int k = 0; k < 8; ++k) {
                const glm::ivec3 q = c0 + glm::ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                const double v = data[((std::size_t(q.z) * n.y + q.y) * n.x + q.x) * 4 + ch];
                vmin = std::min(vmin, v), vmax = std::max(vmax, v);
            }
            spread = std::max(spread, vmax - vmin);
        }
        // Float geometry: entry/exit from planes in eye-relative float, ~16 ulps
        // of the distance (< 64 world units here) in t, times the largest
        // extinction (2) at both ends, twice (colour and attenuation).
        const double dt = 16.0 * std::ldexp(1.0, -24) * 64.0;
        bound += 2.0 * (3.0 * std::ldexp(1.0, -9) * spread) + 4.0 * 2.0 * dt;
    }
    return acc;
}

struct Result3 {
    double worstRatio = 0.0, maxGlVsModel = 0.0, maxGlVsExact = 0.0, maxModelVsExact = 0.0;
    int over = 0;
};

class TetraPassGL : public test::GLTest {};

void renderFrame(gl::FrameRenderer& fr, gl::Framebuffer& fb, Frame& frame, double clearDepth) {
    fr.render(frame, {.framebuffer = fb.handle(), .depthTexture = fb.depthTexture(), .drawOpaque = [clearDepth] {
                          glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
                          glClearDepth(clearDepth);
                          glDepthMask(GL_TRUE);
                          glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                      }});
}

// The campfire's splats and the 16x16x8 cloud box (corner at `origin`) in one
// frame, and the two drawn by hand in a chosen order: the volume alone through
// a frame renderer, the splats alone through gl::Renderer.
struct FireAndCloud {
    TestCloud cl;
    Materials materials{Footprint{}};
    std::uint32_t set = materials.addTextureSet(TextureSet::turbulence({.count = 4, .size = 16, .seed = 3}));
    std::uint32_t colors = materials.addColorTable(ColorTable::fire());
    Camera cam = test::campfireCamera(kSize);
    Frame frame;

    ::testing::AssertionResult build(glm::vec3 origin) {
        auto vol = LodVolume::create(cl.field, {.originWorld = origin});
        if (!vol) return ::testing::AssertionFailure() << vol.error();
        frame.begin(0.0, cam);
        frame.builder().add(test::campfireGrid(3), materials, {.textureSet = set, .colorTable = colors});
        FrameVolume& fv = frame.volumes().emplace_back();
        fv.table = &*cl.table;
        if (!vol->update(cam, {.detailC = 20.0f}, &*cl.transfer, fv.lod)) return ::testing::AssertionFailure() << "update failed";
        frame.end();
        if (frame.splats().empty() || fv.lod.tets.empty()) return ::testing::AssertionFailure() << "no splats or no tetrahedra";
        return ::testing::AssertionSuccess();
    }

    Image byHand(gl::FrameRenderer& volumes, gl::Renderer& splats, gl::Framebuffer& fb, bool splatsFirst) const {
        Frame cloudOnly;
        cloudOnly.begin(0.0, cam);
        cloudOnly.volumes().push_back(frame.volumes()[0]);
        cloudOnly.end();
        fb.clear({0, 0, 0, 0});
        auto drawSplats = [&] { splats.draw(frame.splats(), cam, {.framebuffer = fb.handle(), .width = kSize.x, .height = kSize.y}); };
        if (splatsFirst) drawSplats();
        volumes.render(cloudOnly, {.framebuffer = fb.handle(), .depthTexture = fb.depthTexture()});
        if (!splatsFirst) drawSplats();
        return fb.read();
    }
};

// Outside the cloud, LOD refinement: the GL image equals the pass's CPU model
// within the derived bound at every pixel, and so stays within the table's own
// error of the exact integral through the same emitted mesh.
void expectFrameMatchesTheReference(const Camera& cam, Frame& frame, const PreIntegrationTable& table, const TransferFunction& transfer) {
    const FrameVolume& fv = frame.volumes()[0];
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    renderFrame(*fr, *fb, frame, 1.0);
    const Image img = fb->read();
    EXPECT_GT(fr->stats().tetrahedra.drawn, 0u);
    Result3 r;
    int covered = 0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const glm::dvec3 d = pixelRay(cam, x, y), o(cam.eye());
            double bound = 0.0;
            const glm::dvec4 model = passModel(fv.lod.tets, table, o, d, 1e30, bound);
            const glm::dvec4 exact = integrateRay(fv.lod.tets, transfer, o, d, 0.0, 1e30);
            double eModel = 0.0, eExact = 0.0, eME = 0.0;
            for (int c = 0; c < 4; ++c) {
                eModel = std::max(eModel, std::abs(double(img.at(x, y, c)) - model[c]));
                eExact = std::max(eExact, std::abs(double(img.at(x, y, c)) - exact[c]));
                eME = std::max(eME, std::abs(model[c] - exact[c]));
            }
            covered += exact.a > 0.05 ? 1 : 0;
            r.maxGlVsModel = std::max(r.maxGlVsModel, eModel);
            r.maxGlVsExact = std::max(r.maxGlVsExact, eExact);
            r.maxModelVsExact = std::max(r.maxModelVsExact, eME);
            r.worstRatio = std::max(r.worstRatio, eModel / bound);
            if (eModel > bound) ++r.over;
            EXPECT_LE(eExact, eME + bound) << "pixel " << x << "," << y;
        }
    EXPECT_GT(covered, kSize.x * kSize.y / 10) << "the view should see cloud";
    EXPECT_EQ(r.over, 0) << "worst |GL - model| / bound " << r.worstRatio;
    ::testing::Test::RecordProperty("max_gl_vs_model", std::to_string(r.maxGlVsModel));
    ::testing::Test::RecordProperty("max_gl_vs_exact", std::to_string(r.maxGlVsExact));
    ::testing::Test::RecordProperty("max_table_vs_exact", std::to_string(r.maxModelVsExact));
    std::printf("GL vs model max %.2e (worst ratio to bound %.3f); GL vs exact max %.4f; table model vs exact max %.4f\n", r.maxGlVsModel,
                r.worstRatio, r.maxGlVsExact, r.maxModelVsExact);
}

void expectPassMatchesTheReference(TestCloud cl) {
    const Camera cam = Camera::lookAt({-14.0f, 6.0f, 10.0f}, {8.0f, 8.0f, 4.0f}, {0, 0, 1}, glm::radians(50.0f), kSize, 0.5f, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*cl.table;
    ASSERT_TRUE(cl.volume->update(cam, {.detailC = 20.0f}, &*cl.transfer, fv.lod));
    frame.end();
    ASSERT_GT(fv.lod.tets.size(), 50u);
    expectFrameMatchesTheReference(cam, frame, *cl.table, *cl.transfer);
}

TEST_F(TetraPassGL, MatchesTheReferenceOnTheSameMeshWithinADerivedBound) { expectPassMatchesTheReference(TestCloud()); }

// Roettger & Ertl's sec. 5.1 model: the table indexed by the light gamma
// (rho = Id) and the density entering through the length, l' = l f / f_max
// (eq. 9). The same pass and the same bound; the exact integral takes the
// length scale per tetrahedron as the pass does.
TEST_F(TetraPassGL, PaperEquation9ModelMatchesTheReferenceWithinTheSameBound) {
    expectPassMatchesTheReference(TestCloud{CloudModel::LightTableDensityLength});
}

namespace {

// The lit-cloud tests' cloud: 17x17x9 (seed 5), LowAlbedo under a white sun
// from (0.6, -0.3, 1) of `sunIntensity`, two HG lobes, ambient 0.03.
splatfx::CloudCreateDesc lowAlbedoTestCloud(float sunIntensity) {
    splatfx::CloudCreateDesc d;
    d.cloud = {.dims = {17, 17, 9}, .seed = 5, .featureCells = 6.0f, .coverage = 0.6f};
    d.lighting.model = CloudLightModel::LowAlbedo;
    d.lighting.sun = Light::directional({-0.6f, 0.3f, -1.0f}, glm::vec3(1.0f), sunIntensity);
    const HgLobe lobes[] = {{0.6f, 0.7f}, {-0.3f, 0.3f}};
    d.lighting.gas.phase = *PhaseFunction::create(lobes);
    d.lighting.gas.ambient = glm::vec3(0.03f);
    return d;
}

} // namespace

// A Cloud in the low-albedo model (cloud.hpp) with two HG lobes: the source
// per vertex s = T phase / max phase written by Cloud::update, drawn with
// the cloud's own affine transfer and table, against the exact integral of
// the lit cloud through the same emitted mesh, within the same derived
// bound. The sun (intensity 0.15) keeps the peak source A + B below 1, as
// the bound's "colours <= 1" needs.
TEST_F(TetraPassGL, LowAlbedoCloudMatchesTheReferenceWithinTheSameBound) {
    splatfx::CloudCreateDesc d = lowAlbedoTestCloud(0.15f);
    d.table = {.scalarResolution = 32, .lengthResolution = 64};
    auto cloud = splatfx::Cloud::create(d);
    ASSERT_TRUE(cloud) << cloud.error();
    const glm::dvec3 peak = cloud->transfer().color(1.0);
    ASSERT_LE(std::max({peak.x, peak.y, peak.z}), 1.0);
    const Camera cam = Camera::lookAt({-14.0f, 6.0f, 10.0f}, {8.0f, 8.0f, 4.0f}, {0, 0, 1}, glm::radians(50.0f), kSize, 0.5f, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &cloud->table();
    ASSERT_TRUE(cloud->update(cam, {.detailC = 6.0f}, fv.lod)); // coarse: the brute-force model costs O(tetrahedra) per pixel
    frame.end();
    ASSERT_GT(fv.lod.tets.size(), 50u);
    expectFrameMatchesTheReference(cam, frame, cloud->table(), cloud->transfer());
}

// A lit ground fog layer (GroundFog::setLighting, low albedo, a forward HG
// lobe): the vertices carry s = T phase / max phase and the fog's scalar as
// length scale, drawn with the layer's affine lit transfer and its 2 x 2 x 128
// table, against the exact integral through the same emitted mesh within the
// same derived bound. The sun (intensity 0.15) keeps the peak source A + B
// below 1, as the bound's "colours <= 1" needs.
TEST_F(TetraPassGL, LitGroundFogMatchesTheReferenceWithinTheSameBound) {
    GroundFogDesc d;
    d.dims = {9, 7};
    d.originWorld = {-4.0f, 0.0f, -3.0f};
    d.density = 0.8f;
    for (int j = 0; j < 7; ++j)
        for (int i = 0; i < 9; ++i) {
            const float x = float(i) / 8.0f, z = float(j) / 6.0f;
            d.terrainHeight.push_back(1.2f * std::sin(5.0f * x) * std::cos(4.0f * z) + 0.3f * x);
            d.fogTop.push_back(1.0f + 0.4f * std::cos(3.0f * z));
        }
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    GroundFogLighting L;
    L.sun = Light::directional({0.5f, -0.6f, 0.3f}, glm::vec3(1.0f), 0.15f);
    const HgLobe lobe{.g = 0.5f};
    L.gas.phase = *PhaseFunction::create(std::span<const HgLobe>(&lobe, 1));
    L.gas.ambient = glm::vec3(0.05f);
    L.extinctionPerWorld = 1.5f;
    ASSERT_TRUE(fog->setLighting(L));
    const glm::dvec3 peak = fog->litTransfer().color(1.0);
    ASSERT_LE(std::max({peak.x, peak.y, peak.z}), 1.0);
    const Camera cam = Camera::lookAt({-7.0f, 5.0f, 8.0f}, {0.0f, 0.5f, 0.0f}, {0, 1, 0}, glm::radians(50.0f), kSize, 0.5f, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &fog->litTable();
    ASSERT_TRUE(fog->update(cam, fv.lod));
    frame.end();
    ASSERT_GT(fv.lod.tets.size(), 50u);
    expectFrameMatchesTheReference(cam, frame, fog->litTable(), fog->litTransfer());
}

// The host's depth ends every segment: a plane through the middle of the
// cloud (the depth buffer cleared to it) hides what lies behind it and the
// part of each tetrahedron in front of it is drawn exactly (the scalar at the
// cut interpolated), against the references integrated to the same depth.
TEST_F(TetraPassGL, HostDepthCutsSegmentsInsideTetrahedra) {
    TestCloud cl;
    const float nearP = 0.5f, farP = 200.0f;
    const Camera cam = Camera::lookAt({-14.0f, 6.0f, 10.0f}, {8.0f, 8.0f, 4.0f}, {0, 0, 1}, glm::radians(50.0f), kSize, nearP, farP);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*cl.table;
    ASSERT_TRUE(cl.volume->update(cam, {.detailC = 20.0f}, &*cl.transfer, fv.lod));
    frame.end();
    // A view-aligned plane at view depth 22 (through the cloud): NDC depth of it.
    const double zView = 22.0, n = nearP, f = farP;
    const double ndc = ((f + n) / (f - n)) - 2.0 * f * n / ((f - n) * zView);
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    renderFrame(*fr, *fb, frame, 0.5 * ndc + 0.5);
    const Image cut = fb->read(), depth = fb->readDepth();
    renderFrame(*fr, *fb, frame, 1.0);
    const Image whole = fb->read();
    const glm::dmat4 invProj = glm::inverse(glm::dmat4(cam.proj));
    int over = 0, differs = 0;
    double worst = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const glm::dvec3 d = pixelRay(cam, x, y), o(cam.eye());
            // The host depth as the pass sees it (the stored 24-bit value), to a ray distance.
            auto tOf = [&](double dep) {
                const double nx = (x + 0.5) / kSize.x * 2.0 - 1.0, ny = 1.0 - (y + 0.5) / kSize.y * 2.0;
                glm::dvec4 v = invProj * glm::dvec4(nx, ny, dep * 2.0 - 1.0, 1.0);
                return glm::length(glm::dvec3(v) / v.w);
            };
            const double dep = depth.at(x, y, 0), tHost = tOf(dep);
            EXPECT_NEAR(tHost * glm::dot(d, glm::dvec3(cam.forward())), zView, 1e-2) << "depth buffer holds the plane";
            double bound = 0.0;
            const glm::dvec4 model = passModel(fv.lod.tets, *cl.table, o, d, tHost, bound);
            const glm::dvec4 exact = integrateRay(fv.lod.tets, *cl.transfer, o, d, 0.0, tHost);
            // The shader reconstructs the distance in float: ~16 ulps of the
            // depth near 1 moves the cut by |t(dep + 2^-20) - t(dep)|, which
            // changes the colour by at most 2 x extinction (2) x that.
            bound += 4.0 * cl.maxExtinction * std::abs(tOf(dep + std::ldexp(1.0, -20)) - tHost);
            double e = 0.0, eME = 0.0, dWhole = 0.0;
            for (int c = 0; c < 4; ++c) {
                e = std::max(e, std::abs(double(cut.at(x, y, c)) - model[c]));
                eME = std::max(eME, std::abs(model[c] - exact[c]));
                dWhole = std::max(dWhole, std::abs(double(cut.at(x, y, c)) - double(whole.at(x, y, c))));
            }
            over += e > bound ? 1 : 0;
            worst = std::max(worst, e / bound);
            differs += dWhole > 0.02 ? 1 : 0;
            EXPECT_LE(std::abs(double(cut.at(x, y, 3)) - exact.a), eME + bound) << "pixel " << x << "," << y;
        }
    EXPECT_EQ(over, 0) << "worst |GL - model| / bound " << worst;
    EXPECT_GT(differs, kSize.x * kSize.y / 20) << "the plane should hide part of the cloud";
}

// The engines' depth conventions (issue 26): the ray end read from the host
// depth (a plane through the cloud at view depth 22) in each of the four
// conventions, reversed ones with float depth, gives OpenGL's default image
// within one 8-bit step per channel (RGBA8 readback: the conventions differ
// only in the depths' last bits, which can move a value across one rounding
// boundary, never two).
TEST_F(TetraPassGL, HostDepthCutIsTheSameInAllFourConventions) {
    TestCloud cl;
    const DepthConvention conventions[] = {
        {}, {.clip = ClipDepth::ZeroToOne}, {.reversed = true}, {.clip = ClipDepth::ZeroToOne, .reversed = true}};
    Image base;
    for (const DepthConvention& dc : conventions) {
        const Camera cam =
            Camera::lookAt({-14.0f, 6.0f, 10.0f}, {8.0f, 8.0f, 4.0f}, {0, 0, 1}, glm::radians(50.0f), kSize, 0.5f, 200.0f, dc);
        Frame frame;
        frame.begin(0.0, cam);
        FrameVolume& fv = frame.volumes().emplace_back();
        fv.table = &*cl.table;
        ASSERT_TRUE(cl.volume->update(cam, {.detailC = 20.0f}, &*cl.transfer, fv.lod));
        frame.end();
        const glm::dvec4 c = glm::dmat4(cam.proj) * glm::dvec4(0.0, 0.0, -22.0, 1.0);
        const double window = dc.clip == ClipDepth::ZeroToOne ? c.z / c.w : 0.5 * c.z / c.w + 0.5;
        auto fr = gl::FrameRenderer::create();
        auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .floatDepth = dc.reversed});
        ASSERT_TRUE(fr && fb);
        glClipControl(GL_LOWER_LEFT, dc.clip == ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
        renderFrame(*fr, *fb, frame, window);
        glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        EXPECT_TRUE(fr->stats().notes.empty()) << fr->stats().notes.front();
        EXPECT_GT(fr->stats().tetrahedra.drawn, 0u);
        const Image got = fb->read();
        if (base.pixels.empty()) {
            base = got;
            continue;
        }
        double worst = 0.0;
        for (std::size_t i = 0; i < got.pixels.size(); ++i) worst = std::max(worst, double(std::abs(got.pixels[i] - base.pixels[i])));
        EXPECT_LE(worst, 1.0 / 255.0 + 1e-6) << describe(dc);
    }
}

// The camera inside the cloud: the emitted list (clipped at the near plane as
// volumes) integrates to the finest mesh's integral from the near plane, and
// the GL image matches the pass model within the bound at every pixel: no
// pixel loses a tetrahedron at the near plane (no holes).
TEST_F(TetraPassGL, CameraInsideTheCloudRendersWithoutHoles) {
    TestCloud cl;
    // The eye at the densest grid point, looking along +x.
    const auto it = std::max_element(cl.field.scalar.begin(), cl.field.scalar.end());
    const std::size_t i = std::size_t(it - cl.field.scalar.begin());
    const glm::vec3 eye(float(i % 17), float((i / 17) % 17), float(i / (17 * 17)));
    ASSERT_GT(*it, 0.3f);
    const float nearP = 0.3f;
    const Camera cam = Camera::lookAt(eye, eye + glm::vec3(1.0f, 0.3f, 0.1f), {0, 0, 1}, glm::radians(60.0f), kSize, nearP, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*cl.table;
    ASSERT_TRUE(cl.volume->update(cam, {.detailC = 1e6f}, &*cl.transfer, fv.lod)); // finest level everywhere
    frame.end();
    ASSERT_GT(fv.lod.stats.clippedInput, 0u) << "the near plane must cut the mesh";
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    renderFrame(*fr, *fb, frame, 1.0);
    const Image img = fb->read();
    int over = 0, dense = 0;
    double worst = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const glm::dvec3 d = pixelRay(cam, x, y), o(cam.eye());
            const double tNear = nearP / glm::dot(d, glm::dvec3(cam.forward()));
            const glm::dvec4 finest = cl.volume->integrateRay(*cl.transfer, o, d, tNear, 1e30);
            const glm::dvec4 emitted = integrateRay(fv.lod.tets, *cl.transfer, o, d, 0.0, 1e30);
            // Same field, clipped vertices in float (~2^-24 x 20 world units): 1e-4 is
            // far above that and far below any missing piece of a cell.
            for (int c = 0; c < 4; ++c) EXPECT_NEAR(emitted[c], finest[c], 1e-4) << "pixel " << x << "," << y;
            double bound = 0.0;
            const glm::dvec4 model = passModel(fv.lod.tets, *cl.table, o, d, 1e30, bound);
            double e = 0.0;
            for (int c = 0; c < 4; ++c) e = std::max(e, std::abs(double(img.at(x, y, c)) - model[c]));
            over += e > bound ? 1 : 0;
            worst = std::max(worst, e / bound);
            dense += finest.a > 0.2 ? 1 : 0;
        }
    EXPECT_GT(dense, kSize.x * kSize.y / 4) << "inside a cloud most pixels see cloud";
    EXPECT_EQ(over, 0) << "worst |GL - model| / bound " << worst;
}

// Inside the cloud into an 8-bit host (FrameRendererDesc::volumeLayer): drawn
// straight, every tetrahedron's blend is rounded to 8 bits, and the dozens a
// pixel sees add up to steps along their projected faces (the faint straight
// streaks of samples/17-into-the-cloud); through the layer the frame is the
// float frame rounded once. e: the 8-bit image minus the float host's image
// (the frame CameraInsideTheCloudRendersWithoutHoles holds to the pass model)
// rounded here, in 8-bit levels; "steps": the RMS of e minus its 5x5 box mean
// (what changes from pixel to pixel; a smooth offset drops out).
TEST_F(TetraPassGL, VolumeLayerRoundsAnEightBitHostOnceInsideTheCloud) {
    TestCloud cl;
    const auto it = std::max_element(cl.field.scalar.begin(), cl.field.scalar.end());
    const std::size_t i = std::size_t(it - cl.field.scalar.begin());
    const glm::vec3 eye(float(i % 17), float((i / 17) % 17), float(i / (17 * 17)));
    const Camera cam = Camera::lookAt(eye, eye + glm::vec3(1.0f, 0.3f, 0.1f), {0, 0, 1}, glm::radians(60.0f), kSize, 0.3f, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*cl.table;
    ASSERT_TRUE(cl.volume->update(cam, {.detailC = 1e6f}, &*cl.transfer, fv.lod)); // finest level: the most tetrahedra per pixel
    frame.end();
    auto layered = gl::FrameRenderer::create();
    auto straight = gl::FrameRenderer::create({.volumeLayer = false});
    auto fb8 = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y});
    auto fb32 = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(layered && straight && fb8 && fb32);
    auto usesLayer = [](const gl::FrameRenderer& r) {
        return std::any_of(r.plan().steps.begin(), r.plan().steps.end(), [](const gl::PlanStep& s) { return s.kind == gl::StepKind::ReducedBegin; });
    };
    renderFrame(*layered, *fb32, frame, 1.0);
    const Image ref = fb32->read();
    EXPECT_FALSE(usesLayer(*layered)) << "an RGBA32F host is drawn into straight";
    auto fb16 = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F16});
    ASSERT_TRUE(fb16);
    renderFrame(*layered, *fb16, frame, 1.0);
    EXPECT_TRUE(usesLayer(*layered)) << "RGBA16F rounds every blend: it takes the layer";
    renderFrame(*layered, *fb8, frame, 1.0);
    const Image once = fb8->read();
    EXPECT_TRUE(usesLayer(*layered));
    EXPECT_TRUE(layered->stats().notes.empty()) << layered->stats().notes.front();
    renderFrame(*straight, *fb8, frame, 1.0);
    const Image perTet = fb8->read();
    EXPECT_FALSE(usesLayer(*straight));

    struct Measure {
        double max = 0.0, steps = 0.0;
    };
    auto measure = [&](const Image& img) {
        std::vector<double> e(std::size_t(kSize.x * kSize.y * 3));
        auto at = [&](int x, int y, int c) -> double& { return e[std::size_t((y * kSize.x + x) * 3 + c)]; };
        Measure m;
        for (int y = 0; y < kSize.y; ++y)
            for (int x = 0; x < kSize.x; ++x)
                for (int c = 0; c < 3; ++c) {
                    at(x, y, c) = 255.0 * double(img.at(x, y, c)) - std::round(255.0 * std::clamp(double(ref.at(x, y, c)), 0.0, 1.0));
                    m.max = std::max(m.max, std::abs(at(x, y, c)));
                }
        double sum2 = 0.0;
        int n = 0;
        for (int y = 2; y + 2 < kSize.y; ++y)
            for (int x = 2; x + 2 < kSize.x; ++x)
                for (int c = 0; c < 3; ++c) {
                    double mean = 0.0;
                    for (int j = -2; j <= 2; ++j)
                        for (int k = -2; k <= 2; ++k) mean += at(x + k, y + j, c);
                    const double d = at(x, y, c) - mean / 25.0;
                    sum2 += d * d, ++n;
                }
        m.steps = std::sqrt(sum2 / n);
        return m;
    };
    const Measure a = measure(once), b = measure(perTet);
    std::printf("8-bit host inside the cloud: through the layer max |e| %.0f, steps %.3f levels; straight max |e| %.0f, steps %.3f levels\n", a.max,
                a.steps, b.max, b.steps);
    // The layer (RGBA32F) takes the same blends in the same order from the same
    // transparent black as the float host, so only the final conversion to 8
    // bits differs from our rounding: GL allows it to round either way, so
    // |e| <= 1 level; the steps, at most 1 on scattered pixels, under half a level.
    EXPECT_LE(a.max, 1.0);
    EXPECT_LT(a.steps, 0.5);
    // Straight, the per-tetrahedron rounding is what the measure sees: errors
    // beyond one rounding, changing from pixel to pixel above the bound.
    EXPECT_GT(b.max, 1.0);
    EXPECT_GT(b.steps, 0.5);
}

// An orthographic camera: rays parallel to forward from the plane through the
// eye; the pass's other shader variant, against the same model.
TEST_F(TetraPassGL, OrthographicCameraMatchesTheModel) {
    TestCloud cl;
    const glm::vec3 eye{-14.0f, 6.0f, 10.0f}, target{8.0f, 8.0f, 4.0f};
    const glm::mat4 view = glm::lookAt(eye, target, glm::vec3(0, 0, 1));
    const glm::mat4 proj = glm::ortho(-12.0f, 12.0f, -9.0f, 9.0f, 0.5f, 200.0f);
    const Camera cam = Camera::fromMatrices(view, proj, kSize);
    ASSERT_FALSE(cam.perspective());
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*cl.table;
    ASSERT_TRUE(cl.volume->update(cam, {.detailC = 20.0f}, &*cl.transfer, fv.lod));
    frame.end();
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    renderFrame(*fr, *fb, frame, 1.0);
    const Image img = fb->read();
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    const glm::dvec3 d(cam.forward()), e(cam.eye());
    int over = 0, covered = 0;
    double worst = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const double nx = (x + 0.5) / kSize.x * 2.0 - 1.0, ny = 1.0 - (y + 0.5) / kSize.y * 2.0;
            glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0);
            const glm::dvec3 pa = glm::dvec3(a) / a.w, o = pa - d * glm::dot(pa - e, d);
            double bound = 0.0;
            const glm::dvec4 model = passModel(fv.lod.tets, *cl.table, o, d, 1e30, bound);
            double err = 0.0;
            for (int c = 0; c < 4; ++c) err = std::max(err, std::abs(double(img.at(x, y, c)) - model[c]));
            over += err > bound ? 1 : 0;
            worst = std::max(worst, err / bound);
            covered += model.a > 0.05 ? 1 : 0;
        }
    EXPECT_GT(covered, kSize.x * kSize.y / 10);
    EXPECT_EQ(over, 0) << "worst |GL - model| / bound " << worst;
}

// Hard cases a host's own list may hold: a zero-volume tetrahedron, one with a
// non-finite vertex and a transparent one are skipped (counted), and the image
// is exactly that of the one visible tetrahedron.
TEST_F(TetraPassGL, DegenerateNonFiniteAndTransparentTetrahedraAreSkipped) {
    TestCloud cl;
    const Camera cam = Camera::lookAt({0.0f, -6.0f, 0.5f}, {0.0f, 0.0f, 0.3f}, {0, 0, 1}, glm::radians(50.0f), kSize, 0.1f, 100.0f);
    Tetrahedron visible;
    visible.position = {glm::vec3(-1, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1.5f, 0), glm::vec3(0, 0.5f, 1.5f)};
    if (glm::dot(visible.position[1] - visible.position[0],
                 glm::cross(visible.position[2] - visible.position[0], visible.position[3] - visible.position[0])) < 0.0f)
        std::swap(visible.position[2], visible.position[3]);
    visible.scalar = {0.9f, 0.7f, 0.8f, 1.0f};
    visible.lengthScale = {1.0f, 1.0f, 1.0f, 1.0f};
    Tetrahedron flat = visible;
    flat.position[3] = 0.5f * (flat.position[0] + flat.position[1]); // coplanar: zero volume
    Tetrahedron nan = visible;
    nan.position[2].x = std::numeric_limits<float>::quiet_NaN();
    Tetrahedron clear = visible;
    clear.scalar = {0.0f, 0.01f, 0.0f, 0.02f}; // below the transfer function's threshold
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    auto draw = [&](std::vector<Tetrahedron> tets) {
        Frame frame;
        frame.begin(0.0, cam);
        FrameVolume& fv = frame.volumes().emplace_back();
        fv.table = &*cl.table;
        fv.lod.tets = std::move(tets);
        frame.end();
        renderFrame(*fr, *fb, frame, 1.0);
        return fb->read();
    };
    const Image alone = draw({visible});
    EXPECT_EQ(fr->stats().tetrahedra.drawn, 1u);
    const Image mixed = draw({flat, nan, visible, clear});
    EXPECT_EQ(fr->stats().tetrahedra.drawn, 1u);
    EXPECT_EQ(fr->stats().tetrahedra.transparent, 1u);
    double maxAbs = 0.0, alpha = 0.0;
    for (std::size_t i = 0; i < alone.pixels.size(); ++i) {
        ASSERT_TRUE(std::isfinite(mixed.pixels[i]));
        maxAbs = std::max(maxAbs, double(std::abs(mixed.pixels[i] - alone.pixels[i])));
        if (i % 4 == 3) alpha = std::max(alpha, double(alone.pixels[i]));
    }
    EXPECT_EQ(maxAbs, 0.0);
    EXPECT_GT(alpha, 0.1) << "the visible tetrahedron is drawn";
}

// Splats and tetrahedra in one back-to-front order: a fire in front of a
// cloud draws after it, a cloud in front of the fire draws after the fire;
// each equals drawing the two passes by hand in that order, and the wrong
// order gives a visibly different image.
TEST_F(TetraPassGL, SplatsAndTetrahedraCompositeInDepthOrder) {
    FireAndCloud fc;
    auto fr = gl::FrameRenderer::create();
    auto splatsOnly = gl::Renderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && splatsOnly && fb);
    ASSERT_TRUE(fr->upload(fc.materials));
    ASSERT_TRUE(splatsOnly->upload(fc.materials));
    for (const bool cloudInFront : {false, true}) {
        SCOPED_TRACE(cloudInFront ? "cloud in front" : "cloud behind");
        // The cloud box: behind the fire (z in [-20, -12]) or between it and the eye (z in [4, 12]).
        ASSERT_TRUE(fc.build({-8.0f, -4.0f, cloudInFront ? 4.0f : -20.0f}));
        ASSERT_EQ(fc.frame.drawOrder().size(), 2u); // the two lists do not overlap in depth here
        EXPECT_EQ(fc.frame.drawOrder()[0].kind, cloudInFront ? DrawBatch::Kind::Splats : DrawBatch::Kind::Tetrahedra);
        renderFrame(*fr, *fb, fc.frame, 1.0);
        const Image together = fb->read();
        const Image right = fc.byHand(*fr, *splatsOnly, *fb, cloudInFront), wrong = fc.byHand(*fr, *splatsOnly, *fb, !cloudInFront);
        double dRight = 0.0, dWrong = 0.0;
        for (std::size_t i = 0; i < together.pixels.size(); ++i) {
            dRight = std::max(dRight, double(std::abs(together.pixels[i] - right.pixels[i])));
            dWrong = std::max(dWrong, double(std::abs(together.pixels[i] - wrong.pixels[i])));
        }
        EXPECT_EQ(dRight, 0.0);
        EXPECT_GT(dWrong, 0.05) << "the order must matter where the fire and the cloud overlap";
    }
}

// Ground fog (sec. 6) through the same pass: prisms over a wavy terrain with
// the eye inside the fog; every pixel against the pass model within the bound.
TEST_F(TetraPassGL, GroundFogDrawsThroughThePass) {
    GroundFogDesc d;
    d.dims = {17, 17};
    d.originWorld = {-8.0f, 0.0f, -8.0f};
    for (int j = 0; j < 17; ++j)
        for (int i = 0; i < 17; ++i) {
            d.terrainHeight.push_back(1.5f * std::sin(0.7f * float(i)) * std::cos(0.5f * float(j)));
            d.fogTop.push_back(0.6f);
        }
    auto fog = GroundFog::create(d);
    auto tf = makeGroundFogTransfer({0.8f, 0.85f, 0.9f}, 0.7f);
    ASSERT_TRUE(fog && tf);
    auto table = PreIntegrationTable::create(*tf, {.scalarResolution = 16, .lengthResolution = 64, .maxLengthWorld = 30.0f});
    ASSERT_TRUE(table);
    const Camera cam = Camera::lookAt({-7.0f, 0.4f, -6.5f}, {6.0f, -0.2f, 5.0f}, {0, 1, 0}, glm::radians(60.0f), kSize, 0.1f, 100.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*table;
    ASSERT_TRUE(fog->update(cam, fv.lod));
    frame.end();
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    renderFrame(*fr, *fb, frame, 1.0);
    const Image img = fb->read();
    int over = 0, covered = 0;
    double worst = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const glm::dvec3 dir = pixelRay(cam, x, y), o(cam.eye());
            double bound = 0.0;
            const glm::dvec4 model = passModel(fv.lod.tets, *table, o, dir, 1e30, bound);
            double e = 0.0;
            for (int c = 0; c < 4; ++c) e = std::max(e, std::abs(double(img.at(x, y, c)) - model[c]));
            over += e > bound ? 1 : 0;
            worst = std::max(worst, e / bound);
            covered += model.a > 0.05 ? 1 : 0;
        }
    EXPECT_GT(covered, kSize.x * kSize.y / 5);
    EXPECT_EQ(over, 0) << "worst |GL - model| / bound " << worst;
}

// With the splats at reduced resolution (FrameRendererDesc::resolutionScale)
// the tetrahedra are still drawn at full resolution: a frame of tetrahedra
// alone gives exactly the full-resolution image.
TEST_F(TetraPassGL, ReducedResolutionSplatsLeaveTheTetrahedraAtFullResolution) {
    TestCloud cl;
    const Camera cam = Camera::lookAt({-14.0f, 6.0f, 10.0f}, {8.0f, 8.0f, 4.0f}, {0, 0, 1}, glm::radians(50.0f), kSize, 0.5f, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*cl.table;
    ASSERT_TRUE(cl.volume->update(cam, {.detailC = 20.0f}, &*cl.transfer, fv.lod));
    frame.end();
    auto full = gl::FrameRenderer::create();
    auto half = gl::FrameRenderer::create({.resolutionScale = 2});
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(full && half && fb);
    renderFrame(*full, *fb, frame, 1.0);
    const Image a = fb->read();
    renderFrame(*half, *fb, frame, 1.0);
    const Image b = fb->read();
    double maxAbs = 0.0, alpha = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        maxAbs = std::max(maxAbs, double(std::abs(a.pixels[i] - b.pixels[i])));
        if (i % 4 == 3) alpha = std::max(alpha, double(a.pixels[i]));
    }
    EXPECT_GT(alpha, 0.1);
    EXPECT_EQ(maxAbs, 0.0);
    EXPECT_EQ(half->stats().tetrahedra.drawn, full->stats().tetrahedra.drawn);
}

// FrameRendererDesc::reduceTetrahedra: the tetrahedra go into the splats'
// reduced image in the frame's one back-to-front order. With the cloud in
// front of the fire the reduced frame is closer to the full-resolution frame
// in the right order than to the one in the wrong order (the fire drawn over
// the cloud); the per-pass path
// (tetrahedra at full resolution, then all splats) is closer to the wrong one.
TEST_F(TetraPassGL, ReducedTetrahedraKeepTheOneOrderWithTheSplats) {
    FireAndCloud fc;
    auto full = gl::FrameRenderer::create();
    auto oneOrder = gl::FrameRenderer::create({.resolutionScale = 2, .reduceTetrahedra = true});
    auto perPass = gl::FrameRenderer::create({.resolutionScale = 2});
    auto splatsOnly = gl::Renderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(full && oneOrder && perPass && splatsOnly && fb);
    for (gl::FrameRenderer* r : {&*full, &*oneOrder, &*perPass}) ASSERT_TRUE(r->upload(fc.materials));
    ASSERT_TRUE(splatsOnly->upload(fc.materials));
    ASSERT_TRUE(fc.build({-8.0f, -4.0f, 4.0f})); // the cloud between the fire and the eye
    ASSERT_EQ(fc.frame.drawOrder().size(), 2u);
    ASSERT_EQ(fc.frame.drawOrder()[0].kind, DrawBatch::Kind::Splats); // the fire first: the cloud is nearer
    // Full resolution in the right order, and by hand in the wrong one (the fire over the cloud).
    renderFrame(*full, *fb, fc.frame, 1.0);
    const Image right = fb->read();
    const Image wrong = fc.byHand(*full, *splatsOnly, *fb, false);
    auto distance = [](const Image& a, const Image& b) {
        double d = 0.0;
        for (std::size_t i = 0; i < a.pixels.size(); ++i) d += std::abs(double(a.pixels[i]) - double(b.pixels[i]));
        return d;
    };
    ASSERT_GT(distance(right, wrong), 0.0);
    renderFrame(*oneOrder, *fb, fc.frame, 1.0);
    const Image reduced = fb->read();
    EXPECT_LT(distance(reduced, right), distance(reduced, wrong));
    renderFrame(*perPass, *fb, fc.frame, 1.0);
    const Image split = fb->read();
    EXPECT_GT(distance(split, right), distance(split, wrong)) << "the per-pass path draws the splats last";
}

// (issue 17 item 8) The camera inside one tetrahedron: cut at the
// near plane as a volume (clipTetrahedron: the tip left by three vertices
// behind the plane, and a prism of three pieces when one is), the pass draws
// every pixel (no holes), within the derived bound of its CPU model, and the
// pieces integrate to the original tetrahedron's integral from the near plane.
TEST_F(TetraPassGL, CameraInsideOneTetrahedronIsClippedWithoutHoles) {
    TestCloud cl;
    const float nearP = 0.2f;
    const glm::vec3 eye{0.3f, 0.2f, 0.0f};
    const Camera cam = Camera::lookAt(eye, eye + glm::vec3(0.1f, 0.05f, 1.0f), {0, 1, 0}, glm::radians(40.0f), kSize, nearP, 200.0f);
    auto positive = [](Tetrahedron t) {
        if (glm::dot(t.position[1] - t.position[0], glm::cross(t.position[2] - t.position[0], t.position[3] - t.position[0])) < 0.0f)
            std::swap(t.position[2], t.position[3]);
        return t;
    };
    Tetrahedron tip, prism;
    // Three vertices behind the eye (z = -3), the apex far ahead: the visible part is a tip.
    tip.position = {glm::vec3(-20, -20, -3), glm::vec3(20, -20, -3), glm::vec3(0, 25, -3), glm::vec3(0.5f, 0.3f, 30)};
    // One vertex behind, three far ahead: the visible part is a prism of three.
    prism.position = {glm::vec3(0.2f, 0.1f, -3), glm::vec3(-30, -30, 30), glm::vec3(30, -30, 30), glm::vec3(0, 35, 30)};
    for (Tetrahedron* t : {&tip, &prism}) {
        // One scalar: one colour along every ray, so the pieces' list order cannot matter.
        t->scalar = {0.5f, 0.5f, 0.5f, 0.5f};
        t->lengthScale = {1.0f, 1.0f, 1.0f, 1.0f};
        *t = positive(*t);
    }
    const glm::vec3 f = cam.forward();
    for (const auto& [tet, expectPieces] : {std::pair{tip, 1}, std::pair{prism, 3}}) {
        std::vector<Tetrahedron> pieces;
        ASSERT_EQ(clipTetrahedron(tet, f, glm::dot(f, eye) + nearP, pieces), expectPieces);
        Frame frame;
        frame.begin(0.0, cam);
        FrameVolume& fv = frame.volumes().emplace_back();
        fv.table = &*cl.table;
        fv.lod.tets = pieces;
        frame.end();
        auto fr = gl::FrameRenderer::create();
        auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
        ASSERT_TRUE(fr && fb);
        renderFrame(*fr, *fb, frame, 1.0);
        const Image img = fb->read();
        int over = 0, holes = 0, seen = 0;
        double worst = 0.0;
        for (int y = 0; y < kSize.y; ++y)
            for (int x = 0; x < kSize.x; ++x) {
                const glm::dvec3 d = pixelRay(cam, x, y), o(eye);
                const double tNear = nearP / glm::dot(d, glm::dvec3(f));
                const glm::dvec4 whole = integrateRay({tet}, *cl.transfer, o, d, tNear, 1e30);
                const glm::dvec4 cut = integrateRay(pieces, *cl.transfer, o, d, 0.0, 1e30);
                // Clipped vertices in float (~2^-24 x 60 world units) move the ends by far less than 1e-4.
                for (int c = 0; c < 4; ++c) EXPECT_NEAR(cut[c], whole[c], 1e-4) << "pixel " << x << "," << y;
                double bound = 0.0;
                const glm::dvec4 model = passModel(pieces, *cl.table, o, d, 1e30, bound);
                double e = 0.0;
                for (int c = 0; c < 4; ++c) e = std::max(e, std::abs(double(img.at(x, y, c)) - model[c]));
                over += e > bound ? 1 : 0;
                worst = std::max(worst, e / bound);
                holes += whole.a > 0.01 && !(double(img.at(x, y, 3)) > 0.5 * whole.a) ? 1 : 0;
                seen += whole.a > 0.5 ? 1 : 0;
            }
        EXPECT_GT(seen, kSize.x * kSize.y * 9 / 10) << "from inside, nearly every ray sees dense cloud";
        EXPECT_EQ(holes, 0) << expectPieces << " piece(s): every ray from inside crosses the tetrahedron";
        EXPECT_EQ(over, 0) << expectPieces << " piece(s): worst |GL - model| / bound " << worst;
    }
}

// (issue 17 item 8) A sliver (thickness 1e-3 of its size, far above
// the degenerate cut of 1e-9) seen face-on and grazing: finite pixels, within
// the model's bound, i.e. its huge barycentric gradients do not blow up the
// entry and exit distances.
TEST_F(TetraPassGL, SliverTetrahedraStayFiniteAndWithinTheBound) {
    TestCloud cl;
    Tetrahedron sliver;
    sliver.position = {glm::vec3(-2, -2, 0), glm::vec3(2, -2, 0), glm::vec3(0, 2.5f, 0), glm::vec3(0.1f, 0.0f, 0.004f)};
    if (glm::dot(sliver.position[1] - sliver.position[0],
                 glm::cross(sliver.position[2] - sliver.position[0], sliver.position[3] - sliver.position[0])) < 0.0f)
        std::swap(sliver.position[2], sliver.position[3]);
    sliver.scalar = {1.0f, 0.6f, 0.9f, 1.0f};
    sliver.lengthScale = {1.0f, 1.0f, 1.0f, 1.0f};
    // Face-on, and grazing (2.4 degrees off its plane: long thin chords through it).
    for (const glm::vec3 eye : {glm::vec3(0.2f, 0.1f, 6.0f), glm::vec3(6.0f, 0.3f, 0.25f)}) {
        const Camera cam = Camera::lookAt(eye, {0.0f, 0.0f, 0.002f}, {0, 1, 0}, glm::radians(50.0f), kSize, 0.1f, 100.0f);
        Frame frame;
        frame.begin(0.0, cam);
        FrameVolume& fv = frame.volumes().emplace_back();
        fv.table = &*cl.table;
        fv.lod.tets = {sliver};
        frame.end();
        auto fr = gl::FrameRenderer::create();
        auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
        ASSERT_TRUE(fr && fb);
        renderFrame(*fr, *fb, frame, 1.0);
        EXPECT_EQ(fr->stats().tetrahedra.drawn, 1u) << "a sliver is not degenerate";
        const Image img = fb->read();
        int over = 0;
        double worst = 0.0, alpha = 0.0;
        for (int y = 0; y < kSize.y; ++y)
            for (int x = 0; x < kSize.x; ++x) {
                const glm::dvec3 d = pixelRay(cam, x, y), o(eye);
                double bound = 0.0;
                const glm::dvec4 model = passModel(fv.lod.tets, *cl.table, o, d, 1e30, bound);
                alpha = std::max(alpha, double(img.at(x, y, 3)));
                double e = 0.0;
                for (int c = 0; c < 4; ++c) {
                    ASSERT_TRUE(std::isfinite(img.at(x, y, c))) << "pixel " << x << "," << y;
                    e = std::max(e, std::abs(double(img.at(x, y, c)) - model[c]));
                }
                over += e > bound ? 1 : 0;
                worst = std::max(worst, e / bound);
            }
        EXPECT_GT(alpha, 1e-3) << "the sliver is drawn; eye z " << eye.z;
        EXPECT_EQ(over, 0) << "eye (" << eye.x << ", " << eye.y << ", " << eye.z << "): worst |GL - model| / bound " << worst;
    }
}

// How many tetrahedra the ray o + t d (t > 0) crosses.
int crossings(const std::vector<Tetrahedron>& tets, glm::dvec3 o, glm::dvec3 d) {
    static constexpr int kFaces[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};
    int n = 0;
    for (const Tetrahedron& t : tets) {
        double lo = 0.0, hi = 1e30;
        for (const auto& f : kFaces) {
            const auto& p = t.position;
            const glm::dvec3 a(p[std::size_t(f[0])]), b(p[std::size_t(f[1])]), c(p[std::size_t(f[2])]), q(p[std::size_t(f[3])]);
            glm::dvec3 nrm = glm::cross(b - a, c - a);
            if (glm::dot(nrm, q - a) < 0.0) nrm = -nrm;
            const double num = glm::dot(nrm, o - a), den = glm::dot(nrm, d);
            if (den == 0.0) {
                if (num < 0.0) hi = lo - 1.0;
                continue;
            }
            if (den > 0.0) lo = std::max(lo, -num / den);
            else hi = std::min(hi, -num / den);
        }
        n += hi > lo ? 1 : 0;
    }
    return n;
}

// (issue 17) The sort-free emissive model (sec. 6, eq. 10): the
// layer emitted in grid order draws the sorted image up to float rounding,
// because one-colour "over" blends commute; with a transfer function whose
// colour varies the two orders differ far beyond that bound, so the equality
// is the model's property, not a test that cannot fail.
TEST_F(TetraPassGL, SortFreeGroundFogMatchesTheSortedImage) {
    GroundFogDesc d;
    d.dims = {17, 17};
    d.originWorld = {-8.0f, 0.0f, -8.0f};
    for (int j = 0; j < 17; ++j)
        for (int i = 0; i < 17; ++i) {
            d.terrainHeight.push_back(1.5f * std::sin(0.7f * float(i)) * std::cos(0.5f * float(j)));
            d.fogTop.push_back(0.6f);
        }
    GroundFogDesc free = d;
    free.sortFree = true;
    auto sortedFog = GroundFog::create(d);
    auto freeFog = GroundFog::create(free);
    ASSERT_TRUE(sortedFog && freeFog);
    // Seen from above at a slant: rays cross many prisms.
    const Camera cam = Camera::lookAt({-12.0f, 6.0f, -10.0f}, {2.0f, -0.5f, 2.0f}, {0, 1, 0}, glm::radians(55.0f), kSize, 0.1f, 100.0f);
    auto render = [&](const GroundFog& fog, const PreIntegrationTable& table, std::vector<Tetrahedron>* tetsOut) {
        Frame frame;
        frame.begin(0.0, cam);
        FrameVolume& fv = frame.volumes().emplace_back();
        fv.table = &table;
        EXPECT_TRUE(fog.update(cam, fv.lod));
        frame.end();
        if (tetsOut) *tetsOut = fv.lod.tets;
        auto fr = gl::FrameRenderer::create();
        auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
        EXPECT_TRUE(fr && fb);
        renderFrame(*fr, *fb, frame, 1.0);
        return fb->read();
    };
    auto oneColour = makeGroundFogTransfer({0.8f, 0.85f, 0.9f}, 0.7f);
    auto twoColours = TransferFunction::create({{0.0f, {1.0f, 0.1f, 0.1f}, 0.0f}, {1.0f, {0.1f, 0.2f, 1.0f}, 0.7f}});
    ASSERT_TRUE(oneColour && twoColours);
    auto table1 = PreIntegrationTable::create(*oneColour, {.scalarResolution = 16, .lengthResolution = 64, .maxLengthWorld = 30.0f});
    auto table2 = PreIntegrationTable::create(*twoColours, {.scalarResolution = 16, .lengthResolution = 64, .maxLengthWorld = 30.0f});
    ASSERT_TRUE(table1 && table2);
    std::vector<Tetrahedron> sortedTets, freeTets;
    const Image sorted = render(*sortedFog, *table1, &sortedTets), unsorted = render(*freeFog, *table1, &freeTets);
    ASSERT_EQ(sortedTets.size(), freeTets.size()) << "the same layer, only the order differs";
    int moved = 0;
    for (std::size_t i = 0; i < sortedTets.size(); ++i) moved += sortedTets[i].position != freeTets[i].position ? 1 : 0;
    ASSERT_GT(moved, int(sortedTets.size() / 4)) << "the grid order must differ from the back-to-front one";
    const Image sorted2 = render(*sortedFog, *table2, nullptr), unsorted2 = render(*freeFog, *table2, nullptr);
    int over = 0, layered = 0, orderMatters = 0;
    double worst = 0.0, worstTwo = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const int n = crossings(sortedTets, glm::dvec3(cam.eye()), pixelRay(cam, x, y));
            // F32 blending: each "over" rounds twice (product, sum) by at most
            // 2^-24 of values <= 1, and an earlier error is only scaled by
            // (1 - a) <= 1, so n layers differ by at most 2 n 2^-24 per order: twice that.
            const double bound = 4.0 * std::max(n, 1) * std::ldexp(1.0, -24);
            double e = 0.0, e2 = 0.0;
            for (int c = 0; c < 4; ++c) {
                e = std::max(e, std::abs(double(sorted.at(x, y, c)) - double(unsorted.at(x, y, c))));
                e2 = std::max(e2, std::abs(double(sorted2.at(x, y, c)) - double(unsorted2.at(x, y, c))));
            }
            over += e > bound ? 1 : 0;
            worst = std::max(worst, e / bound);
            layered += n >= 4 ? 1 : 0;
            orderMatters += e2 > 100.0 * bound ? 1 : 0;
            worstTwo = std::max(worstTwo, e2);
        }
    EXPECT_GT(layered, kSize.x * kSize.y / 10) << "many pixels should see several prisms";
    EXPECT_EQ(over, 0) << "worst |sorted - sort-free| / bound " << worst;
    EXPECT_GT(orderMatters, kSize.x * kSize.y / 20) << "with two colours the order must matter (max difference " << worstTwo << ")";
    std::printf("sort-free ground fog: worst |sorted - sort-free| / bound %.3f; two-colour max difference %.3f\n", worst, worstTwo);
}

// (issue 14) One medium: a fog in front of, inside and around the
// cloud. Every GL pixel matches the pass's CPU model of the fog variant within
// the derived bound, and the model matches the physical integral of cloud and
// fog together (renderTetraExact's ray integral) within the table's error
// plus the placement bound. The fog changes most covered pixels by far more
// than the bound, so a pass that dropped the fog would fail.
TEST_F(TetraPassGL, FogAttenuatesEveryTetrahedronAsOneMedium) {
    TestCloud cl;
    const Camera cam = Camera::lookAt({-14.0f, 6.0f, 10.0f}, {8.0f, 8.0f, 4.0f}, {0, 0, 1}, glm::radians(50.0f), kSize, 0.5f, 200.0f);
    FogDesc fd;
    fd.terms = {FogTerm::constant(0.05), FogTerm::cosine(0.03, 0.5, {1.0, 0.0, 0.3}, 0.4)};
    fd.colour = {0.9, 0.5, 0.2};
    auto fog = Fog::create(fd);
    ASSERT_TRUE(fog) << fog.error();
    auto shared = std::make_shared<const Fog>(*fog);
    Frame frame;
    frame.begin(0.0, cam);
    frame.setFog(shared);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*cl.table;
    ASSERT_TRUE(cl.volume->update(cam, {.detailC = 20.0f}, &*cl.transfer, fv.lod));
    frame.end();
    // No host fog pass: the tetrahedra alone carry the fog (the host's is tested in tests/fog).
    auto fr = gl::FrameRenderer::create({.fogHost = false});
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    renderFrame(*fr, *fb, frame, 1.0);
    EXPECT_TRUE(fr->stats().fog.tetrahedra) << fr->stats().fog.error;
    const Image img = fb->read();
    int over = 0, overExact = 0, overRule = 0, covered = 0, changed = 0;
    double worst = 0.0, worstExact = 0.0, worstRule = 0.0, maxRule = 0.0, maxPlacement = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const glm::dvec3 d = pixelRay(cam, x, y), o(cam.eye());
            double bound = 0.0, boundClear = 0.0;
            FogModel fm{.fog = &*fog, .transfer = &*cl.transfer};
            const glm::dvec4 model = passModel(fv.lod.tets, *cl.table, o, d, 1e30, bound, &fm);
            const glm::dvec4 clear = passModel(fv.lod.tets, *cl.table, o, d, 1e30, boundClear);
            RayFogStats rs;
            // To the far plane (the quadrature of a cosine fog to 1e30 would never end).
            const double tFar = 200.0 / glm::dot(d, glm::dvec3(cam.forward()));
            const glm::dvec4 exact = integrateRayWithFog(fv.lod.tets, *cl.transfer, o, d, 0.0, tFar, {.fog = &*fog, .fogHost = false}, &rs);
            ASSERT_TRUE(rs.converged);
            double e = 0.0, eExact = 0.0, eRule = 0.0, effect = 0.0;
            for (int c = 0; c < 4; ++c) {
                e = std::max(e, std::abs(double(img.at(x, y, c)) - model[c]));
                eExact = std::max(eExact, std::abs(model[c] - exact[c]));
                eRule = std::max(eRule, std::abs(fm.exactSegments[c] - exact[c]));
                effect = std::max(effect, std::abs(model[c] - clear[c]));
            }
            // The reference's own error: its estimate (tolerance-level) counted twice.
            const double refError = 2.0 * rs.errorEstimate + 1e-9;
            const double boundExact = fm.tableError + fm.placement + refError;
            over += e > bound ? 1 : 0;
            overExact += eExact > boundExact ? 1 : 0;
            overRule += eRule > fm.placement + refError ? 1 : 0;
            worst = std::max(worst, e / bound);
            worstExact = std::max(worstExact, eExact / boundExact);
            if (fm.placement > 1e-6) worstRule = std::max(worstRule, eRule / fm.placement);
            maxRule = std::max(maxRule, eRule);
            maxPlacement = std::max(maxPlacement, fm.placement);
            if (exact.a > 0.05) {
                ++covered;
                // A pass that dropped the fog would be within boundClear of `clear`,
                // hence more than `bound` from `model` wherever effect > bound + boundClear.
                changed += effect > bound + boundClear ? 1 : 0;
            }
        }
    EXPECT_GT(covered, kSize.x * kSize.y / 10) << "the view should see cloud";
    EXPECT_EQ(over, 0) << "worst |GL - model| / bound " << worst;
    EXPECT_EQ(overExact, 0) << "worst |model - exact| / bound " << worstExact;
    EXPECT_EQ(overRule, 0) << "worst |rule on exact segments - exact| / placement bound " << worstRule;
    EXPECT_GT(changed, covered / 2) << "the fog must change most covered pixels by more than the GL bounds";
    RecordProperty("fog_rule_vs_exact_max", std::to_string(maxRule));
    std::printf("fogged tetrahedra: worst |GL - model|/bound %.3f; worst |model - exact|/bound %.3f; fog rule on exact "
                "segments vs exact: max %.2e, worst ratio to the placement bound %.3f (bound at most %.2e)\n",
                worst, worstExact, maxRule, worstRule, maxPlacement);
}

// A low-albedo Cloud under a white sun and an orange point light (lights of
// different colours): every vertex carries an RGB source (LodFrame::rgb) and
// the pass draws channel c with the table's channel c at (s_c front, s_c
// back, length). Per channel, the GL image against the pass's CPU model and
// the exact integral through the same mesh with that channel's source as the
// scalar (the transfer's extinction does not depend on s, so channel c of the
// RGB integral is channel c of that scalar integral, alpha the same for all):
// within the same derived bound as the one-scalar tests, channel by channel.
TEST_F(TetraPassGL, CloudUnderLightsOfTwoColoursMatchesTheReferencePerChannel) {
    splatfx::CloudCreateDesc d = lowAlbedoTestCloud(0.02f);
    d.lighting.lights = {Light::point({26.0f, 9.0f, 6.0f}, {1.0f, 0.45f, 0.1f}, 10.0f)};
    // 256 length samples: the bound's texel spread along the length small enough beside the
    // colour the two lights' difference makes (see `tinted`). The torch is behind the cloud
    // (seen from the camera), lighting its far side in the forward lobe.
    d.table = {.scalarResolution = 32, .lengthResolution = 256};
    auto cloud = splatfx::Cloud::create(d);
    ASSERT_TRUE(cloud) << cloud.error();
    const glm::dvec3 peak = cloud->transfer().color(1.0);
    ASSERT_LE(std::max({peak.x, peak.y, peak.z}), 1.0); // the bound's "colours <= 1"
    const Camera cam = Camera::lookAt({-14.0f, 6.0f, 10.0f}, {8.0f, 8.0f, 4.0f}, {0, 0, 1}, glm::radians(50.0f), kSize, 0.5f, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &cloud->table();
    ASSERT_TRUE(cloud->update(cam, {.detailC = 6.0f}, fv.lod)); // coarse: the brute-force model costs O(tetrahedra) per pixel
    frame.end();
    ASSERT_GT(fv.lod.tets.size(), 50u);
    ASSERT_EQ(fv.lod.rgb.size(), fv.lod.tets.size());
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    renderFrame(*fr, *fb, frame, 1.0);
    const Image img = fb->read();
    EXPECT_GT(fr->stats().tetrahedra.drawn, 0u);
    EXPECT_EQ(fr->stats().tetrahedra.rgb, fr->stats().tetrahedra.drawn);
    EXPECT_TRUE(fr->stats().tetrahedra.error.empty()) << fr->stats().tetrahedra.error;
    // The mesh with channel c's source as its scalar.
    std::vector<Tetrahedron> channel[3];
    for (int c = 0; c < 3; ++c) {
        channel[c] = fv.lod.tets;
        for (std::size_t i = 0; i < channel[c].size(); ++i)
            for (std::size_t k = 0; k < 4; ++k) channel[c][i].scalar[k] = fv.lod.rgb[i][k][c];
    }
    int over = 0, covered = 0, tinted = 0;
    double worst = 0.0, maxModel = 0.0, maxRatio = 0.0, minRatio = 1e30;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const glm::dvec3 dir = pixelRay(cam, x, y), o(cam.eye());
            glm::dvec4 model(0.0), exact(0.0);
            double bound = 0.0, eME = 0.0;
            for (int c = 0; c < 3; ++c) {
                double b = 0.0;
                const glm::dvec4 m = passModel(channel[c], cloud->table(), o, dir, 1e30, b);
                const glm::dvec4 e = integrateRay(channel[c], cloud->transfer(), o, dir, 0.0, 1e30);
                model[c] = m[c], exact[c] = e[c];
                if (c == 2) model.a = m.a, exact.a = e.a;
                bound = std::max(bound, b);
            }
            double eModel = 0.0;
            for (int c = 0; c < 4; ++c) {
                eModel = std::max(eModel, std::abs(double(img.at(x, y, c)) - model[c]));
                eME = std::max(eME, std::abs(model[c] - exact[c]));
                EXPECT_LE(std::abs(double(img.at(x, y, c)) - exact[c]), eME + bound) << "pixel " << x << "," << y << " channel " << c;
            }
            over += eModel > bound ? 1 : 0;
            worst = std::max(worst, eModel / bound);
            maxModel = std::max(maxModel, eModel);
            if (exact.a > 0.05) {
                ++covered;
                // The test can fail: a pass drawing one scalar for all channels (the
                // largest, tets[i].scalar; its own model within `bound` of it) would
                // be more than `bound` from this model wherever the two models differ by over 2 bound.
                double b1 = 0.0;
                const glm::dvec4 grey = passModel(fv.lod.tets, cloud->table(), o, dir, 1e30, b1);
                double dGrey = 0.0;
                for (int c = 0; c < 3; ++c) dGrey = std::max(dGrey, std::abs(grey[c] - model[c]));
                tinted += dGrey > 2.0 * std::max(bound, b1) ? 1 : 0;
                maxRatio = std::max(maxRatio, exact.r / std::max(exact.b, 1e-12));
                minRatio = std::min(minRatio, exact.r / std::max(exact.b, 1e-12));
            }
        }
    EXPECT_GT(covered, kSize.x * kSize.y / 10) << "the view should see cloud";
    // The torch's side of the cloud (the white sun dominates the rest): these pixels are where the
    // test tells an RGB source from one scalar; the CPU models alone decide which they are.
    EXPECT_GT(tinted, covered / 50) << "one scalar for all channels must be told apart from the RGB source";
    EXPECT_EQ(over, 0) << "worst |GL - model| / bound " << worst;
    // More than one chromaticity: red over blue varies over the cloud (one light colour would give one ratio).
    EXPECT_GT(maxRatio, 1.2 * minRatio);
    std::printf("two colours: GL vs model max %.2e (worst ratio to bound %.3f), %d of %d covered pixels more than 2 bounds from one scalar (red / blue %.3f to %.3f)\n",
                maxModel, worst, tinted, covered, minRatio, maxRatio);
}

// The RGB variant fed the same source in all three channels draws the
// one-scalar image bit for bit: the red record is the scalar's, built by the
// same arithmetic, and each channel's lookup is the one-scalar lookup at the
// same coordinates. So a cloud whose lights share one colour (frame.rgb
// empty, the one-scalar path, cloud_lights_test.cpp) is drawn as before, and
// the RGB machinery adds nothing of its own.
TEST_F(TetraPassGL, RgbVariantWithEqualChannelsIsTheOneScalarImageBitForBit) {
    splatfx::CloudCreateDesc d;
    d.cloud = {.dims = {17, 17, 9}, .seed = 5, .featureCells = 6.0f, .coverage = 0.6f};
    d.lighting.model = CloudLightModel::LowAlbedo;
    d.lighting.sun = Light::directional({-0.6f, 0.3f, -1.0f}, glm::vec3(1.0f), 0.08f);
    d.lighting.lights = {Light::point({3.0f, 4.0f, 10.0f}, {2.0f, 2.0f, 2.0f}, 1.0f)}; // white: one colour
    const HgLobe lobes[] = {{0.6f, 0.7f}, {-0.3f, 0.3f}};
    d.lighting.gas.phase = *PhaseFunction::create(lobes);
    d.table = {.scalarResolution = 32, .lengthResolution = 64};
    auto cloud = splatfx::Cloud::create(d);
    ASSERT_TRUE(cloud) << cloud.error();
    const Camera cam = Camera::lookAt({-14.0f, 6.0f, 10.0f}, {8.0f, 8.0f, 4.0f}, {0, 0, 1}, glm::radians(50.0f), kSize, 0.5f, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &cloud->table();
    ASSERT_TRUE(cloud->update(cam, {.detailC = 10.0f}, fv.lod));
    frame.end();
    ASSERT_GT(fv.lod.tets.size(), 50u);
    ASSERT_TRUE(fv.lod.rgb.empty()) << "one light colour: one scalar";
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    renderFrame(*fr, *fb, frame, 1.0);
    const Image scalar = fb->read();
    EXPECT_EQ(fr->stats().tetrahedra.rgb, 0u);
    for (const Tetrahedron& t : fv.lod.tets)
        fv.lod.rgb.push_back({glm::vec3(t.scalar[0]), glm::vec3(t.scalar[1]), glm::vec3(t.scalar[2]), glm::vec3(t.scalar[3])});
    renderFrame(*fr, *fb, frame, 1.0);
    const Image rgb = fb->read();
    EXPECT_EQ(fr->stats().tetrahedra.rgb, fr->stats().tetrahedra.drawn);
    int differ = 0, covered = 0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            covered += scalar.at(x, y, 3) > 0.05f ? 1 : 0;
            for (int c = 0; c < 4; ++c) differ += scalar.at(x, y, c) != rgb.at(x, y, c) ? 1 : 0;
        }
    EXPECT_GT(covered, kSize.x * kSize.y / 10) << "the view should see cloud";
    EXPECT_EQ(differ, 0);
    // An RGB list of another length than the tetrahedra's: drawn with the scalar, and said (ERRORS.md row 325).
    fv.lod.rgb.pop_back();
    renderFrame(*fr, *fb, frame, 1.0);
    EXPECT_EQ(fr->stats().tetrahedra.rgb, 0u);
    const std::string want = "frame volume 0: LodFrame::rgb holds " + std::to_string(fv.lod.tets.size() - 1) + " entries for " +
                             std::to_string(fv.lod.tets.size()) + " tetrahedra: drawn with their scalar";
    EXPECT_EQ(fr->stats().tetrahedra.error, want);
    EXPECT_NE(std::find(fr->stats().notes.begin(), fr->stats().notes.end(), want), fr->stats().notes.end());
    const Image again = fb->read();
    for (std::size_t i = 0; i < again.pixels.size(); ++i) ASSERT_EQ(again.pixels[i], scalar.pixels[i]);
}

} // namespace
