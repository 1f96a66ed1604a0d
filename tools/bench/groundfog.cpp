// splatfx-bench groundfog (issue 17, sec. 6): the LOD ground fog over the
// Jacksboro DEM (sample 22's terrain and fog) on a flight at constant speed:
// tetrahedra drawn against the full-resolution layer, ms per frame with LOD
// and full, the error of each LOD frame against the full layer's frame (GL,
// same camera), and the popping metric (largest and 99th-percentile per-pixel
// change between consecutive frames) with and without geomorphing, against
// the full layer's own frame-to-frame change.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "bench_gl.hpp"
#include "options.hpp"
#include "bench_stats.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/scene_file.hpp"
#include "splatfx/volume.hpp"

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
};

// Sample 22's layer: spacing 1, heightScale 1228.78, position y -4.69, fog top 5.
splatfx::GroundFogDesc jacksboro(const splatfx::Image& img, bool lod, float minAccuracyC, float densityDepth) {
    splatfx::GroundFogDesc d;
    d.densityDepthWorld = densityDepth;
    const int w = img.width, h = img.height;
    d.dims = {w, h};
    d.originWorld = splatfx::heightmapPoint(0, 0, w, h, 0.0f, 1.0f, 0.0f);
    d.spacingWorld = 1.0f;
    d.lod = lod;
    d.minAccuracyC = minAccuracyC;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
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
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    auto img = splatfx::readImage(o.dem, splatfx::Alpha::Straight);
    if (!img) return std::fprintf(stderr, "%s\n", img.error().c_str()), 1;
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
