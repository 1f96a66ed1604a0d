// splatfx-bench accuracy: for every knob that trades accuracy for speed, the
// error of the GL renderer (headless, as users run it) against the exact
// double-precision reference, and the time per frame (issue 5).
//
// One scene: the paper's 7x20x5 fire (Fig. 1) at 0.5 spacing over host
// geometry (a ground plane and a log in front of the fire's base, drawn with
// depth), seen by the campfire sample's camera. Each knob is varied from the
// shipping defaults with every other setting left at its default. The truth
// is splat-exact (reference.hpp) on the same splat model with textures at
// 128 texels; the kernel-radius knob is measured untextured against an
// untruncated (6 sigma) Gaussian, the texture-count knob on a frame whose
// voxels sit between textures, and the solver-substeps knob on a fluid
// simulation against 32 substeps. Separately it reports what splatting itself
// costs against volume-exact rendering, and the reference's own convergence.
// The fog knobs (issue 14; --fog-only runs just these) put the same fire and
// host in a Biri fog (benchFog) and measure against splat-exact with the fog
// integrated numerically along every ray: the host image's fog texture, the
// splats' fog per splat instead of per fragment, and dropping fog terms.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "bench_stats.hpp"
#include "options.hpp"
#include "spawn.hpp"
#include "commands.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/gl/scaled_renderer.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/solver.hpp"
#include "splatfx/splatfx.hpp"

namespace accuracy_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using bench::median;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using splatfx::gl::Precision;

double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }
// CPU time of the whole process (this thread, the driver's and llvmpipe's
// rasterizer threads): what a frame costs, unlike wall time barely moved by
// other processes competing for the cores.
double processCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

struct Options {
    std::string out = "bench-accuracy";
    glm::ivec2 size{320, 240};
    int reps = 11;
    bool replotOnly = false; // --replot: only run gnuplot on an existing DIR/accuracy.gp
    bool plots = true;
    bool fogOnly = false;    // --fog-only: only the fog knobs (issue 14) and their reference
    bool cloudsOnly = false; // --clouds-only: only the LOD clouds' knobs (issue 17, cloud_knobs.cpp)
};

// Texture slices: the truth set has kTruthCount textures along the noise loop
// at 128 texels; a set of K textures is every (kTruthCount / K)-th of them, so
// K textures are exactly K points of the same loop (same normalization).
constexpr int kTruthCount = 32;
constexpr int kTruthLayer = 128;
constexpr std::uint32_t kSeed = 1;

// The splats' variation in every setting and its truth (--paper-lattice:
// none): the presets' default, so the figures are those of what is drawn.
splatfx::SplatVariation gVariation = splatfx::SplatVariation::recommended(1);

struct Config {
    int tableSize = 256; // FootprintDesc::tableSize
    int layerSize = 32;  // MaterialsDesc::layerSize
    int count = 8;       // textures in the set
    Precision precision = Precision::U8;
    splatfx::SortMode sort = splatfx::SortMode::Exact;
    std::uint32_t buckets = 64;
    int scale = 1;
    bool textured = true;
    bool gaussian = false;
    float gaussianRadius = 2.0f;
    float footprintCut = splatfx::gl::RendererDesc{}.footprintCut;                // the SDK default
    bool octagons = splatfx::gl::RendererDesc{}.trimCorners;                      // the SDK default
    splatfx::gl::TextureSampling sampling = splatfx::gl::RendererDesc{}.sampling; // the SDK default
    int upsample = splatfx::gl::RendererDesc{}.upsample;
    // Fog knobs (issue 14): the bench fog's first `fogTerms` terms
    // (0: no fog), the host image's fog texture ({0, 0}: per pixel) and the
    // splats' fog once per splat instead of per fragment.
    int fogTerms = 0;
    glm::ivec2 fogTexture{0, 0};
    bool fogPerSplat = false;
};

// The bench fog: Biri et al.'s Fig. 6 formula (paperFig6Fog) with
// one paper unit = 4 world units (the fire is 10 units tall), thinned so the
// fog in front of the fire has an optical depth of about 0.5, with no wind
// (one still frame), far cut-off 60. Its terms in the paper's order: the constant,
// the three cosines, the product of two.
splatfx::FogDesc benchFog(int terms) {
    splatfx::FogDesc d = splatfx::paperFig6Fog();
    const double scale = 4.0, density = 0.15;
    for (splatfx::FogTerm& t : d.terms) {
        t.weight *= density / scale;
        t.wave /= scale;
        t.wave2 /= scale;
    }
    // Dropping terms keeps the density non-negative: the constant (first) stays.
    d.terms.resize(std::size_t(std::clamp(terms, 0, int(d.terms.size()))));
    d.colour = {0.55, 0.58, 0.65};
    // Fully fogged beyond 60 units (the sky): the reference then integrates
    // no ray longer than that (the camera's far plane is at 1000).
    d.farDistanceWorld = 60.0;
    return d;
}

struct Row {
    std::string knob, setting;
    double cpuMs = 0, totalMs = 0, rmse = 0, maxErr = 0, psnr = 0; // totalMs: wall; cpuMs: process CPU time
    bool pareto = false;
    bool mainTruth = true; // measured against the main (textured, on-texture) truth
};

struct Error {
    double rmse = 0, maxErr = 0, psnr = 0;
};
Error compare(const splatfx::Image& a, const splatfx::Image& b) {
    double sum = 0, worst = 0;
    size_t n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double d = double(a.at(x, y, c)) - double(b.at(x, y, c));
                sum += d * d;
                worst = std::max(worst, std::abs(d));
                ++n;
            }
    Error e;
    e.rmse = std::sqrt(sum / double(std::max<size_t>(n, 1)));
    e.maxErr = worst;
    e.psnr = e.rmse > 0 ? 20.0 * std::log10(1.0 / e.rmse) : 999.0;
    return e;
}

// The campfire sample's flame shape; each voxel gets a loop position j in
// [0, kTruthCount) from a hash, quantized to multiples of `quantum`.
splatfx::Grid fireGrid(int quantum) {
    splatfx::Grid g = *splatfx::Grid::box({7, 20, 5}, glm::vec3(0.5f));
    for (splatfx::Voxel& v : g.voxels) {
        v.opacity = 0.55f * splatfx::flameOpacity(v.cell, g.dims);
        const std::uint32_t j = splatfx::hashCell(v.cell, kSeed, 7) % kTruthCount;
        v.texture = j - j % std::uint32_t(quantum); // loop position, in truth-set textures
    }
    // Turned half a turn about its (centred) vertical axis so the lattice's
    // storage order runs front to back: SortMode::None then shows the worst
    // order rather than an accidentally good one.
    g.transform = glm::rotate(glm::mat4(1.0f), glm::pi<float>(), glm::vec3(0, 1, 0));
    return g;
}

// The grid as a set of `count` textures shows it: texture floor(j K / N), cross-faded by the remainder.
splatfx::Grid forCount(splatfx::Grid g, int count) {
    for (splatfx::Voxel& v : g.voxels) {
        const double pos = double(v.texture) * count / kTruthCount;
        v.texture = std::uint32_t(std::floor(pos));
        v.phase = float(pos - std::floor(pos));
    }
    return g;
}

splatfx::TextureSet subset(const splatfx::TextureSet& all, int count) {
    splatfx::TextureSet s = all;
    s.layers.clear();
    for (int k = 0; k < count; ++k) s.layers.push_back(all.layers[size_t(k * (kTruthCount / count))]);
    return s;
}

splatfx::Camera camera(glm::ivec2 size) {
    return splatfx::Camera::lookAt({0.0f, 4.8f, 15.0f}, {0.0f, 4.6f, 0.0f}, {0, 1, 0}, glm::radians(45.0f), size);
}

// Host geometry: a ground plane and a log across the fire's base.
class Host {
public:
    bool init(std::string& err) {
        const char* vs = "#version 450 core\nlayout(location=0) in vec3 p; layout(location=1) in vec3 c; uniform mat4 uVP; out vec3 vC;\n"
                         "void main() { vC = c; gl_Position = uVP * vec4(p, 1.0); }\n";
        const char* fs = "#version 450 core\nin vec3 vC; out vec4 o; void main() { o = vec4(vC, 1.0); }\n";
        const splatfx::Result<GLuint> program = splatfx::gl::linkProgram({vs}, {fs}, "host geometry");
        if (!program) return (err = program.error()), false;
        mProgram = *program;
        std::vector<float> v;
        auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 col) {
            for (glm::vec3 p : {a, b, c, a, c, d}) v.insert(v.end(), {p.x, p.y, p.z, col.r, col.g, col.b});
        };
        quad({-8, 0, -8}, {8, 0, -8}, {8, 0, 6}, {-8, 0, 6}, {0.18f, 0.2f, 0.14f});
        const glm::vec3 lo{-2.4f, 0.0f, 1.1f}, hi{2.4f, 0.7f, 1.8f}, bark{0.35f, 0.2f, 0.1f};
        quad({lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, bark);        // front
        quad({lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, bark * 1.3f); // top
        quad({lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}, bark * 0.8f); // left end
        quad({hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, bark * 0.8f); // right end
        mCount = GLsizei(v.size() / 6);
        glCreateBuffers(1, &mBuffer);
        glNamedBufferStorage(mBuffer, GLsizeiptr(v.size() * sizeof(float)), v.data(), 0);
        glCreateVertexArrays(1, &mVao);
        glVertexArrayVertexBuffer(mVao, 0, mBuffer, 0, 6 * sizeof(float));
        for (GLuint a = 0; a < 2; ++a) {
            glEnableVertexArrayAttrib(mVao, a);
            glVertexArrayAttribFormat(mVao, a, 3, GL_FLOAT, GL_FALSE, a * 3 * sizeof(float));
            glVertexArrayAttribBinding(mVao, a, 0);
        }
        return true;
    }
    void draw(const splatfx::gl::Framebuffer& fb, const splatfx::Camera& cam) const {
        glBindFramebuffer(GL_FRAMEBUFFER, fb.handle());
        glViewport(0, 0, fb.width(), fb.height());
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glDisable(GL_BLEND);
        glUseProgram(mProgram);
        const glm::mat4 vp = cam.proj * cam.view;
        glUniformMatrix4fv(glGetUniformLocation(mProgram, "uVP"), 1, GL_FALSE, glm::value_ptr(vp));
        glBindVertexArray(mVao);
        glDrawArrays(GL_TRIANGLES, 0, mCount);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
    }

private:
    GLuint mProgram = 0, mVao = 0, mBuffer = 0;
    GLsizei mCount = 0;
};

const glm::vec4 kSky{0.02f, 0.02f, 0.04f, 1.0f};

struct Bench {
    Options opt;
    Host host;
    splatfx::Camera cam;
    std::optional<splatfx::gl::Framebuffer> pristine; // host colour + depth, F32
    splatfx::Image hostColor, hostDepth;
    splatfx::TextureSet truthSet; // kTruthCount textures at kTruthLayer texels, not windowed
    std::vector<Row> rows;

    splatfx::ReferenceHost refHost() const { return {.backgroundImage = &hostColor, .depth = &hostDepth}; }

    // Copies the host's colour and depth into fb (what the host draws before the effect).
    void restoreHost(const splatfx::gl::Framebuffer& fb) const {
        glBlitNamedFramebuffer(pristine->handle(), fb.handle(), 0, 0, opt.size.x, opt.size.y, 0, 0, opt.size.x, opt.size.y,
                               GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    }

    splatfx::Footprint footprint(const Config& c) const {
        return splatfx::Footprint({.kernel = c.gaussian ? splatfx::Kernel::Gaussian : splatfx::Kernel::CrawfisMax,
                                   .tableSize = c.tableSize,
                                   .gaussianRadius = c.gaussianRadius});
    }

    // A setting ready to time: its GL target, renderer and per-frame CPU work.
    struct Setting {
        Row row;
        Config config;
        std::unique_ptr<splatfx::Materials> mat;
        splatfx::Grid grid;
        std::optional<splatfx::Frame> frame;
        std::uint32_t setId = 0;
        std::optional<splatfx::gl::Framebuffer> fb;
        std::optional<splatfx::gl::FrameRenderer> sr;
        const splatfx::Image* truth = nullptr;
        std::shared_ptr<const splatfx::Fog> fog; // null: clear air
        double extraCpuMs = 0.0;
        std::vector<double> cpu, total;

        const splatfx::Frame& prepare(const splatfx::Camera& cam) {
            frame->begin(0.0, cam);
            frame->setFog(fog);
            frame->builder().add(grid, *mat, {.textureSet = setId, .colorTable = 0, .textured = config.textured, .crossfade = true, .variation = gVariation});
            frame->end(config.sort);
            return *frame;
        }
    };
    std::vector<std::unique_ptr<Setting>> settings;

    // Registers one setting of the fire; everything is timed later, round-robin.
    void add(const std::string& knob, const std::string& setting, const Config& c, const splatfx::Grid& truthGrid, const splatfx::Image& truth,
             bool mainTruth = true, bool remapTextures = true, double extraCpuMs = 0.0) {
        if (opt.fogOnly && knob.rfind("fog", 0) != 0) return; // --fog-only
        auto s = std::make_unique<Setting>();
        s->row = Row{knob, setting};
        s->row.mainTruth = mainTruth;
        s->config = c;
        s->mat = std::make_unique<splatfx::Materials>(materials(c, subset(truthSet, c.count), s->setId));
        s->grid = remapTextures ? forCount(truthGrid, c.count) : truthGrid;
        s->frame.emplace(splatfx::SplatBuilderDesc{.buckets = c.buckets});
        s->truth = &truth;
        s->extraCpuMs = extraCpuMs;
        auto fb = splatfx::gl::Framebuffer::create({.width = opt.size.x, .height = opt.size.y, .color = c.precision});
        splatfx::gl::RendererDesc rdesc;
        rdesc.footprintCut = c.footprintCut;
        rdesc.trimCorners = c.octagons;
        rdesc.sampling = c.sampling;
        rdesc.upsample = c.upsample;
        rdesc.fogPerSplat = c.fogPerSplat;
        if (c.fogTerms > 0) {
            auto fog = splatfx::Fog::create(benchFog(c.fogTerms));
            if (!fog) {
                std::fprintf(stderr, "accuracy: bench fog: %s\n", fog.error().c_str());
                return;
            }
            s->fog = std::make_shared<const splatfx::Fog>(std::move(*fog));
        }
        auto sr = splatfx::gl::FrameRenderer::create({.splats = rdesc, .resolutionScale = c.scale, .fogTextureSize = c.fogTexture});
        if (!fb || !sr || !sr->upload(*s->mat)) {
            std::fprintf(stderr, "accuracy: cannot set up GL for %s %s\n", knob.c_str(), setting.c_str());
            return;
        }
        s->fb = std::move(*fb);
        s->sr = std::move(*sr);
        settings.push_back(std::move(s));
    }

    // Rounds over all settings (so drift in this shared machine's speed hits
    // every setting alike): each round times one frame of each, from the host
    // image to glFinish. Then one more frame of each is compared with its truth.
    void measureAll() {
        for (int r = -2; r < opt.reps; ++r) { // two warm-up rounds
            for (auto& s : settings) {
                restoreHost(*s->fb);
                glFinish();
                const double c0 = processCpuMs();
                const auto t0 = Clock::now();
                s->sr->render(s->prepare(cam), {.framebuffer = s->fb->handle()});
                glFinish();
                const auto t2 = Clock::now();
                const double c2 = processCpuMs();
                if (r >= 0) s->cpu.push_back(c2 - c0), s->total.push_back(ms(t0, t2));
            }
            std::printf("\r  timing round %d / %d", r + 3, opt.reps + 2);
            std::fflush(stdout);
        }
        std::printf("\n");
        for (auto& s : settings) {
            restoreHost(*s->fb);
            s->sr->render(s->prepare(cam), {.framebuffer = s->fb->handle()});
            const Error e = compare(s->fb->read(), *s->truth);
            Row& row = s->row;
            row.cpuMs = median(s->cpu) + s->extraCpuMs;
            row.totalMs = median(s->total) + s->extraCpuMs;
            row.rmse = e.rmse, row.maxErr = e.maxErr, row.psnr = e.psnr;
            std::printf("  %-24s %-26s wall %8.3f ms  CPU %8.3f ms  RMSE %.5f  max %.4f  PSNR %6.2f dB\n", row.knob.c_str(), row.setting.c_str(),
                        row.totalMs, row.cpuMs, row.rmse, row.maxErr, row.psnr);
            rows.push_back(row);
        }
    }

    splatfx::Materials materials(const Config& c, const splatfx::TextureSet& set, std::uint32_t& setId) const {
        splatfx::Materials m(footprint(c), {.layerSize = c.layerSize});
        setId = m.addTextureSet(set);
        m.addColorTable(splatfx::ColorTable::fire());
        return m;
    }

    // Splat-exact truth for a grid drawn with the full truth set at 128 texels
    // (or untextured); with `fog`, the fog integrated numerically along every
    // pixel ray through the splats to the host's surface (SplatExactDesc::fog).
    splatfx::Image truthImage(const splatfx::Grid& grid, const Config& c, const splatfx::Fog* fog = nullptr) const {
        std::uint32_t setId = 0;
        Config tc = c;
        tc.layerSize = kTruthLayer;
        const splatfx::Materials mat = materials(tc, truthSet, setId);
        splatfx::SplatBuilder builder;
        builder.begin(cam);
        builder.add(grid, mat, {.textureSet = setId, .colorTable = 0, .textured = c.textured, .crossfade = true, .variation = gVariation});
        auto img = splatfx::renderSplatExact(builder.splats(), cam, mat, {.host = refHost(), .fog = fog});
        return img ? *img : splatfx::Image{};
    }
};

// The machine's load when the run starts and ends: timings on a shared machine mean little without it.
std::string loadAverage() {
    std::ifstream in("/proc/loadavg");
    std::string a, b, c;
    in >> a >> b >> c;
    return in ? a + " " + b + " " + c : std::string("unknown");
}

const char* precisionName(Precision p) { return p == Precision::U8 ? "U8" : p == Precision::F16 ? "F16" : "F32"; }

// Returns -1 to go on, else the exit code (cli::parse).
int parse(int argc, char** argv, Options& o) {
    CLI::App app{"Error against the exact reference vs time per frame, for every quality knob.", "splatfx-bench accuracy"};
    app.add_option("--out", o.out, "where accuracy.csv, accuracy.dat, accuracy.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    // 2048 a side: the run keeps a dozen float images of this size
    // (references in double), about 1 GB at the cap.
    cli::addSize(app, "--size", o.size.x, o.size.y, 16, 2048, "frame size");
    cli::addNumber(app, "--reps", o.reps, 1, 10000, "timed frames per setting, median reported");
    bool noPlots = false;
    app.add_flag("--no-plots", noPlots, "print the tables only");
    app.add_flag("--replot", o.replotOnly, "only run gnuplot again on DIR/accuracy.gp (after editing it)");
    app.add_flag("--fog-only", o.fogOnly, "only the fog knobs (host fog texture, per-splat fog, fog terms) and their reference");
    app.add_flag("--clouds-only", o.cloudsOnly, "only the LOD clouds' knobs (table size, c, C, max vs average Delta) against the finest level");
    bool paperLattice = false;
    app.add_flag("--paper-lattice", paperLattice, "splats on the voxel lattice as in the paper (no SplatVariation; default: the presets' recommended one)");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (paperLattice) gVariation = {};
    if (noPlots || o.cloudsOnly) o.plots = false; // the clouds' table is printed, not plotted
    return -1;
}

void writePlots(const Bench& b, const std::string& dir) {
    // Data: one block per knob (gnuplot "index"), then the Pareto front.
    std::vector<std::string> knobs;
    for (const Row& r : b.rows)
        if (std::find(knobs.begin(), knobs.end(), r.knob) == knobs.end()) knobs.push_back(r.knob);
    {
        std::ofstream d(dir + "/accuracy.dat");
        for (const std::string& k : knobs) {
            d << "# " << k << "\n";
            for (const Row& r : b.rows)
                if (r.knob == k) d << r.cpuMs << " " << r.rmse << " \"" << r.setting << "\"\n";
            d << "\n\n";
        }
        d << "# all settings against the main truth\n";
        for (const Row& r : b.rows)
            if (r.mainTruth) d << r.cpuMs << " " << r.rmse << " \"" << r.knob << ": " << r.setting << "\"\n";
        d << "\n\n# pareto front\n";
        std::vector<Row> front;
        for (const Row& r : b.rows)
            if (r.pareto) front.push_back(r);
        std::sort(front.begin(), front.end(), [](const Row& x, const Row& y) { return x.cpuMs < y.cpuMs; });
        for (const Row& r : front) d << r.cpuMs << " " << r.rmse << " \"" << r.knob << ": " << r.setting << "\"\n";
    }
    std::ofstream gp(dir + "/accuracy.gp");
    const int cols = 3, rowsN = int(knobs.size() + cols - 1) / cols;
    gp << "# Written by splatfx-bench accuracy; run: gnuplot accuracy.gp\n"
       << "set terminal pngcairo size " << 420 * cols << "," << 330 * rowsN << " font 'sans,9'\n"
       << "set output 'accuracy_knobs.png'\n"
       << "set multiplot layout " << rowsN << "," << cols << " title 'splatfx accuracy vs time per knob (GL vs exact reference, " << b.opt.size.x
       << "x" << b.opt.size.y << ")'\n"
       << "set logscale y\nset grid\nset xrange [0:*]\nset xlabel 'CPU time per frame (ms, median, all threads)'\nset ylabel 'RMSE vs "
          "reference'\nset key off\n"
       << "set offsets graph 0.12, graph 0.12, graph 0.1, graph 0.1\n";
    for (size_t k = 0; k < knobs.size(); ++k)
        gp << "set title '" << knobs[k] << "'\nplot 'accuracy.dat' index " << k << " using 1:2 with linespoints pt 7 lc rgb '#c0392b', "
           << "'' index " << k << " using 1:2:3 with labels offset 0,0.9 font 'sans,8'\n";
    gp << "unset multiplot\n"
       << "set terminal pngcairo size 900,640 font 'sans,10'\nset output 'accuracy_pareto.png'\nset key top right\nset autoscale x\n"
       << "set title 'All settings against the main truth, and their Pareto front'\n"
       << "plot 'accuracy.dat' index " << knobs.size() << " using 1:2 with points pt 6 lc rgb '#7f8c8d' title 'setting', "
       << "'' index " << knobs.size() + 1 << " using 1:2 with linespoints pt 7 lw 2 lc rgb '#c0392b' title 'Pareto front', "
       << "'' index " << knobs.size() + 1 << " using 1:2:3 with labels left offset 1,0 font 'sans,8' notitle\n";
}

// gnuplot on DIR/accuracy.gp, run inside DIR (the script names its outputs relative to it).
cli::SpawnResult plotCommand(const std::string& outDir) { return cli::spawn({.argv = {"gnuplot", "accuracy.gp"}, .workingDir = outDir}); }

} // namespace

int runAccuracy(int argc, char** argv) {
    Bench b;
    if (const int code = parse(argc, argv, b.opt); code >= 0) return code;
    if (b.opt.replotOnly) {
        const cli::SpawnResult gp = plotCommand(b.opt.out);
        if (!gp.started || gp.exitCode != 0) {
            std::fprintf(stderr, "accuracy: gnuplot failed on %s/accuracy.gp%s%s\n", b.opt.out.c_str(), gp.started ? "" : ": ", gp.error.c_str());
            return 1;
        }
        std::printf("accuracy: replotted %s/accuracy.gp\n", b.opt.out.c_str());
        return 0;
    }
    const auto start = Clock::now();
    std::error_code ec;
    fs::create_directories(b.opt.out, ec);
    if (b.opt.plots && !cli::spawn({.argv = {"gnuplot", "--version"}, .output = cli::ChildOutput::Discard}).started) {
        std::fprintf(stderr, "accuracy: gnuplot is not installed; install it (Debian: apt-get install gnuplot-nox) or pass --no-plots\n");
        return 1;
    }
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "accuracy: %s\n", ctx.error().c_str());
        return 1;
    }
    std::printf("splatfx-bench accuracy: %dx%d, %d timed frames per setting, GL renderer: %s\n", b.opt.size.x, b.opt.size.y, b.opt.reps,
                ctx->renderer().c_str());
    std::printf("cores: %u, load average (1/5/15 min): %s\n", std::thread::hardware_concurrency(), loadAverage().c_str());
    // The clouds' knobs: a 65x65x17 field (the popping run's) at 256x192, 9 frames a setting.
    const auto cloudKnobs = [&] { return runCloudKnobs({65, 65, 17}, {256, 192}, 9); };
    if (b.opt.cloudsOnly) return cloudKnobs();
    b.cam = camera(b.opt.size);
    std::string err;
    if (!b.host.init(err)) {
        std::fprintf(stderr, "accuracy: %s\n", err.c_str());
        return 1;
    }
    b.pristine = std::move(*splatfx::gl::Framebuffer::create({.width = b.opt.size.x, .height = b.opt.size.y, .color = Precision::F32}));
    b.pristine->clear(kSky);
    b.host.draw(*b.pristine, b.cam);
    b.hostColor = b.pristine->read();
    b.hostDepth = b.pristine->readDepth();
    b.truthSet = splatfx::TextureSet::turbulence({.count = kTruthCount, .size = kTruthLayer, .seed = kSeed});

    std::printf("computing reference images (splat-exact, double precision)...\n");
    std::fflush(stdout);
    const Config def;
    const splatfx::Grid onTexture = fireGrid(kTruthCount / def.count); // every voxel exactly on one of the 8 textures
    const splatfx::Grid between = fireGrid(1);                         // voxels anywhere along the loop
    const bool all = !b.opt.fogOnly;
    const splatfx::Image truth = all ? b.truthImage(onTexture, def) : splatfx::Image{};
    const splatfx::Image truthBetween = all ? b.truthImage(between, def) : splatfx::Image{};
    Config gaussTruthCfg;
    gaussTruthCfg.textured = false;
    gaussTruthCfg.gaussian = true;
    gaussTruthCfg.gaussianRadius = 4.2f; // 6 sigma: the truncated mass is below 1e-7
    const splatfx::Image truthGauss = all ? b.truthImage(onTexture, gaussTruthCfg) : splatfx::Image{};
    // The fire in the full bench fog, fog and splats integrated together.
    auto fullFog = splatfx::Fog::create(benchFog(5));
    if (!fullFog) {
        std::fprintf(stderr, "accuracy: bench fog: %s\n", fullFog.error().c_str());
        return 1;
    }
    const splatfx::Image truthFog = b.truthImage(onTexture, def, &*fullFog);
    std::printf("reference images done (%.1f s)\n\n", ms(start, Clock::now()) / 1e3);

    std::printf("setting up every knob setting (materials, GL targets)...\n");
    for (int n : {4, 8, 16, 64, 256, 1024}) {
        Config c;
        c.tableSize = n;
        b.add("footprint table", std::to_string(n) + " entries" + (n == 256 ? " (default)" : ""), c, onTexture, truth);
    }
    for (int n : {8, 16, 32, 64, 128}) {
        Config c;
        c.layerSize = n;
        b.add("texture resolution", std::to_string(n) + "^2 texels" + (n == 32 ? " (default)" : ""), c, onTexture, truth);
    }
    for (int n : {1, 2, 4, 8, 16, 32}) {
        Config c;
        c.count = n;
        b.add("texture count", std::to_string(n) + " textures" + (n == 8 ? " (default)" : ""), c, between, truthBetween, false);
    }
    for (Precision p : {Precision::U8, Precision::F16, Precision::F32}) {
        Config c;
        c.precision = p;
        b.add("framebuffer precision", std::string(precisionName(p)) + (p == Precision::U8 ? " (default)" : ""), c, onTexture, truth);
    }
    {
        Config c;
        c.sort = splatfx::SortMode::None;
        b.add("sort", "none", c, onTexture, truth);
        c.sort = splatfx::SortMode::Bucketed;
        c.buckets = 8;
        b.add("sort", "bucketed, 8 bins", c, onTexture, truth);
        c.buckets = 64;
        b.add("sort", "bucketed, 64 bins", c, onTexture, truth);
        c.sort = splatfx::SortMode::Exact;
        b.add("sort", "exact (default)", c, onTexture, truth);
    }
    for (int s : {4, 2, 1}) {
        Config c;
        c.scale = s;
        b.add("render scale", s == 1 ? "full (default)" : s == 2 ? "half" : "quarter", c, onTexture, truth);
    }
    const float defaultCut = splatfx::gl::RendererDesc{}.footprintCut;
    for (float cut : {0.6f, 0.7f, defaultCut, 0.9f, 1.0f}) {
        Config c;
        c.footprintCut = cut;
        char label[64];
        std::snprintf(label, sizeof label, "%.4g of the radius%s", cut, cut == defaultCut ? " (default)" : "");
        b.add("footprint cut (RendererDesc)", label, c, onTexture, truth);
    }
    for (bool octagons : {false, true}) {
        Config c;
        c.octagons = octagons;
        const bool isDefault = octagons == splatfx::gl::RendererDesc{}.trimCorners;
        b.add("footprint shape (RendererDesc)",
              std::string(octagons ? "octagon, 6 triangles" : "square, 2 triangles") + (isDefault ? " (default)" : ""), c, onTexture, truth);
    }
    {
        using splatfx::gl::TextureSampling;
        auto sampled = [&](TextureSampling s, int factor, const std::string& label) {
            Config c;
            c.sampling = s;
            c.upsample = factor;
            b.add("texture sampling (RendererDesc)", label, c, onTexture, truth);
        };
        sampled(TextureSampling::Bilinear, 0, "bilinear");
        sampled(TextureSampling::Nearest, 0, "nearest");
        for (int factor : {2, 4, 8}) sampled(TextureSampling::Upsampled, factor, "upsampled " + std::to_string(factor) + "x, nearest");
        // The default, labelled with what it resolved to on this GL.
        Config c;
        const std::size_t before = b.settings.size();
        b.add("texture sampling (RendererDesc)", "auto", c, onTexture, truth);
        if (b.settings.size() > before) { // add() keeps nothing when GL setup fails
            const splatfx::gl::Renderer& r = b.settings.back()->sr->splatRenderer();
            b.settings.back()->row.setting = r.sampling() == TextureSampling::Upsampled
                                                 ? "auto: upsampled " + std::to_string(r.upsampleFactor()) + "x (default)"
                                                 : "auto: bilinear (default)";
        }
    }
    for (float radius : {1.05f, 1.4f, 1.75f, 2.0f, 2.8f}) {
        Config c = gaussTruthCfg;
        c.gaussianRadius = radius;
        char label[64];
        std::snprintf(label, sizeof label, "%.2f (%.1f sigma)%s", radius, radius / 0.7f, radius == 2.0f ? " (default)" : "");
        b.add("kernel radius (Gaussian)", label, c, onTexture, truthGauss, false);
    }
    {
        // Combinations, to populate the Pareto front.
        Config c;
        c.scale = 2;
        c.precision = Precision::F16;
        b.add("combined", "half + F16", c, onTexture, truth);
        c.layerSize = 64;
        b.add("combined", "half + F16 + 64^2", c, onTexture, truth);
        c = Config{};
        c.precision = Precision::F16;
        c.layerSize = 64;
        b.add("combined", "full + F16 + 64^2", c, onTexture, truth);
        c = Config{};
        c.scale = 4;
        c.sort = splatfx::SortMode::Bucketed;
        c.layerSize = 16;
        b.add("combined", "quarter + 64 bins + 16^2", c, onTexture, truth);
    }

    // Fog knobs (issue 14), against the fire and host in the full bench fog.
    {
        const glm::ivec2 sz = b.opt.size;
        for (int div : {1, 2, 4, 8}) {
            Config c;
            c.fogTerms = 5;
            c.fogTexture = div == 1 ? glm::ivec2(0) : glm::max(sz / div, glm::ivec2(1));
            char label[64];
            if (div == 1) std::snprintf(label, sizeof label, "per pixel (default)");
            else std::snprintf(label, sizeof label, "%dx%d texture (1/%d)", c.fogTexture.x, c.fogTexture.y, div);
            b.add("fog: host image", label, c, onTexture, truthFog, false);
        }
        for (bool perSplat : {false, true}) {
            Config c;
            c.fogTerms = 5;
            c.fogPerSplat = perSplat;
            b.add("fog: splats", perSplat ? "once per splat" : "per fragment (default)", c, onTexture, truthFog, false);
        }
        for (int terms : {5, 4, 2, 1, 0}) {
            Config c;
            c.fogTerms = terms;
            b.add("fog: terms kept",
                  terms == 5   ? "all 5 (default: the fog as given)"
                  : terms == 0 ? "0 (no fog)"
                               : std::to_string(terms) + " of 5",
                  c, onTexture, truthFog, false);
        }
    }

    // Object dynamics: the fluid solver's substeps, against 32 substeps.
    splatfx::Image truthSolver;
    if (all) {
        const int frames = 45;
        const double dt = 1.0 / 30.0;
        auto simulate = [&](int substeps, double& msPerFrame) {
            splatfx::FluidSolverDesc d;
            d.dims = {8, 20, 6};
            d.spacing = glm::vec3(0.5f);
            d.substeps = substeps;
            auto solver = splatfx::FluidSolver::create(d);
            solver->addEmitter({.desc = {.offset = {0, 0.6f, 0}, .radius = 1.2f}, .motion = {}});
            const double c0 = processCpuMs();
            for (int f = 0; f < frames; ++f) solver->step(dt);
            msPerFrame = (processCpuMs() - c0) / frames; // single-threaded: CPU time is its cost
            splatfx::Grid g;
            solver->toGrid(g, {});
            return g;
        };
        Config c;
        c.textured = false;
        double unused = 0.0;
        const splatfx::Grid truthGrid = simulate(32, unused);
        truthSolver = b.truthImage(truthGrid, c);
        for (int s : {1, 2, 4, 8, 16}) {
            double solveMs = 0.0;
            const splatfx::Grid g = simulate(s, solveMs);
            b.add("solver substeps", std::to_string(s) + (s == 1 ? " (default)" : ""), c, g, truthSolver, false, false, solveMs);
        }
    }
    std::printf("timing %zu settings round-robin; median per frame (splat build + sort + GL draw to glFinish), error vs reference:\n",
                b.settings.size());
    b.measureAll();

    // Pareto front over the settings measured against the main truth.
    for (Row& r : b.rows) {
        if (!r.mainTruth) continue;
        r.pareto = true;
        for (const Row& o : b.rows)
            if (o.mainTruth && &o != &r && o.cpuMs <= r.cpuMs && o.rmse <= r.rmse && (o.cpuMs < r.cpuMs || o.rmse < r.rmse)) r.pareto = false;
    }

    // What splatting itself costs: untextured splats against volume-exact rendering.
    if (all) std::printf("\nsplatting vs volume rendering (untextured fire, no host geometry, %dx%d):\n", b.opt.size.x / 2, b.opt.size.y / 2);
    if (all) {
        const glm::ivec2 vs = b.opt.size / 2;
        const splatfx::Camera vcam = camera(vs);
        splatfx::Materials mat(splatfx::Footprint{});
        mat.addColorTable(splatfx::ColorTable::fire());
        splatfx::VolumeField field(mat);
        field.add(onTexture, {.textured = false});
        splatfx::VolumeExactStats vstats;
        const auto t0 = Clock::now();
        auto vol = splatfx::renderVolumeExact(field, vcam, {.host = {.background = kSky}, .tolerance = 1e-4}, &vstats);
        const double volMs = ms(t0, Clock::now());
        splatfx::SplatBuilder builder;
        builder.begin(vcam);
        builder.add(onTexture, mat, {.textured = false});
        builder.sort();
        const auto t1 = Clock::now();
        auto spl = splatfx::renderSplatExact(builder.splats(), vcam, mat, {.host = {.background = kSky}});
        const double splMs = ms(t1, Clock::now());
        std::printf("  volume-exact: %.0f ms, converged to %.1e (max estimate %.1e, %llu pixels unconverged)\n", volMs, 1e-4, vstats.maxErrorEstimate,
                    static_cast<unsigned long long>(vstats.unconverged));
        const Error se = compare(*spl, *vol);
        std::printf("  splat-exact vs volume-exact:          RMSE %.5f  max %.4f  PSNR %6.2f dB   (%.0f ms)\n", se.rmse, se.maxErr, se.psnr, splMs);
        for (Precision p : {Precision::U8, Precision::F32}) {
            auto fb = splatfx::gl::Framebuffer::create({.width = vs.x, .height = vs.y, .color = p});
            auto r = splatfx::gl::Renderer::create();
            if (!fb || !r || !r->upload(mat)) continue;
            fb->clear(kSky);
            r->draw(builder.splats(), vcam, {.framebuffer = fb->handle(), .width = vs.x, .height = vs.y});
            const Error ge = compare(fb->read(), *vol);
            std::printf("  GL (%s, defaults) vs volume-exact:    RMSE %.5f  max %.4f  PSNR %6.2f dB\n", precisionName(p), ge.rmse, ge.maxErr,
                        ge.psnr);
        }
        (void)splatfx::writeImage(b.opt.out + "/volume_exact.png", *vol);
        (void)splatfx::writeImage(b.opt.out + "/splat_exact_untextured.png", *spl);
    }

    // The reference's own accuracy: step halving on the same field (colour varies along rays).
    if (all)
        std::printf("\nvolume-exact self-check (fixed steps vs step h0/256, %dx%d, h0 = 0.2 = a quarter of the kernel radius):\n", b.opt.size.x / 4,
                    b.opt.size.y / 4);
    if (all) {
        const glm::ivec2 vs = b.opt.size / 4;
        const splatfx::Camera vcam = camera(vs);
        splatfx::Materials mat(splatfx::Footprint{});
        mat.addColorTable(splatfx::ColorTable::fire());
        splatfx::VolumeField field(mat);
        field.add(onTexture, {.textured = false});
        const double h0 = 0.2;
        auto fine = splatfx::renderVolumeExact(field, vcam, {.fixedStep = h0 / 256});
        double prev = 0.0;
        for (int k = 0; k <= 4; ++k) {
            auto img = splatfx::renderVolumeExact(field, vcam, {.fixedStep = h0 / (1 << k)});
            double worst = 0.0;
            for (size_t i = 0; i < img->pixels.size(); ++i) worst = std::max(worst, double(std::abs(img->pixels[i] - fine->pixels[i])));
            if (k == 0) std::printf("  step h0/%-3d max error %.3e\n", 1 << k, worst);
            else std::printf("  step h0/%-3d max error %.3e   ratio %.2f\n", 1 << k, worst, prev / worst);
            prev = worst;
        }
    }

    // Table and CSV.
    const std::string csvPath = b.opt.out + "/accuracy.csv";
    std::ofstream csv(csvPath);
    csv << "knob,setting,cpu_ms,wall_ms,rmse,max_error,psnr_db,pareto,main_truth\n";
    std::printf("\n| knob | setting | CPU ms/frame | vs default | wall ms/frame | RMSE | max error | PSNR (dB) | Pareto |\n"
                "|---|---|---:|---:|---:|---:|---:|---:|:-:|\n");
    auto defaultMs = [&](const std::string& knob) {
        for (const Row& r : b.rows)
            if (r.knob == knob && (r.setting.find("default") != std::string::npos)) return r.cpuMs;
        for (const Row& r : b.rows)
            if (r.knob == "render scale" && r.setting.find("default") != std::string::npos) return r.cpuMs;
        return 1.0;
    };
    for (const Row& r : b.rows) {
        csv << '"' << r.knob << "\",\"" << r.setting << "\"," << r.cpuMs << ',' << r.totalMs << ',' << r.rmse << ',' << r.maxErr << ',' << r.psnr
            << ',' << (r.pareto ? 1 : 0) << ',' << (r.mainTruth ? 1 : 0) << '\n';
        std::printf("| %s | %s | %.2f | %.2fx | %.2f | %.5f | %.4f | %.2f | %s |\n", r.knob.c_str(), r.setting.c_str(), r.cpuMs,
                    r.cpuMs / defaultMs(r.knob), r.totalMs, r.rmse, r.maxErr, r.psnr, r.pareto ? "yes" : "");
    }
    csv.close();
    std::printf("\nwrote %s\n", csvPath.c_str());

    if (b.opt.plots) {
        writePlots(b, b.opt.out);
        // An argument vector, never a shell line: --out may hold quotes or ';'.
        const cli::SpawnResult gp = plotCommand(b.opt.out);
        if (!gp.started || gp.exitCode != 0) {
            std::fprintf(stderr, "accuracy: gnuplot failed on %s/accuracy.gp%s%s\n", b.opt.out.c_str(), gp.started ? "" : ": ", gp.error.c_str());
            return 1;
        }
        std::printf("wrote %s/accuracy_knobs.png and %s/accuracy_pareto.png (data: accuracy.dat, script: accuracy.gp)\n", b.opt.out.c_str(),
                    b.opt.out.c_str());
    }
    if (!b.opt.fogOnly) {
        std::printf("\n");
        if (int rc = cloudKnobs(); rc != 0) return rc;
    }
    std::printf("accuracy: done in %.1f s; load average at the end: %s\n", ms(start, Clock::now()) / 1e3, loadAverage().c_str());
    return 0;
}
} // namespace accuracy_cmd

int runAccuracy(int argc, char** argv) { return accuracy_cmd::runAccuracy(argc, argv); }
