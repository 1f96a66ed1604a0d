// splatfx-bench shadows: Ebert & Parent 1990's Table 2 on this machine
// (issue 16, item 6). The steam-from-a-glass scene (procedural steam over an
// opaque glass in front of a wall, lit by an oblique sun) drawn through
// Scene::prepare + gl::FrameRenderer with the host geometry shading with
// shadowGlsl(), in six ways: no shadowing; the gas's shadow on the geometry
// only; traced self-shadowing; table self-shadowing at 16^3 .. 128^3. Time
// per frame as a ratio to no shadowing, measured in one run, and each table's
// transmittance error against tracing.
//
// The steam is re-sampled every frame (it evolves, as in the paper), so
// every table is rebuilt every frame; --static samples it once, so the
// tables are built once and reused (what "rebuilt only on change" buys).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>

#include "geometry_renderer.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/procedural_gas.hpp"
#include "splatfx/splatfx.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

struct Config {
    const char* name;
    bool geometryShadow;
    splatfx::SelfShadow self;
    int tableN; // self-shadowing table entries per axis (Table)
};
const Config kConfigs[] = {
    {"no shadowing", false, splatfx::SelfShadow::Off, 0},
    {"shadows on the geometry only (64^3)", true, splatfx::SelfShadow::Off, 0},
    {"traced self-shadowing", true, splatfx::SelfShadow::Traced, 0},
    {"table 16^3", true, splatfx::SelfShadow::Table, 16},
    {"table 32^3", true, splatfx::SelfShadow::Table, 32},
    {"table 64^3", true, splatfx::SelfShadow::Table, 64},
    {"table 128^3", true, splatfx::SelfShadow::Table, 128},
};
constexpr int kSceneShadowN = 64; // the geometry's shadow table (shared with a 64^3 self-shadow table)

// The glass of Fig. 6/8: opaque, rim at y = 0.9; a wall behind it; the ground.
std::vector<splatfx::GeometryDesc> glassScene() {
    using splatfx::GeometryType;
    std::vector<splatfx::GeometryDesc> g(3);
    g[0].name = "ground", g[0].type = GeometryType::Plane, g[0].size = {8.0f, 0.0f, 8.0f}, g[0].color = {0.55f, 0.5f, 0.45f};
    g[1].name = "wall", g[1].type = GeometryType::Box, g[1].size = {8.0f, 5.0f, 0.2f}, g[1].color = {0.7f, 0.7f, 0.72f};
    g[1].transform = glm::translate(glm::mat4(1.0f), {0.0f, 0.0f, -1.6f});
    g[2].name = "glass", g[2].type = GeometryType::Cylinder, g[2].size = {0.7f, 0.9f, 0.7f}, g[2].color = {0.6f, 0.75f, 0.8f};
    return g;
}

splatfx::ProceduralGasDesc steamDesc() {
    splatfx::ProceduralGasDesc d;
    d.kind = splatfx::GasKind::Steam;
    d.steam.source = {0.0f, 0.9f, 0.0f};
    d.steam.sourceRadius = 0.28f;
    d.steam.height = 2.2f;
    return d;
}

// The lattice the steam is sampled on: 16 x 24 x 16 cells of 0.1 above the rim.
splatfx::Grid steamLattice() {
    splatfx::Grid g = *splatfx::Grid::box({16, 24, 16}, glm::vec3(0.1f));
    g.transform = glm::translate(glm::mat4(1.0f), {0.0f, 0.9f, 0.0f});
    return g;
}

splatfx::Light sun() { return splatfx::Light::directional({0.45f, -0.75f, -0.6f}, glm::vec3(1.0f), 1.0f); }

struct Result {
    double medianMs = 0.0, cpuMs = 0.0;
    std::uint64_t builds = 0; // tables built over the timed frames
    std::size_t splats = 0;
};

} // namespace

int runShadows(int argc, char** argv) {
    int frames = 15, warm = 3;
    bool animated = true;
    std::vector<glm::ivec2> sizes = {{360, 250}, {640, 480}};
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--frames" && i + 1 < argc) frames = std::max(3, std::atoi(argv[++i]));
        else if (a == "--static") animated = false;
        else if (a == "--quick") frames = 5, warm = 1, sizes = {{360, 250}};
        else {
            std::printf("splatfx-bench shadows [--frames N] [--static] [--quick]\n"
                        "  Ebert & Parent 1990 Table 2: steam from a glass at 360x250 and 640x480, no shadowing, shadows\n"
                        "  on the geometry only, traced self-shadowing, table self-shadowing at 16^3..128^3: median frame\n"
                        "  time (Scene::prepare + FrameRenderer::render + glFinish) as a ratio to no shadowing, and each\n"
                        "  table's transmittance error against tracing. --static: the steam does not evolve (tables reused).\n");
            return a == "--help" || a == "-h" ? 0 : 2;
        }
    }
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "shadows: %s\n", ctx.error().c_str());
        return 1;
    }
    splatfx::Materials m{splatfx::Footprint{}};
    const std::uint32_t set = m.addTextureSet(splatfx::TextureSet::turbulence({.count = 8, .size = 32, .seed = 3}));
    const splatfx::ColorTable steamTable = splatfx::ColorTable::constant({0.92f, 0.93f, 0.96f, 1.0f});
    const std::uint32_t table = m.addColorTable(steamTable);
    splatfx::EffectDesc desc;
    desc.name = "steam";
    desc.layers = {splatfx::EffectLayer{.style = {.textureSet = set, .colorTable = table}}};
    const splatfx::ProceduralGasDesc gas = steamDesc();
    const splatfx::Grid lattice = steamLattice();
    auto gasAt = [&](double t) { return *splatfx::sampleProceduralGas(gas, lattice, float(t)); };

    std::printf("steam from a glass: %zu of %d lattice cells hold steam at t = 2 s; %s; on %s\n", gasAt(2.0).voxels.size(),
                16 * 24 * 16, animated ? "the steam evolves (tables rebuilt every frame)" : "static steam (tables reused)",
                ctx->renderer().c_str());

    for (glm::ivec2 size : sizes) {
        auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y});
        auto fr = splatfx::gl::FrameRenderer::create();
        auto geo = scenehost::GeometryRenderer::create(glassScene());
        if (!fb || !fr || !geo) {
            std::fprintf(stderr, "shadows: %s\n", !fb ? fb.error().c_str() : !fr ? fr.error().c_str() : geo.error().c_str());
            return 1;
        }
        if (auto s = fr->upload(m); !s) {
            std::fprintf(stderr, "shadows: %s\n", s.error().c_str());
            return 1;
        }
        const splatfx::Camera cam =
            splatfx::Camera::lookAt({0.6f, 1.7f, 4.2f}, {0.0f, 1.3f, 0.0f}, {0, 1, 0}, glm::radians(45.0f), size, 0.1f, 50.0f);
        const splatfx::Light light = sun();
        std::vector<Result> results;
        for (const Config& c : kConfigs) {
            splatfx::Scene scene;
            (void)scene.addLight(light);
            splatfx::EffectLighting lit{.enabled = true,
                                        .gas = {.albedo = 0.6f, .multipleScattering = 0.3f, .ambient = glm::vec3(0.15f)},
                                        .selfShadow = c.self,
                                        .tableDims = glm::ivec3(std::max(c.tableN, 1))};
            const splatfx::HgLobe lobes[] = {{.g = 0.5f, .weight = 0.7f}, {.g = -0.2f, .weight = 0.3f}};
            lit.gas.phase = *splatfx::PhaseFunction::create(lobes);
            const splatfx::EffectId id = scene.add(*splatfx::Effect::fromGrid(gasAt(2.0), desc), {.name = "steam", .lighting = lit});
            scene.setSceneShadow({.enabled = c.geometryShadow, .dims = glm::ivec3(kSceneShadowN)});
            splatfx::Frame frame;
            std::vector<double> wall, cpu;
            Result r;
            for (int f = 0; f < warm + frames; ++f) {
                const double t = 2.0 + f / 30.0;
                if (animated) scene.effect(id) = *splatfx::Effect::fromGrid(gasAt(t), desc); // untimed: the same for every row
                glFinish();
                const auto a = Clock::now();
                const std::clock_t c0 = std::clock();
                scene.prepare(t, cam, m, frame);
                fr->render(frame, {.framebuffer = fb->handle(), .drawOpaque = [&] {
                                       glClearColor(0.1f, 0.1f, 0.12f, 1.0f);
                                       glClearDepth(1.0);
                                       glDepthMask(GL_TRUE);
                                       glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                                       scenehost::GeometryLighting gl;
                                       gl.light = glm::vec4(-glm::normalize(light.direction), 0.0f);
                                       gl.shadow = fr->shadowBinding();
                                       geo->draw(t, cam, gl);
                                   }});
                glFinish();
                if (f >= warm) {
                    wall.push_back(ms(Clock::now() - a));
                    cpu.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
                    r.builds += frame.counters().shadowTableBuilds;
                }
            }
            if (!scene.lightingError().empty()) std::fprintf(stderr, "shadows: %s\n", scene.lightingError().c_str());
            std::sort(wall.begin(), wall.end());
            std::sort(cpu.begin(), cpu.end());
            r.medianMs = wall[wall.size() / 2];
            r.cpuMs = cpu[cpu.size() / 2];
            r.splats = frame.splats().size();
            results.push_back(r);
        }

        // Each table's error against tracing, on the voxels of one frame (t = 2.5 s).
        const splatfx::Grid g = gasAt(2.5);
        auto field = splatfx::DensityField::fromGrid(g, {.colorTable = &steamTable});
        std::printf("\n%dx%d, %zu splats, median of %d frames (wall ms; process CPU ms incl. llvmpipe's threads):\n", size.x, size.y,
                    results[0].splats, frames);
        std::printf("| configuration | frame (ms) | CPU (ms) | vs no shadowing | tables built / frame | mean error (1/255) | max error (1/255) |\n");
        std::printf("|---|---|---|---|---|---|---|\n");
        for (std::size_t k = 0; k < results.size(); ++k) {
            const Config& c = kConfigs[k];
            std::string err = "", maxErr = "";
            if (c.self == splatfx::SelfShadow::Table && field) {
                splatfx::ShadowTable tab({.dims = glm::ivec3(c.tableN)});
                if (tab.update(*field, light)) {
                    double sum = 0.0, worst = 0.0;
                    for (const splatfx::Voxel& v : g.voxels) {
                        const glm::vec3 p = g.worldPosition(v.cell);
                        const double e = std::abs(double(tab.transmittance(p)) - std::exp2(-double(field->opticalDepthToLight(p, light))));
                        sum += e;
                        worst = std::max(worst, e);
                    }
                    char b[64];
                    std::snprintf(b, sizeof b, "%.2f", 255.0 * sum / double(std::max<std::size_t>(g.voxels.size(), 1)));
                    err = b;
                    std::snprintf(b, sizeof b, "%.2f", 255.0 * worst);
                    maxErr = b;
                }
            } else if (c.self == splatfx::SelfShadow::Traced) {
                err = maxErr = "0 (reference)";
            }
            std::printf("| %s | %.1f | %.1f | %.2fx | %.2f | %s | %s |\n", c.name, results[k].medianMs, results[k].cpuMs,
                        results[k].medianMs / results[0].medianMs, double(results[k].builds) / frames, err.c_str(), maxErr.c_str());
        }
        const double traced = results[2].medianMs, t64 = results[5].medianMs;
        std::printf("traced / table 64^3 = %.2fx\n", traced / t64);
    }
    return 0;
}
