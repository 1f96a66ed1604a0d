// splatfx-bench crossshadow (issue 27, item 2): lit effects shadowing one
// another in a Scene. 1, 2 or 4 lit plumes in a column under a slanted sun,
// each lit through the others (every splat's ray to the sun traced through
// the other plumes' fields, scene.hpp) or not (castsShadow off), and 4 side
// by side, where no plume's box can shadow another's (every pair skipped by
// the schedule, Scene::shadowFallsOn). Time: CPU time of Scene::prepare,
// median over --frames. Error: every splat's 8-bit colour against the exact
// transmittance through the other plumes (the lit reference, litFactor, with
// each other plume's voxels as a trilinear medium, integrated in double).
// CPU only.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "bench_stats.hpp"
#include "commands.hpp"
#include "knob_table.hpp"
#include "options.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

namespace crossshadow_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

constexpr float kGrey = 0.7f;

double cpuMs(std::clock_t d) { return 1000.0 * double(d) / double(CLOCKS_PER_SEC); }

// A 12x12x12 plume of 0.5 world units, opacity 0.3 (grey 0.7, albedo 1,
// isotropic, no self-shadow: its colour is 0.7 x the sun's transmittance
// through the other plumes; 0.7 is not a multiple of 1/255, so every row's
// error includes the 8-bit packing), its lowest voxel centre at `at`.
splatfx::Grid plumeGrid(glm::vec3 at) {
    splatfx::Grid g = *splatfx::Grid::box({12, 12, 12}, glm::vec3(0.5f));
    for (splatfx::Voxel& v : g.voxels) v.opacity = 0.3f;
    g.transform = glm::translate(glm::mat4(1.0f), at - g.localPosition({0, 0, 0}));
    return g;
}

// The plume as the reference medium: extinction -ln(1 - opacity) / spacing per voxel, trilinear.
splatfx::ContinuousMedium plumeMedium(const splatfx::Grid& g) {
    auto v = std::make_shared<splatfx::DenseVoxels>();
    v->dims = g.dims;
    v->origin = glm::dvec3(g.worldPosition({0, 0, 0}));
    v->voxelSize = double(g.spacing.x);
    v->values.assign(std::size_t(g.dims.x) * std::size_t(g.dims.y) * std::size_t(g.dims.z), 0.0f);
    for (const splatfx::Voxel& x : g.voxels)
        v->values[std::size_t(x.cell.x + g.dims.x * (x.cell.y + g.dims.y * x.cell.z))] = float(-std::log1p(-double(x.opacity)) / double(g.spacing.x));
    return splatfx::denseMedium(v, splatfx::DenseFilter::Trilinear, 1.0);
}

struct Measured {
    double ms = 0.0, rmse = 0.0, maxErr = 0.0;
    std::size_t splats = 0, pairs = 0, skipped = 0;
};

// n plumes, stacked 8 units apart along the sun (column) or 10 apart along x (side by side).
bool measure(int n, bool column, bool casts, int frames, Measured& out) {
    using namespace splatfx;
    Materials materials{Footprint{}};
    const std::uint32_t grey = materials.addColorTable(ColorTable::constant(glm::vec4(kGrey, kGrey, kGrey, 1.0f)));
    const Light sun = Light::directional({0.2f, -1.0f, 0.1f});
    Scene scene;
    scene.setSceneShadow({.enabled = false});
    if (!scene.addLight(sun)) return false;
    std::vector<Grid> grids;
    for (int k = 0; k < n; ++k) {
        const glm::vec3 at = column ? glm::vec3(-3.0f, 0.0f, -3.0f) - 8.0f * float(k) * glm::vec3(0.2f, -1.0f, 0.1f)
                                    : glm::vec3(-3.0f + 10.0f * float(k), 0.0f, -3.0f);
        grids.push_back(plumeGrid(at));
        EffectDesc ed;
        ed.name = "plume" + std::to_string(k);
        ed.layers = {EffectLayer{.style = {.colorTable = grey, .textured = false}}};
        auto plume = Effect::fromGrid(grids.back(), ed);
        if (!plume) return std::fprintf(stderr, "crossshadow: %s\n", plume.error().c_str()), false;
        scene.add(std::move(*plume),
                  {.name = ed.name, .lighting = {.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off, .castsShadow = casts}});
    }
    // From the side, every plume in view.
    const glm::vec3 centre = column ? glm::vec3(-4.0f, 14.0f, -2.0f) : glm::vec3(12.0f, 3.0f, 0.0f);
    const Camera camera = Camera::lookAt(centre + glm::vec3(0.0f, 0.0f, 70.0f), centre, {0, 1, 0}, glm::radians(60.0f), {320, 240}, 0.1f, 500.0f);
    Frame frame;
    std::vector<double> times;
    for (int f = 0; f < frames; ++f) {
        const std::clock_t t0 = std::clock();
        if (Status st = scene.prepare(0.0, camera, materials, frame); !st) return std::fprintf(stderr, "crossshadow: %s\n", st.error().c_str()), false;
        times.push_back(cpuMs(std::clock() - t0));
    }
    if (!scene.lightingError().empty()) return std::fprintf(stderr, "crossshadow: %s\n", scene.lightingError().c_str()), false;
    out.pairs = scene.counters().crossShadowPairs;
    out.skipped = scene.counters().crossShadowPairsSkipped;
    // Which plume a splat belongs to: the nearest grid box (they are disjoint).
    auto owner = [&](glm::vec3 p) {
        for (int k = 0; k < n; ++k) {
            const glm::vec3 lo = grids[std::size_t(k)].worldPosition({0, 0, 0}) - 0.01f, hi = grids[std::size_t(k)].worldPosition({11, 11, 11}) + 0.01f;
            if (glm::all(glm::greaterThanEqual(p, lo)) && glm::all(glm::lessThanEqual(p, hi))) return k;
        }
        return -1;
    };
    std::vector<VolumeField> others;
    for (int k = 0; k < n; ++k) {
        others.emplace_back(materials);
        for (int j = 0; j < n; ++j)
            if (j != k) others.back().addMedium(plumeMedium(grids[std::size_t(j)]));
    }
    const LitVolumeDesc lit{.lights = {sun}, .gas = {.albedo = 1.0f}};
    double sum = 0.0, maxErr = 0.0;
    std::size_t count = 0;
    for (const Splat& sp : frame.splats()) {
        const int k = owner(sp.center);
        if (k < 0) return std::fprintf(stderr, "crossshadow: a splat outside every plume\n"), false;
        const double exact = double(kGrey) * litFactor(others[std::size_t(k)], glm::dvec3(sp.center), glm::dvec3(camera.eye()), lit).x;
        const double d = double(sp.color & 255u) / 255.0 - exact;
        sum += d * d;
        maxErr = std::max(maxErr, std::fabs(d));
        ++count;
    }
    out.splats = count;
    out.rmse = count ? std::sqrt(sum / double(count)) : 0.0;
    out.maxErr = maxErr;
    out.ms = bench::percentile(times, 0.5);
    return true;
}

} // namespace

int runCrossShadow(int argc, char** argv) {
    CLI::App app{"Lit effects shadowing one another in a Scene: 1, 2, 4 plumes in a column under the sun with and without the\n"
                 "cross-shadow, 4 side by side (every pair skipped); Scene::prepare ms, colour vs the exact transmittance.",
                 "splatfx-bench crossshadow"};
    int frames = 8;
    std::string out = "bench-crossshadow";
    bool noPlots = false;
    cli::addNumber(app, "--frames", frames, 1, 10000, "Scene::prepare calls per row (median reported)");
    app.add_option("--out", out, "where crossshadow.dat, crossshadow.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    app.add_flag("--no-plots", noPlots, "print the table only");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;

    struct Case {
        const char* knob;
        std::string setting;
        int n;
        bool column, casts, isDefault;
    };
    const Case cases[] = {
        {"lit effects", "1 (nothing to cast)", 1, true, true, false},
        {"lit effects", "2 in a column, cross-shadow", 2, true, true, true},
        {"lit effects", "4 in a column, cross-shadow", 4, true, true, false},
        {"cross-shadow", "2 in a column, off (castsShadow false)", 2, true, false, false},
        {"cross-shadow", "4 in a column, off (castsShadow false)", 4, true, false, false},
        {"schedule", "4 side by side (every pair skipped)", 4, false, true, false},
    };
    std::printf("splatfx-bench crossshadow: 12x12x12 plumes (1728 splats each), one slanted sun, median of %d frames\n", frames);
    std::vector<bench::KnobRow> rows;
    for (const Case& c : cases) {
        std::printf("  %s %s ...\n", c.knob, c.setting.c_str());
        std::fflush(stdout);
        Measured m;
        if (!measure(c.n, c.column, c.casts, frames, m)) return 1;
        rows.push_back({.knob = c.knob,
                        .setting = c.setting,
                        .ms = m.ms,
                        .rmse = m.rmse,
                        .maxErr = m.maxErr,
                        .extra = std::to_string(m.splats) + " | " + std::to_string(m.pairs) + " | " + std::to_string(m.skipped),
                        .isDefault = c.isDefault});
    }
    bench::markPareto(rows);
    bench::printTable(rows, "CPU ms per Scene::prepare (median)", "splats | pairs traced | pairs skipped");
    std::printf("\nRMSE / max error: each splat's 8-bit colour against 0.7 x the exact transmittance through the other plumes.\n");
    if (noPlots) return 0;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    return bench::writePlot(rows, out, "crossshadow", "effects shadowing one another: CPU ms per frame vs colour error", "CPU ms per Scene::prepare") ? 0
                                                                                                                                  : 1;
}
} // namespace crossshadow_cmd

int runCrossShadow(int argc, char** argv) { return crossshadow_cmd::runCrossShadow(argc, argv); }
