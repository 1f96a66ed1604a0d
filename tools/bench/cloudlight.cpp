// splatfx-bench cloudlight (issue 27): what relighting a LOD cloud costs when
// its sun moves (Cloud::setLight: the sun's transmittance swept through the
// density, the LOD fields rebuilt), per light model and cloud size, against
// the relight that is skipped (the light unchanged) and the low-albedo
// model's table rebuild (a new sun colour). The error column is the swept
// transmittance against the exact one: the extinction integrated along the
// ray to the sun through the finest tetrahedral mesh of the same density
// (LodVolume::integrateRay, double), at sampled grid points with material.
// The point-light rows (CloudLighting::lights): a low-albedo cloud lit by a
// lamp circling above it (every grid point traced to it, DensityField's
// segment integral) against the same cloud under the moving sun; the sun
// moving with a lamp fixed (the field rescaled, nothing traced); and the
// per-frame update() with and without the lamp (the per-vertex phases). Their
// error is the traced transmittance against the exact one through the finest
// mesh toward the lamp.
// The receive rows: a lit plume under the cloud in a Scene, its light traced
// through the cloud's field (scene.hpp) or not; their error is the plume's
// received transmittance (its splat colour) against the exact one through the
// cloud (the lit reference, litFactor, with the cloud as a trilinear medium).
// The plume-caster rows: a low-albedo cloud shadowed by a plume (a voxel
// block's DensityField, moved one cell per step above the cloud, as a
// simulated plume's field changes every frame) relit by Cloud::setLight with
// the plume as caster: restricted (only the casters changed: the points
// under the old and new box traced again, then the LOD fields rebuilt whole)
// against full (the sun nudged each step as well: the sweep, every point
// traced, the LOD fields); the LOD fields' rebuild alone (LodVolume::create
// on the same field); a plume under the cloud, which cannot shadow it (no
// point traced, nothing rebuilt). Error columns unused there (0).
// CPU only.
#include <algorithm>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "bench_stats.hpp"
#include "commands.hpp"
#include "knob_table.hpp"
#include "options.hpp"
#include "splatfx/cloud.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/volume.hpp"

namespace cloudlight_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

// CPU time of this thread's work (the relight is single-threaded): steadier
// than wall time on a shared machine.
struct Clock {
    static std::clock_t now() { return std::clock(); }
};
double ms(std::clock_t d) { return 1000.0 * double(d) / double(CLOCKS_PER_SEC); }

// The sun at `step` of a day: from one horizon over the top to the other, a
// little off the x-z plane, travelling toward the cloud (-z down).
splatfx::Light sunAt(int step, int steps) {
    const double a = 0.2 + 2.74 * double(step) / double(std::max(1, steps - 1)); // radians above the +x horizon
    return splatfx::Light::directional({-float(std::cos(a)), -0.15f, -float(std::sin(a))});
}

struct Measure {
    double relightMs = 0.0; // median over the steps
    double rmse = 0.0, maxErr = 0.0;
    std::uint64_t relights = 0;
};

// RMSE and max of the swept transmittance against the exact one, at up to
// `samples` grid points with density (every k-th), for the cloud's current sun.
void transmittanceError(const splatfx::Cloud& cloud, const splatfx::CloudCreateDesc& desc, int samples, double& rmse, double& maxErr) {
    const bool roettger = cloud.lighting().model == splatfx::CloudLightModel::Roettger;
    const glm::ivec3 n = cloud.dims();
    splatfx::ScalarVolume field;
    field.dims = n;
    field.scalar = cloud.density();
    // The extinction each model attenuates by, per world unit, linear in the stored scalar.
    double perUnit = double(desc.cloud.lightExtinctionPerCell) / double(desc.volume.spacingWorld);
    if (!roettger) {
        perUnit = desc.transfer.maxExtinctionPerWorld;
        for (float& f : field.scalar) f = f >= desc.transfer.threshold ? f : 0.0f;
    }
    auto vol = splatfx::LodVolume::create(field, desc.volume);
    auto tf = splatfx::TransferFunction::create({{0.0f, glm::vec3(0.0f), 0.0f}, {1.0f, glm::vec3(0.0f), float(perUnit)}});
    if (!vol || !tf) return;
    std::vector<std::size_t> cloudy;
    for (std::size_t i = 0; i < field.scalar.size(); ++i)
        if (field.scalar[i] > 0.0f) cloudy.push_back(i);
    const std::size_t stride = std::max<std::size_t>(1, cloudy.size() / std::size_t(samples));
    const glm::dvec3 toSun = -glm::normalize(glm::dvec3(cloud.lighting().sun.direction));
    double sum = 0.0;
    std::size_t count = 0;
    maxErr = 0.0;
    for (std::size_t k = 0; k < cloudy.size(); k += stride) {
        const std::size_t i = cloudy[k];
        const glm::ivec3 g(int(i % std::size_t(n.x)), int((i / std::size_t(n.x)) % std::size_t(n.y)), int(i / (std::size_t(n.x) * std::size_t(n.y))));
        const glm::dvec3 p = glm::dvec3(vol->originWorld()) + glm::dvec3(g) * double(vol->spacingWorld());
        // The sweep reads the float density; the reference the stored 8-bit one.
        const double exact = 1.0 - vol->integrateRay(*tf, p, toSun, 0.0, 1e9).a;
        const double d = double(cloud.sunTransmittance()[i]) - exact;
        sum += d * d;
        maxErr = std::max(maxErr, std::fabs(d));
        ++count;
    }
    rmse = count ? std::sqrt(sum / double(count)) : 0.0;
}

// The same for light `i` of CloudLighting::lights (a point or spot light):
// the ray to its position, through the mesh (zero outside the grid's box).
void lampError(const splatfx::Cloud& cloud, const splatfx::CloudCreateDesc& desc, std::size_t light, int samples, double& rmse, double& maxErr) {
    const glm::ivec3 n = cloud.dims();
    splatfx::ScalarVolume field;
    field.dims = n;
    field.scalar = cloud.density();
    for (float& f : field.scalar) f = f >= desc.transfer.threshold ? f : 0.0f;
    auto vol = splatfx::LodVolume::create(field, desc.volume);
    auto tf = splatfx::TransferFunction::create({{0.0f, glm::vec3(0.0f), 0.0f}, {1.0f, glm::vec3(0.0f), desc.transfer.maxExtinctionPerWorld}});
    if (!vol || !tf) return;
    std::vector<std::size_t> cloudy;
    for (std::size_t i = 0; i < field.scalar.size(); ++i)
        if (field.scalar[i] > 0.0f) cloudy.push_back(i);
    const std::size_t stride = std::max<std::size_t>(1, cloudy.size() / std::size_t(samples));
    const glm::dvec3 lamp(cloud.lighting().lights[light].position);
    double sum = 0.0;
    std::size_t count = 0;
    maxErr = 0.0;
    for (std::size_t k = 0; k < cloudy.size(); k += stride) {
        const std::size_t i = cloudy[k];
        const glm::ivec3 g(int(i % std::size_t(n.x)), int((i / std::size_t(n.x)) % std::size_t(n.y)), int(i / (std::size_t(n.x) * std::size_t(n.y))));
        const glm::dvec3 p = glm::dvec3(vol->originWorld()) + glm::dvec3(g) * double(vol->spacingWorld());
        const double exact = 1.0 - vol->integrateRay(*tf, p, lamp - p, 0.0, 1.0).a;
        const double d = double(cloud.lightTransmittance(light)[i]) - exact;
        sum += d * d;
        maxErr = std::max(maxErr, std::fabs(d));
        ++count;
    }
    rmse = count ? std::sqrt(sum / double(count)) : 0.0;
}

// A lamp circling 10 cells above the cloud's top at step s of `steps`.
splatfx::Light lampAt(const splatfx::CloudCreateDesc& desc, int step, int steps) {
    const glm::vec3 n(desc.cloud.dims);
    const float h = desc.volume.spacingWorld, a = 6.2831853f * float(step) / float(std::max(1, steps));
    const glm::vec3 c = desc.volume.originWorld + 0.5f * (n - 1.0f) * h;
    const float r = 0.3f * (n.x - 1.0f) * h;
    return splatfx::Light::point(c + glm::vec3(r * std::cos(a), r * std::sin(a), (0.5f * (n.z - 1.0f) + 10.0f) * h), glm::vec3(1.0f),
                                 100.0f * h * h);
}

// Relights with a point light: mode 0 the lamp moves (sun off), 1 the sun
// moves beside a fixed lamp. Median ms per relight.
bool measureLamp(const splatfx::CloudCreateDesc& desc, int mode, int steps, int samples, Measure& out, std::uint64_t& traces) {
    auto cloud = splatfx::Cloud::create(desc);
    if (!cloud) return std::fprintf(stderr, "cloudlight: %s\n", cloud.error().c_str()), false;
    std::vector<double> times;
    splatfx::CloudLighting L = cloud->lighting();
    if (mode == 0) L.sun.intensity = 0.0f;
    L.lights = {lampAt(desc, 0, steps)};
    if (splatfx::Status st = cloud->setLight(L); !st) return std::fprintf(stderr, "cloudlight: %s\n", st.error().c_str()), false;
    const std::uint64_t traces0 = cloud->lightTraces(), relights0 = cloud->relights();
    for (int s = 1; s <= steps; ++s) {
        if (mode == 0) L.lights[0] = lampAt(desc, s, steps);
        else L.sun = sunAt(s - 1, steps);
        const auto t0 = Clock::now();
        if (splatfx::Status st = cloud->setLight(L); !st) return std::fprintf(stderr, "cloudlight: %s\n", st.error().c_str()), false;
        times.push_back(ms(Clock::now() - t0));
    }
    lampError(*cloud, desc, 0, samples, out.rmse, out.maxErr);
    out.relightMs = bench::percentile(times, 0.5);
    out.relights = cloud->relights() - relights0;
    traces = cloud->lightTraces() - traces0;
    return true;
}

// CPU ms of one Cloud::update (median of `frames`) for a camera beside the
// cloud, with the sun alone or with a lamp; and the vertices it wrote.
bool measureUpdate(const splatfx::CloudCreateDesc& desc, bool lamp, int frames, double& msOut, std::size_t& vertices) {
    auto cloud = splatfx::Cloud::create(desc);
    if (!cloud) return false;
    if (lamp) {
        splatfx::CloudLighting L = cloud->lighting();
        L.lights = {lampAt(desc, 0, 1)};
        if (!cloud->setLight(L)) return false;
    }
    const splatfx::Aabb b = cloud->volume().boundsWorld();
    const glm::vec3 c = 0.5f * (b.lo + b.hi);
    const splatfx::Camera camera = splatfx::Camera::lookAt(c + glm::vec3(0.0f, -1.2f * (b.hi.y - b.lo.y), 0.3f * (b.hi.x - b.lo.x)), c, {0, 0, 1},
                                                           glm::radians(60.0f), {640, 480}, 0.1f, 5000.0f);
    splatfx::LodFrame frame;
    std::vector<double> times;
    for (int f = 0; f < frames; ++f) {
        const auto t0 = Clock::now();
        if (!cloud->update(camera, {}, frame)) return false;
        times.push_back(ms(Clock::now() - t0));
    }
    msOut = bench::percentile(times, 0.5);
    vertices = 4 * frame.tets.size();
    return true;
}

bool measure(const splatfx::CloudCreateDesc& desc, int steps, int samples, Measure& out) {
    auto cloud = splatfx::Cloud::create(desc);
    if (!cloud) return std::fprintf(stderr, "cloudlight: %s\n", cloud.error().c_str()), false;
    std::vector<double> times;
    double rmse = 0.0, maxErr = 0.0;
    for (int s = 0; s < steps; ++s) {
        splatfx::CloudLighting L = cloud->lighting();
        L.sun = sunAt(s, steps);
        const auto t0 = Clock::now();
        if (splatfx::Status st = cloud->setLight(L); !st) return std::fprintf(stderr, "cloudlight: %s\n", st.error().c_str()), false;
        times.push_back(ms(Clock::now() - t0));
        // The error over three suns: low, high, low on the other side.
        if (s == 0 || s == steps / 2 || s == steps - 1) {
            double r = 0.0, m = 0.0;
            transmittanceError(*cloud, desc, samples, r, m);
            rmse = std::max(rmse, r);
            maxErr = std::max(maxErr, m);
        }
    }
    out.relightMs = bench::percentile(times, 0.5);
    out.rmse = rmse;
    out.maxErr = maxErr;
    out.relights = cloud->relights();
    return true;
}

// A lit plume (12x12x26 voxels of 0.5, white, albedo 1, isotropic, no
// self-shadow: its colour is the sun's transmittance through the cloud) under
// the middle of the cloud, in a Scene with the cloud (lit, casting or not) or
// without it. ms: CPU time of Scene::prepare (median over `frames`, the sun
// fixed, so the cloud is not relit); error: the splats' colour against the
// exact transmittance through the cloud.
struct Receive {
    double ms = 0.0, rmse = 0.0, maxErr = 0.0;
    std::size_t splats = 0;
};
bool measureReceive(const splatfx::CloudCreateDesc& desc, int cloudMode /* 0 none, 1 not casting, 2 casting */, int frames, Receive& out) {
    using namespace splatfx;
    auto cloud = Cloud::create(desc);
    if (!cloud) return std::fprintf(stderr, "cloudlight: %s\n", cloud.error().c_str()), false;
    const glm::vec3 n(cloud->dims());
    const glm::vec3 below = desc.volume.originWorld + glm::vec3(0.5f * (n.x - 1), 0.5f * (n.y - 1), -20.0f) * desc.volume.spacingWorld;
    Materials materials{Footprint{}};
    const std::uint32_t white = materials.addColorTable(ColorTable::constant(glm::vec4(1.0f)));
    Grid g = *Grid::box({12, 12, 26}, glm::vec3(0.5f));
    for (Voxel& v : g.voxels) v.opacity = 0.4f;
    g.transform = glm::translate(glm::mat4(1.0f), below - g.localPosition({6, 6, 0}));
    EffectDesc ed;
    ed.name = "plume";
    ed.layers = {EffectLayer{.style = {.colorTable = white, .textured = false}}};
    auto plume = Effect::fromGrid(g, ed);
    if (!plume) return std::fprintf(stderr, "cloudlight: %s\n", plume.error().c_str()), false;
    Scene scene;
    scene.setSceneShadow({.enabled = false});
    const Light sun = desc.lighting.sun;
    if (!scene.addLight(sun)) return false;
    const EffectId pid = scene.add(std::move(*plume), {.name = "plume", .lighting = {.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off}});
    const Cloud copy = *cloud;
    if (cloudMode > 0) scene.add(std::move(*cloud), {.name = "cloud", .lighting = {.enabled = true, .castsShadow = cloudMode == 2}});
    // From the side and below: the plume and the cloud's underside in view.
    const Camera camera = Camera::lookAt(below + glm::vec3(0.0f, -60.0f, 10.0f), below + glm::vec3(0.0f, 0.0f, 15.0f), {0, 0, 1}, glm::radians(60.0f),
                                         {320, 240}, 0.1f, 2000.0f);
    Frame frame;
    std::vector<double> times;
    for (int f = 0; f < frames; ++f) {
        const auto t0 = Clock::now();
        if (Status st = scene.prepare(0.0, camera, materials, frame); !st) return std::fprintf(stderr, "cloudlight: %s\n", st.error().c_str()), false;
        times.push_back(ms(Clock::now() - t0));
    }
    if (!scene.status(pid).lit) return std::fprintf(stderr, "cloudlight: the plume was not lit\n"), false;
    // The truth: the cloud's extinction at its grid points (thresholded), trilinear, as a medium.
    auto voxels = std::make_shared<DenseVoxels>();
    voxels->dims = copy.dims();
    voxels->origin = glm::dvec3(desc.volume.originWorld);
    voxels->voxelSize = desc.volume.spacingWorld;
    voxels->values = copy.density();
    for (float& v : voxels->values) v = v >= desc.transfer.threshold ? v : 0.0f;
    VolumeField field(materials);
    field.addMedium(denseMedium(voxels, DenseFilter::Trilinear, desc.transfer.maxExtinctionPerWorld));
    const LitVolumeDesc lit{.lights = {sun}, .gas = {.albedo = 1.0f}};
    double sum = 0.0, maxErr = 0.0;
    for (const Splat& sp : frame.splats()) {
        const double exact = litFactor(field, glm::dvec3(sp.center), glm::dvec3(camera.eye()), lit).x;
        const double d = double(sp.color & 255u) / 255.0 - exact;
        sum += d * d;
        maxErr = std::max(maxErr, std::fabs(d));
    }
    out.splats = frame.splats().size();
    out.rmse = out.splats ? std::sqrt(sum / double(out.splats)) : 0.0;
    out.maxErr = maxErr;
    out.ms = bench::percentile(times, 0.5);
    return true;
}

// A ground fog layer (the brief's hills: a wavy terrain under a wavy top,
// some of it bare) of n x n points, spacing 1, relit (GroundFog::setLighting)
// at `steps` sun positions over the day (y up: sunAt's z is world y); the
// error is the stored T against the reference's transmittance through the
// continuous layer (integrateGroundFogRay) at up to `samples` terrain points.
bool measureGroundFog(int n, int steps, int samples, Measure& out) {
    splatfx::GroundFogDesc d;
    d.dims = {n, n};
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const float x = float(i) / float(n - 1), z = float(j) / float(n - 1);
            d.terrainHeight.push_back(6.0f * std::sin(9.0f * x) * std::cos(7.0f * z) + 3.0f * x);
            d.fogTop.push_back(4.0f + 1.5f * std::cos(5.0f * z));
        }
    auto fog = splatfx::GroundFog::create(d);
    if (!fog) return std::fprintf(stderr, "cloudlight: %s\n", fog.error().c_str()), false;
    splatfx::GroundFogLighting L;
    L.extinctionPerWorld = 0.3f;
    const auto tf = *splatfx::makeGroundFogTransfer(glm::vec3(1.0f), L.extinctionPerWorld);
    std::vector<double> times;
    double rmse = 0.0, maxErr = 0.0;
    for (int s = 0; s < steps; ++s) {
        const glm::vec3 c = sunAt(s, steps).direction;
        L.sun = splatfx::Light::directional({c.x, c.z, c.y});
        const auto t0 = Clock::now();
        if (splatfx::Status st = fog->setLighting(L); !st) return std::fprintf(stderr, "cloudlight: %s\n", st.error().c_str()), false;
        times.push_back(ms(Clock::now() - t0));
        if (s == 0 || s == steps / 2 || s == steps - 1) {
            const std::size_t count = std::size_t(n) * std::size_t(n), stride = std::max<std::size_t>(1, count / std::size_t(samples));
            double sum = 0.0;
            std::size_t k = 0;
            for (std::size_t i = 0; i < count; i += stride, ++k) {
                const glm::vec3 p(float(i % std::size_t(n)), d.terrainHeight[i], float(i / std::size_t(n)));
                splatfx::GroundFogRayStats st;
                splatfx::integrateGroundFogRay(d, tf, glm::dvec3(p), -glm::dvec3(L.sun.direction), 0.0, 1e9, 1e-9, 20, &st);
                const double e = double(fog->sunTransmittance()[2 * i]) - st.transmittance;
                sum += e * e;
                maxErr = std::max(maxErr, std::fabs(e));
            }
            rmse = std::max(rmse, k ? std::sqrt(sum / double(k)) : 0.0);
        }
    }
    out.relightMs = bench::percentile(times, 0.5);
    out.rmse = rmse;
    out.maxErr = maxErr;
    out.relights = fog->relights();
    return true;
}

// A 12x12x26-voxel plume (spacing 0.5 cells, opacity 0.4) whose lowest
// voxel centre is `above` (its field's box moves with it).
splatfx::DensityField plumeField(glm::vec3 at, float spacing) {
    splatfx::Grid g = *splatfx::Grid::box({12, 12, 26}, glm::vec3(0.5f * spacing));
    for (splatfx::Voxel& v : g.voxels) v.opacity = 0.4f;
    g.transform = glm::translate(glm::mat4(1.0f), at - g.localPosition({0, 0, 0}));
    return *splatfx::DensityField::fromGrid(g);
}

// Relights with a moving plume as the caster. mode 0: restricted (the sun
// fixed); 1: full (the sun nudged by 1e-3 each step too); 2: the plume under
// the cloud (cannot shadow it); 3: LodVolume::create alone on the cloud's
// sun-only field. Median ms; points traced again and opticalDepthToLight
// calls over the steps.
bool measurePlume(const splatfx::CloudCreateDesc& desc, int mode, int steps, double& msOut, std::uint64_t& points, std::uint64_t& traces) {
    auto cloud = splatfx::Cloud::create(desc);
    if (!cloud) return std::fprintf(stderr, "cloudlight: %s\n", cloud.error().c_str()), false;
    const float h = desc.volume.spacingWorld;
    const glm::vec3 n(cloud->dims());
    std::vector<double> times;
    if (mode == 3) {
        splatfx::ScalarVolume field;
        field.dims = cloud->dims();
        field.scalar = cloud->sunTransmittance();
        field.lengthScale = cloud->density();
        for (float& f : field.lengthScale) f = f >= desc.transfer.threshold ? f : 0.0f;
        for (int s = 0; s < steps; ++s) {
            const auto t0 = Clock::now();
            if (!splatfx::LodVolume::create(field, desc.volume)) return false;
            times.push_back(ms(Clock::now() - t0));
        }
        msOut = bench::percentile(times, 0.5);
        points = traces = 0;
        return true;
    }
    // Above the cloud's middle, 5 cells over its top (below it: mode 2), moving +x one cell per step.
    auto at = [&](int s) {
        const float z = mode == 2 ? -20.0f : n.z - 1.0f + 5.0f;
        return desc.volume.originWorld + glm::vec3(0.3f * (n.x - 1.0f) + float(s), 0.4f * (n.y - 1.0f), z) * h;
    };
    splatfx::CloudLighting L = cloud->lighting();
    splatfx::DensityField plume = plumeField(at(0), h);
    const splatfx::ShadowCaster* casters[] = {&plume};
    if (splatfx::Status st = cloud->setLight(L, casters); !st) return std::fprintf(stderr, "cloudlight: %s\n", st.error().c_str()), false;
    const std::uint64_t p0 = cloud->receivePoints(), t0c = cloud->receiveTraces();
    const glm::vec3 sun = L.sun.direction;
    for (int s = 1; s <= steps; ++s) {
        plume = plumeField(at(s), h); // the plume's new field: not timed (the simulation's)
        if (mode == 1) L.sun.direction = sun + glm::vec3(1e-3f * float(s % 2), 0.0f, 0.0f);
        const auto t0 = Clock::now();
        if (splatfx::Status st = cloud->setLight(L, casters); !st) return std::fprintf(stderr, "cloudlight: %s\n", st.error().c_str()), false;
        times.push_back(ms(Clock::now() - t0));
    }
    msOut = bench::percentile(times, 0.5);
    points = cloud->receivePoints() - p0;
    traces = cloud->receiveTraces() - t0c;
    return true;
}

std::string dimsText(glm::ivec3 d) { return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z); }

} // namespace

int runCloudLight(int argc, char** argv) {
    CLI::App app{"Cloud relighting as the sun moves: ms per relight per model and cloud size, the skipped relight, the low-albedo table\n"
                 "rebuild; the swept sun transmittance against the exact one through the finest mesh.",
                 "splatfx-bench cloudlight"};
    glm::ivec3 dims{129, 129, 33};
    int steps = 24, samples = 400, frames = 8;
    std::string out = "bench-cloudlight";
    bool noPlots = false;
    cli::addInts(app, "--dims", &dims.x, 3, 2, 4097, "grid points of the default cloud per axis", "X Y Z");
    cli::addNumber(app, "--steps", steps, 2, 10000, "sun positions over the day, one relight each (median reported)");
    cli::addNumber(app, "--frames", frames, 1, 10000, "Scene::prepare calls per receive row (median reported)");
    cli::addNumber(app, "--samples", samples, 1, 1000000, "grid points with material checked against the exact transmittance");
    app.add_option("--out", out, "where cloudlight.dat, cloudlight.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    app.add_flag("--no-plots", noPlots, "print the table only");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;

    auto base = [&](glm::ivec3 d, splatfx::CloudLightModel model) {
        splatfx::CloudCreateDesc desc;
        desc.cloud.dims = d;
        desc.lighting.model = model;
        desc.lighting.gas.phase = *splatfx::PhaseFunction::create(std::vector<splatfx::HgLobe>{{0.6f, 0.8f}, {-0.2f, 0.2f}});
        return desc;
    };
    std::printf("splatfx-bench cloudlight: %d sun positions over a day, %s cloud by default, error at up to %d points\n", steps, dimsText(dims).c_str(),
                samples);
    std::vector<bench::KnobRow> rows;
    struct Case {
        std::string knob, setting;
        glm::ivec3 dims;
        splatfx::CloudLightModel model;
        bool isDefault;
    };
    std::vector<Case> cases = {
        {"model", "Roettger (sec. 5.2)", dims, splatfx::CloudLightModel::Roettger, true},
        {"model", "low albedo, 2 HG lobes", dims, splatfx::CloudLightModel::LowAlbedo, false},
    };
    for (glm::ivec3 d : {glm::ivec3(65, 65, 17), glm::ivec3(257, 257, 33)})
        if (d != dims) cases.push_back({"dims", dimsText(d), d, splatfx::CloudLightModel::Roettger, false});
    for (const Case& c : cases) {
        Measure m;
        std::printf("  %s %s ...\n", c.knob.c_str(), c.setting.c_str());
        std::fflush(stdout);
        if (!measure(base(c.dims, c.model), steps, samples, m)) return 1;
        rows.push_back({.knob = c.knob,
                        .setting = c.setting,
                        .ms = m.relightMs,
                        .rmse = m.rmse,
                        .maxErr = m.maxErr,
                        .extra = std::to_string(m.relights) + " | " + dimsText(c.dims),
                        .isDefault = c.isDefault});
    }
    // The light unchanged: the relight skipped (counter unchanged); and the
    // low-albedo model's new sun colour: the transfer table rebuilt, no sweep.
    {
        auto cloud = splatfx::Cloud::create(base(dims, splatfx::CloudLightModel::LowAlbedo));
        if (!cloud) return std::fprintf(stderr, "cloudlight: %s\n", cloud.error().c_str()), 1;
        std::vector<double> same, colour;
        for (int s = 0; s < steps; ++s) {
            splatfx::CloudLighting L = cloud->lighting();
            auto t0 = Clock::now();
            if (!cloud->setLight(L)) return 1;
            same.push_back(ms(Clock::now() - t0));
            L.sun.color = glm::vec3(1.0f, 0.6f + 0.4f * float(s % 2), 0.4f + 0.6f * float(s % 2));
            t0 = Clock::now();
            if (!cloud->setLight(L)) return 1;
            colour.push_back(ms(Clock::now() - t0));
        }
        double r = 0.0, m = 0.0;
        transmittanceError(*cloud, base(dims, splatfx::CloudLightModel::LowAlbedo), samples, r, m);
        rows.push_back({.knob = "change", .setting = "none (skipped)", .ms = bench::percentile(same, 0.5), .rmse = r, .maxErr = m,
                        .extra = std::to_string(cloud->relights()) + " | " + dimsText(dims)});
        rows.push_back({.knob = "change", .setting = "sun colour (low-albedo table)", .ms = bench::percentile(colour, 0.5), .rmse = r, .maxErr = m,
                        .extra = std::to_string(cloud->tableBuilds()) + " table builds | " + dimsText(dims)});
    }
    // Point lights (low albedo): a lamp moving (every grid point traced), the
    // sun moving beside a fixed lamp (rescaled only), against the sun alone
    // (the "low albedo, 2 HG lobes" row above); and update() per frame.
    for (glm::ivec3 d : {glm::ivec3(65, 65, 17), dims}) {
        const int lampSteps = std::min(steps, 4);
        const char* names[] = {"point light moving (traced)", "sun moving, point light fixed"};
        for (int mode = 0; mode < 2; ++mode) {
            std::printf("  %s %s ...\n", names[mode], dimsText(d).c_str());
            std::fflush(stdout);
            Measure m;
            std::uint64_t traces = 0;
            if (!measureLamp(base(d, splatfx::CloudLightModel::LowAlbedo), mode, mode == 0 ? lampSteps : steps, samples, m, traces)) return 1;
            rows.push_back({.knob = "point light", .setting = names[mode], .ms = m.relightMs, .rmse = m.rmse, .maxErr = m.maxErr,
                            .extra = std::to_string(m.relights) + " (" + std::to_string(traces) + " traces) | " + dimsText(d)});
        }
        if (d != dims) {
            Measure m;
            if (!measure(base(d, splatfx::CloudLightModel::LowAlbedo), steps, samples, m)) return 1;
            rows.push_back({.knob = "point light", .setting = "none: sun moving (low albedo)", .ms = m.relightMs, .rmse = m.rmse, .maxErr = m.maxErr,
                            .extra = std::to_string(m.relights) + " | " + dimsText(d)});
        }
        for (bool lamp : {false, true}) {
            double t = 0.0;
            std::size_t v = 0;
            if (!measureUpdate(base(d, splatfx::CloudLightModel::LowAlbedo), lamp, frames, t, v)) return 1;
            rows.push_back({.knob = "update()", .setting = lamp ? "sun + point light, per frame" : "sun, per frame", .ms = t,
                            .extra = std::to_string(v) + " vertices | " + dimsText(d)});
        }
    }
    // Receiving: the plume's lighting with the cloud's shadow traced, against
    // no cloud and a cloud that does not cast (the receive cost is the difference).
    {
        const char* names[] = {"plume, no cloud", "plume + cloud, not casting", "plume + cloud, casting (traced)"};
        for (int mode = 0; mode < 3; ++mode) {
            std::printf("  receive %s ...\n", names[mode]);
            std::fflush(stdout);
            Receive r;
            if (!measureReceive(base(dims, splatfx::CloudLightModel::Roettger), mode, frames, r)) return 1;
            rows.push_back({.knob = "receive", .setting = names[mode], .ms = r.ms, .rmse = r.rmse, .maxErr = r.maxErr,
                            .extra = std::to_string(r.splats) + " plume splats | " + (mode ? dimsText(dims) : std::string("none"))});
        }
    }
    // A plume caster shadowing the cloud (Cloud::setLight's casters): the
    // restricted relight against the full one, the LOD fields' rebuild alone,
    // and a plume that cannot shadow the cloud.
    for (glm::ivec3 d : {glm::ivec3(65, 65, 17), glm::ivec3(129, 129, 33)}) {
        const char* names[] = {"plume moving: restricted relight", "plume moving: full relight", "plume under the cloud (cannot shadow)",
                               "LOD fields rebuild alone"};
        for (int mode = 0; mode < 4; ++mode) {
            std::printf("  plume caster %s %s ...\n", names[mode], dimsText(d).c_str());
            std::fflush(stdout);
            double t = 0.0;
            std::uint64_t points = 0, traces = 0;
            if (!measurePlume(base(d, splatfx::CloudLightModel::LowAlbedo), mode, std::min(steps, 8), t, points, traces)) return 1;
            rows.push_back({.knob = "plume caster", .setting = names[mode], .ms = t,
                            .extra = std::to_string(points) + " points (" + std::to_string(traces) + " traces) | " + dimsText(d)});
        }
    }
    // Ground fog (GroundFog::setLighting): the layer's own continuous field
    // integrated toward the sun at every grid point's terrain and top.
    for (int n : {65, 129}) {
        std::printf("  ground fog %dx%d ...\n", n, n);
        std::fflush(stdout);
        Measure m;
        if (!measureGroundFog(n, steps, samples, m)) return 1;
        rows.push_back({.knob = "ground fog", .setting = "low albedo, " + std::to_string(n) + "x" + std::to_string(n) + " points",
                        .ms = m.relightMs, .rmse = m.rmse, .maxErr = m.maxErr, .extra = std::to_string(m.relights) + " | none"});
    }
    bench::markPareto(rows);
    bench::printTable(rows, "CPU ms per relight or frame (median)", "relights | cloud");
    std::printf("\nRMSE / max error: swept sun transmittance against the exact one through the finest mesh (worst of three suns;\n"
                "ground fog: the stored T at the terrain against integrateGroundFogRay's through the continuous layer);\n"
                "receive rows: the plume's received transmittance (8-bit colour) against the exact one through the cloud.\n");
    if (noPlots) return 0;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    return bench::writePlot(rows, out, "cloudlight", "cloud relight: CPU ms per relight vs sun transmittance error", "CPU ms per relight") ? 0 : 1;
}
} // namespace cloudlight_cmd

int runCloudLight(int argc, char** argv) { return cloudlight_cmd::runCloudLight(argc, argv); }
