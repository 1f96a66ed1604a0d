// splatfx-bench hdr: what HDR lit colour costs against the 8-bit path
// (issue 27 item 5, issue 26 item 3). A lit 8^3 blob under a sun bright
// enough that its lit colours reach about 3 is lit by a Scene (table
// self-shadow, as a lit effect runs by default) and drawn into an RGBA8, an
// RGBA16F and an RGBA32F host target, with the 8-bit lit colour (brightness
// stopped at 1) and with the HDR one (Scene::setHdrLit). Time: Scene::prepare
// (the lighting and the packing, CPU) plus the splat pass with glFinish,
// median. Error: against the lit volume reference (the model at every sample
// point, transmittance through the continuous field), premultiplied RGBA over
// black. Writes DIR/hdr.dat, hdr.gp and the PNG plots.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "commands.hpp"
#include "knob_table.hpp"
#include "options.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

namespace hdr_cmd { // one namespace per command: the commands build as one unity translation unit

using namespace splatfx;

int runHdr(int argc, char** argv) {
    std::string out = "bench-hdr";
    int width = 96, height = 72, reps = 31;
    float intensity = 4.0f;
    bool noPlots = false;
    CLI::App app{"HDR lit colour against the 8-bit path: RGBA8 / RGBA16F / RGBA32F host targets, lit colours stopped at 1 or kept,\n"
                 "CPU (Scene::prepare) + GL (splat pass) ms per frame and error against the lit volume reference, Pareto.",
                 "splatfx-bench hdr"};
    cli::addNumber(app, "--width", width, 16, 4096, "frame width");
    cli::addNumber(app, "--height", height, 16, 4096, "frame height");
    cli::addNumber(app, "--reps", reps, 1, 1000, "timed frames per setting, median reported");
    cli::addNumber(app, "--intensity", intensity, 0.0f, 1e6f, "the sun's intensity (1 keeps every lit colour below 1; 4 reaches about 3)");
    app.add_option("--out", out, "where hdr.dat, hdr.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    app.add_flag("--no-plots", noPlots, "print the table only");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    auto ctx = HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "hdr: %s\n", ctx.error().c_str()), 1;

    Materials m{Footprint{}};
    const glm::vec4 base{0.85f, 0.8f, 0.75f, 1.0f};
    const std::uint32_t row = m.addColorTable(ColorTable::constant(base));
    Grid grid = *Grid::box({8, 8, 8}, glm::vec3(0.125f));
    for (Voxel& v : grid.voxels) { // the lighting bench's blob
        const glm::vec3 d = (glm::vec3(v.cell) - 3.5f) / 8.0f;
        v.opacity = 0.55f * std::exp(-glm::dot(d, d) / (2.0f * 0.22f * 0.22f));
    }
    glm::vec3 centre(0.0f);
    for (const Voxel& v : grid.voxels) centre += grid.worldPosition(v.cell) / float(grid.voxels.size());
    const Camera cam = Camera::lookAt(centre + glm::vec3(1.2f, 0.5f, 2.6f), centre, {0, 1, 0}, 0.5f, {width, height}, 0.1f, 20.0f);
    const Light sun = Light::directional({0.6f, -0.7f, -0.4f}, glm::vec3(1.0f), intensity);
    const GasLightingDesc gas{.albedo = 0.9f, .ambient = glm::vec3(0.05f)};

    VolumeField field(m);
    field.add(grid, {.textured = false});
    const LitVolumeDesc truth{.lights = {sun}, .gas = gas};
    VolumeExactStats st;
    std::printf("hdr: %zu voxels, %dx%d, sun intensity %g; the lit volume reference...\n", grid.voxels.size(), width, height, double(intensity));
    auto ref = renderVolumeExact(field, cam, {.tolerance = 1e-4, .lighting = &truth}, &st);
    if (!ref) return std::fprintf(stderr, "hdr: %s\n", ref.error().c_str()), 1;
    double peak = 0.0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) peak = std::max(peak, double(ref->at(x, y, c)));

    auto r = gl::Renderer::create();
    if (!r) return std::fprintf(stderr, "hdr: %s\n", r.error().c_str()), 1;
    if (Status s = r->upload(m); !s) return std::fprintf(stderr, "hdr: %s\n", s.error().c_str()), 1;

    struct Setting {
        const char* name;
        gl::Precision target;
        bool hdr;
    };
    const Setting settings[] = {{"RGBA8, 8-bit lit colour", gl::Precision::U8, false},
                                {"RGBA16F, 8-bit lit colour", gl::Precision::F16, false},
                                {"RGBA16F, HDR lit colour", gl::Precision::F16, true},
                                {"RGBA32F, HDR lit colour", gl::Precision::F32, true}};
    // Every setting's scene and target first; then the timed frames interleaved (frame k of
    // every setting before frame k + 1 of any), so the machine's drift falls on all alike.
    struct Run {
        Scene scene;
        std::optional<gl::Framebuffer> fb;
        Frame frame;
        std::vector<double> cpu, gpu;
    };
    std::vector<std::unique_ptr<Run>> runs;
    for (const Setting& s : settings) {
        auto run = std::make_unique<Run>();
        if (auto l = run->scene.addLight(sun); !l) return std::fprintf(stderr, "hdr: %s\n", l.error().c_str()), 1;
        EffectDesc desc;
        desc.name = "blob";
        desc.layers = {EffectLayer{.style = {.colorTable = row, .textured = false}}};
        (void)run->scene.add(*Effect::fromGrid(grid, desc),
                             {.name = "blob", .lighting = {.enabled = true, .gas = gas, .selfShadow = SelfShadow::Table, .tableDims = glm::ivec3(16)}});
        run->scene.setHdrLit(s.hdr);
        auto fb = gl::Framebuffer::create({.width = width, .height = height, .color = s.target});
        if (!fb) return std::fprintf(stderr, "hdr: %s\n", fb.error().c_str()), 1;
        run->fb.emplace(std::move(*fb));
        runs.push_back(std::move(run));
    }
    using Clock = std::chrono::steady_clock;
    for (int k = 0; k <= reps; ++k) // frame 0 builds the tables: not timed
        for (auto& run : runs) {
            // Each frame at a new time, so the lighting runs again (the tables stay: the blob is static).
            const auto t0 = Clock::now();
            if (Status p = run->scene.prepare(0.01 * k, cam, m, run->frame); !p) return std::fprintf(stderr, "hdr: %s\n", p.error().c_str()), 1;
            const auto t1 = Clock::now();
            run->fb->clear(glm::vec4(0.0f));
            r->draw(run->frame.splats(), cam, {.framebuffer = run->fb->handle(), .width = width, .height = height});
            glFinish();
            const auto t2 = Clock::now();
            if (k == 0) continue;
            run->cpu.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
            run->gpu.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
        }
    std::vector<bench::KnobRow> rows;
    for (std::size_t i = 0; i < runs.size(); ++i) {
        const Setting& s = settings[i];
        Run& run = *runs[i];
        if (!run.scene.lightingError().empty()) return std::fprintf(stderr, "hdr: %s\n", run.scene.lightingError().c_str()), 1;
        const Image img = run.fb->read();
        std::sort(run.cpu.begin(), run.cpu.end());
        std::sort(run.gpu.begin(), run.gpu.end());
        bench::KnobRow row;
        row.knob = "host target, lit colour";
        row.setting = s.name;
        row.isDefault = !s.hdr && s.target == gl::Precision::U8;
        const double c = run.cpu[run.cpu.size() / 2], g = run.gpu[run.gpu.size() / 2];
        row.ms = c + g;
        double imgPeak = 0.0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                for (int ch = 0; ch < 3; ++ch) imgPeak = std::max(imgPeak, double(img.at(x, y, ch)));
        char extra[96];
        std::snprintf(extra, sizeof extra, "%.3f | %.3f | %.2f", c, g, imgPeak);
        row.extra = extra;
        bench::imageError(img, *ref, row.rmse, row.maxErr);
        rows.push_back(row);
        std::printf("  %-28s prepare %.3f ms, splat pass %.3f ms, peak %.2f, RMSE %.5f\n", s.name, c, g, imgPeak, row.rmse);
    }
    bench::markPareto(rows);
    std::printf("\n%zu voxels (lit, 16^3 shadow table), %dx%d, sun %g: the reference's brightest channel %.2f (error estimate %.1e). "
                "ms: prepare + splat pass (glFinish), median of %d; errors premultiplied RGBA over black, linear units\n",
                grid.voxels.size(), width, height, double(intensity), peak, st.maxErrorEstimate, reps);
    bench::printTable(rows, "ms per frame", "prepare ms | splat pass ms | peak");
    if (!noPlots) {
        std::error_code ec;
        std::filesystem::create_directories(out, ec);
        bench::writePlot(rows, out, "hdr", "HDR lit colour against the 8-bit path", "ms per frame (prepare + splat pass)");
    }
    return 0;
}
} // namespace hdr_cmd

int runHdr(int argc, char** argv) { return hdr_cmd::runHdr(argc, argv); }
