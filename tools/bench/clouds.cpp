// splatfx-bench clouds (issue 17): LOD volumes drawn as pre-integrated
// projected tetrahedra on a flight through a cloud field: tetrahedra drawn
// against the full-resolution count, frame rate and memory outside and inside
// the cloud, and a popping metric with and without morphing against the
// finest level's own frame-to-frame change. Then (issue 14 with 17) the cost
// and error of Biri fog on the tetrahedra: GL with and without the per-segment
// fog against renderTetraExact (cloud and fog as one medium, double).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <optional>
#include <vector>

#include <epoxy/gl.h>

#include "bench_gl.hpp"
#include "options.hpp"
#include "bench_stats.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/volume.hpp"

namespace clouds_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using bench::percentile;
using Clock = std::chrono::steady_clock;
double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

struct Options {
    glm::ivec3 dims{257, 257, 33};
    float detailC = 10.0f;
    int frames = 120;
    glm::ivec2 size{512, 384};
    glm::ivec3 popDims{65, 65, 17};
    int popFrames = 40;
    glm::ivec2 popSize{256, 192};
    float popDetailC = 10.0f;
    float popStepWorld = 0.25f; // a quarter cell per frame
    // Fog on the tetrahedra: a small cloud (the reference is brute force), frames timed per mode.
    glm::ivec3 fogDims{33, 33, 9};
    glm::ivec2 fogSize{128, 96};
    int fogFrames = 41;
    bool fogOnly = false; // --fog-only: skip the flight and the popping runs
    int scale = 2;        // the flight also at this resolution scale (tetrahedra reduced); 1: only full resolution
    // Streaks inside a cloud: one frame in the middle of the popping run's field, per target mode.
    bool streaksOnly = false; // --streaks-only: only this part
    glm::ivec2 streakSize{512, 384};
    glm::ivec2 streakExactSize{128, 96}; // the same view against renderTetraExact
    int streakFrames = 9;
};

struct CloudSet {
    splatfx::Scene scene;
    splatfx::EffectId id = 0;
    std::size_t tableBytes = 0, volumeBytes = 0;
    std::uint64_t full = 0;
    glm::vec3 ext{0.0f};
};

bool makeClouds(glm::ivec3 dims, float detailC, CloudSet& out) {
    splatfx::CloudDesc cd;
    cd.dims = dims;
    auto field = splatfx::makeCloudVolume(cd);
    if (!field) return std::fprintf(stderr, "%s\n", field.error().c_str()), false;
    auto vol = splatfx::LodVolume::create(*field, {});
    if (!vol) return std::fprintf(stderr, "%s\n", vol.error().c_str()), false;
    auto tf = splatfx::makeCloudTransfer({});
    const float longest = std::sqrt(3.0f) * float(1 << vol->rootLevel()) * vol->spacingWorld();
    auto table = splatfx::PreIntegrationTable::create(*tf, {.maxLengthWorld = longest});
    if (!tf || !table) return std::fprintf(stderr, "transfer/table failed\n"), false;
    out.tableBytes = table->bytes();
    out.volumeBytes = vol->memoryBytes();
    out.full = vol->fullResolutionTets();
    out.ext = glm::vec3(vol->pointDims() - 1) * vol->spacingWorld();
    out.id = out.scene.add(std::move(*vol), std::move(*tf), std::move(*table), {.name = "clouds", .refine = {.detailC = detailC}});
    return true;
}

// The flight of docs/volume.md: at mid height from outside the -x face,
// through the field and out, at constant speed.
splatfx::Camera flight(const glm::vec3& ext, int f, int frames, glm::ivec2 size) {
    const glm::vec3 start(-0.25f * ext.x, 0.37f * ext.y, 0.5f * ext.z), end(1.25f * ext.x, 0.61f * ext.y, 0.5f * ext.z);
    const float u = frames > 1 ? float(f) / float(frames - 1) : 0.0f;
    const glm::vec3 eye = start + (end - start) * u, dir = glm::normalize(end - start);
    return splatfx::Camera::lookAt(eye, eye + dir, {0, 0, 1}, glm::radians(60.0f), size, 0.1f, 5000.0f);
}

// The same line at constant speed: `step` world units per frame from 10% of
// the way (outside the -x face), so the flight approaches and enters the field.
splatfx::Camera slowFlight(const glm::vec3& ext, int f, float step, glm::ivec2 size) {
    const glm::vec3 start(-0.25f * ext.x, 0.37f * ext.y, 0.5f * ext.z), end(1.25f * ext.x, 0.61f * ext.y, 0.5f * ext.z);
    const glm::vec3 dir = glm::normalize(end - start), eye = start + 0.1f * (end - start) + dir * (step * float(f));
    return splatfx::Camera::lookAt(eye, eye + dir, {0, 0, 1}, glm::radians(60.0f), size, 0.1f, 5000.0f);
}

bool inside(const glm::vec3& ext, const splatfx::Camera& c) {
    const glm::vec3 e = c.eye();
    return e.x > 0 && e.y > 0 && e.z > 0 && e.x < ext.x && e.y < ext.y && e.z < ext.z;
}

// ---- 4. Streaks inside a cloud: the volumes rounded per tetrahedron by an 8-bit host ----
//
// One frame in the middle of the popping run's field, drawn into an RGBA8
// host straight (FrameRendererDesc::volumeLayer off: every tetrahedron's
// blend rounded to 8 bits) and through the volume layer (RGBA16F, RGBA32F:
// one rounding at the composite), against the same frame drawn straight into
// an RGBA32F host (GL's own arithmetic, no rounding between tetrahedra) and
// rounded to 8 bits once here (a float frame too). The error e (in 8-bit levels) of a frame
// rounded once is 0 (+-1 where GL's conversion and ours part); per-tetrahedron
// rounding accumulates over the dozens of tetrahedra a pixel sees inside a
// cloud and jumps along their projected faces. "Steps": the RMS of e minus its
// 5x5 box mean, the part of the error that changes from pixel to pixel (the
// straight lines; a smooth offset, such as a rounding bias, drops out of it).
// The same modes at a small size against renderTetraExact (rounded once) say
// that the float frame is the exact one up to the table: cracks or faces
// counted twice would show there, not only in 8 bits.
struct StreakMeasure {
    double rms = 0.0, max = 0.0, steps = 0.0; // in 8-bit levels
};

StreakMeasure streakMeasure(const splatfx::Image& img, const splatfx::Image& ref) {
    const int w = img.width, h = img.height, r = 2;
    std::vector<double> e(std::size_t(w) * std::size_t(h) * 3);
    auto at = [&](int x, int y, int c) -> double& { return e[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 3 + std::size_t(c)]; };
    StreakMeasure m;
    double sum2 = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                const std::size_t p = (std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4 + std::size_t(c);
                const double d = std::round(255.0 * std::clamp(double(img.pixels[p]), 0.0, 1.0)) - std::round(255.0 * std::clamp(double(ref.pixels[p]), 0.0, 1.0));
                at(x, y, c) = d;
                sum2 += d * d, m.max = std::max(m.max, std::abs(d));
            }
    m.rms = std::sqrt(sum2 / double(e.size()));
    double hp2 = 0.0;
    std::size_t n = 0;
    for (int y = r; y + r < h; ++y)
        for (int x = r; x + r < w; ++x)
            for (int c = 0; c < 3; ++c) {
                double mean = 0.0;
                for (int j = -r; j <= r; ++j)
                    for (int i = -r; i <= r; ++i) mean += at(x + i, y + j, c);
                const double d = at(x, y, c) - mean / double((2 * r + 1) * (2 * r + 1));
                hp2 += d * d, ++n;
            }
    m.steps = std::sqrt(hp2 / double(std::max<std::size_t>(n, 1)));
    return m;
}

bool runStreaks(const Options& o, const splatfx::Materials& materials) {
    CloudSet cs;
    if (!makeClouds(o.popDims, o.popDetailC, cs)) return false;
    struct Mode {
        const char* name;
        bool layer;
        splatfx::gl::Precision layerFormat, host;
        std::optional<splatfx::gl::FrameRenderer> renderer{};
        std::vector<double> times{};
        splatfx::Image image{}, small{};
    };
    using splatfx::gl::Precision;
    Mode modes[] = {{"straight into the host (layer off)", false, Precision::F32, Precision::U8},
                    {"volume layer RGBA16F", true, Precision::F16, Precision::U8},
                    {"volume layer RGBA32F (default)", true, Precision::F32, Precision::U8},
                    {"float host RGBA32F, layer off (reference)", false, Precision::F16, Precision::F32}};
    for (Mode& m : modes) {
        auto r = splatfx::gl::FrameRenderer::create({.volumeLayer = m.layer, .volumeLayerPrecision = m.layerFormat});
        if (!r) return std::fprintf(stderr, "%s\n", r.error().c_str()), false;
        m.renderer.emplace(std::move(*r));
    }
    std::uint64_t drawn = 0;
    std::size_t tetsSmall = 0;
    std::vector<std::string> notes;
    for (int pass = 0; pass < 2; ++pass) { // the timed frame, then the small one for the exact reference
        const glm::ivec2 size = pass == 0 ? o.streakSize : o.streakExactSize;
        const splatfx::Camera cam = flight(cs.ext, 1, 3, size); // the middle of the field
        splatfx::Frame frame;
        if (auto s = cs.scene.prepare(1.0, cam, materials, frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), false;
        std::optional<splatfx::gl::Framebuffer> fb8, fb32;
        auto a = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y});
        auto b = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y, .color = Precision::F32});
        if (!a || !b) return std::fprintf(stderr, "streaks: framebuffer failed\n"), false;
        fb8.emplace(std::move(*a)), fb32.emplace(std::move(*b));
        const int rounds = pass == 0 ? o.streakFrames : 1;
        for (int f = -1; f < rounds; ++f) // one warm-up; the modes interleaved, the first one rotating
            for (std::size_t j = 0; j < std::size(modes); ++j) {
                Mode& m = modes[(j + std::size_t(std::max(f, 0))) % std::size(modes)];
                splatfx::gl::Framebuffer& fb = m.host == Precision::U8 ? *fb8 : *fb32;
                const auto t0 = Clock::now();
                m.renderer->render(frame, bench::clearedTarget(fb, {0.0f, 0.0f, 0.0f, 0.0f}));
                glFinish();
                if (pass == 0 && f >= 0) m.times.push_back(ms(Clock::now() - t0));
                (pass == 0 ? m.image : m.small) = fb.read();
                for (const std::string& n : m.renderer->stats().notes) notes.push_back(n);
            }
        if (pass == 0) drawn = modes[0].renderer->stats().tetrahedra.drawn;
        else tetsSmall = frame.volumes().empty() ? 0 : frame.volumes()[0].lod.tets.size();
        if (pass == 1) {
            auto tf = splatfx::makeCloudTransfer({}); // the one makeClouds gave the scene
            if (!tf) return std::fprintf(stderr, "%s\n", tf.error().c_str()), false;
            const auto r0 = Clock::now();
            splatfx::TetraExactStats st;
            auto exact = splatfx::renderTetraExact(frame.volumes()[0].lod.tets, *tf, cam, {}, &st);
            if (!exact) return std::fprintf(stderr, "%s\n", exact.error().c_str()), false;
            std::printf("streaks: exact reference %dx%d, %zu tetrahedra, %.0f ms, %llu pixels unconverged\n", size.x, size.y, tetsSmall,
                        ms(Clock::now() - r0), static_cast<unsigned long long>(st.unconverged));
            const double refMs = percentile(modes[0].times, 0.5);
            std::printf("\nstreaks inside a cloud: field %dx%dx%d, c = %.0f, the popping run's flight at its middle; %dx%d, %llu tetrahedra "
                        "drawn, median of %d frames each (modes interleaved); errors in 8-bit levels (1/255) of RGB against the float "
                        "frame (and the exact one) rounded to 8 bits once, premultiplied over transparent black\n\n",
                        o.popDims.x, o.popDims.y, o.popDims.z, double(o.popDetailC), o.streakSize.x, o.streakSize.y,
                        static_cast<unsigned long long>(drawn), o.streakFrames);
            std::printf("| target | ms/frame | vs straight | steps vs float | RMS vs float | max vs float | steps vs exact "
                        "(%dx%d) | RMS vs exact | max vs exact |\n",
                        o.streakExactSize.x, o.streakExactSize.y);
            std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
            const Mode& ref = modes[3];
            for (const Mode& m : modes) {
                const StreakMeasure f = streakMeasure(m.image, ref.image), x = streakMeasure(m.small, *exact);
                const double t = percentile(m.times, 0.5);
                std::printf("| %s | %.1f | %.2f | %.3f | %.3f | %.0f | %.3f | %.3f | %.0f |\n", m.name, t, t / refMs, f.steps, f.rms, f.max, x.steps,
                            x.rms, x.max);
            }
            std::printf("\nsteps: RMS of the error minus its 5x5 box mean (what changes from pixel to pixel: the straight lines along the faces).\n");
        }
    }
    std::sort(notes.begin(), notes.end());
    notes.erase(std::unique(notes.begin(), notes.end()), notes.end());
    for (const std::string& n : notes) std::printf("note: %s\n", n.c_str());
    return true;
}

} // namespace

int runClouds(int argc, char** argv) {
    Options o;
    CLI::App app{"LOD cloud volumes as pre-integrated projected tetrahedra: count vs full resolution, frame rate and memory outside\n"
                 "and inside, the flight also with the tetrahedra at 1/scale resolution, popping, fog on the tetrahedra.",
                 "splatfx-bench clouds"};
    cli::addInts(app, "--dims", &o.dims.x, 3, 2, 4097, "grid points of the flight's cloud field", "X Y Z");
    cli::addNumber(app, "--c", o.detailC, 0.0f, 1.0e6f, "detail knob c of the flight");
    cli::addNumber(app, "--frames", o.frames, 2, 100000, "frames of the flight");
    cli::addInts(app, "--size", &o.size.x, 2, 16, 8192, "frame size of the flight", "W H");
    cli::addInts(app, "--pop-dims", &o.popDims.x, 3, 2, 4097, "grid points of the popping run's field", "X Y Z");
    cli::addNumber(app, "--pop-frames", o.popFrames, 2, 100000, "frames of the popping run");
    cli::addInts(app, "--pop-size", &o.popSize.x, 2, 16, 8192, "frame size of the popping run", "W H");
    cli::addNumber(app, "--pop-c", o.popDetailC, 0.0f, 1.0e6f, "detail knob c of the popping run");
    cli::addNumber(app, "--pop-step", o.popStepWorld, 1.0e-6f, 1.0e6f, "world units per frame of the popping run");
    cli::addInts(app, "--fog-dims", &o.fogDims.x, 3, 2, 4097, "grid points of the fogged cloud", "X Y Z");
    cli::addInts(app, "--fog-size", &o.fogSize.x, 2, 16, 8192, "frame size of the fog runs", "W H");
    cli::addNumber(app, "--fog-frames", o.fogFrames, 1, 100000, "frames timed per fog mode");
    app.add_flag("--fog-only", o.fogOnly, "skip the flight and the popping runs");
    app.add_flag("--streaks-only", o.streaksOnly, "only the streaks inside a cloud (8-bit target: direct vs the volume layer)");
    cli::addInts(app, "--streak-size", &o.streakSize.x, 2, 16, 8192, "frame size of the streaks part", "W H");
    cli::addInts(app, "--streak-exact-size", &o.streakExactSize.x, 2, 16, 8192, "frame size of the streaks part's exact comparison", "W H");
    cli::addNumber(app, "--streak-frames", o.streakFrames, 1, 100000, "frames timed per streaks mode");
    cli::addChecked(
        app, "--scale",
        [&o](const std::string& option, const std::string& text) -> splatfx::Status {
            if (auto s = cli::parseInt(option, text, 1, 4, o.scale); !s || o.scale == 3)
                return splatfx::makeError(option + " expects 1, 2 or 4, got '" + text + "'");
            return {};
        },
        "the flight also with the tetrahedra at 1/scale resolution: 1, 2 or 4 (default 2; 1: full resolution only)", "N");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "%s\n", ctx.error().c_str()), 1;
    auto fr = splatfx::gl::FrameRenderer::create();
    if (!fr) return std::fprintf(stderr, "%s\n", fr.error().c_str()), 1;
    splatfx::Materials materials{splatfx::Footprint{}};

    if (o.streaksOnly) return runStreaks(o, materials) ? 0 : 1;

    // ---- 1. The flight: counts, frame rate, memory ----
    if (!o.fogOnly) {
        CloudSet cs;
        const auto t0 = Clock::now();
        if (!makeClouds(o.dims, o.detailC, cs)) return 1;
        std::printf("clouds %dx%dx%d, c = %.1f: field + octree + 64x64x128 table %.0f ms\n", o.dims.x, o.dims.y, o.dims.z, o.detailC,
                    ms(Clock::now() - t0));
        auto fb = splatfx::gl::Framebuffer::create({.width = o.size.x, .height = o.size.y});
        if (!fb) return std::fprintf(stderr, "%s\n", fb.error().c_str()), 1;
        // Each frame drawn at full resolution and, with --scale, again with the tetrahedra
        // at 1/scale per axis (FrameRendererDesc::reduceTetrahedra): ratios from one run.
        struct Pass {
            int scale;
            splatfx::gl::FrameRenderer* renderer;
            std::vector<double> tOut, tIn, prepOut, prepIn, errOut, errIn;
        };
        std::optional<splatfx::gl::FrameRenderer> reduced;
        if (o.scale != 1) {
            auto r = splatfx::gl::FrameRenderer::create({.resolutionScale = o.scale, .reduceTetrahedra = true});
            if (!r) return std::fprintf(stderr, "%s\n", r.error().c_str()), 1;
            reduced.emplace(std::move(*r));
        }
        std::vector<Pass> passes{{1, &*fr, {}, {}, {}, {}, {}, {}}};
        if (reduced) passes.push_back({o.scale, &*reduced, {}, {}, {}, {}, {}, {}});
        splatfx::Frame frame;
        std::vector<double> drawnOut, drawnIn;
        std::size_t maxFrameBytes = 0;
        for (int f = -2; f < o.frames; ++f) { // two warm-up frames (table upload, shader compile)
            const splatfx::Camera cam = flight(cs.ext, std::max(f, 0), o.frames, o.size);
            const bool in = inside(cs.ext, cam);
            splatfx::Image fullImage;
            for (Pass& pass : passes) {
                const auto a = Clock::now();
                if (auto s = cs.scene.prepare(f / 60.0 + 1.0, cam, materials, frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
                const auto b = Clock::now();
                pass.renderer->render(frame, bench::clearedTarget(*fb, {0.45f, 0.6f, 0.85f, 1.0f}));
                glFinish();
                const auto c = Clock::now();
                if (f < 0) continue;
                (in ? pass.tIn : pass.tOut).push_back(ms(c - a));
                (in ? pass.prepIn : pass.prepOut).push_back(ms(b - a));
                if (passes.size() > 1) { // against this frame at full resolution: mean per-pixel max |d channel|
                    splatfx::Image img = fb->read();
                    if (pass.scale == 1) {
                        fullImage = std::move(img);
                    } else {
                        double sum = 0.0;
                        for (std::size_t p = 0; p < img.pixels.size(); p += 4) {
                            double e = 0.0;
                            for (std::size_t k = 0; k < 3; ++k) e = std::max(e, double(std::abs(img.pixels[p + k] - fullImage.pixels[p + k])));
                            sum += e;
                        }
                        (in ? pass.errIn : pass.errOut).push_back(sum / double(img.pixels.size() / 4));
                    }
                }
            }
            if (f < 0) continue;
            (in ? drawnIn : drawnOut).push_back(double(fr->stats().tetrahedra.drawn));
            std::size_t bytes = 0;
            for (const auto& v : frame.volumes()) bytes += v.lod.tets.size() * (sizeof(splatfx::Tetrahedron) + 160);
            maxFrameBytes = std::max(maxFrameBytes, bytes);
        }
        auto mean = [](const std::vector<double>& v) {
            double s = 0;
            for (double x : v) s += x;
            return v.empty() ? 0.0 : s / double(v.size());
        };
        std::printf("full resolution: %llu tetrahedra\n", static_cast<unsigned long long>(cs.full));
        for (const Pass& pass : passes)
            for (int in = 0; in < 2; ++in) {
                const auto& t = in ? pass.tIn : pass.tOut;
                const auto& d = in ? drawnIn : drawnOut;
                const auto& p = in ? pass.prepIn : pass.prepOut;
                if (t.empty()) continue;
                const double dm = mean(d), med = percentile(t, 0.5);
                std::printf("%s (%zu frames, %dx%d, tetrahedra at 1/%d): drawn mean %.0f max %.0f (%.0fx fewer than full); frame ms "
                            "median %.1f (%.1f Hz) mean %.1f p90 %.1f; of it prepare (LOD update) median %.1f ms",
                            in ? "inside " : "outside", t.size(), o.size.x, o.size.y, pass.scale, dm, *std::max_element(d.begin(), d.end()),
                            double(cs.full) / std::max(dm, 1.0), med, 1000.0 / med, mean(t), percentile(t, 0.9), percentile(p, 0.5));
                const auto& e = in ? pass.errIn : pass.errOut;
                if (pass.scale != 1 && !e.empty())
                    std::printf("; vs full resolution: %.2fx the time, mean |d| per pixel %.4f (worst frame %.4f)",
                                med / percentile(in ? passes[0].tIn : passes[0].tOut, 0.5), mean(e), *std::max_element(e.begin(), e.end()));
                std::printf("\n");
            }
        std::printf("memory: LOD volume %zu bytes, table %zu bytes (CPU) + %zu (GPU, RGBA32F), per-frame tetrahedra up to %zu bytes "
                    "(CPU list + GPU records)\n",
                    cs.volumeBytes, cs.tableBytes, fr->stats().tetrahedra.tableBytes, maxFrameBytes);
    }

    // ---- 2. Popping: per-pixel change between consecutive frames ----
    if (!o.fogOnly) {
        CloudSet cs;
        if (!makeClouds(o.popDims, o.popDetailC, cs)) return 1;
        auto fb = splatfx::gl::Framebuffer::create({.width = o.popSize.x, .height = o.popSize.y, .color = splatfx::gl::Precision::F32});
        if (!fb) return std::fprintf(stderr, "%s\n", fb.error().c_str()), 1;
        std::printf("popping: clouds %dx%dx%d (full %llu tetrahedra), %d frames at %dx%d, %.3f world units per frame, c = %.1f\n", o.popDims.x,
                    o.popDims.y, o.popDims.z, static_cast<unsigned long long>(cs.full), o.popFrames, o.popSize.x, o.popSize.y, o.popStepWorld,
                    o.popDetailC);
        struct Mode {
            const char* name;
            float c;
            bool morph;
        };
        const Mode modes[] = {{"finest level", 1e9f, true}, {"LOD, morphing", o.popDetailC, true}, {"LOD, no morphing", o.popDetailC, false}};
        double finestMax = 0, finestP99 = 0;
        for (const Mode& m : modes) {
            cs.scene.options(cs.id).refine = {.detailC = m.c, .morph = m.morph};
            splatfx::Frame frame;
            splatfx::Image prev;
            std::vector<double> change;
            double drawn = 0;
            for (int f = 0; f < o.popFrames; ++f) {
                const splatfx::Camera cam = slowFlight(cs.ext, f, o.popStepWorld, o.popSize);
                if (auto s = cs.scene.prepare(f / 60.0 + 1.0, cam, materials, frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
                fr->render(frame, bench::clearedTarget(*fb, {0.0f, 0.0f, 0.0f, 0.0f}));
                drawn += double(fr->stats().tetrahedra.drawn);
                splatfx::Image img = fb->read();
                if (f > 0)
                    for (std::size_t p = 0; p < img.pixels.size(); p += 4) {
                        double e = 0;
                        for (int k = 0; k < 4; ++k)
                            e = std::max(e, double(std::abs(img.pixels[p + std::size_t(k)] - prev.pixels[p + std::size_t(k)])));
                        change.push_back(e);
                    }
                prev = std::move(img);
            }
            const double mx = percentile(change, 1.0), p99 = percentile(change, 0.99);
            if (m.c >= 1e9f) finestMax = mx, finestP99 = p99;
            std::printf("  %-17s drawn mean %9.0f  change max %.4f  p99 %.4f   (vs finest: max %.2fx, p99 %.2fx)\n", m.name, drawn / o.popFrames, mx,
                        p99, mx / std::max(finestMax, 1e-12), p99 / std::max(finestP99, 1e-12));
        }
    }

    // ---- 3. Biri fog on the tetrahedra: cost and error against the one-medium reference ----
    if (!o.fogOnly && !runStreaks(o, materials)) return 1;
    if (o.fogFrames >= 1 && o.fogSize.x >= 1 && o.fogSize.y >= 1) {
        CloudSet cs;
        if (!makeClouds(o.fogDims, 10.0f, cs)) return 1;
        // A constant haze plus a cosine bank: about 1 optical depth from the eye to the cloud.
        splatfx::FogDesc fd;
        fd.terms = {splatfx::FogTerm::constant(0.03), splatfx::FogTerm::cosine(0.02, 0.2, {1.0, 0.3, 0.2}, 0.5)};
        fd.colour = {0.75, 0.78, 0.85};
        auto fog = splatfx::Fog::create(fd);
        auto tf = splatfx::makeCloudTransfer({}); // the one makeClouds gave the scene
        auto frNoFog = splatfx::gl::FrameRenderer::create({.fogHost = false});
        auto frFog = splatfx::gl::FrameRenderer::create({.fogHost = false});
        auto fb = splatfx::gl::Framebuffer::create({.width = o.fogSize.x, .height = o.fogSize.y, .color = splatfx::gl::Precision::F32});
        if (!fog || !tf || !frNoFog || !frFog || !fb) return std::fprintf(stderr, "fog on tetrahedra: setup failed\n"), 1;
        // Outside, above a corner, the whole field in view (z up).
        const splatfx::Camera cam =
            splatfx::Camera::lookAt(glm::vec3(-0.6f, -0.35f, 1.8f) * cs.ext, 0.5f * cs.ext, {0, 0, 1}, glm::radians(60.0f), o.fogSize, 0.1f, 5000.0f);
        splatfx::Frame frame;
        if (auto s = cs.scene.prepare(1.0, cam, materials, frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
        auto shared = std::make_shared<const splatfx::Fog>(*fog);
        auto draw = [&](splatfx::gl::FrameRenderer& r, bool fogged) {
            frame.setFog(fogged ? shared : nullptr);
            r.render(frame, bench::clearedTarget(*fb, {0.0f, 0.0f, 0.0f, 0.0f}));
            glFinish();
        };
        std::vector<double> tNo, tYes;
        for (int f = -2; f < o.fogFrames; ++f) // interleaved (which goes first alternates), two warm-up rounds
            for (int k = 0; k < 2; ++k) {
                const int fogged = (k + f) & 1;
                const auto a = Clock::now();
                draw(fogged ? *frFog : *frNoFog, fogged != 0);
                if (f >= 0) (fogged ? tYes : tNo).push_back(ms(Clock::now() - a));
            }
        draw(*frNoFog, false);
        const splatfx::Image glNo = fb->read();
        draw(*frFog, true);
        const splatfx::Image glYes = fb->read();
        const std::vector<splatfx::Tetrahedron>& tets = frame.volumes().empty() ? std::vector<splatfx::Tetrahedron>{} : frame.volumes()[0].lod.tets;
        const auto r0 = Clock::now();
        splatfx::TetraExactStats sNo, sYes;
        auto refNo = splatfx::renderTetraExact(tets, *tf, cam, {.fogHost = false}, &sNo);
        auto refYes = splatfx::renderTetraExact(tets, *tf, cam, {.fog = &*fog, .fogHost = false}, &sYes);
        const double refMs = ms(Clock::now() - r0);
        if (!refNo || !refYes) return std::fprintf(stderr, "fog on tetrahedra: %s\n", (refNo ? refYes.error() : refNo.error()).c_str()), 1;
        auto err = [](const splatfx::Image& a, const splatfx::Image& b, double& rmse, double& mx) {
            double sum = 0;
            mx = 0;
            for (std::size_t i = 0; i < a.pixels.size(); ++i) {
                const double d = double(a.pixels[i]) - double(b.pixels[i]);
                sum += d * d, mx = std::max(mx, std::abs(d));
            }
            rmse = std::sqrt(sum / double(std::max<std::size_t>(a.pixels.size(), 1)));
        };
        double rNo, mNo, rYes, mYes, rEffect, mEffect;
        err(glNo, *refNo, rNo, mNo);
        err(glYes, *refYes, rYes, mYes);
        err(*refNo, *refYes, rEffect, mEffect);
        std::printf("fog on tetrahedra: clouds %dx%dx%d, %zu tetrahedra drawn, %dx%d, %d frames per mode (RGBA, F32, no host fog pass;\n"
                    "  reference renderTetraExact, cloud and fog as one medium, %.0f ms for both, %llu + %llu pixels unconverged)\n",
                    o.fogDims.x, o.fogDims.y, o.fogDims.z, tets.size(), o.fogSize.x, o.fogSize.y, o.fogFrames, refMs,
                    static_cast<unsigned long long>(sNo.unconverged), static_cast<unsigned long long>(sYes.unconverged));
        std::printf("  no fog               frame ms median %7.2f   vs reference: RMSE %.5f  max %.4f\n", percentile(tNo, 0.5), rNo, mNo);
        std::printf("  per-segment fog      frame ms median %7.2f   vs reference: RMSE %.5f  max %.4f   (%.2fx the no-fog frame)\n",
                    percentile(tYes, 0.5), rYes, mYes, percentile(tYes, 0.5) / std::max(percentile(tNo, 0.5), 1e-9));
        std::printf("  the fog's own effect (reference with vs without): RMSE %.5f  max %.4f\n", rEffect, mEffect);
    }
    return 0;
}
} // namespace clouds_cmd

int runClouds(int argc, char** argv) { return clouds_cmd::runClouds(argc, argv); }
