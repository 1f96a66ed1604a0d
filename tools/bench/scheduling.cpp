// splatfx-bench scheduling: what a level of 1000 effects costs when only a
// few are seen (issue 6), and the error of a solver effect's catch-up.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "cli.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/scene.hpp"

namespace {

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

// Median CPU seconds per frame of scene.update + emit + sort over `frames`.
double frameCost(splatfx::Scene& scene, splatfx::Materials& m, int frames, double t0,
                 const std::function<splatfx::Camera(int)>& camera, double* neededAvg) {
    splatfx::SplatBuilder builder;
    std::vector<double> t;
    double needed = 0;
    for (int f = 0; f < frames; ++f) {
        const splatfx::Camera cam = camera(f);
        const auto a = Clock::now();
        scene.update(t0 + f / 60.0, cam);
        builder.begin(cam);
        scene.emit(builder, m);
        builder.sort();
        t.push_back(std::chrono::duration<double>(Clock::now() - a).count());
        needed += double(scene.counters().needed);
    }
    if (neededAvg) *neededAvg = needed / frames;
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}

} // namespace

int runScheduling(int argc, char** argv) {
    int count = 1000, frames = 60;
    for (int i = 1; i < argc; ++i) { // argv[0] is the subcommand
        const std::string a = argv[i];
        // Strict and bounded (tools/common/cli.hpp): 100000 effects is about 100x the level this bench models.
        splatfx::Status st;
        if (a == "--effects" && i + 1 < argc) st = cli::parseInt("--effects", argv[++i], 20, 100000, count);
        else if (a == "--frames" && i + 1 < argc) st = cli::parseInt("--frames", argv[++i], 5, 100000, frames);
        else if (a == "--quick") frames = 15;
        else {
            std::printf("splatfx-bench scheduling [--effects N] [--frames N] [--quick]\n"
                        "  A level of N effects (fire, steam, smoke solver, fire-to-smoke) of which 10 are in view,\n"
                        "  against a scene holding only those 10; a camera sweep; solver catch-up error.\n");
            return a == "--help" || a == "-h" ? 0 : 2;
        }
        if (!st) {
            std::fprintf(stderr, "scheduling: %s\n", st.error().c_str());
            return 2;
        }
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
    std::printf("built in %.1f s\n\n", std::chrono::duration<double>(Clock::now() - buildStart).count());

    const auto fixed = [](int) {
        return splatfx::Camera::lookAt({0, 6, 40}, {0, 4, 0}, {0, 1, 0}, glm::radians(50.0f), {1280, 720}, 0.1f, 1000.0f);
    };
    // Warm both scenes up to the same time, then time them frame by frame
    // alternately, so machine load affects both alike.
    frameCost(level, m, 10, 0.0, fixed, nullptr);
    frameCost(onlySeen, m, 10, 0.0, fixed, nullptr);
    std::vector<double> costsLevel, costsOnly;
    double neededLevel = 0, neededOnly = 0;
    for (int f = 0; f < frames; ++f) {
        double n = 0;
        costsLevel.push_back(frameCost(level, m, 1, (10 + f) / 60.0, fixed, &n));
        neededLevel += n / frames;
        costsOnly.push_back(frameCost(onlySeen, m, 1, (10 + f) / 60.0, fixed, &n));
        neededOnly += n / frames;
    }
    std::sort(costsLevel.begin(), costsLevel.end());
    std::sort(costsOnly.begin(), costsOnly.end());
    const double costLevel = costsLevel[costsLevel.size() / 2], costOnly = costsOnly[costsOnly.size() / 2];
    std::printf("Fixed camera, %d frames (CPU: update + emit + sort, median per frame, scenes timed alternately)\n", frames);
    std::printf("  %-28s %8s %10s\n", "scene", "needed", "ms/frame");
    std::printf("  %-28s %8.1f %10.3f\n", (std::to_string(count) + " effects declared").c_str(), neededLevel, 1e3 * costLevel);
    std::printf("  %-28s %8.1f %10.3f\n", "only the 10 in view", neededOnly, 1e3 * costOnly);
    std::printf("  ratio %.2fx (target: at most 1.5x)\n\n", costLevel / costOnly);

    // The sweep: a full turn in `frames * 4` frames; effects enter and leave.
    const int sweepFrames = frames * 4;
    const auto sweep = [&](int f) {
        const float a = 6.2831853f * float(f) / float(sweepFrames);
        const glm::vec3 eye(0, 6, 20);
        return splatfx::Camera::lookAt(eye, eye + glm::vec3(std::sin(a), -0.05f, -std::cos(a)), {0, 1, 0}, glm::radians(50.0f),
                                       {1280, 720}, 0.1f, 1000.0f);
    };
    double neededSweep = 0;
    const double costSweep = frameCost(level, m, sweepFrames, 1.0, sweep, &neededSweep);
    std::uint64_t catchUps = 0;
    for (splatfx::EffectId id = 0; id < level.size(); ++id) catchUps += level.status(id).catchUps;
    std::printf("Sweeping camera (one turn in %d frames): %.1f of %d effects needed per frame on average, %.3f ms/frame median,\n"
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
        auto catchUp = [&](splatfx::Effect& e, int maxSteps) {
            const int n = std::clamp(int(std::ceil(gap / opts.catchUpStepSec)), 1, maxSteps);
            for (int i = 0; i < n; ++i) e.step(gap / n);
            return n;
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
