// splatfx-bench emitted: a campfire as light for the host (issue 27 item 3).
// The point lights fitted to its emission (fitEmittedLights, 1 to 8, the
// volume's own occlusion on and off) against the exact irradiance its splats
// give (reference::emittedIrradianceExact, occlusion along every ray) at
// points around it: the ground at 0.5 to 1.5 m, a wall 1 to 3 m away, and a
// point inside the flame. Each receiver sees the splats built by a camera
// at it (billboards facing it), over a few frames of the texture cycling.
// Time: fitEmittedLights per frame (CPU, median), also for the same flame at
// 8 and 27 times the voxels. Separately, what
// splatfx_emittedIrradiance costs per shaded pixel: a full-screen host pass
// with a Lambert sun, with and without the emitted lights, glFinish, median.
// --validate FILE writes the small case tools/validate/emitted_irradiance.py checks.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>

#include "bench_stats.hpp"
#include "commands.hpp"
#include "knob_table.hpp"
#include "options.hpp"
#include "splatfx/context.hpp"
#include "splatfx/dynamics.hpp"
#include "splatfx/emitted_light.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene_file.hpp"
#include "splatfx/shapes.hpp"
#include "splatfx/splats.hpp"

namespace emitted_cmd { // one namespace per command: the commands build as one unity translation unit

using namespace splatfx;

namespace {

using Clock = std::chrono::steady_clock;
double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

constexpr std::uint32_t kSeed = 27;

// The campfire sample's 7x20x5 flame at 0.1 m spacing (0.6 x 1.9 x 0.4 m),
// its base centred on the origin; voxels cycle the turbulence textures from
// hashed starts, `frame` steps along.
Grid campfire(std::uint32_t frame) {
    Grid g = *Grid::box({7, 20, 5}, glm::vec3(0.1f));
    for (Voxel& v : g.voxels) {
        v.opacity = 0.55f * flameOpacity(v.cell, g.dims);
        v.colorCoord = float(v.cell.y) / 19.0f;
        v.texture = hashCell(v.cell, kSeed, 7) + frame;
    }
    const glm::vec3 lo = g.worldPosition({0, 0, 0}), hi = g.worldPosition(g.dims - 1);
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-0.5f * (lo.x + hi.x), -lo.y, -0.5f * (lo.z + hi.z)));
    return g;
}

struct Receiver {
    const char* group;
    glm::vec3 point, normal;
};

std::vector<Receiver> receivers() {
    std::vector<Receiver> r;
    for (float radius : {0.5f, 1.0f, 1.5f})
        for (int k = 0; k < 4; ++k) {
            const float a = 0.4f + 1.5707963f * float(k);
            r.push_back({"ground", {radius * std::cos(a), 0.0f, radius * std::sin(a)}, {0, 1, 0}});
        }
    for (float x : {1.0f, 2.0f, 3.0f})
        for (float y : {0.3f, 1.0f}) r.push_back({"wall", {x, y, 0.2f}, {-1, 0, 0}});
    // Far: the ground and a wall 5 and 8 m away.
    for (float d : {5.0f, 8.0f}) {
        r.push_back({"far", {0.3f * d, 0.0f, 0.95f * d}, {0, 1, 0}});
        r.push_back({"far", {-d, 1.0f, 0.3f}, {1, 0, 0}});
    }
    r.push_back({"inside", {0.0f, 0.5f, 0.0f}, {0, 1, 0}});
    r.push_back({"inside", {0.0f, 1.1f, 0.05f}, {1, 0, 0}});
    r.push_back({"inside", {0.1f, 0.3f, 0.0f}, {0, 0, 1}});
    return r;
}

std::vector<Splat> splatsSeenFrom(const Grid& g, const Materials& m, std::uint32_t set, glm::vec3 eye) {
    SplatBuilder b(SplatBuilderDesc{.frustumCull = false});
    const glm::vec3 target(0.0f, 0.8f, 0.0f);
    const glm::vec3 up = std::abs(glm::normalize(target - eye).y) > 0.95f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    b.begin(Camera::lookAt(eye, target, up, 1.2f, {64, 64}, 1e-3f, 100.0f));
    b.add(g, m, {.textureSet = set, .colorTable = 0, .textured = true});
    return b.splats();
}

double sum3(glm::dvec3 v) { return v.x + v.y + v.z; }

// The error table's receiver groups, in its column order.
int groupOf(const Receiver& r) {
    const std::string g = r.group;
    return g == "ground" ? 0 : g == "wall" ? 1 : g == "far" ? 2 : 3;
}

// The campfire at `k` times the voxels along each axis (spacing / k: the same
// flame), as the view builds it: the fit's cost against the emitter's size.
std::vector<Splat> finerCampfire(int k, const Materials& m, std::uint32_t set, glm::vec3 eye) {
    Grid g = *Grid::box({7 * k, 20 * k, 5 * k}, glm::vec3(0.1f / float(k)));
    for (Voxel& v : g.voxels) {
        v.opacity = 0.55f * flameOpacity(v.cell, g.dims);
        v.colorCoord = float(v.cell.y) / float(g.dims.y - 1);
        v.texture = hashCell(v.cell, kSeed, 7);
    }
    const glm::vec3 lo = g.worldPosition({0, 0, 0}), hi = g.worldPosition(g.dims - 1);
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-0.5f * (lo.x + hi.x), -lo.y, -0.5f * (lo.z + hi.z)));
    return splatsSeenFrom(g, m, set, eye);
}

// The validation case: two plain splats of a truncated Gaussian kernel, the
// second partly behind the first, and three receivers.
int writeValidation(const std::string& path) {
    const FootprintDesc fd{.kernel = Kernel::Gaussian, .gaussianSigma = 0.7f, .gaussianRadius = 2.0f};
    Materials m{Footprint(fd)};
    const std::uint32_t rowA = m.addColorTable(ColorTable::constant({1.0f, 0.5f, 0.25f, 1.0f}));
    const std::uint32_t rowB = m.addColorTable(ColorTable::constant({0.2f, 0.6f, 1.0f, 1.0f}));
    auto splat = [](glm::vec3 c, glm::vec3 toward, float a, float density, std::uint32_t row) {
        const glm::vec3 w = glm::normalize(toward - c);
        const glm::vec3 u = glm::normalize(glm::cross(glm::vec3(0, 1, 0), w)), v = glm::cross(w, u);
        Splat s;
        s.center = c, s.axisU = u * a, s.axisV = v * a, s.density = density, s.colorRow = float(row), s.colorCoord = 0.5f;
        return s;
    };
    const glm::vec3 eye(0.0f, 0.1f, 0.0f);
    const std::vector<Splat> splats{splat({0.05f, 0.0f, -1.5f}, eye, 0.3f, 1.2f, rowA), splat({0.25f, 0.1f, -2.2f}, eye, 0.4f, 0.8f, rowB)};
    const Receiver points[] = {{"", eye, {0.0f, 0.0f, -1.0f}}, {"", {0.6f, -0.3f, 0.4f}, {-0.3f, 0.2f, -1.0f}}, {"", {-0.8f, 0.5f, -1.0f}, {0.6f, -0.2f, -0.7f}}};
    std::ofstream o(path);
    if (!o) return std::fprintf(stderr, "emitted: cannot write %s\n", path.c_str()), 1;
    o.precision(9);
    o << "# splatfx emitted-irradiance validation case, version 1 (splatfx-bench emitted --validate)\n"
      << "# kernel sigma radius (kernel units; truncated Gaussian)\n"
      << "kernel " << fd.gaussianSigma << " " << fd.gaussianRadius << "\n"
      << "# splat cx cy cz Ux Uy Uz Vx Vy Vz density r g b\n";
    for (const Splat& s : splats) {
        const glm::vec3 c = glm::vec3(m.colorRow(std::uint32_t(s.colorRow))[128]);
        o << "splat " << s.center.x << " " << s.center.y << " " << s.center.z << " " << s.axisU.x << " " << s.axisU.y << " " << s.axisU.z << " "
          << s.axisV.x << " " << s.axisV.y << " " << s.axisV.z << " " << s.density << " " << c.r << " " << c.g << " " << c.b << "\n";
    }
    o << "# point px py pz nx ny nz E_r E_g E_b errorEstimate (the reference, faceSize 512)\n";
    for (const Receiver& r : points) {
        // The reference takes the points and normals in double; write what it gets.
        auto e = emittedIrradianceExact(splats, m, glm::dvec3(r.point), glm::dvec3(r.normal), {.faceSize = 512});
        if (!e) return std::fprintf(stderr, "emitted: %s\n", e.error().c_str()), 1;
        o << "point " << r.point.x << " " << r.point.y << " " << r.point.z << " " << r.normal.x << " " << r.normal.y << " " << r.normal.z << " "
          << e->irradiance.x << " " << e->irradiance.y << " " << e->irradiance.z << " " << e->errorEstimate << "\n";
    }
    std::printf("wrote %s; check it with\n  python3 tools/validate/emitted_irradiance.py %s\n", path.c_str(), path.c_str());
    return 0;
}

// Sample 29's fire over `frames` frames at its fps: the exact irradiance at a
// point of the cabin wall against the Scene's fitted lights (the sample's own
// emitsLight) and the default grid fitted to the same splats. Prints the
// flicker (RMS relative deviation from the mean, the largest and smallest)
// of each and how the fit follows the exact frame by frame.
int flicker(const std::string& path, int frames, int faceSize) {
    Materials m{Footprint{}};
    auto file = loadSceneFile(path, m);
    if (!file) return std::fprintf(stderr, "emitted: %s\n", file.error().c_str()), 1;
    const glm::vec3 wall(-1.5f, 1.2f, -3.25f), normal(0.0f, 0.0f, 1.0f); // the cabin's front, left of the door
    const Camera camera = Camera::lookAt(wall, glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0, 1, 0), 2.0f, {64, 64}, 1e-3f, 100.0f);
    SplatBuilder builder(SplatBuilderDesc{.frustumCull = false});
    std::vector<double> exact, fitted, gridded;
    const auto t0 = Clock::now();
    double worstEstimate = 0.0;
    for (int f = 0; f < frames; ++f) {
        const double t = double(f) / double(std::max(file->output.fps, 1.0f));
        if (Status st = file->scene.update(t, camera); !st) return std::fprintf(stderr, "emitted: %s\n", st.error().c_str()), 1;
        builder.begin(camera);
        file->scene.emit(builder, m);
        if (!file->scene.lightingError().empty()) return std::fprintf(stderr, "emitted: %s\n", file->scene.lightingError().c_str()), 1;
        auto e = emittedIrradianceExact(builder.splats(), m, glm::dvec3(wall), glm::dvec3(normal), {.faceSize = faceSize});
        if (!e) return std::fprintf(stderr, "emitted: %s\n", e.error().c_str()), 1;
        exact.push_back(sum3(e->irradiance));
        worstEstimate = std::max(worstEstimate, e->errorEstimate / sum3(e->irradiance));
        const std::vector<EmittedLight> lights(file->scene.emittedLights().begin(), file->scene.emittedLights().end());
        fitted.push_back(sum3(glm::dvec3(emittedIrradiance(lights, wall, normal))));
        EmittedLightDesc gd = file->scene.options(file->effects.at(0).id).emitsLight;
        gd.mode = EmittedLightMode::Grid;
        auto g = fitEmittedGrid(builder.splats(), m, gd);
        if (!g) return std::fprintf(stderr, "emitted: %s\n", g.error().c_str()), 1;
        gridded.push_back(sum3(glm::dvec3(emittedIrradiance(*g, wall, normal))));
    }
    auto stats = [&](const std::vector<double>& v, const char* name) {
        double mean = 0.0, sq = 0.0, lo = 1e300, hi = -1e300, follow = 0.0;
        for (double x : v) mean += x / double(v.size());
        for (std::size_t i = 0; i < v.size(); ++i) {
            sq += (v[i] / mean - 1.0) * (v[i] / mean - 1.0), lo = std::min(lo, v[i] / mean), hi = std::max(hi, v[i] / mean);
            double em = 0.0;
            for (double x : exact) em += x / double(exact.size());
            // How far the fit's frame-to-frame change is from the exact's (both relative to their means).
            follow += (v[i] / mean - exact[i] / em) * (v[i] / mean - exact[i] / em);
        }
        std::printf("| %s | %.4g | %.4f | %.4f | %.4f | %.4f |\n", name, mean, std::sqrt(sq / double(v.size())), lo, hi,
                    std::sqrt(follow / double(v.size())));
    };
    std::printf("\nFlicker: sample 29's fire (%s), %d frames at %d fps, the irradiance (channel sum) on the cabin wall at (%.2f, %.2f, %.2f);\n"
                "the exact at %d^2-pixel faces took %.1f s (largest relative error estimate %.4f). Flicker: RMS of E / mean(E) - 1; range: its\n"
                "smallest and largest E / mean(E); vs exact: RMS over frames of (E / mean(E) - E_exact / mean(E_exact)).\n\n"
                "| irradiance | mean | flicker RMS | min / mean | max / mean | vs exact |\n| --- | ---: | ---: | ---: | ---: | ---: |\n",
                path.c_str(), frames, int(file->output.fps), double(wall.x), double(wall.y), double(wall.z), faceSize, ms(t0, Clock::now()) / 1e3,
                worstEstimate);
    stats(exact, "exact (emittedIrradianceExact)");
    stats(fitted, "fitted lights (the sample's emitsLight)");
    stats(gridded, "grid (the default 3x3x3)");
    return 0;
}

// A full-screen host pass: a ground point per pixel, a Lambert sun, and
// (withEmitted) splatfx_emittedIrradiance added.
const char* kVertex = R"(#version 450 core
void main() { gl_Position = vec4((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0, 0.0, 1.0); }
)";
const char* kHost = R"(
uniform vec2 uSize;
out vec4 fragColor;
void main() {
    vec2 f = gl_FragCoord.xy / uSize;
    vec3 p = vec3(-4.0 + 8.0 * f.x, 0.0, -3.0 + 6.0 * f.y);
    vec3 n = normalize(vec3(0.1 * sin(9.0 * f.x), 1.0, 0.1 * cos(7.0 * f.y)));
    vec3 albedo = vec3(0.5, 0.45, 0.4);
    vec3 light = vec3(0.05) + vec3(0.3) * max(dot(n, normalize(vec3(0.3, 1.0, 0.2))), 0.0);
#ifdef WITH_EMITTED
    light += splatfx_emittedIrradiance(p, n);
#endif
#ifdef WITH_GRID
    light += splatfx_emittedGridIrradiance(p, n);
#endif
    fragColor = vec4(albedo * light, 1.0);
}
)";

} // namespace

int runEmitted(int argc, char** argv) {
    std::string out = "bench-emitted", validate;
    int reps = 21, frames = 2, faceSize = 128, width = 1024, height = 768;
    bool noPlots = false;
    std::string scenePath = "samples/29-night-campfire/scene.json";
    int flickerFrames = 40, flickerFaceSize = 64;
    CLI::App app{"A campfire as light for the host: fitted point lights (1..8, occlusion on/off) against the exact irradiance of its\n"
                 "emission on the ground, a wall and inside the flame; fit ms per frame; splatfx_emittedIrradiance's cost per pixel.",
                 "splatfx-bench emitted"};
    cli::addNumber(app, "--reps", reps, 1, 1000, "timed fits (and GL passes) per setting, median reported");
    cli::addNumber(app, "--frames", frames, 1, 64, "frames of the texture cycling the error is averaged over");
    cli::addNumber(app, "--face-size", faceSize, 8, 1024, "the reference's cube-face pixels per side");
    cli::addNumber(app, "--width", width, 16, 4096, "host pass width");
    cli::addNumber(app, "--height", height, 16, 4096, "host pass height");
    app.add_option("--out", out, "where emitted.dat, emitted.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    app.add_option("--validate", validate, "only write the small case for tools/validate/emitted_irradiance.py to FILE")->type_name("FILE");
    app.add_flag("--no-plots", noPlots, "print the tables only");
    app.add_option("--flicker-scene", scenePath, "the night campfire whose wall flicker is measured")->type_name("FILE")->capture_default_str();
    cli::addNumber(app, "--flicker-frames", flickerFrames, 0, 400, "frames of the flicker measurement (0: skip it)");
    cli::addNumber(app, "--flicker-face-size", flickerFaceSize, 8, 1024, "the flicker reference's cube-face pixels per side");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (!validate.empty()) return writeValidation(validate);

    Materials m{Footprint{}};
    const std::uint32_t set = m.addTextureSet(TextureSet::turbulence({.count = 8, .size = 32, .seed = kSeed, .contrast = 2.5f}));
    m.addColorTable(ColorTable::fire());
    const std::vector<Receiver> rec = receivers();
    const glm::vec3 viewEye(0.0f, 1.2f, 4.0f);

    // The truth per frame and receiver, and each frame's splats as the view builds them (what a Scene fits).
    std::vector<std::vector<double>> truth(static_cast<std::size_t>(frames));
    std::vector<std::vector<Splat>> viewSplats(static_cast<std::size_t>(frames));
    double worstEstimate = 0.0;
    const auto t0 = Clock::now();
    for (int f = 0; f < frames; ++f) {
        const Grid g = campfire(std::uint32_t(3 * f));
        viewSplats[std::size_t(f)] = splatsSeenFrom(g, m, set, viewEye);
        for (const Receiver& r : rec) {
            auto e = emittedIrradianceExact(splatsSeenFrom(g, m, set, r.point), m, glm::dvec3(r.point), glm::dvec3(r.normal), {.faceSize = faceSize});
            if (!e) return std::fprintf(stderr, "emitted: %s\n", e.error().c_str()), 1;
            truth[std::size_t(f)].push_back(sum3(e->irradiance));
            worstEstimate = std::max(worstEstimate, 3.0 * e->errorEstimate / sum3(e->irradiance));
        }
    }
    std::printf("emitted: %zu splats, %zu receivers x %d frames; the exact irradiance took %.1f s (largest relative error estimate %.4f)\n",
                viewSplats[0].size(), rec.size(), frames, ms(t0, Clock::now()) / 1e3, worstEstimate);

    std::vector<bench::KnobRow> rows;
    const EmittedLightDesc defaults{};
    // One row: `irradiance(frame)` gives a function of (point, normal) for that frame's fit.
    auto addRow = [&](const std::string& knob, const std::string& setting, bool isDefault, auto&& fitFrame) -> bool {
        double sq = 0.0, worst = 0.0, signedSum = 0.0;
        double group[4] = {0, 0, 0, 0};
        int groupN[4] = {0, 0, 0, 0}, n = 0, nOutside = 0;
        for (int f = 0; f < frames; ++f) {
            auto irradiance = fitFrame(std::size_t(f));
            if (!irradiance) return false;
            for (std::size_t i = 0; i < rec.size(); ++i) {
                const double t = truth[std::size_t(f)][i];
                const double rel = (sum3(glm::dvec3((*irradiance)(rec[i].point, rec[i].normal))) - t) / t;
                sq += rel * rel, ++n;
                worst = std::max(worst, std::abs(rel));
                const int k = groupOf(rec[i]);
                if (k != 3) signedSum += rel, ++nOutside;
                group[k] += rel * rel, ++groupN[k];
            }
        }
        std::vector<double> times;
        for (int k = 0; k < reps; ++k) {
            const auto a = Clock::now();
            auto irradiance = fitFrame(std::size_t(k % frames));
            times.push_back(ms(a, Clock::now()));
            if (!irradiance) return false;
        }
        char extra[160];
        std::snprintf(extra, sizeof extra, "%.3f | %.3f | %.3f | %.3f | %+.3f", std::sqrt(group[0] / groupN[0]), std::sqrt(group[1] / groupN[1]),
                      std::sqrt(group[2] / groupN[2]), std::sqrt(group[3] / groupN[3]), signedSum / nOutside);
        rows.push_back({.knob = knob,
                        .setting = setting,
                        .ms = bench::median(times),
                        .rmse = std::sqrt(sq / n),
                        .maxErr = worst,
                        .extra = extra,
                        .isDefault = isDefault});
        return true;
    };
    using Irradiance = std::function<glm::vec3(glm::vec3, glm::vec3)>;
    for (bool occlusion : {true, false})
        for (int lights : {1, 2, 4, 8}) {
            const EmittedLightDesc desc{.enabled = true, .lights = lights, .occlusion = occlusion};
            const bool ok =
                addRow(occlusion ? "lights, occlusion on" : "lights, occlusion off", std::to_string(lights) + (lights == 1 ? " light" : " lights"),
                       occlusion && lights == defaults.lights && defaults.mode == EmittedLightMode::PointLights,
                       [&](std::size_t f) -> std::optional<Irradiance> {
                           auto fit = fitEmittedLights(viewSplats[f], m, desc);
                           if (!fit) return std::fprintf(stderr, "emitted: %s\n", fit.error().c_str()), std::nullopt;
                           return Irradiance([l = std::move(*fit)](glm::vec3 p, glm::vec3 n) { return emittedIrradiance(l, p, n); });
                       });
            if (!ok) return 1;
        }
    struct GridSetting {
        glm::ivec3 dims;
        float margin;
        bool occlusion;
    };
    const GridSetting grids[] = {{{2, 2, 2}, 0.5f, true}, {{2, 3, 2}, 0.5f, true}, {{3, 3, 3}, 0.5f, true},
                                 {{2, 8, 2}, 0.5f, true}, {{3, 3, 3}, 1.0f, true}, {{3, 3, 3}, 0.5f, false}};
    for (const auto& [dims, margin, occlusion] : grids) {
        const EmittedLightDesc desc{.enabled = true, .mode = EmittedLightMode::Grid, .occlusion = occlusion, .gridDims = dims, .gridMargin = margin};
        char setting[64];
        std::snprintf(setting, sizeof setting, "%dx%dx%d, margin %.1f", dims.x, dims.y, dims.z, double(margin));
        const bool ok = addRow(occlusion ? "grid, occlusion on" : "grid, occlusion off", setting,
                               defaults.mode == EmittedLightMode::Grid && dims == defaults.gridDims && margin == defaults.gridMargin && occlusion,
                               [&](std::size_t f) -> std::optional<Irradiance> {
                                   auto fit = fitEmittedGrid(viewSplats[f], m, desc);
                                   if (!fit) return std::fprintf(stderr, "emitted: %s\n", fit.error().c_str()), std::nullopt;
                                   return Irradiance([g = std::move(*fit)](glm::vec3 p, glm::vec3 n) { return emittedIrradiance(g, p, n); });
                               });
        if (!ok) return 1;
    }
    bench::markPareto(rows);
    std::printf(
        "\nError: relative, of the irradiance (channel sum) against the exact one, RMS and largest over every receiver and frame;\n"
        "per group RMS; mean signed: the mean relative error outside the flame (below 0: the fit too dark). Time: fitEmittedLights / fitEmittedGrid\n"
        "on one frame's %zu splats.\n",
        viewSplats[0].size());
    bench::printTable(rows, "fit ms/frame", "ground RMS | wall RMS | far RMS | inside RMS | mean signed");

    // The fit's cost as the emitter grows (same flame, finer voxels).
    std::printf("\nThe fit's cost against the emitter's size (the same flame at finer spacing; 2 lights; the default grid), median of %d:\n\n"
                "| voxels | splats | occlusion on ms | occlusion off ms | grid 3x3x3 ms |\n| ---: | ---: | ---: | ---: | ---: |\n",
                reps);
    for (int k : {1, 2, 3}) {
        const std::vector<Splat> sp = finerCampfire(k, m, set, viewEye);
        double t[2];
        for (int o = 0; o < 2; ++o) {
            std::vector<double> times;
            for (int r = 0; r < reps; ++r) {
                const auto a = Clock::now();
                auto fit = fitEmittedLights(sp, m, {.enabled = true, .lights = 2, .occlusion = o == 0});
                times.push_back(ms(a, Clock::now()));
                if (!fit) return 1;
            }
            t[o] = bench::median(times);
        }
        std::vector<double> times;
        for (int r = 0; r < reps; ++r) {
            const auto a = Clock::now();
            auto fit = fitEmittedGrid(sp, m, {.enabled = true, .mode = EmittedLightMode::Grid});
            times.push_back(ms(a, Clock::now()));
            if (!fit) return 1;
        }
        std::printf("| %d | %zu | %.3f | %.3f | %.3f |\n", 700 * k * k * k, sp.size(), t[0], t[1], bench::median(times));
    }

    if (flickerFrames > 0)
        if (const int code = flicker(scenePath, flickerFrames, flickerFaceSize); code != 0) return code;

    // The GLSL's cost per shaded pixel.
    auto ctx = HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "emitted: %s\n", ctx.error().c_str()), 1;
    auto fb = gl::Framebuffer::create({.width = width, .height = height, .color = gl::Precision::U8});
    if (!fb) return std::fprintf(stderr, "emitted: %s\n", fb.error().c_str()), 1;
    const std::string include = shadowGlsl();
    auto plain = gl::linkProgram({kVertex}, {"#version 450 core\n", include.c_str(), kHost}, "host");
    auto lit = gl::linkProgram({kVertex}, {"#version 450 core\n#define WITH_EMITTED\n", include.c_str(), kHost}, "host+emitted");
    auto gridded = gl::linkProgram({kVertex}, {"#version 450 core\n#define WITH_GRID\n", include.c_str(), kHost}, "host+grid");
    if (!plain || !lit || !gridded)
        return std::fprintf(stderr, "emitted: %s\n", (!plain ? plain.error() : !lit ? lit.error() : gridded.error()).c_str()), 1;
    auto grid = fitEmittedGrid(viewSplats[0], m, {.enabled = true, .mode = EmittedLightMode::Grid});
    if (!grid) return 1;
    auto fit8 = fitEmittedLights(viewSplats[0], m, {.enabled = true, .lights = 8});
    if (!fit8) return 1;
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    constexpr int kDraws = 8; // full-screen passes per timed sample
    // One sample: kDraws full-screen passes of `prog` with the first `count` lights, glFinish.
    auto samplePass = [&](unsigned prog, int count) {
        gl::ShadowBinding b;
        if (count >= 0) b.emittedLights.assign(fit8->begin(), fit8->begin() + std::min<std::ptrdiff_t>(count, std::ptrdiff_t(fit8->size())));
        else b.emittedGrid = *grid;
        gl::setShadowUniforms(prog, b);
        glProgramUniform2f(prog, glGetUniformLocation(prog, "uSize"), float(width), float(height));
        glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
        glViewport(0, 0, width, height);
        glDisable(GL_BLEND);
        glDisable(GL_DEPTH_TEST);
        glUseProgram(prog);
        glBindVertexArray(vao);
        glFinish();
        const auto a = Clock::now();
        for (int d = 0; d < kDraws; ++d) glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
        glFinish();
        const double t = ms(a, Clock::now()) / kDraws;
        glBindVertexArray(0);
        glUseProgram(0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        return t;
    };
    // Interleaved (sample k of every setting before k + 1 of any), so the
    // machine's drift falls on all alike; the first round warms up.
    const int counts[] = {0, 1, 2, 4, 8, -1}; // -1: the grid
    std::vector<std::vector<double>> samples(6);
    for (int k = 0; k <= reps; ++k)
        for (int i = 0; i < 6; ++i) {
            const double t = samplePass(counts[i] == 0 ? *plain : counts[i] < 0 ? *gridded : *lit, counts[i]);
            if (k > 0) samples[std::size_t(i)].push_back(t);
        }
    const double base = bench::median(samples[0]);
    std::printf("\nThe host pass at %dx%d (a Lambert sun per pixel), %d passes per sample, median of %d, glFinish:\n\n"
                "| host pass | ms/pass | ns/pixel | vs without |\n| --- | ---: | ---: | ---: |\n| without emitted lights | %.3f | %.2f | 1.00x |\n",
                width, height, kDraws, reps, base, base * 1e6 / (double(width) * height));
    for (int i = 1; i < 5; ++i) {
        const double t = bench::median(samples[std::size_t(i)]);
        std::printf("| + splatfx_emittedIrradiance, %d light%s | %.3f | %.2f | %.2fx |\n", counts[i], counts[i] == 1 ? "" : "s", t,
                    t * 1e6 / (double(width) * height), t / base);
    }
    const double tg = bench::median(samples[5]);
    std::printf("| + splatfx_emittedGridIrradiance, 3x3x3 | %.3f | %.2f | %.2fx |\n", tg, tg * 1e6 / (double(width) * height), tg / base);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(*plain);
    glDeleteProgram(*lit);
    glDeleteProgram(*gridded);

    if (noPlots) return 0;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    bench::writePlot(rows, out, "emitted", "Fitted lights against the exact irradiance of a campfire", "fitEmittedLights ms per frame");
    return 0;
}
} // namespace emitted_cmd

int runEmitted(int argc, char** argv) { return emitted_cmd::runEmitted(argc, argv); }
