// splatfx-bench soak: every preset simulated for a long stretch of scene time
// at a fixed 60 Hz step (issue 13, item 9), checking what a game running for
// hours relies on: no NaN or Inf ever enters the grids (or a solver's fields),
// Effect::bounds stays flat (does not grow without limit), and the process's
// resident memory stays flat. Prints a table; exits 1 if any preset fails.
// CPU only: no GL context is needed (simulation never touches GL).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <string>
#include <unistd.h>
#include <vector>

#include "options.hpp"
#include "commands.hpp"
#include "splatfx/splatfx.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// Resident set size from /proc/self/statm (second field, in pages).
double rssMiB() {
    std::ifstream in("/proc/self/statm");
    long long size = 0, resident = 0;
    in >> size >> resident;
    return in ? double(resident) * double(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0) : -1.0;
}

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The first non-finite value in the effect's grids and solver fields, or "".
std::string firstNonFinite(const splatfx::Effect& e) {
    auto checkGrid = [](const splatfx::Grid& g, const char* which) -> std::string {
        for (size_t i = 0; i < g.voxels.size(); ++i) {
            const splatfx::Voxel& v = g.voxels[i];
            if (!std::isfinite(v.opacity) || !std::isfinite(v.colorCoord) || !std::isfinite(v.phase) || !finite3(v.stretch))
                return std::string(which) + " voxel " + std::to_string(i);
        }
        return "";
    };
    if (std::string w = checkGrid(e.grid(), "grid"); !w.empty()) return w;
    for (size_t l = 0; l < e.layerCount(); ++l)
        if (std::string w = checkGrid(e.layerGrid(l), "layer grid"); !w.empty()) return w + " (layer " + std::to_string(l) + ")";
    if (const splatfx::FluidSolver* s = e.solver()) {
        for (size_t i = 0; i < s->density().size(); ++i)
            if (!std::isfinite(s->density()[i])) return "solver density cell " + std::to_string(i);
        for (size_t i = 0; i < s->temperature().size(); ++i)
            if (!std::isfinite(s->temperature()[i])) return "solver temperature cell " + std::to_string(i);
        if (!std::isfinite(s->maxSpeed())) return "solver velocity";
    }
    return "";
}

struct Preset {
    const char* name;
    std::function<splatfx::Result<splatfx::Effect>(splatfx::Materials&)> make;
};

struct Outcome {
    std::string name;
    long long steps = 0;
    double wallSec = 0.0;
    std::string nonFinite; // where the first NaN/Inf appeared ("" = none)
    double nonFiniteAtSec = 0.0;
    splatfx::Aabb firstBox, lastBox; // union of bounds over the first and the last tenth of the run
    double rssFirstMiB = 0.0, rssLastMiB = 0.0;
    // What the bounds do not show: live voxels and (solvers) total density,
    // largest over the first and the last tenth, so a slow build-up is visible.
    std::size_t voxelsFirst = 0, voxelsLast = 0;
    double massFirst = 0.0, massLast = 0.0;
    bool boundsFlat = true, memoryFlat = true;
};

glm::vec3 extent(const splatfx::Aabb& b) { return b.empty() ? glm::vec3(0.0f) : b.hi - b.lo; }

} // namespace

int runSoak(int argc, char** argv) {
    double minutes = 60.0;
    std::string only;
    CLI::App app{"Steps every preset (fire, smoke, steam, dust, fireToSmoke, ghosts) at 60 Hz for M minutes of scene time (default 60:\n"
                 "216000 steps each), checking every step for NaN/Inf in the grids and solver fields, and that Effect::bounds and the\n"
                 "resident memory (/proc/self/statm) stay flat. Exit 1 on any failure.",
                 "splatfx-bench soak"};
    cli::addNumber(app, "--minutes", minutes, 0.1, 24.0 * 60.0, "minutes of scene time per preset");
    app.add_option("--preset", only, "only this preset")->type_name("NAME");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    namespace P = splatfx::presets;
    const std::vector<Preset> presets = {
        {"fire", [](splatfx::Materials& m) { return P::fire(m); }},
        {"smoke", [](splatfx::Materials& m) { return P::smoke(m); }},
        {"steam", [](splatfx::Materials& m) { return P::steam(m); }},
        {"dust", [](splatfx::Materials& m) { return P::dust(m); }},
        {"fireToSmoke", [](splatfx::Materials& m) { return P::fireToSmoke(m); }},
        {"ghosts", [](splatfx::Materials& m) { return P::ghosts(m); }},
    };
    bool known = only.empty();
    for (const Preset& p : presets) known = known || only == p.name;
    if (!known) {
        std::fprintf(stderr, "soak: --preset must be fire, smoke, steam, dust, fireToSmoke or ghosts, got '%s'\n", only.c_str());
        return 2;
    }

    const double dt = 1.0 / 60.0;
    const long long steps = std::llround(minutes * 60.0 * 60.0);
    const long long tenth = std::max(1ll, steps / 10);
    // Bounds are sampled once per scene second (and at the window edges);
    // the check itself runs every step.
    const long long boundsEvery = 60;
    std::printf("splatfx-bench soak: %.1f min of scene time per preset at 60 Hz = %lld steps, NaN/Inf checked every step\n", minutes, steps);
    std::vector<Outcome> out;
    for (const Preset& p : presets) {
        if (!only.empty() && only != p.name) continue;
        Outcome o;
        o.name = p.name;
        {
            splatfx::Materials materials(splatfx::Footprint{});
            auto made = p.make(materials);
            if (!made) {
                std::fprintf(stderr, "soak: %s: %s\n", p.name, made.error().c_str());
                return 1;
            }
            splatfx::Effect& e = *made;
            const auto start = Clock::now();
            for (long long k = 1; k <= steps; ++k) {
                e.step(dt);
                if (o.nonFinite.empty()) {
                    o.nonFinite = firstNonFinite(e);
                    if (!o.nonFinite.empty()) o.nonFiniteAtSec = e.time();
                }
                const bool inFirst = k <= tenth, inLast = k > steps - tenth;
                if ((inFirst || inLast) && (k % boundsEvery == 0 || k == tenth || k == steps)) {
                    const splatfx::Aabb b = e.bounds(e.time(), e.time());
                    (inFirst ? o.firstBox : o.lastBox).extend(b);
                    std::size_t& vox = inFirst ? o.voxelsFirst : o.voxelsLast;
                    double& mass = inFirst ? o.massFirst : o.massLast;
                    vox = std::max(vox, e.grid().voxels.size());
                    if (e.solver()) mass = std::max(mass, e.solver()->totalDensity());
                    if (inFirst && inLast) o.lastBox.extend(b); // runs shorter than 10 steps
                }
                if (k == tenth) o.rssFirstMiB = rssMiB();
                if (k % 36000 == 0) {
                    std::printf("\r  %s: %lld / %lld steps", p.name, k, steps);
                    std::fflush(stdout);
                }
            }
            o.rssLastMiB = rssMiB();
            o.wallSec = std::chrono::duration<double>(Clock::now() - start).count();
            o.steps = steps;
        }
        // Flat bounds: the last tenth's box lies inside the first tenth's,
        // allowing 1e-4 of its extent per side for float rounding of the
        // motion matrices (presets at rest give identical boxes).
        const glm::vec3 slack = 1e-4f * glm::max(extent(o.firstBox), glm::vec3(1.0f));
        o.boundsFlat = !o.firstBox.empty() && !o.lastBox.empty() && glm::all(glm::greaterThanEqual(o.lastBox.lo, o.firstBox.lo - slack)) &&
                       glm::all(glm::lessThanEqual(o.lastBox.hi, o.firstBox.hi + slack));
        // Flat memory: steady-state stepping should allocate nothing that it
        // keeps; 1 MiB over the last 90% of 216000 steps is under 6 bytes a
        // step, so any per-step leak shows, while allocator page noise does not.
        o.memoryFlat = o.rssLastMiB - o.rssFirstMiB <= 1.0;
        std::printf("\r  %s: %lld steps in %.1f s%30s\n", p.name, steps, o.wallSec, "");
        out.push_back(o);
    }

    std::printf("\n| preset | steps | scene time | wall s | us/step | NaN/Inf | bounds extent, first 10%% -> last 10%% | RSS MiB, at 10%% -> end | "
                "max voxels, first -> last 10%% | max solver density sum | verdict |\n"
                "|---|---:|---:|---:|---:|---|---|---|---|---|---|\n");
    bool ok = true;
    for (const Outcome& o : out) {
        const glm::vec3 a = extent(o.firstBox), b = extent(o.lastBox);
        const bool pass = o.nonFinite.empty() && o.boundsFlat && o.memoryFlat;
        ok = ok && pass;
        const std::string nan = o.nonFinite.empty() ? "none" : o.nonFinite + " at " + std::to_string(o.nonFiniteAtSec) + " s";
        char mass[64] = "-";
        if (o.massFirst > 0.0 || o.massLast > 0.0) std::snprintf(mass, sizeof mass, "%.1f -> %.1f", o.massFirst, o.massLast);
        std::printf(
            "| %s | %lld | %.1f min | %.1f | %.1f | %s | %.2f x %.2f x %.2f -> %.2f x %.2f x %.2f%s | %.1f -> %.1f%s | %zu -> %zu | %s | %s |\n",
            o.name.c_str(), o.steps, o.steps * dt / 60.0, o.wallSec, 1e6 * o.wallSec / double(o.steps), nan.c_str(), a.x, a.y, a.z, b.x, b.y, b.z,
            o.boundsFlat ? "" : " (GROWS)", o.rssFirstMiB, o.rssLastMiB, o.memoryFlat ? "" : " (GROWS)", o.voxelsFirst, o.voxelsLast, mass,
            pass ? "pass" : "FAIL");
    }
    std::printf("\nsoak: %s\n", ok ? "every preset stayed finite with flat bounds and memory" : "FAILED (see the table)");
    return ok ? 0 : 1;
}
