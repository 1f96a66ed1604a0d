// splatfx-bench shadows: Ebert & Parent 1990's Table 2 on this machine
// (issue 16, item 6). The steam-from-a-glass scene (procedural steam over an
// opaque glass in front of a wall, lit by an oblique sun) drawn through
// Scene::prepare + gl::FrameRenderer with the host geometry shading with
// shadowGlsl(), in six ways: no shadowing; the gas's shadow on the geometry
// only; traced self-shadowing; table self-shadowing at 16^3 .. 128^3. Time
// per frame as a ratio to no shadowing, measured in one run, and each table's
// transmittance error against tracing. Then the phase-lobe knob (phaseLobes).
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

#include "bench_gl.hpp"
#include "commands.hpp"
#include "options.hpp"
#include "geometry_renderer.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/procedural_gas.hpp"
#include "splatfx/splatfx.hpp"

namespace shadows_cmd { // one namespace per command: the commands build as one unity translation unit

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

// ---- The phase-lobe knob: how many Henyey-Greenstein lobes a phase needs.
// The exact phase is Cornette-Shanks (g = 0.75), the usual stand-in for the
// Mie scattering of water droplets (steam, fog); its (1 + mu^2) factor is not
// a finite sum of HG lobes, so each added lobe buys accuracy at a cost.
constexpr double kPi = 3.14159265358979323846;
constexpr double kCsG = 0.75;
double cornetteShanks(double mu) {
    const double g2 = kCsG * kCsG;
    return 3.0 / (8.0 * kPi) * (1.0 - g2) * (1.0 + mu * mu) / ((2.0 + g2) * std::pow(1.0 + g2 - 2.0 * kCsG * mu, 1.5));
}
double hg(double g, double mu) { return (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * mu, 1.5)); }

// Least-squares weights of lobes gs against the exact phase on samples of mu
// (uniform in mu: uniform over the sphere), in relative error (the forward
// peak would otherwise decide alone), constrained to sum to 1 (both sides
// integrate to 1 over the sphere). False when the system is singular or a
// weight comes out negative (not a valid phase function).
bool fitWeights(const std::vector<double>& gs, std::vector<double>& w, double& err) {
    const int n = int(gs.size()), m = n + 1; // KKT: [H'H 1; 1' 0] [w; l] = [H'1; 1]
    std::vector<double> a(std::size_t(m * m), 0.0), b(std::size_t(m), 0.0);
    constexpr int kSamples = 401;
    auto mu = [](int k) { return -1.0 + 2.0 * k / (kSamples - 1); };
    for (int k = 0; k < kSamples; ++k) {
        const double y = cornetteShanks(mu(k));
        for (int i = 0; i < n; ++i) {
            const double hi = hg(gs[std::size_t(i)], mu(k)) / y;
            b[std::size_t(i)] += hi;
            for (int j = 0; j < n; ++j) a[std::size_t(i * m + j)] += hi * hg(gs[std::size_t(j)], mu(k)) / y;
        }
    }
    for (int i = 0; i < n; ++i) a[std::size_t(i * m + n)] = a[std::size_t(n * m + i)] = 1.0;
    b[std::size_t(n)] = 1.0;
    for (int c = 0; c < m; ++c) { // Gauss-Jordan with partial pivoting; m <= 5
        int piv = c;
        for (int r = c + 1; r < m; ++r)
            if (std::abs(a[std::size_t(r * m + c)]) > std::abs(a[std::size_t(piv * m + c)])) piv = r;
        if (std::abs(a[std::size_t(piv * m + c)]) < 1e-12) return false;
        for (int j = 0; j < m; ++j) std::swap(a[std::size_t(c * m + j)], a[std::size_t(piv * m + j)]);
        std::swap(b[std::size_t(c)], b[std::size_t(piv)]);
        for (int r = 0; r < m; ++r) {
            if (r == c) continue;
            const double f = a[std::size_t(r * m + c)] / a[std::size_t(c * m + c)];
            for (int j = 0; j < m; ++j) a[std::size_t(r * m + j)] -= f * a[std::size_t(c * m + j)];
            b[std::size_t(r)] -= f * b[std::size_t(c)];
        }
    }
    w.assign(std::size_t(n), 0.0);
    for (int i = 0; i < n; ++i) {
        w[std::size_t(i)] = b[std::size_t(i)] / a[std::size_t(i * m + i)];
        if (!(w[std::size_t(i)] >= 0.0)) return false;
    }
    err = 0.0;
    for (int k = 0; k < kSamples; ++k) {
        double p = 0.0;
        for (int i = 0; i < n; ++i) p += w[std::size_t(i)] * hg(gs[std::size_t(i)], mu(k));
        const double r = p / cornetteShanks(mu(k)) - 1.0;
        err += r * r;
    }
    return true;
}

// The best n lobes: the best n - 1 (with the new lobe at weight 0, so the
// error never grows with n), then coordinate descent over each lobe's g on a
// 0.01 grid, weights by constrained least squares.
std::vector<splatfx::HgLobe> fitLobes(int n, const std::vector<splatfx::HgLobe>& start) {
    std::vector<double> gs, bestW;
    for (const splatfx::HgLobe& l : start) gs.push_back(l.g), bestW.push_back(l.weight);
    gs.push_back(0.0);
    bestW.push_back(n == 1 ? 1.0 : 0.0);
    double bestErr = 1e300, e;
    std::vector<double> w;
    if (n > 1 && fitWeights(gs, w, e)) bestErr = e, bestW = w;
    for (int sweep = 0; sweep < 12; ++sweep)
        for (int i = n - 1; i >= 0; --i) { // the new lobe first
            double keep = gs[std::size_t(i)];
            for (int k = -95; k <= 95; ++k) {
                gs[std::size_t(i)] = k / 100.0;
                if (fitWeights(gs, w, e) && e < bestErr) bestErr = e, keep = gs[std::size_t(i)], bestW = w;
            }
            gs[std::size_t(i)] = keep;
        }
    std::vector<splatfx::HgLobe> out;
    for (int i = 0; i < n; ++i) out.push_back({.g = float(gs[std::size_t(i)]), .weight = float(bestW[std::size_t(i)])});
    return out;
}

struct Result {
    double medianMs = 0.0, cpuMs = 0.0;
    std::uint64_t builds = 0; // tables built over the timed frames
    std::size_t splats = 0;
};

// The phase-lobe knob on the steam's voxels at t = 2.5 s, self-shadowed by a
// 64^3 table, seen by the bench camera: lit factors with 1..4 fitted lobes
// against the exact phase, and the time lightPoints takes with each.
// The exact factors come from linearity: with one light the factor is
// A + B 4 pi p(cos theta) per point, so two evaluations with known phases
// (isotropic and one HG lobe) give A and B, and the exact phase gives the truth.
int phaseLobes(const splatfx::Grid& g, const splatfx::ColorTable& steamTable) {
    auto field = splatfx::DensityField::fromGrid(g, {.colorTable = &steamTable});
    if (!field) {
        std::fprintf(stderr, "shadows: %s\n", field.error().c_str());
        return 1;
    }
    const splatfx::Light light[] = {sun()};
    splatfx::ShadowTables tables({.dims = glm::ivec3(64)});
    if (auto s = tables.update(*field, light); !s) {
        std::fprintf(stderr, "shadows: %s\n", s.error().c_str());
        return 1;
    }
    std::vector<glm::vec3> points;
    for (const splatfx::Voxel& v : g.voxels) points.push_back(g.worldPosition(v.cell));
    const glm::vec3 eye{0.6f, 1.7f, 4.2f};
    splatfx::GasLightingDesc gas{.albedo = 0.6f, .multipleScattering = 0.3f, .ambient = glm::vec3(0.15f)};
    auto factorsWith = [&](const splatfx::PhaseFunction& p, std::vector<glm::vec3>& out) {
        gas.phase = p;
        return splatfx::lightPoints(points, 0.1f, eye, light, &tables, gas, out);
    };
    std::vector<glm::vec3> iso, probe;
    const splatfx::HgLobe probeLobe[] = {{.g = 0.5f, .weight = 1.0f}};
    if (!factorsWith(splatfx::PhaseFunction{}, iso) || !factorsWith(*splatfx::PhaseFunction::create(probeLobe), probe)) return 1;
    const glm::vec3 travel = glm::normalize(light[0].direction);
    std::vector<glm::vec3> exact(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        const double mu = glm::dot(travel, glm::normalize(eye - points[i]));
        const glm::dvec3 b = (glm::dvec3(probe[i]) - glm::dvec3(iso[i])) / (4.0 * kPi * hg(0.5, mu) - 1.0);
        exact[i] = glm::vec3(glm::dvec3(iso[i]) - b + b * (4.0 * kPi * cornetteShanks(mu)));
    }
    std::printf("\nphase lobes: the steam's %zu voxels lit with 1..4 HG lobes fitted to Cornette-Shanks (g = %.2f), 64^3 table;\n"
                "factor error in 1/255 of the lit colour against the exact phase; lightPoints time, median of 21 runs:\n",
                points.size(), kCsG);
    std::printf("| lobes | fitted (g: weight) | phase RMS rel. error | mean error (1/255) | max error (1/255) | lightPoints (ms) |\n");
    std::printf("|---|---|---|---|---|---|\n");
    std::vector<splatfx::HgLobe> lobes;
    for (int n = 1; n <= splatfx::PhaseFunction::kMaxLobes; ++n) {
        lobes = fitLobes(n, lobes);
        auto phase = splatfx::PhaseFunction::create(lobes);
        if (!phase) {
            std::fprintf(stderr, "shadows: %s\n", phase.error().c_str());
            return 1;
        }
        double rel = 0.0; // RMS relative error over the sphere (uniform in mu), what the fit minimizes
        for (int k = 0; k <= 400; ++k) {
            const double mu = -1.0 + k / 200.0, r = double((*phase)(float(mu))) / cornetteShanks(mu) - 1.0;
            rel += r * r / 401.0;
        }
        rel = std::sqrt(rel);
        std::vector<glm::vec3> f;
        std::vector<double> times;
        for (int r = 0; r < 21; ++r) {
            const auto a = Clock::now();
            if (!factorsWith(*phase, f)) return 1;
            times.push_back(ms(Clock::now() - a));
        }
        std::sort(times.begin(), times.end());
        double sum = 0.0, worst = 0.0;
        for (std::size_t i = 0; i < points.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                const double e = std::abs(double(f[i][c]) - double(exact[i][c])) * steamTable.entries[0][c];
                sum += e, worst = std::max(worst, e);
            }
        std::string fitted;
        for (int i = 0; i < phase->lobeCount(); ++i) {
            char b[48];
            std::snprintf(b, sizeof b, "%s%.2f: %.3f", i ? ", " : "", phase->lobe(i).g, phase->lobe(i).weight);
            fitted += b;
        }
        std::printf("| %d | %s | %.1f %% | %.2f | %.2f | %.2f |\n", n, fitted.c_str(), 100.0 * rel,
                    255.0 * sum / double(3 * std::max<std::size_t>(points.size(), 1)), 255.0 * worst, times[times.size() / 2]);
    }
    return 0;
}

} // namespace

int runShadows(int argc, char** argv) {
    int frames = 15, warm = 3;
    bool animated = true;
    std::vector<glm::ivec2> sizes = {{360, 250}, {640, 480}};
    bool still = false, quick = false;
    CLI::App app{"Ebert & Parent 1990 Table 2: steam from a glass at 360x250 and 640x480, no shadowing, shadows on the geometry only,\n"
                 "traced self-shadowing, table self-shadowing at 16^3..128^3: median frame time (Scene::prepare +\n"
                 "FrameRenderer::render + glFinish) as a ratio to no shadowing, and each table's transmittance error against tracing.\n"
                 "Then the phase-lobe knob: 1..4 HG lobes fitted to Cornette-Shanks, lit error and lightPoints time.",
                 "splatfx-bench shadows"};
    CLI::Option* framesOption = cli::addNumber(app, "--frames", frames, 3, 100000, "timed frames per configuration");
    app.add_flag("--static", still, "the steam does not evolve (tables reused)");
    app.add_flag("--quick", quick, "one size, 5 frames (unless --frames is given), 1 warm-up");
    bool lights = false, noPlots = false;
    std::string out = "bench-shadow-lights";
    app.add_flag("--lights", lights,
                 "every light casts (issue 27): 1..4 lights' scene-shadow tables (16^3..64^3) vs tracing the ground, and a point light\n"
                 "inside the plume: box table vs a direction x distance table at the same memory (CPU only)");
    app.add_option("--out", out, "--lights: where shadow_lights.dat, .gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    app.add_flag("--no-plots", noPlots, "--lights: print the tables only");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (lights) return runShadowLights(out, frames, noPlots);
    animated = !still;
    if (quick) {
        if (framesOption->count() == 0) frames = 5;
        warm = 1, sizes = {{360, 250}};
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
    auto gasAt = [&](double t) { return *splatfx::sampleProceduralGas(gas, lattice, t); };

    std::printf("steam from a glass: %zu of %d lattice cells hold steam at t = 2 s; %s; on %s\n", gasAt(2.0).voxels.size(), 16 * 24 * 16,
                animated ? "the steam evolves (tables rebuilt every frame)" : "static steam (tables reused)", ctx->renderer().c_str());

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
                if (auto s = scene.prepare(t, cam, m, frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
                fr->render(frame, {.framebuffer = fb->handle(), .drawOpaque = [&] {
                                       bench::clearHost({0.1f, 0.1f, 0.12f, 1.0f});
                                       scenehost::GeometryLighting gl;
                                       gl.lights[0].light = glm::vec4(-glm::normalize(light.direction), 0.0f);
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
    return phaseLobes(gasAt(2.5), steamTable);
}
} // namespace shadows_cmd

int runShadows(int argc, char** argv) { return shadows_cmd::runShadows(argc, argv); }
