// The LOD clouds' quality knobs (issue 17, item 7), run by `splatfx-bench
// accuracy` (alone with --clouds-only): the pre-integration table's size, the
// detail c, the minimum accuracy C and max-vs-average Delta, each varied from
// the defaults with the rest left alone. Error: the GL frame (RGBA32F,
// premultiplied over black) against the finest level integrated exactly
// (LodVolume::integrateRay: every linear piece of the finest mesh integrated
// by integrateSegment, no table), per pixel the largest channel difference.
// Also the resolution scale: the tetrahedra drawn at 1/2 or 1/4 resolution per
// axis and upsampled (FrameRendererDesc::reduceTetrahedra).
// Time: the GL frame (prepare + render + glFinish) as a median of repeats.
// Two views: outside the field with all of it in view, and inside it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "bench_gl.hpp"
#include "bench_stats.hpp"
#include "commands.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/volume.hpp"

namespace cloud_knobs_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using bench::median;
using Clock = std::chrono::steady_clock;

struct Knobs {
    glm::ivec2 table{64, 128}; // scalar x length resolution (the table's default)
    float detailC = 10.0f;     // LodRefineDesc::detailC default
    float minC = 4.0f;         // LodVolumeDesc::minAccuracyC default
    splatfx::DeltaMode delta = splatfx::DeltaMode::Max;
    int scale = 1; // FrameRendererDesc::resolutionScale, the tetrahedra reduced with it (reduceTetrahedra)
    splatfx::CloudModel model = splatfx::CloudModel::DensityTableLightLength;
};

struct Row {
    std::string knob, value;
    Knobs k;
};

struct View {
    const char* name;
    splatfx::Camera camera;
    splatfx::Image exact[2]; // per cloud model: the finest level, no table, RGBA premultiplied over black
};

// The ray through a pixel centre (x right, y top row first, as Framebuffer::read orders rows).
glm::dvec3 pixelRay(const splatfx::Camera& cam, int x, int y) {
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    const double nx = (x + 0.5) / cam.viewport.x * 2.0 - 1.0, ny = 1.0 - (y + 0.5) / cam.viewport.y * 2.0;
    const glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
    return glm::normalize(glm::dvec3(b) / b.w - glm::dvec3(a) / a.w);
}

} // namespace

int runCloudKnobs(glm::ivec3 dims, glm::ivec2 size, int reps) {
    // One renderer per resolution scale (1, 2, 4).
    std::vector<splatfx::gl::FrameRenderer> renderers;
    for (int scale : {1, 2, 4}) {
        auto fr = splatfx::gl::FrameRenderer::create({.resolutionScale = scale, .reduceTetrahedra = true, .fogHost = false});
        if (!fr) return std::fprintf(stderr, "clouds knobs: %s\n", fr.error().c_str()), 1;
        renderers.push_back(std::move(*fr));
    }
    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y, .color = splatfx::gl::Precision::F32});
    if (!fb) return std::fprintf(stderr, "clouds knobs: %s\n", fb.error().c_str()), 1;
    // The two cloud models (Roettger & Ertl sec. 5.2, the default, and sec. 5.1 with eq. 9): the same cloud, its own field and transfer.
    std::vector<splatfx::ScalarVolume> fields;
    std::vector<splatfx::TransferFunction> transfers;
    for (splatfx::CloudModel model : {splatfx::CloudModel::DensityTableLightLength, splatfx::CloudModel::LightTableDensityLength}) {
        splatfx::CloudDesc cd;
        cd.dims = dims;
        cd.model = model;
        auto field = splatfx::makeCloudVolume(cd);
        auto tf = splatfx::makeCloudTransfer({}, model);
        if (!field || !tf) return std::fprintf(stderr, "clouds knobs: %s\n", field ? tf.error().c_str() : field.error().c_str()), 1;
        fields.push_back(std::move(*field));
        transfers.push_back(std::move(*tf));
    }
    splatfx::Materials materials{splatfx::Footprint{}};

    // A scene of the field with these knobs (the octree depends on C and Delta, the table on its size).
    auto makeScene = [&](const Knobs& k, splatfx::Scene& scene) -> bool {
        const std::size_t m = k.model == splatfx::CloudModel::DensityTableLightLength ? 0 : 1;
        const splatfx::ScalarVolume* field = &fields[m];
        const splatfx::TransferFunction* tf = &transfers[m];
        auto vol = splatfx::LodVolume::create(*field, {.minAccuracyC = k.minC, .delta = k.delta});
        if (!vol) return std::fprintf(stderr, "clouds knobs: %s\n", vol.error().c_str()), false;
        const float longest = std::sqrt(3.0f) * float(1 << vol->rootLevel()) * vol->spacingWorld();
        auto table =
            splatfx::PreIntegrationTable::create(*tf, {.scalarResolution = k.table.x, .lengthResolution = k.table.y, .maxLengthWorld = longest});
        if (!table) return std::fprintf(stderr, "clouds knobs: %s\n", table.error().c_str()), false;
        scene.add(std::move(*vol), *tf, std::move(*table), {.name = "clouds", .refine = {.detailC = k.detailC}});
        return true;
    };
    splatfx::Scene finest[2];
    if (!makeScene({}, finest[0]) || !makeScene({.model = splatfx::CloudModel::LightTableDensityLength}, finest[1])) return 1;
    const splatfx::LodVolume& ref = *finest[0].findLodVolume(0);
    const glm::vec3 ext = glm::vec3(ref.pointDims() - 1) * ref.spacingWorld();

    std::vector<View> views;
    views.push_back({"outside",
                     splatfx::Camera::lookAt(glm::vec3(-0.6f, -0.35f, 1.8f) * ext, 0.5f * ext, {0, 0, 1}, glm::radians(60.0f), size, 0.1f, 5000.0f),
                     {}});
    views.push_back({"inside",
                     splatfx::Camera::lookAt(glm::vec3(0.3f, 0.4f, 0.5f) * ext, glm::vec3(0.9f, 0.55f, 0.5f) * ext, {0, 0, 1}, glm::radians(60.0f),
                                             size, 0.1f, 5000.0f),
                     {}});
    const auto e0 = Clock::now();
    for (View& v : views)
        for (std::size_t m = 0; m < 2; ++m) {
            const splatfx::LodVolume& vol = *finest[m].findLodVolume(0);
            v.exact[m] = {size.x, size.y, 4, std::vector<float>(std::size_t(size.x) * std::size_t(size.y) * 4, 0.0f)};
            const glm::dvec3 eye(v.camera.eye()), fwd(v.camera.forward());
            for (int y = 0; y < size.y; ++y)
                for (int x = 0; x < size.x; ++x) {
                    const glm::dvec3 d = pixelRay(v.camera, x, y);
                    // GL starts every ray at the near plane (volumetric clipping, sec. 4.3).
                    const double tNear = double(v.camera.nearPlane()) / std::max(glm::dot(d, fwd), 1e-9);
                    const glm::dvec4 c = vol.integrateRay(transfers[m], eye, d, tNear, 1e30);
                    for (int k = 0; k < 4; ++k) v.exact[m].at(x, y, k) = float(c[k]);
                }
        }
    const double exactMs = std::chrono::duration<double, std::milli>(Clock::now() - e0).count();

    std::vector<Row> rows;
    rows.push_back({"defaults", "", {}});
    for (glm::ivec2 t : {glm::ivec2(16, 32), glm::ivec2(32, 64), glm::ivec2(128, 256)})
        rows.push_back(
            {"table (finest mesh)", std::to_string(t.x) + "x" + std::to_string(t.x) + "x" + std::to_string(t.y), {.table = t, .detailC = 1e9f}});
    rows.push_back({"table (finest mesh)", "64x64x128", {.detailC = 1e9f}});
    for (float c : {2.0f, 5.0f, 20.0f, 50.0f}) rows.push_back({"c", std::to_string(int(c)), {.detailC = c}});
    for (float C : {2.0f, 8.0f, 16.0f}) rows.push_back({"C", std::to_string(int(C)), {.minC = C}});
    rows.push_back({"delta", "average", {.delta = splatfx::DeltaMode::Average}});
    for (int scale : {2, 4}) rows.push_back({"resolution scale", std::to_string(scale), {.scale = scale}});
    // Sec. 5.1 against its own finest level: what the paper's eq. 9 model costs and how well the table holds it.
    rows.push_back({"model", "5.1 (eq. 9)", {.model = splatfx::CloudModel::LightTableDensityLength}});

    std::printf("LOD clouds knobs: field %dx%dx%d (full %llu tetrahedra), %dx%d RGBA32F, median of %d frames; defaults: "
                "table 64x64x128, c = 10, C = 4, Delta max, model sec. 5.2\n"
                "error: GL vs the finest level (of the row's model) integrated exactly (no table; %.0f ms for both views), per pixel the largest of "
                "|dR|, |dG|, |dB|, |dA| (premultiplied)\n\n",
                dims.x, dims.y, dims.z, static_cast<unsigned long long>(ref.fullResolutionTets()), size.x, size.y, reps, exactMs);
    std::printf("%-20s %-12s %-8s %10s %9s %9s %9s %9s\n", "knob", "value", "view", "tets", "ms/frame", "mean err", "p99 err", "max err");
    for (const Row& r : rows) {
        splatfx::Scene scene;
        if (!makeScene(r.k, scene)) return 1;
        splatfx::gl::FrameRenderer* fr = &renderers[r.k.scale == 4 ? 2 : std::size_t(r.k.scale - 1)];
        for (const View& v : views) {
            splatfx::Frame frame;
            std::vector<double> t;
            for (int f = -1; f < reps; ++f) { // one warm-up frame: the table upload, the shader
                const auto a = Clock::now();
                if (auto s = scene.prepare(1.0, v.camera, materials, frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
                fr->render(frame, bench::clearedTarget(*fb, {0.0f, 0.0f, 0.0f, 0.0f}));
                glFinish();
                if (f >= 0) t.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
            }
            const splatfx::Image img = fb->read();
            std::vector<double> err;
            err.reserve(std::size_t(size.x) * std::size_t(size.y));
            double sum = 0.0;
            for (int y = 0; y < size.y; ++y)
                for (int x = 0; x < size.x; ++x) {
                    double e = 0.0;
                    const splatfx::Image& exact = v.exact[r.k.model == splatfx::CloudModel::DensityTableLightLength ? 0 : 1];
                    for (int k = 0; k < 4; ++k) e = std::max(e, std::abs(double(img.at(x, y, k)) - double(exact.at(x, y, k))));
                    err.push_back(e);
                    sum += e;
                }
            std::sort(err.begin(), err.end());
            std::printf("%-20s %-12s %-8s %10llu %9.1f %9.4f %9.4f %9.4f\n", r.knob.c_str(), r.value.c_str(), v.name,
                        static_cast<unsigned long long>(fr->stats().tetrahedra.drawn), median(t), sum / double(err.size()),
                        err[std::min(err.size() - 1, std::size_t(0.99 * double(err.size())))], err.back());
        }
    }
    return 0;
}
} // namespace cloud_knobs_cmd

int runCloudKnobs(glm::ivec3 dims, glm::ivec2 size, int reps) { return cloud_knobs_cmd::runCloudKnobs(dims, size, reps); }
