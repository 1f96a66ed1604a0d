// A small lit GL frame decomposed against the lit volume reference (issue 24,
// item 1): a Scene lights a 3x3x3 blob with an 8^3 self-shadowing table and
// the splat pass draws it; the same splats redrawn with the colours of each
// better stage (tracing, the continuous field's shadows, the exact phase)
// separate the table, the light's field and the lobe fit in the GL image,
// and the volume reference separates splatting, 8-bit colour and per-voxel
// lighting. Each GL term is bounded by blending's linearity in the colours.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "image_stats.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

constexpr double kPi = 3.14159265358979323846;

double cornetteShanks(double mu) {
    const double g = 0.75, g2 = g * g;
    return 3.0 / (8.0 * kPi) * (1.0 - g2) * (1.0 + mu * mu) / ((2.0 + g2) * std::pow(1.0 + g2 - 2.0 * g * mu, 1.5));
}

std::uint32_t pack(glm::vec3 c) { // scene_lighting.cpp's packLit for colours <= 1 (asserted below)
    auto b = [](float v) { return std::uint32_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); };
    return b(c.r) | b(c.g) << 8 | b(c.b) << 16;
}
glm::vec3 unpack(std::uint32_t c) { return glm::vec3(float(c & 255u), float((c >> 8) & 255u), float((c >> 16) & 255u)) / 255.0f; }


class LitReferenceGL : public test::GLTest {};

} // namespace

TEST_F(LitReferenceGL, ALitFrameDecomposesIntoTableLightFieldLobeSplattingEightBitAndPerVoxelTerms) {
    Materials m{Footprint{}};
    const glm::vec4 base = test::smallLitBlobBase();
    const std::uint32_t row = m.addColorTable(ColorTable::constant(base));
    const Grid grid = test::smallLitBlob();
    std::vector<glm::vec3> centres;
    for (const Voxel& v : grid.voxels) centres.push_back(grid.worldPosition(v.cell));
    const Camera cam = test::smallLitBlobCamera(grid, {48, 36});
    const std::vector<Light> lights = {Light::directional(test::smallLitBlobSunDir(), glm::vec3(1.0f), 1.6f)};
    const HgLobe lobes[] = {{.g = 0.82f, .weight = 0.992f}, {.g = -0.54f, .weight = 0.008f}}; // fitted to Cornette-Shanks
    const GasLightingDesc gas{.phase = *PhaseFunction::create(lobes), .albedo = 0.9f, .ambient = glm::vec3(0.05f)};

    // The frame the GL path draws: a Scene's lit effect, table self-shadowing at 8^3.
    Scene scene;
    ASSERT_TRUE(scene.addLight(lights[0]));
    (void)test::addLitEffect(scene, grid, row, "blob", {.enabled = true, .gas = gas, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(8)});
    Frame frame;
    ASSERT_TRUE(scene.prepare(0.0, cam, m, frame));
    ASSERT_TRUE(scene.lightingError().empty()) << scene.lightingError();
    const std::vector<Splat> drawn = frame.splats();
    ASSERT_EQ(drawn.size(), grid.voxels.size());
    std::vector<std::size_t> voxelOf(drawn.size());
    for (std::size_t s = 0; s < drawn.size(); ++s) {
        std::size_t best = 0;
        for (std::size_t v = 1; v < centres.size(); ++v)
            if (glm::length(centres[v] - drawn[s].center) < glm::length(centres[best] - drawn[s].center)) best = v;
        ASSERT_LT(glm::length(centres[best] - drawn[s].center), 1e-5f);
        voxelOf[s] = best;
    }

    // Per-voxel colours of each stage (base x the model's factor at the voxel centre).
    auto colours = [&](const ShadowProvider* shadows) {
        std::vector<glm::vec3> f;
        EXPECT_TRUE(lightPoints(centres, grid.spacing.x, cam.eye(), lights, shadows, gas, f));
        for (glm::vec3& c : f) c *= glm::vec3(base);
        return f;
    };
    auto density = DensityField::fromGrid(grid);
    ASSERT_TRUE(density);
    ShadowTables tables({.dims = glm::ivec3(8)});
    ASSERT_TRUE(tables.update(*density, lights));
    const ShadowTracer tracer(*density, lights);
    VolumeField field(m);
    field.add(grid, {.textured = false});
    const VolumeFieldShadows exactShadows(field, lights);
    const std::vector<glm::vec3> cTable = colours(&tables), cTraced = colours(&tracer), cKernel = colours(&exactShadows);
    LitVolumeDesc lit{.lights = lights, .gas = gas};
    LitVolumeDesc litCs = lit;
    litCs.phase = cornetteShanks;
    std::vector<glm::vec3> cCs;
    for (const glm::vec3& c : centres) cCs.push_back(glm::vec3(litFactor(field, glm::dvec3(c), glm::dvec3(cam.eye()), litCs)) * glm::vec3(base));
    for (const std::vector<glm::vec3>* set : {&cTable, &cTraced, &cKernel, static_cast<const std::vector<glm::vec3>*>(&cCs)})
        for (const glm::vec3& c : *set) ASSERT_LE(std::max({c.r, c.g, c.b}), 1.0f) << "pack() assumes colours <= 1";
    // The frame carries exactly the table stage's colours: what the decomposition starts from.
    for (std::size_t s = 0; s < drawn.size(); ++s) ASSERT_EQ(drawn[s].color & 0x00ffffffu, pack(cTable[voxelOf[s]])) << "splat " << s;

    // GL: the frame's splats, with each stage's 8-bit colours.
    auto r = gl::Renderer::create();
    ASSERT_TRUE(r) << r.error();
    ASSERT_TRUE(r->upload(m));
    auto glImage = [&](const std::vector<glm::vec3>& c) {
        std::vector<Splat> splats = drawn;
        for (std::size_t s = 0; s < splats.size(); ++s) splats[s].color = (splats[s].color & 0xff000000u) | pack(c[voxelOf[s]]);
        auto fb = gl::Framebuffer::create({.width = cam.viewport.x, .height = cam.viewport.y, .color = gl::Precision::F32});
        EXPECT_TRUE(fb);
        fb->clear(glm::vec4(0.0f));
        r->draw(splats, cam, {.framebuffer = fb->handle(), .width = cam.viewport.x, .height = cam.viewport.y});
        return fb->read();
    };
    const Image gTable = glImage(cTable), gTraced = glImage(cTraced), gKernel = glImage(cKernel), gCs = glImage(cCs);
    // Blending is linear in the colours: premultiplied "over" gives each splat a weight that
    // depends on the alphas alone, and the weights sum to the pixel's alpha. So a GL term is at
    // most the frame's largest alpha times the largest change of an 8-bit splat colour, plus the
    // F32 target's rounding (27 blends of values <= 1: < 1e-5).
    const double glAlpha = test::maxAlpha(gTable);
    ASSERT_GT(glAlpha, 0.5);
    auto glTerm = [&](const char* name, const Image& a, const Image& b, const std::vector<glm::vec3>& ca, const std::vector<glm::vec3>& cb) {
        double dc = 0.0;
        for (std::size_t v = 0; v < ca.size(); ++v) {
            const glm::vec3 d = glm::abs(unpack(pack(ca[v])) - unpack(pack(cb[v])));
            dc = std::max(dc, double(std::max({d.r, d.g, d.b})));
        }
        const double e = test::maxDiff(a, b);
        EXPECT_LE(e, glAlpha * dc + 1e-5) << name;
        std::printf("  %-34s GL image %.3f/255 (bound %.3f)\n", name, 255.0 * e, 255.0 * (glAlpha * dc + 1e-5));
        return e;
    };
    std::printf("lit GL frame, 3x3x3 blob, 48x36:\n");
    const double tableTerm = glTerm("shadow table 8^3 vs tracing", gTable, gTraced, cTable, cTraced);
    glTerm("light's field (trilinear vs kernels)", gTraced, gKernel, cTraced, cKernel);
    glTerm("HG lobe fit (vs Cornette-Shanks)", gKernel, gCs, cKernel, cCs);
    EXPECT_GT(tableTerm, 0.5 / 255.0) << "an 8^3 table's error must show through the GL frame";

    // The volume reference, from the same colours on: splatting (GL vs the volume of the same
    // 8-bit colours, measured: it is what splatting itself costs, docs/BENCHMARKS.md "Accuracy"),
    // 8-bit (half a level times the alpha) and per-voxel lighting (the per-sample reference).
    std::vector<glm::vec3> cKernel8;
    for (const glm::vec3& c : cKernel) cKernel8.push_back(unpack(pack(c)));
    VolumeField v8(m), vf(m);
    v8.add(grid, {.textured = false}, cKernel8);
    vf.add(grid, {.textured = false}, cKernel);
    const double h = 0.25 * 0.25 * 0.25;
    auto vol8 = renderVolumeExact(v8, cam, {.fixedStep = h}), volF = renderVolumeExact(vf, cam, {.fixedStep = h});
    VolumeExactStats st;
    auto exact = renderVolumeExact(field, cam, {.tolerance = 1e-6, .lighting = &lit}, &st);
    auto volFc = renderVolumeExact(vf, cam, {.tolerance = 1e-6});
    ASSERT_TRUE(vol8 && volF && exact && volFc);
    const double splatting = test::maxDiff(gKernel, *vol8, 4), eight = test::maxDiff(*vol8, *volF), perVoxel = test::maxDiff(*volFc, *exact);
    const double volAlpha = test::maxAlpha(*exact);
    EXPECT_LE(eight, volAlpha * 0.5 / 255.0 + 1e-7);
    EXPECT_GT(perVoxel, 100.0 * st.maxErrorEstimate) << "the reference must resolve the per-voxel term";
    const double total = test::maxDiff(gTable, *exact);
    std::printf("  %-34s %.3f/255 (RGBA, measured)\n  %-34s %.3f/255 (bound %.3f)\n  %-34s %.3f/255 (reference error %.1e)\n"
                "  GL frame vs the lit reference: %.3f/255\n",
                "splatting (GL vs volume)", 255.0 * splatting, "8-bit lit colour", 255.0 * eight, volAlpha * 0.5,
                "per-voxel lighting", 255.0 * perVoxel, st.maxErrorEstimate, 255.0 * total);
    EXPECT_TRUE(std::isfinite(total));
}
