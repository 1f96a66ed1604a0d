// splatfx-bench lodrefine: figures for docs/volume.md, on the CPU. A cloud
// field, a flight through it, and per frame the tetrahedra emitted against
// the full-resolution count and the CPU time of LodVolume::update.
//
//   splatfx-bench lodrefine [--dims X Y Z] [--c DETAIL] [--C MIN_ACCURACY] [--frames N] [--average]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "commands.hpp"
#include "options.hpp"
#include "splatfx/volume.hpp"

namespace lod_refine_cmd { // one namespace per command: the commands build as one unity translation unit

int runLodRefine(int argc, char** argv) {
    glm::ivec3 dims(257, 257, 33);
    float detailC = 10.0f, minC = 4.0f;
    int frames = 120;
    bool average = false;
    CLI::App app{"LOD cloud volume refinement on the CPU: a cloud field, a flight through it; tetrahedra emitted per frame against the\n"
                 "full-resolution count, LodVolume::update time, memory, near-plane clipping, error against the finest level.",
                 "splatfx-bench lodrefine"};
    cli::addInts(app, "--dims", &dims.x, 3, 2, 4097, "grid points of the cloud field per axis", "X Y Z");
    cli::addNumber(app, "--c", detailC, 0.0f, 1.0e6f, "detail knob c of the refinement");
    cli::addNumber(app, "--C", minC, 0.0f, 1.0e6f, "minimum accuracy C of the octree");
    cli::addNumber(app, "--frames", frames, 1, 100000, "frames of the flight");
    app.add_flag("--average", average, "Delta from the average, not the maximum, error");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    using Clock = std::chrono::steady_clock;
    auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };

    splatfx::CloudDesc cd;
    cd.dims = dims;
    auto t0 = Clock::now();
    auto field = splatfx::makeCloudVolume(cd);
    if (!field) {
        std::fprintf(stderr, "%s\n", field.error().c_str());
        return 1;
    }
    auto t1 = Clock::now();
    splatfx::LodVolumeDesc vd;
    vd.minAccuracyC = minC;
    vd.delta = average ? splatfx::DeltaMode::Average : splatfx::DeltaMode::Max;
    auto vol = splatfx::LodVolume::create(*field, vd);
    if (!vol) {
        std::fprintf(stderr, "%s\n", vol.error().c_str());
        return 1;
    }
    auto t2 = Clock::now();
    auto tf = splatfx::makeCloudTransfer({});
    const float longest = std::sqrt(3.0f) * float(1 << vol->rootLevel()) * vol->spacingWorld();
    auto table = splatfx::PreIntegrationTable::create(*tf, {.maxLengthWorld = longest});
    auto t3 = Clock::now();
    std::size_t cloudy = 0;
    for (float s : field->scalar) cloudy += s > 0.0f;
    std::printf("field %dx%dx%d (padded %dx%dx%d, %dx%dx%d roots of n=%d), %.1f%% of points cloudy\n", dims.x, dims.y, dims.z, vol->pointDims().x,
                vol->pointDims().y, vol->pointDims().z, vol->roots().x, vol->roots().y, vol->roots().z, vol->rootLevel(),
                100.0 * double(cloudy) / double(field->scalar.size()));
    const double points = double(vol->pointDims().x) * vol->pointDims().y * vol->pointDims().z;
    std::printf("memory %zu bytes = %.3f bytes per grid point (scalar + light + Delta/e'/range per node)\n", vol->memoryBytes(),
                double(vol->memoryBytes()) / points);
    std::printf("cloud field %.0f ms, octree build %.0f ms, pre-integration table %dx%dx%d (%zu bytes) %.0f ms\n", ms(t1 - t0), ms(t2 - t1),
                table->dims().x, table->dims().y, table->dims().z, table->bytes(), ms(t3 - t2));

    // Flight: in at mid height from outside the -x face, through the field, out the far side.
    const glm::vec3 ext = glm::vec3(vol->pointDims() - 1) * vol->spacingWorld();
    const float zMid = 0.5f * ext.z;
    const glm::vec3 start(-0.25f * ext.x, 0.37f * ext.y, zMid), end(1.25f * ext.x, 0.61f * ext.y, zMid);
    splatfx::LodRefineDesc rd;
    rd.detailC = detailC;
    splatfx::LodFrame frame;
    std::vector<double> times, tets;
    std::uint64_t clipped = 0, extra = 0, emittedInside = 0, framesInside = 0;
    double maxTets = 0;
    // Error against the finest level: every 10th frame, 32x24 rays integrated through the
    // emitted list and through the finest mesh (both exact, CPU), premultiplied RGBA.
    double errSum = 0.0, errMax = 0.0;
    std::vector<double> errs;
    std::uint64_t errRays = 0;
    for (int f = 0; f < frames; ++f) {
        const float u = frames > 1 ? float(f) / float(frames - 1) : 0.0f;
        const glm::vec3 eye = start + (end - start) * u;
        const glm::vec3 dir = glm::normalize(end - start);
        const splatfx::Camera cam = splatfx::Camera::lookAt(eye, eye + dir, {0, 0, 1}, glm::radians(60.0f), {512, 384}, 0.1f, 5000.0f);
        const auto a = Clock::now();
        if (!vol->update(cam, rd, &*tf, frame)) return 1;
        times.push_back(ms(Clock::now() - a));
        tets.push_back(double(frame.stats.emitted));
        maxTets = std::max(maxTets, double(frame.stats.emitted));
        clipped += frame.stats.clippedInput;
        extra += frame.stats.clippedExtra;
        if (f % 10 == 0 && frame.tets.size() <= 200000) {
            for (int py = 0; py < 24; ++py)
                for (int px = 0; px < 32; ++px) {
                    const float ndcX = (float(px) + 0.5f) / 32.0f * 2.0f - 1.0f, ndcY = (float(py) + 0.5f) / 24.0f * 2.0f - 1.0f;
                    const float th = std::tan(glm::radians(30.0f));
                    const glm::dvec3 d = glm::normalize(glm::dvec3(cam.forward()) + double(ndcX * th * 512.0f / 384.0f) * glm::dvec3(cam.right()) +
                                                        double(ndcY * th) * glm::dvec3(cam.up()));
                    const double tNear = double(cam.nearPlane()) / glm::dot(d, glm::dvec3(cam.forward()));
                    const glm::dvec4 lod = splatfx::integrateRay(frame.tets, *tf, glm::dvec3(eye), d, tNear, 1e4);
                    const glm::dvec4 fine = vol->integrateRay(*tf, glm::dvec3(eye), d, tNear, 1e4);
                    const glm::dvec4 e = glm::abs(lod - fine);
                    const double m = std::max(std::max(e.r, e.g), std::max(e.b, e.a));
                    errSum += m;
                    errs.push_back(m);
                    errMax = std::max(errMax, m);
                    ++errRays;
                }
        }
        if (eye.x > 0.0f && eye.x < ext.x) {
            ++framesInside;
            emittedInside += frame.stats.emitted;
        }
    }
    double sumT = 0, sumN = 0;
    for (std::size_t i = 0; i < times.size(); ++i) {
        sumT += times[i];
        sumN += tets[i];
    }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    const double full = double(vol->fullResolutionTets());
    std::printf("flight of %d frames, c = %.0f, C = %.2f, Delta %s\n", frames, double(detailC), double(minC), average ? "average" : "max");
    std::printf("  full resolution %.0f tetrahedra; emitted mean %.0f (%.0fx fewer), max %.0f; inside the field mean %.0f\n", full, sumN / frames,
                full / std::max(1.0, sumN / frames), maxTets, framesInside ? double(emittedInside) / double(framesInside) : 0.0);
    std::printf("  update() CPU time per frame: mean %.2f ms, median %.2f ms, max %.2f ms\n", sumT / frames, sorted[sorted.size() / 2],
                sorted.back());
    std::printf("  near-plane clipping: %llu tetrahedra cut, %llu added (%.2f%% of emitted)\n", (unsigned long long)clipped,
                (unsigned long long)extra, 100.0 * double(extra) / std::max(1.0, sumN));
    if (errRays) {
        std::sort(errs.begin(), errs.end());
        std::printf("  error vs the finest level (max over RGBA of |LOD - finest| per ray, %llu rays): mean %.4f, median %.4f, "
                    "99th percentile %.4f, max %.4f\n",
                    (unsigned long long)errRays, errSum / double(errRays), errs[errs.size() / 2], errs[errs.size() * 99 / 100], errMax);
    }
    return 0;
}
} // namespace lod_refine_cmd

int runLodRefine(int argc, char** argv) { return lod_refine_cmd::runLodRefine(argc, argv); }
