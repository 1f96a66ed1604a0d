// splatfx-bench scheduling: what a level of 1000 effects costs when only a
// few are seen (issue 6), drawn, against those few alone (issue 12), and the
// error of a solver effect's catch-up.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include <epoxy/gl.h>

#include "bench_stats.hpp"
#include "mixed_level.hpp"
#include "options.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/scene.hpp"

namespace scheduling_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using bench::median;
using Clock = std::chrono::steady_clock;

// Effects are simulated and drawn up to this far from the camera (world units).
constexpr float kRange = 150.0f;

splatfx::Result<splatfx::Effect> makeEffect(splatfx::Materials& m, int kind, glm::vec3 at, std::uint32_t seed) {
    switch (kind % 4) {
    case 0: return splatfx::presets::fire(m, {.position = at, .seed = seed});
    case 1: return splatfx::presets::steam(m, {.position = at, .seed = seed});
    case 2: return splatfx::presets::smoke(m, {.dims = {6, 12, 6}, .position = at, .seed = seed});
    default: return splatfx::presets::fireToSmoke(m, {.position = at, .seed = seed});
    }
}

// What a drawn frame needs from the host: a target, the SDK's frame and its renderer.
struct FrameDraw {
    splatfx::gl::Framebuffer& fb;
    splatfx::gl::FrameRenderer& renderer;
    splatfx::Frame frame;
};

// One full frame as a game runs it: Scene::prepare (schedule, simulate, emit,
// sort), then the frame renderer with the clear as the host's opaque pass,
// and wait for the pixels (glFinish), so the time is CPU + GL.
void drawFrame(splatfx::Scene& scene, const splatfx::Materials& m, FrameDraw& d, const splatfx::Camera& cam, double timeSec) {
    if (auto s = scene.prepare(timeSec, cam, m, d.frame); !s) std::fprintf(stderr, "%s\n", s.error().c_str());
    d.renderer.render(d.frame, {.framebuffer = d.fb.handle(), .drawOpaque = [&] { d.fb.clear({0.02f, 0.02f, 0.04f, 1.0f}); }});
    glFinish();
}

// Median seconds per frame over `frames` (drawn when `d` is given, else
// CPU only: update + emit + sort).
double frameCost(splatfx::Scene& scene, splatfx::Materials& m, int frames, double t0, const std::function<splatfx::Camera(int)>& camera,
                 double* neededAvg, FrameDraw* d = nullptr) {
    splatfx::SplatBuilder builder;
    std::vector<double> t;
    double needed = 0;
    for (int f = 0; f < frames; ++f) {
        const splatfx::Camera cam = camera(f);
        const auto a = Clock::now();
        if (d) {
            drawFrame(scene, m, *d, cam, t0 + f / 60.0);
        } else {
            if (auto s = scene.update(t0 + f / 60.0, cam); !s) std::fprintf(stderr, "%s\n", s.error().c_str());
            builder.begin(cam);
            scene.emit(builder, m);
            builder.sort();
        }
        t.push_back(std::chrono::duration<double>(Clock::now() - a).count());
        needed += double(scene.counters().needed);
    }
    if (neededAvg) *neededAvg = needed / frames;
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}

// The mixed level (mixed_level.hpp): every kind, lit and shadowing, a few in
// view, against a scene holding only what that view needs (the items the
// level drew or advanced to cast into it, and the fog terms it kept), drawn
// alternately; then one frame of each read back and compared pixel by pixel.
int runMixed(int count, int frames, glm::ivec2 size, const std::string& imagePath) {
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "scheduling: %s\n", ctx.error().c_str()), 1;
    splatfx::Materials m{splatfx::Footprint{}};
    splatfx::Scene level, needed;
    std::printf("building the mixed level of %d items (effects, gases, clouds, ground fog; fog terms; lit and casting) ...\n", count);
    const auto buildStart = Clock::now();
    if (splatfx::Status s = bench::buildMixedLevel(level, m, count, [](int) { return true; }); !s)
        return std::fprintf(stderr, "scheduling: %s\n", s.error().c_str()), 1;
    auto fog = splatfx::Fog::create(bench::mixedFog(count));
    if (!fog) return std::fprintf(stderr, "scheduling: %s\n", fog.error().c_str()), 1;
    level.setFog(*fog);
    int kinds[7] = {};
    for (int i = 0; i < count; ++i) ++kinds[bench::mixedItem(i, count).kind];
    std::printf("built in %.1f s: %d fire, %d steam, %d smoke solvers (lit), %d fire-to-smoke, %d procedural gases (lit), %d cloud decks,\n"
                "  %d ground fog layers, %zu fog terms; %u texture sets\n",
                std::chrono::duration<double>(Clock::now() - buildStart).count(), kinds[0], kinds[1], kinds[2], kinds[3], kinds[4], kinds[5], kinds[6],
                fog->desc().terms.size(), m.setCount());
    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y});
    auto renderer = splatfx::gl::FrameRenderer::create();
    auto renderer2 = splatfx::gl::FrameRenderer::create();
    if (!fb || !renderer || !renderer2) return std::fprintf(stderr, "scheduling: framebuffer or renderer failed\n"), 1;
    FrameDraw drawLevel{*fb, *renderer, splatfx::Frame{}}, drawNeeded{*fb, *renderer2, splatfx::Frame{}};
    const auto fixed = [&](int) { return bench::mixedCamera(size); };
    // What this view needs, as the level decides it at t = 0.
    if (splatfx::Status s = level.prepare(0.0, fixed(0), m, drawLevel.frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
    std::vector<bool> keep(std::size_t(count), false);
    for (int i = 0; i < count; ++i) keep[std::size_t(i)] = level.status(splatfx::EffectId(i)).needed || level.status(splatfx::EffectId(i)).castsIntoView;
    if (splatfx::Status s = bench::buildMixedLevel(needed, m, count, [&](int i) { return bool(keep[std::size_t(i)]); }); !s)
        return std::fprintf(stderr, "scheduling: %s\n", s.error().c_str()), 1;
    if (drawLevel.frame.fog()) {
        needed.setFog(*splatfx::Fog::create(drawLevel.frame.fog()->desc()));
        (void)needed.setFogCulling({.enabled = false}); // already only the kept terms (a valid desc)
    }
    if (splatfx::Status s = needed.prepare(0.0, fixed(0), m, drawNeeded.frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
    for (auto* r : {&*renderer, &*renderer2})
        if (splatfx::Status s = r->upload(m); !s) return std::fprintf(stderr, "scheduling: %s\n", s.error().c_str()), 1;
    std::printf("drawing at %dx%d on %s\n\n", size.x, size.y, ctx->renderer().c_str());
    frameCost(level, m, 10, 1 / 60.0, fixed, nullptr, &drawLevel);
    frameCost(needed, m, 10, 1 / 60.0, fixed, nullptr, &drawNeeded);
    std::vector<double> tLevel, tNeeded;
    for (int f = 0; f < frames; ++f) {
        tLevel.push_back(frameCost(level, m, 1, (11 + f) / 60.0, fixed, nullptr, &drawLevel));
        tNeeded.push_back(frameCost(needed, m, 1, (11 + f) / 60.0, fixed, nullptr, &drawNeeded));
    }
    // The CPU part alone: Scene::prepare (schedule, advance, emit, light, shadow, sort, fog), alternately.
    std::vector<double> cLevel, cNeeded;
    for (int f = 0; f < frames; ++f) {
        const double t = (11 + frames + f) / 60.0;
        for (auto [scene, frame, out] : {std::tuple{&level, &drawLevel.frame, &cLevel}, std::tuple{&needed, &drawNeeded.frame, &cNeeded}}) {
            const auto a = Clock::now();
            if (splatfx::Status s = scene->prepare(t, fixed(0), m, *frame); !s) return std::fprintf(stderr, "%s\n", s.error().c_str()), 1;
            out->push_back(std::chrono::duration<double>(Clock::now() - a).count());
        }
    }
    // One more frame each at the same time, read back.
    const double tLast = (11 + 2 * frames) / 60.0;
    drawFrame(level, m, drawLevel, fixed(0), tLast);
    const splatfx::Image a = fb->read();
    drawFrame(needed, m, drawNeeded, fixed(0), tLast);
    const splatfx::Image b = fb->read();
    if (!imagePath.empty())
        if (splatfx::Status s = splatfx::writeImage(imagePath, a); !s) return std::fprintf(stderr, "scheduling: %s\n", s.error().c_str()), 1;
    float worst = 0.0f;
    std::size_t differing = 0;
    for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) {
            float d = 0.0f;
            for (int c = 0; c < 4; ++c) d = std::max(d, std::abs(a.at(x, y, c) - b.at(x, y, c)));
            worst = std::max(worst, d);
            differing += d > 0.0f;
        }
    const splatfx::SceneCounters& cl = level.counters();
    const splatfx::SceneCounters& cn = needed.counters();
    std::printf("Mixed level, fixed camera, %d frames drawn at %dx%d (update + emit + light + sort + draw + glFinish, median, alternately)\n",
                frames, size.x, size.y);
    std::printf("  %-26s %8s %8s %9s %9s %11s %11s %10s\n", "scene", "declared", "drawn", "cast-only", "splats", "tetrahedra", "fog terms", "ms/frame");
    auto row = [&](const char* name, const splatfx::SceneCounters& c, double t) {
        std::printf("  %-26s %8zu %8zu %9zu %9llu %11llu %5zu (-%zu) %10.3f\n", name, c.declared, c.needed, c.castOnly, (unsigned long long)c.splats,
                    (unsigned long long)c.tetrahedra, c.fogTermsDrawn, c.fogTermsSkipped, 1e3 * t);
    };
    row((std::to_string(count) + " items declared").c_str(), cl, median(tLevel));
    row("only what the view needs", cn, median(tNeeded));
    std::printf("  ratio %.2fx (target: at most 1.3x)\n", median(tLevel) / median(tNeeded));
    std::printf("  CPU part alone (Scene::prepare, median of %d, alternately): %.3f vs %.3f ms/frame, ratio %.2fx\n", frames, 1e3 * median(cLevel),
                1e3 * median(cNeeded), median(cLevel) / median(cNeeded));
    std::size_t castShadowing = 0, drawnShadowing = 0;
    for (splatfx::EffectId id = 0; id < level.size(); ++id) {
        castShadowing += level.status(id).castsIntoView && level.status(id).inSceneShadow;
        drawnShadowing += level.status(id).needed && level.status(id).inSceneShadow;
    }
    std::printf("  level: %zu lit casters culled (shadow cannot reach the view); in the scene shadow: %zu drawn + %zu cast-only "
                "(a cast-only caster with no density yet casts nothing)\n",
                cl.castersCulled, drawnShadowing, castShadowing);
    if (!level.lightingError().empty()) std::printf("  level: lighting: %s\n", level.lightingError().c_str());
    std::printf("  in-view image, level vs only-needed: %zu pixels differ, largest difference %.3g (expected 0: out-of-view content changes nothing)\n",
                differing, double(worst));
    return differing == 0 ? 0 : 1;
}

} // namespace

int runScheduling(int argc, char** argv) {
    int count = 1000, frames = 60;
    glm::ivec2 size{640, 480};
    bool quick = false;
    CLI::App app{"A level of N effects (fire, steam, smoke solver, fire-to-smoke) of which 10 are in view, against a scene holding\n"
                 "only those 10, drawn headless; a camera sweep; solver catch-up error.",
                 "splatfx-bench scheduling"};
    // Strict and bounded: 100000 effects is about 100x the level this bench models.
    cli::addNumber(app, "--effects", count, 20, 100000, "effects in the level");
    CLI::Option* framesOption = cli::addNumber(app, "--frames", frames, 5, 100000, "timed frames per run");
    cli::addSize(app, "--size", size.x, size.y, 16, 8192, "frame size");
    app.add_flag("--quick", quick, "15 frames (unless --frames is given)");
    bool mixed = false;
    app.add_flag("--mixed", mixed,
                 "the mixed level instead: every kind (effects, gases, clouds, ground fog, fog terms; lit and shadow-casting), a few in view, "
                 "against only what the view needs; and the in-view pixels compared");
    std::string imagePath;
    app.add_option("--image", imagePath, "with --mixed: write the level's last frame here (PNG)")->type_name("FILE");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (quick && framesOption->count() == 0) frames = 15;
    if (mixed) return runMixed(count, frames, size, imagePath);
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "scheduling: %s\n", ctx.error().c_str());
        return 1;
    }
    splatfx::Materials m{splatfx::Footprint{}};
    splatfx::Scene level, onlySeen;
    // 10 effects in front of the camera (x in [-20, 20], z = 0); the rest on a
    // ring 60..400 units away in every direction, so the sweep meets them.
    std::printf("building %d effects ...\n", count);
    const auto buildStart = Clock::now();
    for (int i = 0; i < count; ++i) {
        glm::vec3 at;
        if (i < 10) {
            at = {-20.0f + 4.5f * i, 0.0f, 0.0f};
        } else {
            // Spread evenly around the camera (golden angle). Inside the view
            // wedge they stand beyond the range; elsewhere anywhere from 60 to
            // 400 units: culled by range or by the frustum, and met by the sweep.
            const float angle = std::fmod(2.399963f * i, 6.2831853f) - 3.1415927f; // 0 = straight ahead (-z)
            const bool ahead = std::abs(angle) < 1.0f;
            const float r = ahead ? kRange + 20.0f + 250.0f * float(i) / count : 60.0f + 340.0f * float(i) / count;
            at = {r * std::sin(angle), 0.0f, 40.0f - r * std::cos(angle)};
        }
        auto e = makeEffect(m, i, at, std::uint32_t(i + 1));
        if (!e) {
            std::fprintf(stderr, "scheduling: %s\n", e.error().c_str());
            return 1;
        }
        if (i < 10) onlySeen.add(*e, {.name = "seen " + std::to_string(i), .rangeWorld = kRange});
        level.add(std::move(*e), {.name = "effect " + std::to_string(i), .rangeWorld = kRange});
        if ((i + 1) % 200 == 0) std::printf("  %d/%d\n", i + 1, count);
    }
    std::printf("built in %.1f s: %u texture sets, %u layers (with the footprint), %u colour tables, %.2f MB of float texels\n",
                std::chrono::duration<double>(Clock::now() - buildStart).count(), m.setCount(), m.layerCount(), m.colorTableCount(),
                double(m.texelBytes()) / 1e6);

    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y});
    auto renderer = splatfx::gl::FrameRenderer::create();
    if (!fb || !renderer) {
        std::fprintf(stderr, "scheduling: %s\n", (fb ? renderer.error() : fb.error()).c_str());
        return 1;
    }
    if (splatfx::Status s = renderer->upload(m); !s) {
        std::fprintf(stderr, "scheduling: %s\n", s.error().c_str());
        return 1;
    }
    FrameDraw draw{*fb, *renderer, splatfx::Frame{}};
    std::printf("drawing at %dx%d on %s\n\n", size.x, size.y, ctx->renderer().c_str());

    const auto fixed = [&](int) { return splatfx::Camera::lookAt({0, 6, 40}, {0, 4, 0}, {0, 1, 0}, glm::radians(50.0f), size, 0.1f, 1000.0f); };
    // Warm both scenes up to the same time, then time them frame by frame
    // alternately, so machine load affects both alike: drawn full frames
    // first (what a player waits for), then the CPU part alone.
    frameCost(level, m, 10, 0.0, fixed, nullptr, &draw);
    frameCost(onlySeen, m, 10, 0.0, fixed, nullptr, &draw);
    std::vector<double> drawnLevel, drawnOnly, costsLevel, costsOnly;
    double neededLevel = 0, neededOnly = 0;
    std::uint64_t splatsLevel = 0, splatsOnly = 0;
    for (int f = 0; f < frames; ++f) {
        double n = 0;
        drawnLevel.push_back(frameCost(level, m, 1, (10 + f) / 60.0, fixed, &n, &draw));
        neededLevel += n / frames;
        splatsLevel += level.counters().splats;
        drawnOnly.push_back(frameCost(onlySeen, m, 1, (10 + f) / 60.0, fixed, &n, &draw));
        neededOnly += n / frames;
        splatsOnly += onlySeen.counters().splats;
    }
    for (int f = 0; f < frames; ++f) {
        costsLevel.push_back(frameCost(level, m, 1, (10 + frames + f) / 60.0, fixed, nullptr));
        costsOnly.push_back(frameCost(onlySeen, m, 1, (10 + frames + f) / 60.0, fixed, nullptr));
    }
    const double frameLevel = median(drawnLevel), frameOnly = median(drawnOnly);
    const double costLevel = median(costsLevel), costOnly = median(costsOnly);
    std::printf("Fixed camera, %d frames drawn at %dx%d (full frame: update + emit + sort + draw + glFinish,\n"
                "  median per frame, scenes timed alternately)\n",
                frames, size.x, size.y);
    std::printf("  %-28s %8s %10s %10s\n", "scene", "needed", "splats", "ms/frame");
    std::printf("  %-28s %8.1f %10.0f %10.3f\n", (std::to_string(count) + " effects declared").c_str(), neededLevel, double(splatsLevel) / frames,
                1e3 * frameLevel);
    std::printf("  %-28s %8.1f %10.0f %10.3f\n", "only the 10 in view", neededOnly, double(splatsOnly) / frames, 1e3 * frameOnly);
    std::printf("  ratio %.2fx (target: at most 1.5x)\n\n", frameLevel / frameOnly);
    std::printf("CPU part alone (update + emit + sort, median of %d frames, alternately)\n", frames);
    std::printf("  %-28s %10.3f ms/frame\n", (std::to_string(count) + " effects declared").c_str(), 1e3 * costLevel);
    std::printf("  %-28s %10.3f ms/frame\n", "only the 10 in view", 1e3 * costOnly);
    std::printf("  ratio %.2fx\n\n", costLevel / costOnly);

    // The sweep: a full turn in `frames * 4` frames; effects enter and leave.
    const int sweepFrames = frames * 4;
    const auto sweep = [&](int f) {
        const float a = 6.2831853f * float(f) / float(sweepFrames);
        const glm::vec3 eye(0, 6, 20);
        return splatfx::Camera::lookAt(eye, eye + glm::vec3(std::sin(a), -0.05f, -std::cos(a)), {0, 1, 0}, glm::radians(50.0f), size, 0.1f, 1000.0f);
    };
    double neededSweep = 0;
    const double costSweep = frameCost(level, m, sweepFrames, 1.0, sweep, &neededSweep, &draw);
    std::uint64_t catchUps = 0;
    for (splatfx::EffectId id = 0; id < level.size(); ++id) catchUps += level.status(id).catchUps;
    std::printf("Sweeping camera, drawn (one turn in %d frames): %.1f of %d effects needed per frame on average, %.3f ms/frame median,\n"
                "  %llu solver catch-ups on re-entry\n\n",
                sweepFrames, neededSweep, count, 1e3 * costSweep, (unsigned long long)catchUps);

    // Catch-up error: a smoke plume hidden for `gap` seconds, then brought
    // back in at most 8 coarse steps, against a twin stepped every 1/60 s.
    std::printf("Solver catch-up (smoke, 10x20x10, returning after a gap; at most 8 steps):\n");
    std::printf("  %8s %8s %12s %12s %12s\n", "gap s", "steps", "rel. L1 err", "32 steps", "total");
    for (double gap : {0.25, 0.5, 1.0, 2.0, 5.0, 10.0}) {
        auto a = splatfx::presets::smoke(m, {});
        auto c = splatfx::presets::smoke(m, {});
        auto b = splatfx::presets::smoke(m, {});
        const double warm = 2.0;
        for (int i = 0; i < int(warm * 60); ++i) a->step(1.0 / 60), b->step(1.0 / 60), c->step(1.0 / 60);
        for (int i = 0; i < int(std::round(gap * 60)); ++i) b->step(1.0 / 60);
        const splatfx::EffectOptions opts;
        // The kind's own catch-up (what Scene runs on re-entry), with the step cap varied.
        auto catchUp = [&](splatfx::Effect& e, int maxSteps) {
            const splatfx::AdvanceContext ctx{.catchUpStepSec = opts.catchUpStepSec, .maxCatchUpSteps = maxSteps, .resumed = true};
            return e.advanceTo(e.time() + gap, ctx).steps;
        };
        const int n = catchUp(*a, opts.maxCatchUpSteps);
        catchUp(*c, 32);
        auto error = [&](const splatfx::Effect& e) {
            const auto& da = e.solver()->density();
            const auto& db = b->solver()->density();
            double diff = 0, total = 0;
            for (size_t i = 0; i < da.size(); ++i) diff += std::abs(double(da[i]) - db[i]), total += db[i];
            return diff / total;
        };
        std::printf("  %8.2f %8d %12.4f %12.4f %12.2f\n", gap, n, error(*a), error(*c), b->solver()->totalDensity());
    }
    return 0;
}
} // namespace scheduling_cmd

int runScheduling(int argc, char** argv) { return scheduling_cmd::runScheduling(argc, argv); }
