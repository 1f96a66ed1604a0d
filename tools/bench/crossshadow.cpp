// splatfx-bench crossshadow (issue 27, item 2): lit effects shadowing one
// another in a Scene. 1, 2 or 4 lit plumes in a column under a slanted sun,
// each lit through the others (every splat's ray to the sun traced through
// the other plumes' fields, scene.hpp) or not (castsShadow off), and 4 side
// by side, where no plume's box can shadow another's (every pair skipped by
// the schedule, Scene::shadowFallsOn). Time: CPU time of Scene::prepare,
// median over --frames. Error: every splat's 8-bit colour against the exact
// transmittance through the other plumes (the lit reference, litFactor, with
// each other plume's voxels as a trilinear medium, integrated in double).
// Ground fog rows: a lit layer casting on a plume in it (GroundFogCaster), and
// into a scene shadow table as the sun turns. CPU only.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <optional>
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

// Each splat's red channel (8-bit, grey base) against exact(splat), an
// optional: empty stops with false. Fills out's splats, rmse and maxErr.
template <class Exact>
bool splatErrors(const std::vector<splatfx::Splat>& splats, Exact exact, Measured& out) {
    double sum = 0.0, maxErr = 0.0;
    for (const splatfx::Splat& sp : splats) {
        const std::optional<double> e = exact(sp);
        if (!e) return false;
        const double d = double(sp.color & 255u) / 255.0 - *e;
        sum += d * d;
        maxErr = std::max(maxErr, std::fabs(d));
    }
    out.splats = splats.size();
    out.rmse = splats.empty() ? 0.0 : std::sqrt(sum / double(splats.size()));
    out.maxErr = maxErr;
    return true;
}

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
    const bool inPlumes = splatErrors(
        frame.splats(),
        [&](const Splat& sp) -> std::optional<double> {
            const int k = owner(sp.center);
            if (k < 0) return std::nullopt;
            return double(kGrey) * litFactor(others[std::size_t(k)], glm::dvec3(sp.center), glm::dvec3(camera.eye()), lit).x;
        },
        out);
    if (!inPlumes) return std::fprintf(stderr, "crossshadow: a splat outside every plume\n"), false;
    out.ms = bench::percentile(times, 0.5);
    return true;
}

// A lit ground fog layer casting (GroundFogCaster, volume.hpp) on one plume
// standing in it: a hilly 65x65 layer (spacing 0.25, 16 x 16 world units,
// 0.6 to 1.6 thick) and the plume's 12x12x12 voxels from 0.25 above the
// terrain, under the same slanted sun. Error: each splat against 0.7 x the
// fog's exact transmittance toward the sun (integrateGroundFogRay); with
// the fog not casting that is the missing shadow. With `sceneShadow`, a
// 64^3 scene shadow table over the casters and the sun turning by a
// thousandth of a radian every frame (the table and the fog's own relight
// rebuilt each frame); the table's own error at the terrain under the fog
// (against the same reference) goes into `tableRmse` / `tableMax`: [0] every
// 4th grid point, [1] those 2 units clear of the layer's sides.
bool measureFog(bool casts, bool sceneShadow, int frames, Measured& out, double* tableRmse, double* tableMax) {
    using namespace splatfx;
    Materials materials{Footprint{}};
    const std::uint32_t grey = materials.addColorTable(ColorTable::constant(glm::vec4(kGrey, kGrey, kGrey, 1.0f)));
    GroundFogDesc fd;
    fd.dims = {65, 65};
    fd.originWorld = {-8.0f, 0.0f, -8.0f};
    fd.spacingWorld = 0.25f;
    for (int j = 0; j < 65; ++j)
        for (int i = 0; i < 65; ++i) {
            const float h = 0.5f * std::sin(0.15f * float(i)) * std::cos(0.11f * float(j));
            fd.terrainHeight.push_back(h);
            fd.fogTop.push_back(h + 1.1f + 0.5f * std::sin(0.07f * float(i + 2 * j)));
        }
    const TransferFunction tf = *makeGroundFogTransfer(glm::vec3(0.9f), 0.9f);
    auto fog = GroundFog::create(fd);
    if (!fog) return std::fprintf(stderr, "crossshadow: %s\n", fog.error().c_str()), false;
    auto table = PreIntegrationTable::create(tf, {.scalarResolution = 4, .lengthResolution = 16});
    Scene scene;
    scene.setSceneShadow({.enabled = sceneShadow, .dims = glm::ivec3(64)});
    const EffectId fogId = scene.add(std::move(*fog), tf, std::move(*table), {.name = "fog", .lighting = {.enabled = true, .castsShadow = casts}});
    const Grid grid = plumeGrid({-1.5f, 0.75f, -1.5f});
    EffectDesc ed;
    ed.name = "plume";
    ed.layers = {EffectLayer{.style = {.colorTable = grey, .textured = false}}};
    auto plume = Effect::fromGrid(grid, ed);
    if (!plume) return std::fprintf(stderr, "crossshadow: %s\n", plume.error().c_str()), false;
    scene.add(std::move(*plume),
              {.name = "plume", .lighting = {.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off, .castsShadow = false}});
    const glm::vec3 travel(0.2f, -1.0f, 0.1f);
    if (!scene.addLight(Light::directional(travel))) return false;
    const Camera camera = Camera::lookAt({0.0f, 12.0f, 30.0f}, {0.0f, 1.0f, 0.0f}, {0, 1, 0}, glm::radians(60.0f), {320, 240}, 0.1f, 500.0f);
    Frame frame;
    std::vector<double> times;
    glm::vec3 sun = travel;
    for (int f = 0; f < frames; ++f) {
        if (sceneShadow) { // turn the sun a little about y: every frame's table and relight are new
            const float a = 1e-3f * float(f + 1);
            sun = glm::vec3(travel.x * std::cos(a) - travel.z * std::sin(a), travel.y, travel.x * std::sin(a) + travel.z * std::cos(a));
            if (!scene.setLight(0, Light::directional(sun))) return false;
        }
        const std::clock_t t0 = std::clock();
        if (Status st = scene.prepare(0.0, camera, materials, frame); !st) return std::fprintf(stderr, "crossshadow: %s\n", st.error().c_str()), false;
        times.push_back(cpuMs(std::clock() - t0));
    }
    if (!scene.lightingError().empty()) return std::fprintf(stderr, "crossshadow: %s\n", scene.lightingError().c_str()), false;
    out.pairs = scene.counters().crossShadowPairs;
    out.skipped = scene.counters().crossShadowPairsSkipped;
    const glm::dvec3 toSun = -glm::normalize(glm::dvec3(sun));
    auto fogT = [&](glm::dvec3 p) {
        GroundFogRayStats st;
        integrateGroundFogRay(fd, tf, p, toSun, 0.0, 1e4, 1e-10, 20, &st);
        return st.transmittance;
    };
    splatErrors(frame.splats(), [&](const Splat& sp) { return std::optional<double>(double(kGrey) * fogT(glm::dvec3(sp.center))); }, out);
    out.ms = bench::percentile(times, 0.5);
    if (tableRmse && sceneShadow && frame.shadow().valid && scene.status(fogId).inSceneShadow) {
        // The table at the terrain under the fog (trilinear in the table's box), every 4th grid point, against the layer's T.
        const FrameShadow& sh = frame.shadow();
        auto node = [&](int x, int y, int z) {
            x = std::clamp(x, 0, sh.dims.x - 1), y = std::clamp(y, 0, sh.dims.y - 1), z = std::clamp(z, 0, sh.dims.z - 1);
            return double(sh.depth[std::size_t(x) + std::size_t(sh.dims.x) * (std::size_t(y) + std::size_t(sh.dims.y) * std::size_t(z))]);
        };
        double tsum = 0.0, tmax = 0.0, isum = 0.0, imax = 0.0;
        std::size_t tn = 0, in = 0;
        for (int j = 0; j < 65; j += 4)
            for (int i = 0; i < 65; i += 4) {
                const glm::vec3 p(fd.originWorld.x + 0.25f * float(i), fd.terrainHeight[std::size_t(i + 65 * j)], fd.originWorld.z + 0.25f * float(j));
                const glm::vec3 u = glm::vec3(sh.worldToTable * glm::vec4(p, 1.0f)) * glm::vec3(sh.dims - 1);
                const glm::ivec3 c = glm::ivec3(glm::floor(u));
                const glm::vec3 w = u - glm::vec3(c);
                double depth = 0.0;
                for (int k = 0; k < 8; ++k) {
                    const double wx = k & 1 ? w.x : 1.0 - w.x, wy = k & 2 ? w.y : 1.0 - w.y, wz = k & 4 ? w.z : 1.0 - w.z;
                    depth += wx * wy * wz * node(c.x + (k & 1), c.y + ((k >> 1) & 1), c.z + ((k >> 2) & 1));
                }
                const double d = std::exp2(-depth) - fogT(glm::dvec3(p));
                tsum += d * d;
                tmax = std::max(tmax, std::fabs(d));
                ++tn;
                if (i >= 8 && i <= 56 && j >= 8 && j <= 56) { // 2 units (8 grid points) clear of the layer's sides
                    isum += d * d;
                    imax = std::max(imax, std::fabs(d));
                    ++in;
                }
            }
        tableRmse[0] = std::sqrt(tsum / double(tn)), tableMax[0] = tmax;
        tableRmse[1] = std::sqrt(isum / double(in)), tableMax[1] = imax;
    }
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
    // A ground fog layer casting on one plume in it (and into the scene shadow, the sun turning).
    struct FogCase {
        std::string setting;
        bool casts, sceneShadow;
    };
    const FogCase fogCases[] = {
        {"1 plume in a 65x65 layer, the fog casting", true, false},
        {"1 plume in a 65x65 layer, the fog not casting (castsShadow false)", false, false},
        {"+ 64^3 scene shadow, sun turning: the fog in the table", true, true},
        {"+ 64^3 scene shadow, sun turning: the fog not casting", false, true},
    };
    double tableRmse[2] = {-1.0, -1.0}, tableMax[2] = {-1.0, -1.0}; // every point; 2 units clear of the sides
    for (const FogCase& c : fogCases) {
        std::printf("  ground fog %s ...\n", c.setting.c_str());
        std::fflush(stdout);
        Measured m;
        if (!measureFog(c.casts, c.sceneShadow, frames, m, tableRmse, tableMax)) return 1;
        rows.push_back({.knob = "ground fog",
                        .setting = c.setting,
                        .ms = m.ms,
                        .rmse = m.rmse,
                        .maxErr = m.maxErr,
                        .extra = std::to_string(m.splats) + " | " + std::to_string(m.pairs) + " | " + std::to_string(m.skipped),
                        .isDefault = false});
    }
    bench::markPareto(rows);
    bench::printTable(rows, "CPU ms per Scene::prepare (median)", "splats | pairs traced | pairs skipped");
    std::printf("\nRMSE / max error: each splat's 8-bit colour against 0.7 x the exact transmittance through the other plumes\n"
                "(ground fog rows: through the layer, integrateGroundFogRay).\n");
    if (tableRmse[0] >= 0.0)
        std::printf("The 64^3 scene shadow table under the fog (terrain, every 4th grid point, trilinear) against the layer's exact T:\n"
                    "RMSE %.4f, max %.4f; 2 units clear of the layer's sides: RMSE %.4f, max %.4f.\n",
                    tableRmse[0], tableMax[0], tableRmse[1], tableMax[1]);
    if (noPlots) return 0;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    return bench::writePlot(rows, out, "crossshadow", "effects shadowing one another: CPU ms per frame vs colour error", "CPU ms per Scene::prepare") ? 0
                                                                                                                                  : 1;
}
} // namespace crossshadow_cmd

int runCrossShadow(int argc, char** argv) { return crossshadow_cmd::runCrossShadow(argc, argv); }
