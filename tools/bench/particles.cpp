// splatfx-bench particles: splats at particle positions (King et al. 1999,
// sec. 6) against the same number of grid splats. Three kinds per count: a
// grid's voxels, a host's particles (SplatBuilder::add(span)) at random
// points of the same box, and the closed-form emitter evaluated at t
// (ParticleEmitter::particlesAt, then add). Each row times the CPU work of a
// frame (evaluate, build, sort; median) and the GL splat pass (draw +
// glFinish; median), and its error: the GL frame against the exact
// reference (renderSplatExact) at a small size.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "bench_stats.hpp"
#include "commands.hpp"
#include "knob_table.hpp"
#include "options.hpp"
#include "splatfx/context.hpp"
#include "splatfx/splatfx.hpp"

namespace particles_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using Clock = std::chrono::steady_clock;

constexpr float kSpacing = 0.3f, kOpacity = 0.3f;

splatfx::Grid box(glm::ivec3 dims) {
    splatfx::Grid g = *splatfx::Grid::box(dims, glm::vec3(kSpacing));
    for (splatfx::Voxel& v : g.voxels) v.opacity = kOpacity, v.texture = std::uint32_t(v.cell.x * 7 + v.cell.y * 3 + v.cell.z);
    return g;
}

// N particles uniform in the grid's box, with the grid's size and opacity.
std::vector<splatfx::Particle> scatter(const splatfx::Grid& g) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const splatfx::Voxel& v : g.voxels) lo = glm::min(lo, g.worldPosition(v.cell)), hi = glm::max(hi, g.worldPosition(v.cell));
    std::vector<splatfx::Particle> out;
    std::uint32_t h = 12345u;
    auto unit = [&h] { return splatfx::hashUnit(h = splatfx::hash32(h + 0x9e3779b9u)); };
    for (std::size_t i = 0; i < g.voxels.size(); ++i) {
        const glm::vec3 p = lo + (hi - lo) * glm::vec3(unit(), unit(), unit());
        out.push_back({.position = p, .sizeWorld = kSpacing, .velocity = {0, 1, 0}, .opacity = kOpacity, .colorCoord = p.y / hi.y,
                       .texture = std::uint32_t(i), .id = std::uint32_t(i)});
    }
    return out;
}

// The small case tools/validate/particle_flight.py integrates on its own: the
// closed-form flight (ParticleEmitter::flightPosition) for a few drags, ages
// and starts, as CSV.
int validation() {
    std::printf("k,ax,ay,az,wx,wy,wz,x0x,x0y,x0z,v0x,v0y,v0z,age,x,y,z\n");
    for (float k : {0.0f, 1e-6f, 0.4f, 3.0f})
        for (double age : {0.05, 0.7, 2.5, 9.0}) {
            const splatfx::ParticleEmitterDesc d{.acceleration = {0.1f, 0.8f, -0.2f}, .dragPerSec = k, .wind = {1.1f, 0.0f, 0.3f}};
            const glm::dvec3 x0(0.3, 3.2, -0.4), v0(-0.7, 2.6, 0.5);
            const glm::dvec3 x = splatfx::ParticleEmitter::flightPosition(d, x0, v0, age);
            std::printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", double(k),
                        double(d.acceleration.x), double(d.acceleration.y), double(d.acceleration.z), double(d.wind.x), double(d.wind.y),
                        double(d.wind.z), x0.x, x0.y, x0.z, v0.x, v0.y, v0.z, age, x.x, x.y, x.z);
        }
    return 0;
}

} // namespace

int runParticles(int argc, char** argv) {
    CLI::App app{"Splats at particle positions vs the same number of grid splats: CPU frame, GL pass, error vs the exact reference.",
                 "splatfx-bench particles"};
    std::string out = "bench-particles";
    glm::ivec2 size{640, 480}, refSize{80, 60};
    int frames = 15;
    bool noPlots = false, valid = false;
    app.add_flag("--validation", valid, "print the small case tools/validate/particle_flight.py checks, and stop");
    app.add_option("--out", out, "where particles.dat, particles.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    cli::addSize(app, "--size", size.x, size.y, 16, 4096, "window of the timed GL pass");
    cli::addSize(app, "--reference-size", refSize.x, refSize.y, 8, 512, "image size of the error against the exact reference");
    cli::addNumber(app, "--frames", frames, 1, 1000, "timed frames per row, median reported");
    app.add_flag("--no-plots", noPlots, "print the table only");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (valid) return validation();
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "particles: %s\n", ctx.error().c_str()), 1;

    splatfx::Materials mat{splatfx::Footprint{}};
    const std::uint32_t set = mat.addTextureSet(splatfx::TextureSet::turbulence({}));
    const std::uint32_t table = mat.addColorTable(splatfx::ColorTable::fire());
    const splatfx::SplatStyle style{.textureSet = set, .colorTable = table, .crossfade = true};
    auto renderer = splatfx::gl::Renderer::create({.sampling = splatfx::gl::TextureSampling::Bilinear});
    if (!renderer || !renderer->upload(mat)) return std::fprintf(stderr, "particles: renderer\n"), 1;
    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y, .color = splatfx::gl::Precision::F32});
    auto refFb = splatfx::gl::Framebuffer::create({.width = refSize.x, .height = refSize.y, .color = splatfx::gl::Precision::F32});
    if (!fb || !refFb) return std::fprintf(stderr, "particles: framebuffer\n"), 1;
    std::printf("splatfx-bench particles on %s: %dx%d pass, error at %dx%d; figures on a shared machine are noisy, compare within one run\n",
                ctx->renderer().c_str(), size.x, size.y, refSize.x, refSize.y);

    std::vector<bench::KnobRow> rows;
    for (glm::ivec3 dims : {glm::ivec3(10, 26, 6), glm::ivec3(20, 26, 12), glm::ivec3(40, 26, 24)}) {
        const splatfx::Grid g = box(dims);
        const std::vector<splatfx::Particle> host = scatter(g);
        // An emitter with about as many alive: rate * lifetime = N, born in the box, slow.
        const float life = 4.0f;
        const glm::vec3 half = 0.5f * kSpacing * glm::vec3(dims - 1);
        const splatfx::ParticleEmitterDesc ed{.position = {0.0f, half.y, 0.0f}, .halfExtent = half, .ratePerSec = float(g.voxels.size()) / life,
                                              .velocity = {0, 0.05f, 0}, .velocitySpread = glm::vec3(0.05f), .lifetimeSec = life,
                                              .sizeWorld = kSpacing, .sizeEndWorld = kSpacing, .opacity = kOpacity, .fadeIn = 0.0f,
                                              .fadeOut = 0.0f, .texturesPerSec = 6.0f, .maxParticles = splatfx::kMaxParticles};
        const splatfx::ParticleEmitter emitter = *splatfx::ParticleEmitter::create(ed);
        const float reach = 1.3f * std::max({half.x, half.y, half.z}) + 2.0f;
        for (int kind = 0; kind < 3; ++kind) {
            const char* names[3] = {"grid voxels", "host particles", "emitter particles"};
            auto camFor = [&](glm::ivec2 vp) { return splatfx::Camera::lookAt({0.0f, half.y, 2.2f * reach}, {0.0f, half.y, 0.0f}, {0, 1, 0}, 0.9f, vp); };
            std::vector<splatfx::Particle> emitted;
            splatfx::SplatBuilder b;
            auto build = [&](const splatfx::Camera& cam, double t) {
                b.begin(cam);
                if (kind == 0) b.add(g, mat, style);
                else if (kind == 1) b.add(host, mat, {.splat = style, .stretchPerSpeed = 0.1f});
                else {
                    emitter.particlesAt(t, emitted);
                    b.add(emitted, mat, {.splat = style, .stretchPerSpeed = 0.1f});
                }
                b.sort();
            };
            const splatfx::Camera cam = camFor(size);
            std::vector<double> cpu, gpu;
            for (int f = 0; f < frames; ++f) {
                const double t = 10.0 + f / 30.0;
                const auto a = Clock::now();
                build(cam, t);
                cpu.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
                fb->clear({0, 0, 0, 0});
                glFinish();
                const auto c = Clock::now();
                renderer->draw(b.splats(), cam, {.framebuffer = fb->handle(), .width = size.x, .height = size.y});
                glFinish();
                gpu.push_back(std::chrono::duration<double, std::milli>(Clock::now() - c).count());
            }
            const std::size_t count = b.splats().size();
            // Error: the same kind's frame at the small size, GL against the exact reference.
            const splatfx::Camera small = camFor(refSize);
            build(small, 10.0);
            refFb->clear({0, 0, 0, 0});
            renderer->draw(b.splats(), small, {.framebuffer = refFb->handle(), .width = refSize.x, .height = refSize.y});
            auto ref = splatfx::renderSplatExact(b.splats(), small, mat);
            if (!ref) return std::fprintf(stderr, "particles: %s\n", ref.error().c_str()), 1;
            bench::KnobRow row;
            row.knob = names[kind];
            row.setting = std::to_string(g.voxels.size());
            row.ms = bench::median(cpu) + bench::median(gpu);
            bench::imageError(refFb->read(), *ref, row.rmse, row.maxErr);
            char buf[96];
            std::snprintf(buf, sizeof buf, "%.3f | %.3f | %zu", bench::median(cpu), bench::median(gpu), count);
            row.extra = buf;
            row.isDefault = kind == 0 && dims.x == 10;
            rows.push_back(row);
            std::fprintf(stderr, "  %s %s: CPU %.3f ms, GL %.3f ms, RMSE %.5f\n", row.knob.c_str(), row.setting.c_str(), bench::median(cpu),
                         bench::median(gpu), row.rmse);
        }
    }
    bench::markPareto(rows);
    bench::printTable(rows, "ms/frame (CPU + GL)", "CPU ms | GL ms | splats");
    if (noPlots) return 0;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    return bench::writePlot(rows, out, "particles", "particles vs grid splats: error vs the exact reference and time per frame",
                            "ms per frame: CPU (evaluate, build, sort) + GL pass (median)")
               ? 0
               : 1;
}
} // namespace particles_cmd

int runParticles(int argc, char** argv) { return particles_cmd::runParticles(argc, argv); }
