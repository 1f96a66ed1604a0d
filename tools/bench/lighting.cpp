// splatfx-bench lighting: every knob of the lighting (self-shadowing by
// tracing or by a table of 8^3 .. 128^3, HG lobe count, samples per voxel,
// 8-bit vs float lit colour) against the lit volume reference (reference.hpp,
// LitVolumeDesc): the model at every sample point, the exact Cornette-Shanks
// phase, transmittance through the continuous field. Each row's lit colours
// are drawn by the volume reference too (VolumeField with per-voxel colours),
// so the error is the lighting's alone, not splatting's. Time: the CPU work
// of lighting one frame (density field, table build, lightPoints), median.
// Writes DIR/lighting.csv, lighting.dat, lighting.gp and lighting_pareto.png.
// --validate FILE writes the small case tools/validate/lit_volume.py checks.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "spawn.hpp"
#include "commands.hpp"
#include "options.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

namespace lighting_cmd { // one namespace per command: the commands build as one unity translation unit

using namespace splatfx;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Cornette-Shanks, g = 0.75: the exact phase the lobes are fitted to (as `splatfx-bench shadows`).
double cornetteShanks(double mu) {
    const double g = 0.75, g2 = g * g;
    return 3.0 / (8.0 * kPi) * (1.0 - g2) * (1.0 + mu * mu) / ((2.0 + g2) * std::pow(1.0 + g2 - 2.0 * g * mu, 1.5));
}
// The fits `splatfx-bench shadows` prints (docs/BENCHMARKS.md, "Knobs of the lighting").
std::vector<HgLobe> fittedLobes(int n) {
    switch (n) {
    case 1: return {{0.81f, 1.0f}};
    case 2: return {{0.82f, 0.992f}, {-0.54f, 0.008f}};
    case 3: return {{0.82f, 0.642f}, {-0.52f, 0.009f}, {0.83f, 0.350f}};
    default: return {{0.82f, 0.629f}, {-0.52f, 0.005f}, {0.83f, 0.362f}, {-0.51f, 0.004f}};
    }
}

// An 8x8x8 smooth blob of spacing 0.125 (the lighting tests' shape), one colour.
Grid blob() {
    Grid g = *Grid::box({8, 8, 8}, glm::vec3(0.125f));
    for (Voxel& v : g.voxels) {
        const glm::vec3 d = (glm::vec3(v.cell) - 3.5f) / 8.0f;
        v.opacity = 0.55f * std::exp(-glm::dot(d, d) / (2.0f * 0.22f * 0.22f));
    }
    return g;
}

struct Setting {
    std::string knob, setting;
    SelfShadow shadow = SelfShadow::Table;
    int tableN = 32, lobes = 2, samples = 1;
    bool eightBit = true;
    bool kernelTrace = false; // trace the reference's continuous field (VolumeFieldShadows), not the DensityField
};
struct Row {
    Setting s;
    double cpuMs = 0.0, rmse = 0.0, maxErr = 0.0;
    bool pareto = false;
};

std::vector<Setting> settings() {
    std::vector<Setting> v;
    const Setting d{.knob = "default", .setting = "table 32^3, 2 lobes, 1 sample, 8-bit"};
    v.push_back(d);
    auto add = [&](const char* knob, std::string name, auto edit) {
        Setting s = d;
        s.knob = knob, s.setting = std::move(name);
        edit(s);
        v.push_back(s);
    };
    add("self-shadow", "off", [](Setting& s) { s.shadow = SelfShadow::Off; });
    add("self-shadow", "traced", [](Setting& s) { s.shadow = SelfShadow::Traced; });
    add("self-shadow", "kernel field traced (bench-side)", [](Setting& s) { s.shadow = SelfShadow::Traced, s.kernelTrace = true; });
    for (int n : {8, 16, 64, 128}) add("self-shadow", "table " + std::to_string(n) + "^3", [n](Setting& s) { s.tableN = n; });
    for (int n : {1, 3, 4}) add("phase lobes", std::to_string(n), [n](Setting& s) { s.lobes = n; });
    for (int n : {2, 3}) add("samples per voxel", std::to_string(n * n * n) + " (bench-side)", [n](Setting& s) { s.samples = n; });
    add("lit-colour precision", "float", [](Setting& s) { s.eightBit = false; });
    return v;
}

double ms(std::clock_t a, std::clock_t b) { return 1000.0 * double(b - a) / CLOCKS_PER_SEC; }

// Writes the small case of tools/validate/lit_volume.py and the reference's pixels for it.
int writeValidation(const std::string& path) {
    Materials m{Footprint{}};
    const glm::vec4 base{0.9f, 0.7f, 0.5f, 1.0f};
    m.addColorTable(ColorTable::constant(base));
    Grid g = *Grid::box({2, 1, 1}, glm::vec3(0.3f));
    g.voxels[0].opacity = 0.6f, g.voxels[1].opacity = 0.35f;
    VolumeField f(m);
    f.add(g, {.textured = false});
    const glm::vec3 eye{0.35f, 0.25f, 1.6f}, target{0.15f, 0.0f, 0.0f};
    const float fovY = 0.5f, nearP = 0.1f;
    const glm::ivec2 vp{8, 6};
    const Camera cam = Camera::lookAt(eye, target, {0, 1, 0}, fovY, vp, nearP, 20.0f);
    LitVolumeDesc lit;
    lit.lights = {Light::point({-0.5f, 0.6f, 0.2f}, glm::vec3(1.0f), 0.5f)};
    const HgLobe lobe[] = {{.g = 0.5f, .weight = 1.0f}};
    lit.gas = {.phase = *PhaseFunction::create(lobe), .albedo = 0.8f};
    VolumeExactStats st;
    auto img = renderVolumeExact(f, cam, {.tolerance = 1e-9, .maxHalvings = 16, .threads = 1, .lighting = &lit}, &st);
    if (!img) return std::fprintf(stderr, "lighting: %s\n", img.error().c_str()), 1;
    std::ofstream o(path);
    o.precision(17);
    o << "# splatfx lit-volume validation case, version 1 (splatfx-bench lighting --validate)\n";
    o << "eye " << eye.x << ' ' << eye.y << ' ' << eye.z << "\ntarget " << target.x << ' ' << target.y << ' ' << target.z << "\nup 0 1 0\n";
    o << "fovY " << fovY << "\nviewport " << vp.x << ' ' << vp.y << "\nnear " << nearP << "\nspacing " << g.spacing.x << '\n';
    for (const Voxel& v : g.voxels) {
        const glm::vec3 c = g.worldPosition(v.cell);
        o << "voxel " << c.x << ' ' << c.y << ' ' << c.z << ' ' << v.opacity << '\n';
    }
    o << "color " << base.r << ' ' << base.g << ' ' << base.b << '\n';
    const Light& L = lit.lights[0];
    o << "pointlight " << L.position.x << ' ' << L.position.y << ' ' << L.position.z << ' ' << L.intensity << '\n';
    o << "hg " << lit.gas.phase.lobe(0).g << "\nalbedo " << lit.gas.albedo << '\n';
    o << "reference_error_estimate " << st.maxErrorEstimate << '\n';
    for (const glm::ivec2 p : {glm::ivec2{2, 2}, glm::ivec2{3, 3}, glm::ivec2{4, 2}, glm::ivec2{5, 3}, glm::ivec2{4, 4}})
        o << "pixel " << p.x << ' ' << p.y << ' ' << img->at(p.x, p.y, 0) << ' ' << img->at(p.x, p.y, 1) << ' ' << img->at(p.x, p.y, 2) << ' '
          << img->at(p.x, p.y, 3) << '\n';
    std::printf("lighting: wrote %s (reference error estimate %.1e, %llu unconverged pixels); check it with\n"
                "  python3 tools/validate/lit_volume.py %s\n",
                path.c_str(), st.maxErrorEstimate, (unsigned long long)st.unconverged, path.c_str());
    return 0;
}

} // namespace

int runLighting(int argc, char** argv) {
    std::string out = "lighting-bench", validate;
    int reps = 9;
    glm::ivec2 size{64, 48};
    bool noPlots = false;
    CLI::App app{"Every lighting knob (self-shadow by tracing or table 8^3..128^3, HG lobes, samples per voxel, 8-bit vs float lit colour)\n"
                 "against the lit volume reference (the model at every sample point, exact Cornette-Shanks phase, transmittance\n"
                 "through the continuous field): image error, CPU time of the lighting, vs default, Pareto; data, gnuplot script, PNG.",
                 "splatfx-bench lighting"};
    app.add_option("--out", out, "where lighting.csv, lighting.dat, lighting.gp and lighting_pareto.png go")->type_name("DIR")->capture_default_str();
    cli::addSize(app, "--size", size.x, size.y, 8, 512, "image size of the comparison");
    cli::addNumber(app, "--reps", reps, 1, 1000, "timed runs per setting, median reported");
    app.add_flag("--no-plots", noPlots, "print the table only");
    app.add_option("--validate", validate, "only write the small case for tools/validate/lit_volume.py to FILE")->type_name("FILE");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (!validate.empty()) return writeValidation(validate);

    Materials m{Footprint{}};
    const glm::vec4 base{0.85f, 0.8f, 0.75f, 1.0f};
    const ColorTable table = ColorTable::constant(base);
    m.addColorTable(table);
    const Grid grid = blob();
    glm::vec3 centre(0.0f);
    std::vector<glm::vec3> centres;
    for (const Voxel& v : grid.voxels) centres.push_back(grid.worldPosition(v.cell)), centre += centres.back() / float(grid.voxels.size());
    const Camera cam = Camera::lookAt(centre + glm::vec3(1.2f, 0.5f, 2.6f), centre, {0, 1, 0}, 0.5f, size, 0.1f, 20.0f);
    const glm::vec3 eye = cam.eye();
    const std::vector<Light> lights = {Light::directional({0.6f, -0.7f, -0.4f}, glm::vec3(1.0f), 1.4f)};
    const GasLightingDesc gasBase{.albedo = 0.9f, .ambient = glm::vec3(0.05f)};

    VolumeField field(m);
    field.add(grid, {.textured = false});
    LitVolumeDesc truth;
    truth.lights = lights;
    truth.gas = gasBase;
    truth.phase = cornetteShanks;
    std::printf("lighting: %zu voxels (8^3 blob), %dx%d; the reference (the model at every sample point, Cornette-Shanks g = 0.75)...\n",
                grid.voxels.size(), size.x, size.y);
    VolumeExactStats refStats;
    const std::clock_t r0 = std::clock();
    auto ref = renderVolumeExact(field, cam, {.tolerance = 1e-5, .lighting = &truth}, &refStats);
    if (!ref) return std::fprintf(stderr, "lighting: %s\n", ref.error().c_str()), 1;
    std::printf("  done in %.1f s CPU, error estimate %.1e, %llu unconverged pixels\n", ms(r0, std::clock()) / 1000.0, refStats.maxErrorEstimate,
                (unsigned long long)refStats.unconverged);

    std::vector<Row> rows;
    for (const Setting& s : settings()) {
        GasLightingDesc gas = gasBase;
        const std::vector<HgLobe> lobes = fittedLobes(s.lobes);
        gas.phase = *PhaseFunction::create(lobes);
        // Samples per voxel: the factor averaged over n^3 points spread over the voxel's cell.
        std::vector<glm::vec3> points;
        const int n = s.samples;
        for (const glm::vec3& c : centres)
            for (int k = 0; k < n * n * n; ++k) {
                const glm::vec3 o = (glm::vec3(k % n, (k / n) % n, k / (n * n)) + 0.5f) / float(n) - 0.5f;
                points.push_back(c + o * grid.spacing);
            }
        std::vector<glm::vec3> factors, colours(centres.size());
        std::vector<double> times;
        for (int r = 0; r < reps; ++r) {
            const std::clock_t a = std::clock();
            auto density = DensityField::fromGrid(grid);
            if (!density) return std::fprintf(stderr, "lighting: %s\n", density.error().c_str()), 1;
            ShadowTracer tracer(*density, lights);
            ShadowTables tables({.dims = glm::ivec3(s.tableN)});
            const ShadowProvider* shadows = nullptr;
            VolumeField kernels(m);
            if (s.kernelTrace) kernels.add(grid, {.textured = false});
            const VolumeFieldShadows kernelTracer(kernels, lights);
            if (s.shadow == SelfShadow::Traced) shadows = s.kernelTrace ? static_cast<const ShadowProvider*>(&kernelTracer) : &tracer;
            if (s.shadow == SelfShadow::Table) {
                if (Status st = tables.update(*density, lights); !st) return std::fprintf(stderr, "lighting: %s\n", st.error().c_str()), 1;
                shadows = &tables;
            }
            if (Status st = lightPoints(points, grid.spacing.x, eye, lights, shadows, gas, factors); !st)
                return std::fprintf(stderr, "lighting: %s\n", st.error().c_str()), 1;
            for (std::size_t i = 0; i < centres.size(); ++i) {
                glm::vec3 sum(0.0f);
                for (int k = 0; k < n * n * n; ++k) sum += factors[i * std::size_t(n * n * n) + std::size_t(k)];
                colours[i] = glm::vec3(base) * sum / float(n * n * n);
            }
            times.push_back(ms(a, std::clock()));
        }
        if (s.eightBit) // as Scene packs it (scene_lighting.cpp): hue kept above 1, then round(c 255) / 255
            for (glm::vec3& c : colours) {
                const float mx = std::max({c.r, c.g, c.b});
                if (mx > 1.0f) c /= mx;
                for (int a = 0; a < 3; ++a) c[a] = std::floor(std::clamp(c[a], 0.0f, 1.0f) * 255.0f + 0.5f) / 255.0f;
            }
        VolumeField lit(m);
        lit.add(grid, {.textured = false}, colours);
        auto img = renderVolumeExact(lit, cam, {.tolerance = 1e-5});
        if (!img) return std::fprintf(stderr, "lighting: %s\n", img.error().c_str()), 1;
        Row row{.s = s};
        double se = 0.0;
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x)
                for (int c = 0; c < 3; ++c) {
                    const double e = double(img->at(x, y, c)) - double(ref->at(x, y, c));
                    se += e * e;
                    row.maxErr = std::max(row.maxErr, std::abs(e));
                }
        row.rmse = std::sqrt(se / (3.0 * size.x * size.y));
        std::sort(times.begin(), times.end());
        row.cpuMs = times[times.size() / 2];
        rows.push_back(row);
        std::printf("  %-22s %-40s %.3f ms\n", s.knob.c_str(), s.setting.c_str(), row.cpuMs);
    }
    for (Row& r : rows) {
        r.pareto = true;
        for (const Row& o : rows)
            if (&o != &r && o.cpuMs <= r.cpuMs && o.rmse <= r.rmse && (o.cpuMs < r.cpuMs || o.rmse < r.rmse)) r.pareto = false;
    }
    const double defMs = rows[0].cpuMs;
    std::printf("\n%zu voxels, %dx%d, reference error estimate %.1e; errors in 1/255 of the image (RGB), CPU ms of the lighting per frame "
                "(median of %d)\n\n",
                grid.voxels.size(), size.x, size.y, refStats.maxErrorEstimate, reps);
    std::printf("| knob | setting | CPU ms | vs default | RMSE (1/255) | max error (1/255) | Pareto |\n|---|---|---|---|---|---|---|\n");
    for (const Row& r : rows)
        std::printf("| %s | %s | %.3f | %.2fx | %.3f | %.3f | %s |\n", r.s.knob.c_str(), r.s.setting.c_str(), r.cpuMs, r.cpuMs / defMs,
                    255.0 * r.rmse, 255.0 * r.maxErr, r.pareto ? "yes" : "");

    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    {
        std::ofstream csv(out + "/lighting.csv");
        csv << "knob,setting,cpu_ms,rmse_255,max_error_255,pareto\n";
        for (const Row& r : rows)
            csv << r.s.knob << ',' << r.s.setting << ',' << r.cpuMs << ',' << 255.0 * r.rmse << ',' << 255.0 * r.maxErr << ',' << (r.pareto ? 1 : 0) << '\n';
        std::ofstream d(out + "/lighting.dat");
        d << "# all settings: cpu_ms rmse(1/255) label\n";
        for (const Row& r : rows) d << r.cpuMs << ' ' << 255.0 * r.rmse << " \"" << r.s.knob << ": " << r.s.setting << "\"\n";
        d << "\n\n# pareto front\n";
        std::vector<Row> front;
        for (const Row& r : rows)
            if (r.pareto) front.push_back(r);
        std::sort(front.begin(), front.end(), [](const Row& a, const Row& b) { return a.cpuMs < b.cpuMs; });
        for (const Row& r : front) d << r.cpuMs << ' ' << 255.0 * r.rmse << " \"" << r.s.knob << ": " << r.s.setting << "\"\n";
        std::ofstream gp(out + "/lighting.gp");
        gp << "# Written by splatfx-bench lighting; run: gnuplot lighting.gp\n"
           << "set terminal pngcairo size 1000,680 font 'sans,9'\nset output 'lighting_pareto.png'\n"
           << "set title 'Lighting knobs against the lit volume reference (" << size.x << "x" << size.y << ")'\n"
           << "set logscale xy\nset grid\nset xlabel 'CPU time of the lighting per frame (ms, median)'\nset ylabel 'RMSE vs reference (1/255)'\n"
           << "set key top right\n"
           << "plot 'lighting.dat' index 0 using 1:2 with points pt 6 lc rgb '#7f8c8d' title 'setting', "
           << "'' index 0 using 1:2:3 with labels left offset 0.6,0.4 font 'sans,7' notitle, "
           << "'' index 1 using 1:2 with linespoints pt 7 lw 2 lc rgb '#c0392b' title 'Pareto front'\n";
    }
    if (!noPlots) {
        const cli::SpawnResult gp = cli::spawn({.argv = {"gnuplot", "lighting.gp"}, .workingDir = out});
        if (!gp.started || gp.exitCode != 0)
            std::fprintf(stderr, "lighting: gnuplot failed on %s/lighting.gp (install gnuplot-nox or pass --no-plots)\n", out.c_str());
        else
            std::printf("\nwrote %s/lighting_pareto.png (data: lighting.dat, lighting.csv; script: lighting.gp)\n", out.c_str());
    }
    return 0;
}
} // namespace lighting_cmd

int runLighting(int argc, char** argv) { return lighting_cmd::runLighting(argc, argv); }
