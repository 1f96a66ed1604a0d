// splatfx-bench cloudcolour (issue 27): what lights of different colours on
// one low-albedo cloud cost against lights sharing one colour. The same cloud
// under a white sun and a point light, the light white (one scalar per
// vertex: the one-scalar records and program) or a torch's orange (an RGB
// source per vertex, LodFrame::rgb: 12 vec4 records a tetrahedron instead of
// 10, three table lookups a segment instead of one). Per mode: Cloud::update
// (the LOD refinement and the per-vertex sources, CPU) and the projected-
// tetrahedra pass (gl::FrameRenderer on a cleared target, glFinish), medians
// of interleaved frames from one run, and the ratio; the bytes the frame's
// tetrahedra take (LodFrame and the pass's records).
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "bench_gl.hpp"
#include "bench_stats.hpp"
#include "commands.hpp"
#include "options.hpp"
#include "splatfx/cloud.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"

namespace cloudcolour_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using Clock = std::chrono::steady_clock;
double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

} // namespace

int runCloudColour(int argc, char** argv) {
    int size = 65, width = 256, height = 192, frames = 21;
    float detailC = 10.0f;
    CLI::App app{"Lights of different colours on one low-albedo cloud (an RGB source per vertex) against one colour (one scalar):\n"
                 "Cloud::update ms and tetrahedra pass ms per frame, medians of interleaved frames, ratio; bytes per frame.",
                 "splatfx-bench cloudcolour"};
    cli::addNumber(app, "--size", size, 9, 257, "grid points along x and y (z: a quarter of it, + 1)");
    cli::addNumber(app, "--width", width, 16, 4096, "frame width");
    cli::addNumber(app, "--height", height, 16, 4096, "frame height");
    cli::addNumber(app, "--frames", frames, 1, 10000, "timed frames per mode, median reported");
    cli::addNumber(app, "--detail", detailC, 0.5f, 1e6f, "the refinement's detailC");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "cloudcolour: %s\n", ctx.error().c_str()), 1;

    const int nz = size / 4 + 1;
    const float ext = float(size - 1);
    struct Mode {
        const char* name;
        glm::vec3 torch;
        std::optional<splatfx::Cloud> cloud{};
        std::optional<splatfx::gl::FrameRenderer> renderer{};
        splatfx::Frame frame{};
        std::vector<double> updateMs{}, passMs{};
    };
    Mode modes[2] = {{"one colour (white torch): one scalar", glm::vec3(1.0f)}, {"two colours (orange torch): RGB per vertex", {1.0f, 0.45f, 0.1f}}};
    const splatfx::Camera cam = splatfx::Camera::lookAt(glm::vec3(-0.4f, -0.5f, 0.9f) * ext, glm::vec3(0.5f * ext, 0.5f * ext, 0.1f * ext), {0, 0, 1},
                                                        glm::radians(60.0f), {width, height}, 0.1f, 5000.0f);
    for (Mode& m : modes) {
        splatfx::CloudCreateDesc d;
        d.cloud = {.dims = {size, size, nz}, .seed = 7, .featureCells = 8.0f, .coverage = 0.55f};
        d.lighting.model = splatfx::CloudLightModel::LowAlbedo;
        d.lighting.sun = splatfx::Light::directional({-0.4f, 0.2f, -1.0f}, glm::vec3(1.0f), 0.8f);
        d.lighting.lights = {splatfx::Light::point({0.3f * ext, 0.4f * ext, 0.4f * ext}, m.torch, 0.02f * ext * ext)};
        const splatfx::HgLobe lobes[] = {{0.6f, 0.7f}, {-0.3f, 0.3f}};
        d.lighting.gas.phase = *splatfx::PhaseFunction::create(lobes);
        auto c = splatfx::Cloud::create(d);
        if (!c) return std::fprintf(stderr, "cloudcolour: %s\n", c.error().c_str()), 1;
        m.cloud.emplace(std::move(*c));
        auto r = splatfx::gl::FrameRenderer::create();
        if (!r) return std::fprintf(stderr, "cloudcolour: %s\n", r.error().c_str()), 1;
        m.renderer.emplace(std::move(*r));
    }
    auto fb = splatfx::gl::Framebuffer::create({.width = width, .height = height, .color = splatfx::gl::Precision::F16});
    if (!fb) return std::fprintf(stderr, "cloudcolour: %s\n", fb.error().c_str()), 1;
    for (int f = -2; f < frames; ++f) // interleaved (which goes first alternates), two warm-up rounds
        for (int k = 0; k < 2; ++k) {
            Mode& m = modes[(k + f) & 1];
            m.frame.begin(0.0, cam);
            splatfx::FrameVolume& fv = m.frame.volumes().emplace_back();
            fv.table = &m.cloud->table();
            fv.tableVersion = m.cloud->tableVersion();
            const auto a = Clock::now();
            if (splatfx::Status s = m.cloud->update(cam, {.detailC = detailC}, fv.lod); !s)
                return std::fprintf(stderr, "cloudcolour: %s\n", s.error().c_str()), 1;
            const auto b = Clock::now();
            m.frame.end();
            glFinish();
            const auto c = Clock::now();
            m.renderer->render(m.frame, bench::clearedTarget(*fb, {0.0f, 0.0f, 0.0f, 0.0f}));
            glFinish();
            const auto e = Clock::now();
            if (f >= 0) m.updateMs.push_back(ms(b - a)), m.passMs.push_back(ms(e - c));
        }
    std::printf("cloudcolour: cloud %dx%dx%d, detailC %.1f, %dx%d RGBA16F, %d frames per mode, interleaved (medians)\n", size, size, nz, detailC,
                width, height, frames);
    for (const Mode& m : modes) {
        const splatfx::LodFrame& lod = m.frame.volumes()[0].lod;
        const auto& st = m.renderer->stats();
        const std::size_t frameBytes = lod.tets.size() * sizeof(splatfx::Tetrahedron) + lod.rgb.size() * sizeof(lod.rgb[0]);
        const std::size_t recordBytes = std::size_t(st.tetrahedra.drawn) * (lod.rgb.empty() ? 10u : 12u) * 16u;
        std::printf("  %-45s %7zu tetrahedra (%llu drawn, %llu RGB)  update ms %8.2f  pass ms %8.2f  LodFrame %6.2f MB  records %6.2f MB%s%s\n",
                    m.name, lod.tets.size(), static_cast<unsigned long long>(st.tetrahedra.drawn), static_cast<unsigned long long>(st.tetrahedra.rgb),
                    bench::median(m.updateMs), bench::median(m.passMs), double(frameBytes) / 1e6, double(recordBytes) / 1e6,
                    st.notes.empty() ? "" : "  note: ", st.notes.empty() ? "" : st.notes[0].c_str());
    }
    std::printf("  ratio two colours / one colour: update %.2fx, pass %.2fx\n",
                bench::median(modes[1].updateMs) / std::max(bench::median(modes[0].updateMs), 1e-9),
                bench::median(modes[1].passMs) / std::max(bench::median(modes[0].passMs), 1e-9));
    return 0;
}

} // namespace cloudcolour_cmd

int runCloudColour(int argc, char** argv) { return cloudcolour_cmd::runCloudColour(argc, argv); }
