// splatfx-bench groundfog (issue 17, sec. 6): the LOD ground fog over the
// Jacksboro DEM (sample 22's terrain and fog) on a flight at constant speed:
// tetrahedra drawn against the full-resolution layer, ms per frame with LOD
// and full, the error of each LOD frame against the full layer's frame (GL,
// same camera), and the popping metric (largest and 99th-percentile per-pixel
// change between consecutive frames) with and without geomorphing, against
// the full layer's own frame-to-frame change.
//
// --knobs: every quality knob of the layer (LOD or full resolution, c, C,
// morphing, sorted or sort-free, grid resolution, frame resolution scale)
// against the layer's continuous field (renderGroundFogExact, not its
// tetrahedra), with time, "vs default" and the Pareto front; writes
// groundfog.dat, groundfog.gp and the PNG plots like `accuracy`.
// --validate-case: the reference's values for tools/validate/ground_fog.py's case.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "bench_gl.hpp"
#include "options.hpp"
#include "bench_stats.hpp"
#include "spawn.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/scene_file.hpp"
#include "splatfx/volume.hpp"

namespace groundfog_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using bench::percentile;
using Clock = std::chrono::steady_clock;
double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

struct Options {
    std::string dem = "samples/22-fog-jacksboro/data/jacksboro_dem.pgm";
    glm::ivec2 size{512, 384};
    int frames = 48;
    float stepWorld = 1.0f; // world units per frame along the flight
    float detailC = 1.0f;
    float minAccuracyC = 4.0f;
    std::string out;           // --out DIR: the last frame of each mode as PNG
    float densityDepth = 0.0f; // --affine DEPTH: GroundFogDesc::densityDepthWorld (0: the paper's model)
    glm::ivec2 probe{-1};      // --probe X Y: print the exact ray integral (integrateRay) of that pixel per frame and mode
    bool knobs = false;        // --knobs: the knob table against the exact field instead of the flight
    glm::ivec2 knobSize{192, 144};
    int reps = 9;
    std::string plotDir = "bench-groundfog";
    bool plots = true;
    bool validateCase = false;
};

// Sample 22's layer: spacing 1, heightScale 1228.78, position y -4.69, fog top 5.
splatfx::GroundFogDesc jacksboro(const splatfx::Image& img, bool lod, float minAccuracyC, float densityDepth, int every = 1) {
    splatfx::GroundFogDesc d;
    d.densityDepthWorld = densityDepth;
    // every > 1: a coarser grid over every `every`-th sample (the same extent where it divides).
    const int w = img.width, h = img.height;
    d.dims = {(w - 1) / every + 1, (h - 1) / every + 1};
    d.originWorld = splatfx::heightmapPoint(0, 0, w, h, 0.0f, 1.0f, 0.0f);
    d.spacingWorld = float(every);
    d.lod = lod;
    d.minAccuracyC = minAccuracyC;
    for (int j = 0; j < h; j += every)
        for (int i = 0; i < w; i += every) {
            d.terrainHeight.push_back(-4.69f + 1228.78f * img.at(i, j, 0));
            d.fogTop.push_back(5.0f);
        }
    return d;
}

// Sample 23's flight: from the south-west corner over the valleys at 20-30
// world units above the fog, at constant speed, looking ahead and down.
splatfx::Camera flight(int f, float step, glm::ivec2 size) {
    const glm::vec3 start(-110.0f, 30.0f, 80.0f), end(90.0f, 22.0f, -70.0f);
    const glm::vec3 dir = glm::normalize(end - start), eye = start + dir * (step * float(f));
    return splatfx::Camera::lookAt(eye, eye + dir * 60.0f + glm::vec3(0.0f, -18.0f, 0.0f), {0, 1, 0}, glm::radians(55.0f), size, 0.5f, 1000.0f);
}

} // namespace

namespace {

namespace fs = std::filesystem;

// tools/validate/ground_fog.py's case, through integrateGroundFogRay: the
// same tiny layer, transfer function and rays (the script prints its values).
int validateCase() {
    splatfx::GroundFogDesc d;
    d.dims = {3, 3};
    d.originWorld = {-1.0f, 0.0f, 0.5f};
    d.spacingWorld = 1.5f;
    d.terrainHeight = {0.0f, 0.4f, 1.1f, 0.2f, -0.3f, 0.6f, 0.9f, 0.1f, -0.2f};
    d.fogTop = {1.2f, 1.0f, 0.9f, 1.4f, 1.6f, 1.0f, 1.3f, 0.8f, 1.1f};
    d.density = 0.8f;
    auto tf = splatfx::TransferFunction::create(
        {{0.0f, {1.0f, 0.9f, 0.8f}, 0.0f}, {0.4f, {0.6f, 0.7f, 0.9f}, 1.2f}, {1.0f, {0.2f, 0.3f, 0.7f}, 2.0f}});
    if (!tf) return std::fprintf(stderr, "%s\n", tf.error().c_str()), 1;
    const glm::dvec3 rays[4][2] = {{{-2.0, 2.5, 0.0}, {1.0, -0.6, 0.7}},
                                   {{3.5, 0.8, 1.2}, {-1.0, 0.05, 0.3}},
                                   {{0.1, 3.0, 2.0}, {0.05, -1.0, 0.02}},
                                   {{-1.5, 0.7, 3.9}, {1.0, 0.0, -0.8}}};
    for (float depth : {0.0f, 2.5f}) {
        d.densityDepthWorld = depth;
        if (depth == 0.0f) std::printf("model: paper's scalar\n");
        else std::printf("model: affine scalar, densityDepthWorld %.1f\n", double(depth));
        for (int r = 0; r < 4; ++r) {
            splatfx::GroundFogRayStats rs;
            const glm::dvec4 c = splatfx::integrateGroundFogRay(d, *tf, rays[r][0], glm::normalize(rays[r][1]), 0.0, 10.0, 1e-12, 20, &rs);
            std::printf("  ray %d  RGBA %.7f %.7f %.7f %.7f  (error estimate %.1e)\n", r, c.r, c.g, c.b, c.a, rs.errorEstimate);
        }
    }
    return 0;
}

struct KnobRow {
    std::string knob, setting;
    bool lod = false;
    float detailC = 10.0f; // LodRefineDesc default
    float minC = 4.0f;     // GroundFogDesc default
    bool morph = true;
    bool sortFree = false;
    int every = 1;  // grid resolution: every n-th height sample
    int scale = 1;  // FrameRendererDesc::resolutionScale (tetrahedra reduced with it)
    double ms = 0.0, rmse = 0.0, maxErr = 0.0, drawn = 0.0;
    bool pareto = false;
    bool repeat = false; // the same setting as an earlier row (another knob's default): plotted once overall
};

void writeKnobPlots(const std::vector<KnobRow>& rows, const std::string& dir, glm::ivec2 size) {
    std::vector<std::string> knobs;
    for (const KnobRow& r : rows)
        if (std::find(knobs.begin(), knobs.end(), r.knob) == knobs.end()) knobs.push_back(r.knob);
    {
        std::ofstream d(dir + "/groundfog.dat");
        for (const std::string& k : knobs) {
            d << "# " << k << "\n";
            for (const KnobRow& r : rows)
                if (r.knob == k) d << r.ms << " " << r.rmse << " \"" << r.setting << "\"\n";
            d << "\n\n";
        }
        d << "# all settings\n";
        for (const KnobRow& r : rows)
            if (!r.repeat) d << r.ms << " " << r.rmse << " \"" << r.knob << ": " << r.setting << "\"\n";
        d << "\n\n# pareto front\n";
        std::vector<KnobRow> front;
        for (const KnobRow& r : rows)
            if (r.pareto && !r.repeat) front.push_back(r);
        std::sort(front.begin(), front.end(), [](const KnobRow& x, const KnobRow& y) { return x.ms < y.ms; });
        for (const KnobRow& r : front) d << r.ms << " " << r.rmse << " \"" << r.knob << ": " << r.setting << "\"\n";
    }
    std::ofstream gp(dir + "/groundfog.gp");
    const int cols = 3, rowsN = int(knobs.size() + cols - 1) / cols;
    gp << "# Written by splatfx-bench groundfog --knobs; run: gnuplot groundfog.gp\n"
       << "set terminal pngcairo size " << 420 * cols << "," << 330 * rowsN << " font 'sans,9'\n"
       << "set output 'groundfog_knobs.png'\n"
       << "set multiplot layout " << rowsN << "," << cols << " title 'splatfx ground fog: accuracy vs time per knob (GL vs the exact field, "
       << size.x << "x" << size.y << ")'\n"
       << "set logscale y\nset grid\nset xrange [0:*]\nset xlabel 'GL frame time (ms, median)'\nset ylabel 'RMSE vs the field'\nset key off\n"
       << "set offsets graph 0.12, graph 0.12, graph 0.1, graph 0.1\n";
    for (std::size_t k = 0; k < knobs.size(); ++k)
        gp << "set title '" << knobs[k] << "'\nplot 'groundfog.dat' index " << k << " using 1:2 with linespoints pt 7 lc rgb '#c0392b', "
           << "'' index " << k << " using 1:2:3 with labels offset 0,0.9 font 'sans,8'\n";
    gp << "unset multiplot\n"
       << "set terminal pngcairo size 900,640 font 'sans,10'\nset output 'groundfog_pareto.png'\nset key top right\nset autoscale x\n"
       << "set title 'Ground fog: all settings against the exact field, and their Pareto front'\n"
       << "plot 'groundfog.dat' index " << knobs.size() << " using 1:2 with points pt 6 lc rgb '#7f8c8d' title 'setting', "
       << "'' index " << knobs.size() + 1 << " using 1:2 with linespoints pt 7 lw 2 lc rgb '#c0392b' title 'Pareto front', "
       << "'' index " << knobs.size() + 1 << " using 1:2:3 with labels left offset 1,0 font 'sans,8' notitle\n";
}

// Every knob against the layer's continuous field, one camera (the flight's middle frame).
int runKnobs(const Options& o, const splatfx::Image& dem) {
    std::error_code ec;
    fs::create_directories(o.plotDir, ec);
    if (o.plots && !cli::spawn({.argv = {"gnuplot", "--version"}, .output = cli::ChildOutput::Discard}).started)
        return std::fprintf(stderr, "groundfog: gnuplot is not installed; install it (Debian: apt-get install gnuplot-nox) or pass --no-plots\n"), 1;
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "%s\n", ctx.error().c_str()), 1;
    auto tf = splatfx::makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, 0.5f);
    if (!tf) return std::fprintf(stderr, "%s\n", tf.error().c_str()), 1;
    const splatfx::Camera cam = flight(o.frames / 2, o.stepWorld, o.knobSize);
    splatfx::Materials materials{splatfx::Footprint{}};

    // The truth: the full-resolution layer's field (every sample), integrated per pixel.
    const splatfx::GroundFogDesc truthDesc = jacksboro(dem, false, o.minAccuracyC, o.densityDepth);
    splatfx::GroundFogExactStats es;
    const auto e0 = Clock::now();
    auto truth = splatfx::renderGroundFogExact(truthDesc, *tf, cam, {}, &es);
    const double exactMs = ms(Clock::now() - e0);
    if (!truth) return std::fprintf(stderr, "%s\n", truth.error().c_str()), 1;

    // Each knob varied from the defaults (GroundFogDesc, LodRefineDesc: full
    // resolution, sorted, every sample, scale 1; the LOD at c 10, C 4,
    // morphing), its default point repeated in its group (measured once).
    std::vector<KnobRow> rows;
    rows.push_back({"layer", "full resolution (default)"});
    rows.push_back({"layer", "LOD (c 10, C 4, morphing)", true});
    for (float c : {0.3f, 1.0f, 3.0f, 10.0f, 30.0f, 100.0f}) {
        char s[32];
        std::snprintf(s, sizeof s, "%g", double(c));
        rows.push_back({"detail c (LOD)", s, true, c});
    }
    for (float C : {2.0f, 4.0f, 8.0f, 16.0f}) rows.push_back({"minimum accuracy C (LOD)", std::to_string(int(C)), true, 10.0f, C});
    rows.push_back({"morphing (LOD)", "on", true});
    rows.push_back({"morphing (LOD)", "off", true, 10.0f, 4.0f, false});
    rows.push_back({"order", "sorted", false});
    rows.push_back({"order", "sort-free (eq. 10)", false, 10.0f, 4.0f, true, true});
    rows.push_back({"order (LOD)", "sorted", true});
    rows.push_back({"order (LOD)", "sort-free (eq. 10)", true, 10.0f, 4.0f, true, true});
    for (int every : {1, 2, 4})
        rows.push_back({"grid resolution", every == 1 ? "every sample" : "every " + std::to_string(every) + " samples", false, 10.0f, 4.0f, true, false, every});
    for (int scale : {1, 2, 4}) rows.push_back({"frame resolution scale", "1/" + std::to_string(scale), false, 10.0f, 4.0f, true, false, 1, scale});
    auto same = [](const KnobRow& a, const KnobRow& b) {
        return a.lod == b.lod && a.sortFree == b.sortFree && a.every == b.every && a.scale == b.scale &&
               (!a.lod || (a.detailC == b.detailC && a.minC == b.minC && a.morph == b.morph));
    };

    auto fb = splatfx::gl::Framebuffer::create({.width = o.knobSize.x, .height = o.knobSize.y, .color = splatfx::gl::Precision::F32});
    if (!fb) return std::fprintf(stderr, "%s\n", fb.error().c_str()), 1;
    std::vector<std::unique_ptr<splatfx::gl::FrameRenderer>> renderers;
    for (int scale : {1, 2, 4}) {
        auto fr = splatfx::gl::FrameRenderer::create({.resolutionScale = scale, .reduceTetrahedra = scale > 1});
        if (!fr) return std::fprintf(stderr, "%s\n", fr.error().c_str()), 1;
        renderers.push_back(std::make_unique<splatfx::gl::FrameRenderer>(std::move(*fr)));
    }
    // One scene per distinct setting, all alive, timed in rounds (every
    // setting once per round): a change in the machine's load hits them all
    // alike instead of whichever setting was running then.
    struct Live {
        std::size_t row;
        splatfx::Scene scene;
        splatfx::Frame frame;
        std::vector<double> ms;
    };
    std::vector<std::unique_ptr<Live>> live;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        KnobRow& r = rows[i];
        if (std::any_of(rows.begin(), rows.begin() + std::ptrdiff_t(i), [&](const KnobRow& q) { return same(q, r); })) {
            r.repeat = true;
            continue;
        }
        splatfx::GroundFogDesc d = jacksboro(dem, r.lod, r.minC, o.densityDepth, r.every);
        d.sortFree = r.sortFree;
        auto fog = splatfx::GroundFog::create(d);
        auto table = splatfx::PreIntegrationTable::create(*tf, {.scalarResolution = 32, .lengthResolution = 128, .maxLengthWorld = 12.0f});
        if (!fog || !table) return std::fprintf(stderr, "%s\n", fog ? table.error().c_str() : fog.error().c_str()), 1;
        auto l = std::make_unique<Live>();
        l->row = i;
        l->scene.add(std::move(*fog), *tf, std::move(*table), {.name = "fog", .refine = {.detailC = r.detailC, .morph = r.morph}});
        live.push_back(std::move(l));
    }
    auto draw = [&](Live& l) -> bool {
        const KnobRow& r = rows[l.row];
        splatfx::gl::FrameRenderer& fr = *renderers[r.scale == 4 ? 2 : std::size_t(r.scale - 1)];
        if (auto s = l.scene.prepare(1.0, cam, materials, l.frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), false;
        fr.render(l.frame, bench::clearedTarget(*fb, {0.0f, 0.0f, 0.0f, 0.0f}));
        glFinish();
        return true;
    };
    for (int f = -1; f < o.reps; ++f) // one warm-up round: shaders, table uploads
        for (auto& l : live) {
            const auto a = Clock::now();
            if (!draw(*l)) return 1;
            if (f >= 0) l->ms.push_back(ms(Clock::now() - a));
        }
    for (auto& l : live) {
        KnobRow& r = rows[l->row];
        if (!draw(*l)) return 1;
        r.ms = bench::median(l->ms);
        r.drawn = double(renderers[r.scale == 4 ? 2 : std::size_t(r.scale - 1)]->stats().tetrahedra.drawn);
        const splatfx::Image img = fb->read();
        double se = 0.0, mx = 0.0;
        for (std::size_t p = 0; p < img.pixels.size(); ++p) {
            const double e = double(img.pixels[p]) - double(truth->pixels[p]);
            se += e * e, mx = std::max(mx, std::abs(e));
        }
        r.rmse = std::sqrt(se / double(std::max<std::size_t>(img.pixels.size(), 1)));
        r.maxErr = mx;
    }
    for (KnobRow& r : rows)
        if (r.repeat)
            for (const KnobRow& q : rows)
                if (!q.repeat && same(q, r)) r.ms = q.ms, r.drawn = q.drawn, r.rmse = q.rmse, r.maxErr = q.maxErr;
    for (KnobRow& r : rows) {
        r.pareto = true;
        for (const KnobRow& q : rows)
            if (!same(q, r) && q.ms <= r.ms && q.rmse <= r.rmse && (q.ms < r.ms || q.rmse < r.rmse)) r.pareto = false;
    }
    const double defaultMs = rows.front().ms;
    std::printf("groundfog --knobs: Jacksboro DEM %dx%d, fog top 5, extinction 0.5, density %s; camera: the flight's frame %d; %dx%d RGBA32F over "
                "black, median of %d frames each, taken in rounds over all settings (prepare + render + glFinish); GL renderer: %s\n"
                "truth: renderGroundFogExact of the full-resolution field (%.0f ms, largest error estimate %.1e, %llu unconverged pixels); "
                "error over all RGBA values\n\n",
                dem.width, dem.height, o.densityDepth > 0.0f ? ("affine, depth " + std::to_string(o.densityDepth)).c_str() : "the paper's",
                o.frames / 2, o.knobSize.x, o.knobSize.y, o.reps, ctx->renderer().c_str(), exactMs, es.maxErrorEstimate,
                static_cast<unsigned long long>(es.unconverged));
    std::printf("| knob | setting | tetrahedra drawn | ms/frame | vs default | RMSE | max error | Pareto |\n| --- | --- | ---: | ---: | ---: | ---: | ---: | --- |\n");
    std::ofstream csv(o.plotDir + "/groundfog.csv");
    csv << "knob,setting,drawn,ms,rmse,max_error,pareto\n";
    for (const KnobRow& r : rows) {
        std::printf("| %s | %s | %.0f | %.1f | %.2fx | %.5f | %.4f | %s |\n", r.knob.c_str(), r.setting.c_str(), r.drawn, r.ms, r.ms / defaultMs, r.rmse,
                    r.maxErr, r.pareto ? "yes" : "");
        csv << '"' << r.knob << "\",\"" << r.setting << "\"," << r.drawn << ',' << r.ms << ',' << r.rmse << ',' << r.maxErr << ',' << (r.pareto ? 1 : 0)
            << '\n';
    }
    writeKnobPlots(rows, o.plotDir, o.knobSize);
    if (o.plots) {
        const cli::SpawnResult gp = cli::spawn({.argv = {"gnuplot", "groundfog.gp"}, .workingDir = o.plotDir});
        if (!gp.started || gp.exitCode != 0)
            return std::fprintf(stderr, "groundfog: gnuplot failed on %s/groundfog.gp%s%s\n", o.plotDir.c_str(), gp.started ? "" : ": ", gp.error.c_str()), 1;
        std::printf("\nwrote %s/groundfog_knobs.png and %s/groundfog_pareto.png (data: groundfog.dat, groundfog.csv, script: groundfog.gp)\n",
                    o.plotDir.c_str(), o.plotDir.c_str());
    }
    return 0;
}

} // namespace

int runGroundFog(int argc, char** argv) {
    Options o;
    CLI::App app{"LOD ground fog over the Jacksboro DEM (samples 22 and 23): tetrahedra vs full resolution, ms per frame, error vs\n"
                 "full resolution, popping with and without morphing, along a flight.",
                 "splatfx-bench groundfog"};
    app.add_option("--dem", o.dem, "the terrain, a PGM heightmap")->type_name("FILE.pgm")->capture_default_str();
    cli::addInts(app, "--size", &o.size.x, 2, 16, 8192, "frame size", "W H");
    cli::addNumber(app, "--frames", o.frames, 2, 100000, "frames of the flight");
    cli::addNumber(app, "--step", o.stepWorld, 1.0e-6f, 1.0e6f, "world units per frame along the flight");
    cli::addNumber(app, "--c", o.detailC, 0.0f, 1.0e6f, "detail knob c");
    cli::addNumber(app, "--C", o.minAccuracyC, 0.0f, 1.0e6f, "minimum accuracy C");
    app.add_option("--out", o.out, "write the last frame of each mode as PNG here")->type_name("DIR");
    cli::addNumber(app, "--affine", o.densityDepth, 0.0f, 1.0e6f, "GroundFogDesc::densityDepthWorld (0: the paper's model)");
    cli::addInts(app, "--probe", &o.probe.x, 2, 0, 8191, "print the exact ray integral of this pixel per frame and mode", "X Y");
    app.add_flag("--knobs", o.knobs, "instead of the flight: every knob against the exact field (table, data, gnuplot script, PNG)");
    cli::addInts(app, "--knob-size", &o.knobSize.x, 2, 16, 4096, "frame size of --knobs", "W H");
    cli::addNumber(app, "--reps", o.reps, 1, 1000, "timed frames per setting in --knobs (median)");
    app.add_option("--plot-dir", o.plotDir, "where --knobs writes groundfog.dat, .csv, .gp and the PNG plots")->type_name("DIR")->capture_default_str();
    bool noPlots = false;
    app.add_flag("--no-plots", noPlots, "--knobs without running gnuplot (data and script still written)");
    app.add_flag("--validate-case", o.validateCase, "print the reference's values for tools/validate/ground_fog.py's case and exit");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    o.plots = !noPlots;
    if (o.validateCase) return validateCase();
    auto img = splatfx::readImage(o.dem, splatfx::Alpha::Straight);
    if (!img) return std::fprintf(stderr, "%s\n", img.error().c_str()), 1;
    if (o.knobs) return runKnobs(o, *img);
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "%s\n", ctx.error().c_str()), 1;
    splatfx::Materials materials{splatfx::Footprint{}};

    // Two scenes (full, LOD), each with its own renderer; LOD with and without morphing by its refine desc.
    struct Layer {
        splatfx::Scene scene;
        std::unique_ptr<splatfx::gl::FrameRenderer> renderer;
        std::size_t bytes = 0;
        double buildMs = 0.0;
    };
    Layer layers[2];
    for (int k = 0; k < 2; ++k) {
        const auto t0 = Clock::now();
        auto fog = splatfx::GroundFog::create(jacksboro(*img, k == 1, o.minAccuracyC, o.densityDepth));
        layers[k].buildMs = ms(Clock::now() - t0);
        auto tf = splatfx::makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, 0.5f);
        if (!fog || !tf) return std::fprintf(stderr, "%s\n", fog ? tf.error().c_str() : fog.error().c_str()), 1;
        auto table = splatfx::PreIntegrationTable::create(*tf, {.scalarResolution = 32, .lengthResolution = 128, .maxLengthWorld = 12.0f});
        auto fr = splatfx::gl::FrameRenderer::create();
        if (!table || !fr) return std::fprintf(stderr, "table/renderer failed\n"), 1;
        layers[k].bytes = fog->memoryBytes();
        layers[k].scene.add(std::move(*fog), std::move(*tf), std::move(*table), {.name = "fog", .refine = {.detailC = o.detailC}});
        layers[k].renderer = std::make_unique<splatfx::gl::FrameRenderer>(std::move(*fr));
    }
    auto fb = splatfx::gl::Framebuffer::create({.width = o.size.x, .height = o.size.y, .color = splatfx::gl::Precision::F32});
    if (!fb) return std::fprintf(stderr, "%s\n", fb.error().c_str()), 1;

    struct Mode {
        const char* name;
        int layer;
        bool morph;
        std::vector<double> msFrame, msPrepare, drawn, change, rmse;
        splatfx::Image prev;
        double worst = -1.0; // the largest per-pixel change so far, its frame and pixel
        int worstFrame = -1, worstX = 0, worstY = 0;
    };
    Mode modes[3] = {{"full resolution", 0, true, {}, {}, {}, {}, {}, {}, {}},
                     {"LOD, morphing", 1, true, {}, {}, {}, {}, {}, {}, {}},
                     {"LOD, no morphing", 1, false, {}, {}, {}, {}, {}, {}, {}}};
    std::uint64_t full = 0;
    for (int f = -1; f < o.frames; ++f) { // one warm-up frame (shader compile, table upload)
        const splatfx::Camera cam = flight(std::max(f, 0), o.stepWorld, o.size);
        splatfx::Image fullImg;
        for (Mode& m : modes) {
            Layer& l = layers[m.layer];
            l.scene.options(0).refine = {.detailC = o.detailC, .morph = m.morph};
            splatfx::Frame frame;
            const auto a = Clock::now();
            if (auto s = l.scene.prepare(1.0 + f / 24.0, cam, materials, frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
            const auto b = Clock::now();
            l.renderer->render(frame, bench::clearedTarget(*fb, {0.0f, 0.0f, 0.0f, 0.0f}));
            glFinish();
            const auto c = Clock::now();
            if (f < 0) continue;
            if (!frame.volumes().empty()) full = frame.volumes()[0].lod.stats.fullResolution;
            m.msFrame.push_back(ms(c - a));
            m.msPrepare.push_back(ms(b - a));
            m.drawn.push_back(double(l.renderer->stats().tetrahedra.drawn));
            splatfx::Image im = fb->read();
            if (o.probe.x >= 0 && !frame.volumes().empty()) {
                // The pixel's centre ray (55° vertical field of view, as flight()).
                const double ty = std::tan(0.5 * double(glm::radians(55.0f)));
                const double px = (2.0 * (o.probe.x + 0.5) / o.size.x - 1.0) * ty * double(o.size.x) / double(o.size.y);
                const double py = (1.0 - 2.0 * (o.probe.y + 0.5) / o.size.y) * ty;
                const glm::dvec3 dir = glm::dvec3(cam.forward()) + px * glm::dvec3(cam.right()) + py * glm::dvec3(cam.up());
                auto tf = splatfx::makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, 0.5f);
                const glm::dvec4 exact = splatfx::integrateRay(frame.volumes()[0].lod.tets, *tf, glm::dvec3(cam.eye()), dir, 0.0, 1e4);
                const std::size_t q = (std::size_t(o.probe.y) * std::size_t(o.size.x) + std::size_t(o.probe.x)) * 4;
                std::printf("probe frame %d %-17s exact alpha %.4f  GL alpha %.4f\n", f, m.name, exact.a, double(im.pixels[q + 3]));
            }
            if (m.layer == 0) fullImg = im;
            else {
                double se = 0.0;
                for (std::size_t p = 0; p < im.pixels.size(); ++p) {
                    const double d = double(im.pixels[p]) - double(fullImg.pixels[p]);
                    se += d * d;
                }
                m.rmse.push_back(std::sqrt(se / double(std::max<std::size_t>(im.pixels.size(), 1))));
            }
            if (f > 0)
                for (std::size_t p = 0; p < im.pixels.size(); p += 4) {
                    double e = 0;
                    for (int k = 0; k < 4; ++k) e = std::max(e, double(std::abs(im.pixels[p + std::size_t(k)] - m.prev.pixels[p + std::size_t(k)])));
                    m.change.push_back(e);
                    if (e > m.worst) {
                        const int px = int(p / 4);
                        m.worst = e, m.worstFrame = f, m.worstX = px % o.size.x, m.worstY = px / o.size.x; // read() is top row first
                    }
                }
            if (!o.out.empty() && f == o.frames - 1) {
                const std::string name = o.out + "/groundfog-" + std::to_string(&m - modes) + ".png";
                if (auto st = splatfx::writeImage(name, im); !st) std::fprintf(stderr, "%s\n", st.error().c_str());
            }
            m.prev = std::move(im);
        }
    }
    auto mean = [](const std::vector<double>& v) {
        double s = 0;
        for (double x : v) s += x;
        return v.empty() ? 0.0 : s / double(v.size());
    };
    std::printf("groundfog: Jacksboro DEM %dx%d (%s), fog top 5, %d frames at %dx%d, %.2f world units per frame, c = %.2f, C = %.2f, "
                "density %s\n",
                img->width, img->height, o.dem.c_str(), o.frames, o.size.x, o.size.y, o.stepWorld, o.detailC, o.minAccuracyC,
                o.densityDepth > 0.0f ? ("affine, depth " + std::to_string(o.densityDepth)).c_str() : "the paper's (1 at the terrain, 0 at the top)");
    std::printf("full resolution: %llu tetrahedra; memory full %zu bytes (built %.1f ms), LOD %zu bytes (built %.1f ms)\n",
                static_cast<unsigned long long>(full), layers[0].bytes, layers[0].buildMs, layers[1].bytes, layers[1].buildMs);
    const double finestMax = percentile(modes[0].change, 1.0), finestP99 = percentile(modes[0].change, 0.99);
    for (const Mode& m : modes) {
        const double mx = percentile(m.change, 1.0), p99 = percentile(m.change, 0.99);
        std::printf("  %-17s drawn mean %8.0f (%6.1fx fewer)  frame ms median %7.1f (prepare %6.2f)  RMSE vs full mean %.5f max %.5f  "
                    "change max %.4f p99 %.4f (vs full: max %.2fx, p99 %.2fx)\n",
                    m.name, mean(m.drawn), double(full) / std::max(mean(m.drawn), 1.0), percentile(m.msFrame, 0.5), percentile(m.msPrepare, 0.5),
                    mean(m.rmse), m.rmse.empty() ? 0.0 : *std::max_element(m.rmse.begin(), m.rmse.end()), mx, p99, mx / std::max(finestMax, 1e-12),
                    p99 / std::max(finestP99, 1e-12));
        std::printf("  %-17s largest change between frames %d and %d at pixel (%d, %d) from the top left\n", "", m.worstFrame - 1, m.worstFrame,
                    m.worstX, m.worstY);
    }
    return 0;
}
} // namespace groundfog_cmd

int runGroundFog(int argc, char** argv) { return groundfog_cmd::runGroundFog(argc, argv); }
