// splatfx-bench soak: every preset simulated for a long stretch of scene time
// at a fixed 60 Hz step, checking what a game running for hours relies on: no
// NaN or Inf ever enters the grids (or a solver's fields), Effect::bounds
// stays flat (does not grow without limit), and the process's resident memory
// stays flat. Then the kinds a Scene draws beyond presets (a procedural gas,
// LOD clouds, LOD ground fog, lit effects with self-shadowing tables and the
// scene shadow) through Scene::prepare over the same hour, with an orbiting
// camera: every splat, tetrahedron and shadow-table value finite, no lighting
// error, memory flat. Prints two tables; exits 1 if anything fails.
// CPU only: no GL context is needed (simulation never touches GL).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <unistd.h>
#include <vector>

#include "options.hpp"
#include "commands.hpp"
#include "splatfx/splatfx.hpp"

namespace soak_cmd { // one namespace per command: the commands build as one unity translation unit

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

// A particle effect's splats now (its grid holds no voxels): the first
// non-finite one, or "". The camera looks at the effect's bounds from afar so
// every particle is in view and none is culled.
std::string firstNonFiniteSplat(const splatfx::Effect& e, const splatfx::Materials& materials, splatfx::SplatBuilder& builder) {
    const splatfx::Aabb b = e.bounds(e.time(), e.time());
    if (b.empty()) return "";
    if (!finite3(b.lo) || !finite3(b.hi)) return "bounds";
    const glm::vec3 c = 0.5f * (b.lo + b.hi);
    const float r = std::max(glm::length(b.hi - b.lo), 1.0f);
    builder.begin(splatfx::Camera::lookAt(c + glm::vec3(0.0f, 0.3f * r, 2.0f * r), c, {0, 1, 0}, 1.2f, {320, 240}, 0.1f * r, 10.0f * r));
    e.emit(builder, materials);
    for (std::size_t i = 0; i < builder.splats().size(); ++i) {
        const splatfx::Splat& s = builder.splats()[i];
        if (!finite3(s.center) || !finite3(s.axisU) || !finite3(s.axisV) || !std::isfinite(s.density) || !std::isfinite(s.colorCoord) ||
            !std::isfinite(s.depth))
            return "splat " + std::to_string(i);
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

// ---- Scene kinds ---------------------------------------------------------

// One scene of the second table: a scene file's text (its relative paths
// resolve in the soak's scratch folder) and the point the camera orbits.
struct SceneCase {
    const char* name;
    const char* text;
    glm::vec3 target;
    float radius, height;
};

// Small versions of the samples' kinds, so an hour stays minutes of CPU.
const std::vector<SceneCase>& sceneCases() {
    static const std::vector<SceneCase> cases = {
        {"gas (lit, table)",
         R"({"format": "splatfx-scene", "version": 1, "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3]}],
             "effects": [{"name": "fog", "kind": "gas", "dims": [16, 5, 16], "spacing": 0.22, "opacity": 0.4,
               "gas": {"type": "fog", "turbulence": {"seed": 7, "octaves": 4, "frequency": 1.2}, "frontStart": -2.6, "frontSpeed": 1.1,
                       "swirlPeriodSec": 6, "driftPerSec": 0.3, "fullDensitySec": 2.5},
               "lighting": {"albedo": 0.75, "selfShadow": "table", "tableDims": 24}}]})",
         {1.8f, 0.4f, 1.8f}, 5.0f, 2.0f},
        {"fireToSmoke (lit, table, scene shadow)",
         R"({"format": "splatfx-scene", "version": 1, "lights": [{"type": "directional", "direction": [-0.8, -0.45, -0.3]}],
             "sceneShadow": {"dims": 32},
             "effects": [{"name": "plume", "kind": "fireToSmoke",
               "lighting": {"albedo": 0.6, "emission": 0.4, "selfShadow": "table", "tableDims": 24}}]})",
         {0.0f, 6.0f, 0.0f}, 20.0f, 6.0f},
        {"clouds (LOD)",
         R"({"format": "splatfx-scene", "version": 1,
             "volumes": [{"name": "cumulus", "kind": "clouds", "dims": [33, 9, 33], "spacing": 2, "position": [-32, 10, -32],
               "tableScalars": 32, "tableLengths": 64}]})",
         {0.0f, 18.0f, 0.0f}, 70.0f, 30.0f},
        {"groundFog (LOD)",
         R"({"format": "splatfx-scene", "version": 1,
             "volumes": [{"name": "valley", "kind": "groundFog", "heightmap": "soak_terrain.pgm", "spacing": 1.0, "heightScale": 12,
               "fogTop": 6, "lod": true, "tableScalars": 32, "tableLengths": 64}]})",
         {0.0f, 4.0f, 0.0f}, 60.0f, 25.0f},
    };
    return cases;
}

// A 65 x 65 8-bit heightmap of two ridges and a valley (for the ground fog).
bool writeTerrain(const std::filesystem::path& file) {
    std::ofstream out(file, std::ios::binary);
    out << "P5\n65 65\n255\n";
    for (int j = 0; j < 65; ++j)
        for (int i = 0; i < 65; ++i) {
            const double x = (i - 32) / 32.0, z = (j - 32) / 32.0;
            const double h = 0.5 + 0.4 * std::sin(3.0 * x) * std::cos(2.0 * z) + 0.1 * x * x;
            out.put(char(std::clamp(int(std::lround(255.0 * std::clamp(h, 0.0, 1.0))), 0, 255)));
        }
    return bool(out);
}

// The first non-finite value the frame holds (splats, tetrahedra, the scene shadow), or "".
std::string firstNonFinite(const splatfx::Frame& f) {
    for (std::size_t i = 0; i < f.splats().size(); ++i) {
        const splatfx::Splat& s = f.splats()[i];
        if (!finite3(s.center) || !finite3(s.axisU) || !finite3(s.axisV) || !std::isfinite(s.density) || !std::isfinite(s.colorCoord) ||
            !std::isfinite(s.depth))
            return "splat " + std::to_string(i);
    }
    for (std::size_t v = 0; v < f.volumes().size(); ++v)
        for (std::size_t i = 0; i < f.volumes()[v].lod.tets.size(); ++i) {
            const splatfx::Tetrahedron& t = f.volumes()[v].lod.tets[i];
            for (int k = 0; k < 4; ++k)
                if (!finite3(t.position[k]) || !std::isfinite(t.scalar[k]) || !std::isfinite(t.lengthScale[k]))
                    return "volume " + std::to_string(v) + " tetrahedron " + std::to_string(i);
        }
    if (f.shadow().valid)
        for (std::size_t i = 0; i < f.shadow().depth.size(); ++i)
            if (!std::isfinite(f.shadow().depth[i])) return "scene shadow entry " + std::to_string(i);
    return "";
}

struct SceneOutcome {
    std::string name;
    long long frames = 0;
    double wallSec = 0.0;
    std::string problem; // first non-finite value or failure ("" = none)
    double problemAtSec = 0.0;
    double rssFirstMiB = 0.0, rssLastMiB = 0.0;
    std::size_t drawnFirst = 0, drawnLast = 0; // largest splats + tetrahedra a frame, first and last tenth
    std::uint64_t tableBuilds = 0, litFrames = 0;
    bool memoryFlat = true;
};

} // namespace

namespace {

// Each scene case prepared at `fps` for `minutes` of scene time, the camera
// orbiting its target once a minute (so LOD refinement, culling and the
// view-dependent lighting change every frame). False if any case fails.
bool soakScenes(double minutes, double fps) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path dir = fs::temp_directory_path(ec) / ("splatfx-soak-" + std::to_string(::getpid()));
    fs::create_directories(dir, ec);
    if (ec || !writeTerrain(dir / "soak_terrain.pgm")) {
        std::fprintf(stderr, "soak: cannot write the ground fog's heightmap in %s\n", dir.string().c_str());
        return false;
    }
    const long long frames = std::llround(minutes * 60.0 * fps);
    const long long tenth = std::max(1ll, frames / 10);
    // Memory is judged from the later of 10% and 30 scene seconds: a gas
    // front and a plume fill their domains first (the presets are at rest).
    const long long settle = std::max(tenth, std::llround(30.0 * fps));
    const bool judgeMemory = settle < frames;
    std::printf("\nScene kinds: %.1f min of scene time each at %.0f frames a second = %lld Scene::prepare calls, every value of every "
                "frame checked\n",
                minutes, fps, frames);
    std::vector<SceneOutcome> out;
    for (const SceneCase& c : sceneCases()) {
        SceneOutcome o;
        o.name = c.name;
        {
            splatfx::Materials materials(splatfx::Footprint{});
            auto file = splatfx::parseSceneFile(c.text, (dir / "soak.json").string(), materials);
            if (!file) {
                std::fprintf(stderr, "soak: %s: %s\n", c.name, file.error().c_str());
                fs::remove_all(dir, ec);
                return false;
            }
            splatfx::Frame frame;
            const auto start = Clock::now();
            for (long long k = 0; k < frames && o.problem.empty(); ++k) {
                const double t = double(k) / fps;
                const double a = 2.0 * 3.14159265358979 * t / 60.0;
                const glm::vec3 eye = c.target + glm::vec3(c.radius * float(std::sin(a)), c.height, c.radius * float(std::cos(a)));
                const auto cam = splatfx::Camera::lookAt(eye, c.target, {0, 1, 0}, 0.9f, {320, 240}, 0.1f, 1000.0f);
                if (splatfx::Status st = file->scene.prepare(t, cam, materials, frame); !st)
                    o.problem = st.error();
                else if (!file->scene.lightingError().empty())
                    o.problem = file->scene.lightingError();
                else
                    o.problem = firstNonFinite(frame);
                if (!o.problem.empty()) o.problemAtSec = t;
                o.tableBuilds += frame.counters().shadowTableBuilds;
                o.litFrames += frame.counters().litEffects > 0 ? 1 : 0;
                std::size_t drawn = frame.splats().size();
                for (const splatfx::FrameVolume& v : frame.volumes()) drawn += v.lod.tets.size();
                if (k < tenth) o.drawnFirst = std::max(o.drawnFirst, drawn);
                if (k >= frames - tenth) o.drawnLast = std::max(o.drawnLast, drawn);
                if (k + 1 == settle) o.rssFirstMiB = rssMiB();
                if (k % 600 == 0) {
                    std::printf("\r  %s: %lld / %lld frames", c.name, k, frames);
                    std::fflush(stdout);
                }
            }
            o.rssLastMiB = rssMiB();
            o.wallSec = std::chrono::duration<double>(Clock::now() - start).count();
            o.frames = frames;
        }
        // As the presets: 1 MiB over the last 90% of the frames shows any
        // per-frame leak (36000 frames an hour: under 30 bytes a frame).
        o.memoryFlat = !judgeMemory || o.rssLastMiB - o.rssFirstMiB <= 1.0;
        std::printf("\r  %s: %lld frames in %.1f s%30s\n", c.name, frames, o.wallSec, "");
        out.push_back(o);
    }
    fs::remove_all(dir, ec);
    std::printf("\n| scene | frames | scene time | wall s | ms/frame | NaN/Inf or error | RSS MiB, at max(10%%, 30 s) -> end | splats + tetrahedra a frame, "
                "max first -> last 10%% | lit frames | table builds | verdict |\n"
                "|---|---:|---:|---:|---:|---|---|---|---:|---:|---|\n");
    bool ok = true;
    for (const SceneOutcome& o : out) {
        const bool pass = o.problem.empty() && o.memoryFlat;
        ok = ok && pass;
        const std::string bad = o.problem.empty() ? "none" : o.problem + " at " + std::to_string(o.problemAtSec) + " s";
        char rss[64] = "not judged (under 30 s)";
        if (judgeMemory) std::snprintf(rss, sizeof rss, "%.1f -> %.1f%s", o.rssFirstMiB, o.rssLastMiB, o.memoryFlat ? "" : " (GROWS)");
        std::printf("| %s | %lld | %.1f min | %.1f | %.2f | %s | %s | %zu -> %zu | %llu | %llu | %s |\n", o.name.c_str(), o.frames,
                    double(o.frames) / fps / 60.0, o.wallSec, 1e3 * o.wallSec / double(std::max(1ll, o.frames)), bad.c_str(), rss, o.drawnFirst, o.drawnLast, (unsigned long long)o.litFrames,
                    (unsigned long long)o.tableBuilds, pass ? "pass" : "FAIL");
    }
    return ok;
}

} // namespace

int runSoak(int argc, char** argv) {
    double minutes = 60.0;
    std::string only;
    CLI::App app{"Steps every preset (fire, smoke, steam, dust, fireToSmoke, ghosts, embers) at 60 Hz for M minutes of scene time (default 60:\n"
                 "216000 steps each), checking every step for NaN/Inf in the grids and solver fields (embers: its splats), and that Effect::bounds and the\n"
                 "resident memory (/proc/self/statm) stay flat; then a lit gas, a lit fireToSmoke with the scene shadow, LOD clouds and\n"
                 "LOD ground fog through Scene::prepare at --scene-fps with an orbiting camera: every splat, tetrahedron and shadow\n"
                 "value finite, no lighting error, memory flat. Exit 1 on any failure.",
                 "splatfx-bench soak"};
    double sceneFps = 4.0;
    bool presetsOnly = false, scenesOnly = false;
    cli::addNumber(app, "--minutes", minutes, 0.1, 24.0 * 60.0, "minutes of scene time per preset and per scene");
    app.add_option("--preset", only, "only this preset (no scenes)")->type_name("NAME");
    cli::addNumber(app, "--scene-fps", sceneFps, 1.0, 240.0, "frames a scene second for the scene kinds (Scene::prepare)");
    app.add_flag("--presets-only", presetsOnly, "only the presets' table");
    app.add_flag("--scenes-only", scenesOnly, "only the scene kinds' table");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    namespace P = splatfx::presets;
    const std::vector<Preset> presets = {
        {"fire", [](splatfx::Materials& m) { return P::fire(m); }},
        {"smoke", [](splatfx::Materials& m) { return P::smoke(m); }},
        {"steam", [](splatfx::Materials& m) { return P::steam(m); }},
        {"dust", [](splatfx::Materials& m) { return P::dust(m); }},
        {"fireToSmoke", [](splatfx::Materials& m) { return P::fireToSmoke(m); }},
        {"ghosts", [](splatfx::Materials& m) { return P::ghosts(m); }},
        {"embers", [](splatfx::Materials& m) { return P::embers(m); }},
    };
    bool known = only.empty();
    for (const Preset& p : presets) known = known || only == p.name;
    if (!known) {
        std::fprintf(stderr, "soak: --preset must be fire, smoke, steam, dust, fireToSmoke, ghosts or embers, got '%s'\n", only.c_str());
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
        if ((!only.empty() && only != p.name) || scenesOnly) continue;
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
            // A particle effect (embers) holds no voxels: its splats are checked instead.
            const bool particles = e.grid().voxels.empty() && !e.solver() && e.isStateless();
            splatfx::SplatBuilder builder;
            const auto start = Clock::now();
            for (long long k = 1; k <= steps; ++k) {
                e.step(dt);
                if (o.nonFinite.empty()) {
                    o.nonFinite = particles ? firstNonFiniteSplat(e, materials, builder) : firstNonFinite(e);
                    if (!o.nonFinite.empty()) o.nonFiniteAtSec = e.time();
                }
                const bool inFirst = k <= tenth, inLast = k > steps - tenth;
                if ((inFirst || inLast) && (k % boundsEvery == 0 || k == tenth || k == steps)) {
                    const splatfx::Aabb b = e.bounds(e.time(), e.time());
                    (inFirst ? o.firstBox : o.lastBox).extend(b);
                    std::size_t& vox = inFirst ? o.voxelsFirst : o.voxelsLast;
                    double& mass = inFirst ? o.massFirst : o.massLast;
                    vox = std::max(vox, particles ? builder.splats().size() : e.grid().voxels.size()); // embers: splats drawn
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

    if (!out.empty())
        std::printf("\n| preset | steps | scene time | wall s | us/step | NaN/Inf | bounds extent, first 10%% -> last 10%% | RSS MiB, at max(10%%, 30 s) -> end | "
                "max voxels (embers: splats), first -> last 10%% | max solver density sum | verdict |\n"
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
    if (only.empty() && !presetsOnly) ok = soakScenes(minutes, sceneFps) && ok;
    std::printf("\nsoak: %s\n", ok ? "every preset and scene stayed finite with flat bounds and memory" : "FAILED (see the tables)");
    return ok ? 0 : 1;
}
} // namespace soak_cmd

int runSoak(int argc, char** argv) { return soak_cmd::runSoak(argc, argv); }
