// splatfx-bench shadows --lights: every light casts (issue 27 item 1). A
// plume over the ground lit by 1 to 4 lights (sun, torch, spot, moon), each
// with its own scene-shadow table: the cost per frame of Scene::prepare when
// every light moves (every table rebuilt) and when none does (reused),
// against tracing the ground's transmittance to each light (what a host
// without tables would pay), and the ground's transmittance error against
// tracing. Then a point light inside the plume: the box table
// (ShadowTable, what the Scene uses for every light) against a table in the
// point light's own parameterisation (direction x distance, built here for
// the comparison) at the same memory, both against tracing.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "commands.hpp"
#include "knob_table.hpp"
#include "splatfx/scene.hpp"

namespace shadow_lights_cmd { // one namespace per command: the commands build as one unity translation unit

using namespace splatfx;

namespace {

double cpuMs(std::clock_t a, std::clock_t b) { return 1000.0 * double(b - a) / CLOCKS_PER_SEC; }

// A plume: a Gaussian column 2 wide and 3.2 tall, densest low, its base 1 above the ground.
Grid plume() {
    Grid g = *Grid::box({20, 32, 20}, glm::vec3(0.1f));
    for (Voxel& v : g.voxels) {
        const glm::vec3 c = glm::vec3(v.cell) - glm::vec3(9.5f, 0.0f, 9.5f);
        const float r2 = (c.x * c.x + c.z * c.z) / (4.5f * 4.5f), y = float(v.cell.y) / 31.0f;
        v.opacity = 0.35f * std::exp(-r2) * (1.0f - 0.7f * y);
    }
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-1.0f, 1.0f, -1.0f));
    return g;
}

// The four lights, in the order they are added; `phase` moves each a little.
Light lightAt(int i, float phase) {
    const float s = std::sin(phase), c = std::cos(phase);
    switch (i) {
    case 0: return Light::directional({0.35f + 0.05f * s, -1.0f, 0.2f});
    case 1: return Light::point({2.6f + 0.1f * c, 3.2f, 0.4f}, {1.0f, 0.6f, 0.3f}, 6.0f);
    case 2: return Light::spot({-3.5f, 6.0f + 0.1f * s, 0.5f}, {3.5f, -4.0f, -0.5f}, 0.3f, 0.5f);
    default: return Light::directional({-0.5f, -1.0f, -0.3f + 0.05f * c}, {0.6f, 0.7f, 1.0f}, 0.4f);
    }
}

// The ground a host shades: 160 x 120 points over [-6, 6] x [-4.5, 4.5] at y = 0.
std::vector<glm::vec3> groundPoints() {
    std::vector<glm::vec3> p;
    for (int j = 0; j < 120; ++j)
        for (int i = 0; i < 160; ++i) p.push_back({-6.0f + 12.0f * (float(i) + 0.5f) / 160.0f, 0.0f, -4.5f + 9.0f * (float(j) + 0.5f) / 120.0f});
    return p;
}

// A point light's table in its own parameterisation: for each direction of a
// cube map (6 faces of m x m texels) the optical depth at R distances from
// the light, accumulated outwards along the ray (exact along each ray, up to
// DensityField::opticalDepth's rounding), so only the angular interpolation errs.
struct SphericalTable {
    int m = 0, radial = 0;
    float rMax = 0.0f;
    glm::vec3 light{0.0f};
    std::vector<float> depth; // [face][v][u][k]

    static glm::vec3 direction(int face, float u, float v) { // u, v in [-1, 1]
        const int axis = face / 2;
        const float sign = face % 2 ? -1.0f : 1.0f;
        glm::vec3 d(0.0f);
        d[axis] = sign;
        d[(axis + 1) % 3] = u;
        d[(axis + 2) % 3] = v;
        return glm::normalize(d);
    }
    void build(const DensityField& f, glm::vec3 at, int mIn, int radialIn) {
        m = mIn, radial = radialIn, light = at;
        rMax = 0.0f;
        for (int c = 0; c < 8; ++c) {
            const glm::vec3 corner((c & 1) ? f.boundsMax().x : f.boundsMin().x, (c & 2) ? f.boundsMax().y : f.boundsMin().y,
                                   (c & 4) ? f.boundsMax().z : f.boundsMin().z);
            rMax = std::max(rMax, glm::length(corner - at));
        }
        depth.assign(std::size_t(6 * m * m * radial), 0.0f);
        for (int face = 0; face < 6; ++face)
            for (int v = 0; v < m; ++v)
                for (int u = 0; u < m; ++u) {
                    const glm::vec3 d = direction(face, (2.0f * float(u) + 1.0f) / float(m) - 1.0f, (2.0f * float(v) + 1.0f) / float(m) - 1.0f);
                    float* out = &depth[std::size_t(((face * m + v) * m + u) * radial)];
                    for (int k = 1; k < radial; ++k) {
                        const float r0 = rMax * float(k - 1) / float(radial - 1), r1 = rMax * float(k) / float(radial - 1);
                        out[k] = out[k - 1] + f.opticalDepth(at + d * r0, at + d * r1);
                    }
                }
    }
    float at(int face, int u, int v, float rk) const {
        u = std::clamp(u, 0, m - 1), v = std::clamp(v, 0, m - 1);
        const float* p = &depth[std::size_t(((face * m + v) * m + u) * radial)];
        const int k0 = std::clamp(int(std::floor(rk)), 0, radial - 1), k1 = std::min(k0 + 1, radial - 1);
        const float t = std::clamp(rk - float(k0), 0.0f, 1.0f);
        return p[k0] + (p[k1] - p[k0]) * t;
    }
    float opticalDepth(glm::vec3 p) const {
        const glm::vec3 w = p - light;
        const float r = glm::length(w);
        if (!(r > 0.0f)) return 0.0f;
        const glm::vec3 a = glm::abs(w);
        const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
        const int face = 2 * axis + (w[axis] < 0.0f ? 1 : 0);
        const float u = w[(axis + 1) % 3] / a[axis], v = w[(axis + 2) % 3] / a[axis];
        const float fu = (u + 1.0f) * 0.5f * float(m) - 0.5f, fv = (v + 1.0f) * 0.5f * float(m) - 0.5f;
        const int u0 = int(std::floor(fu)), v0 = int(std::floor(fv));
        const float tu = fu - float(u0), tv = fv - float(v0);
        const float rk = std::min(r, rMax) / rMax * float(radial - 1);
        return (1 - tu) * (1 - tv) * at(face, u0, v0, rk) + tu * (1 - tv) * at(face, u0 + 1, v0, rk) + (1 - tu) * tv * at(face, u0, v0 + 1, rk) +
               tu * tv * at(face, u0 + 1, v0 + 1, rk);
    }
};

struct Err {
    double rmse = 0.0, maxErr = 0.0;
};
template <class F>
Err transmittanceError(const std::vector<glm::vec3>& points, const std::vector<float>& traced, F&& depth) {
    Err e;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const double d = std::exp2(-double(depth(points[i]))) - std::exp2(-double(traced[i]));
        e.rmse += d * d;
        e.maxErr = std::max(e.maxErr, std::abs(d));
    }
    e.rmse = std::sqrt(e.rmse / double(std::max<std::size_t>(points.size(), 1)));
    return e;
}

} // namespace

int runShadowLights(const std::string& out, int frames, bool noPlots) {
    Materials materials{Footprint{}};
    const std::uint32_t row = materials.addColorTable(ColorTable::constant({0.8f, 0.8f, 0.8f, 1.0f}));
    const Grid g = plume();
    auto field = DensityField::fromGrid(g);
    if (!field) return std::fprintf(stderr, "shadows --lights: %s\n", field.error().c_str()), 1;
    EffectDesc desc;
    desc.layers = {EffectLayer{.style = {.colorTable = row, .textured = false}}};
    const Camera cam = Camera::lookAt({0.0f, 5.0f, 9.0f}, {0.0f, 1.0f, 0.0f}, {0, 1, 0}, glm::radians(60.0f), {160, 120}, 0.1f, 100.0f);
    const std::vector<glm::vec3> ground = groundPoints();
    std::printf("a %zu-voxel plume over the ground, %zu ground points, median of %d frames (process CPU ms)\n", g.voxels.size(), ground.size(), frames);

    std::vector<bench::KnobRow> rows;
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    // What Scene::prepare costs without any scene shadow (emitting and lighting the plume): the
    // traced rows add their tracing to it, so both columns time the same frame.
    double baseline = 0.0;
    {
        Scene scene;
        scene.add(*Effect::fromGrid(g, desc), {.name = "plume", .lighting = {.enabled = true, .selfShadow = SelfShadow::Off}});
        (void)scene.addLight(lightAt(0, 0.0f));
        scene.setSceneShadow({.enabled = false});
        Frame frame;
        std::vector<double> t;
        for (int f = 0; f < frames + 1; ++f) {
            const std::clock_t a = std::clock();
            (void)scene.prepare(f / 30.0, cam, materials, frame);
            if (f > 0) t.push_back(cpuMs(a, std::clock()));
        }
        baseline = median(t);
    }
    for (int dims : {16, 32, 64}) {
        for (int n = 1; n <= kMaxShadowLights; ++n) {
            if (dims != 32 && n != kMaxShadowLights) continue; // the dims knob at 4 lights; the light count at 32^3
            Scene scene;
            scene.add(*Effect::fromGrid(g, desc), {.name = "plume", .lighting = {.enabled = true, .selfShadow = SelfShadow::Off}});
            for (int i = 0; i < n; ++i) (void)scene.addLight(lightAt(i, 0.0f));
            scene.setSceneShadow({.dims = glm::ivec3(dims)});
            Frame frame;
            std::vector<double> moving, still;
            std::uint64_t builds = 0;
            for (int f = 0; f < frames + 1; ++f) { // every light moves every frame: every table rebuilt
                for (int i = 0; i < n; ++i) (void)scene.setLight(std::size_t(i), lightAt(i, 0.1f * float(f)));
                const std::clock_t a = std::clock();
                (void)scene.prepare(f / 30.0, cam, materials, frame);
                if (f > 0) moving.push_back(cpuMs(a, std::clock())), builds += frame.counters().shadowTableBuilds;
            }
            for (int f = 0; f < frames; ++f) { // nothing moves: every table reused
                const std::clock_t a = std::clock();
                (void)scene.prepare((frames + 1 + f) / 30.0, cam, materials, frame);
                still.push_back(cpuMs(a, std::clock()));
            }
            if (!scene.lightingError().empty()) std::fprintf(stderr, "shadows --lights: %s\n", scene.lightingError().c_str());
            // Error on the ground, every light, against tracing.
            double sum = 0.0, worst = 0.0;
            std::size_t count = 0;
            for (int i = 0; i < n; ++i) {
                const Light l = scene.lights()[std::size_t(i)];
                ShadowTable t({.dims = glm::ivec3(dims)});
                (void)t.update(*field, l);
                std::vector<float> traced;
                for (glm::vec3 p : ground) traced.push_back(field->opticalDepthToLight(p, l));
                const Err e = transmittanceError(ground, traced, [&](glm::vec3 p) { return t.opticalDepth(p); });
                sum += e.rmse * e.rmse * double(ground.size());
                worst = std::max(worst, e.maxErr);
                count += ground.size();
            }
            char extra[128];
            std::snprintf(extra, sizeof extra, "%.3f | %.2f | %d", median(still), double(builds) / frames, int(frame.counters().shadowLights));
            rows.push_back({.knob = dims == 32 ? "lights (table 32^3)" : "table dims (4 lights)",
                            .setting = dims == 32 ? std::to_string(n) : std::to_string(dims) + "^3",
                            .ms = median(moving),
                            .rmse = std::sqrt(sum / double(count)),
                            .maxErr = worst,
                            .extra = extra,
                            .isDefault = dims == 32 && n == 1});
            if (dims == 32) { // tracing the ground to the same lights instead
                std::vector<double> times;
                float sink = 0.0f;
                for (int f = 0; f < std::max(1, frames / 3); ++f) {
                    const std::clock_t a = std::clock();
                    for (int i = 0; i < n; ++i)
                        for (glm::vec3 p : ground) sink += field->opticalDepthToLight(p, scene.lights()[std::size_t(i)]);
                    times.push_back(cpuMs(a, std::clock()));
                }
                const double tracedMs = baseline + median(times) + (sink < 0.0f ? 1e-9 : 0.0);
                std::snprintf(extra, sizeof extra, "%.3f | - | %d", tracedMs, n);
                rows.push_back({.knob = "traced ground", .setting = std::to_string(n) + " light(s)", .ms = tracedMs, .rmse = 0.0, .maxErr = 0.0, .extra = extra});
            }
        }
    }
    bench::markPareto(rows);
    std::printf("\nEvery light casts: ms = Scene::prepare with every light moving (all tables rebuilt); static = nothing moving.\n"
                "RMSE / max error: the ground's transmittance (every light) against tracing. Traced ground: Scene::prepare without\n"
                "scene shadows (%.3f ms) plus tracing the 19200 points to each light (moving or not: tracing keeps nothing).",
                baseline);
    bench::printTable(rows, "CPU ms/frame (lights moving)", "static ms/frame | tables built/frame | tables");

    // A point light inside the plume: box table against the light's own parameterisation at equal memory.
    const glm::vec3 inside(0.0f, 1.6f, 0.0f);
    const Light torch = Light::point(inside);
    std::vector<glm::vec3> probes = ground;
    for (const Voxel& v : g.voxels)
        if (v.opacity > 0.02f) probes.push_back(g.worldPosition(v.cell)); // and every voxel with material: the gas's own self-shadow
    std::vector<float> traced;
    for (glm::vec3 p : probes) traced.push_back(field->opticalDepthToLight(p, torch));
    std::vector<bench::KnobRow> inRows;
    std::printf("\nA point light inside the plume at (0, 1.6, 0): %zu ground points and %zu voxels against tracing; memory = the table's floats\n"
                "(the box table's build also takes 13 bytes per node of scratch).\n",
                ground.size(), probes.size() - ground.size());
    for (int n : {16, 24, 32, 48, 64}) {
        ShadowTable t({.dims = glm::ivec3(n)});
        std::vector<double> times;
        for (int r = 0; r < 3; ++r) {
            t = ShadowTable({.dims = glm::ivec3(n)});
            const std::clock_t a = std::clock();
            (void)t.update(*field, torch);
            times.push_back(cpuMs(a, std::clock()));
        }
        const Err e = transmittanceError(probes, traced, [&](glm::vec3 p) { return t.opticalDepth(p); });
        char extra[64];
        std::snprintf(extra, sizeof extra, "%.0f", double(n) * n * n * 4.0 / 1024.0);
        inRows.push_back({.knob = "box table (ShadowTable)", .setting = std::to_string(n) + "^3", .ms = median(times), .rmse = e.rmse,
                          .maxErr = e.maxErr, .extra = extra, .isDefault = n == 64});
        // The same number of floats as 6 m^2 x 2m entries: m = n / 12^(1/3).
        const int m = std::max(2, int(std::lround(double(n) / std::cbrt(12.0))));
        SphericalTable s;
        times.clear();
        for (int r = 0; r < 3; ++r) {
            const std::clock_t a = std::clock();
            s.build(*field, inside, m, 2 * m);
            times.push_back(cpuMs(a, std::clock()));
        }
        const Err es = transmittanceError(probes, traced, [&](glm::vec3 p) { return s.opticalDepth(p); });
        std::snprintf(extra, sizeof extra, "%.0f", double(s.depth.size()) * 4.0 / 1024.0);
        inRows.push_back({.knob = "direction x distance", .setting = "6x" + std::to_string(m) + "^2 x " + std::to_string(2 * m), .ms = median(times),
                          .rmse = es.rmse, .maxErr = es.maxErr, .extra = extra});
    }
    bench::markPareto(inRows);
    bench::printTable(inRows, "CPU ms (build)", "KiB");
    if (noPlots) return 0;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    rows.insert(rows.end(), inRows.begin(), inRows.end());
    // The traced rows are the reference (error 0): off the log-scale plot.
    rows.erase(std::remove_if(rows.begin(), rows.end(), [](const bench::KnobRow& r) { return r.rmse <= 0.0; }), rows.end());
    return bench::writePlot(rows, out, "shadow_lights", "every light casts: ground transmittance RMSE vs tracing", "CPU ms") ? 0 : 1;
}
} // namespace shadow_lights_cmd

int runShadowLights(const std::string& out, int frames, bool noPlots) { return shadow_lights_cmd::runShadowLights(out, frames, noPlots); }
