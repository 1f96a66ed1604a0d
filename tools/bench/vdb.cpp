// splatfx-bench vdb: the OpenVDB import's knobs (file voxels per coarse cell,
// and the splat kernel that reconstructs the coarse grid) against the file at
// full resolution: readVdbDensity's voxels read trilinearly (OpenVDB's
// BoxSampler) through renderVolumeExact (denseMedium). Each setting's coarse
// grid is drawn as untextured splatting's field (VolumeField::add) through
// the same integrator; a second error column takes the lattice as cubes of
// its cells' depth (no kernel): the box filter's own share. Time: the CPU
// cost of a frame, GridSequence::sample plus SplatBuilder::add (median of
// 4 x --reps); the import (loadVdb: walk, read, resample) is its own column.
// --validation writes a small grid (DIR/validation.vdb) and prints its
// reference alphas for tools/validate/vdb_reference.py.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "commands.hpp"
#include "options.hpp"

#if SPLATFX_WITH_VDB
#include <glm/gtc/matrix_transform.hpp>

#include "bench_stats.hpp"
#include "knob_table.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/splatfx.hpp"
#include "splatfx/vdb.hpp"
#endif

namespace vdb_cmd { // one namespace per command: the commands build as one unity translation unit

#if SPLATFX_WITH_VDB

namespace {

using Clock = std::chrono::steady_clock;

splatfx::Materials whiteMaterials(splatfx::Kernel kernel) {
    splatfx::FootprintDesc fd;
    fd.kernel = kernel;
    splatfx::Materials m{splatfx::Footprint{fd}};
    m.addColorTable(splatfx::ColorTable::constant({1.0f, 1.0f, 1.0f, 1.0f}));
    return m;
}

// The lattice as cubes of its cells' extinction (optical depth over edge).
splatfx::ContinuousMedium latticeCubes(const splatfx::GridSequence& seq) {
    auto v = std::make_shared<splatfx::DenseVoxels>();
    splatfx::Grid g;
    seq.sample(0.0, g);
    v->dims = seq.dims;
    v->voxelSize = double(seq.spacing.x);
    v->origin = glm::dvec3(g.worldPosition({0, 0, 0}));
    v->values.resize(seq.cellCount());
    for (std::size_t i = 0; i < v->values.size(); ++i) v->values[i] = float(double(seq.frames[0].opticalDepth[i]) / v->voxelSize);
    return splatfx::denseMedium(v, splatfx::DenseFilter::Nearest, 1.0);
}

} // namespace

int runVdb(int argc, char** argv) {
    CLI::App app{"OpenVDB import: voxels per cell and splat filter against the file at full resolution.", "splatfx-bench vdb"};
    std::string out = "bench-vdb";
    std::string file = "samples/20-vdb-smoke/data/fluid_data_0016.vdb";
    glm::ivec2 size{48, 48};
    int reps = 5;
    bool noPlots = false, valid = false;
    app.add_option("--out", out, "where vdb.dat, vdb.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    app.add_option("--file", file, "the .vdb file (grid 'density')")->capture_default_str();
    cli::addSize(app, "--size", size.x, size.y, 8, 512, "image size");
    cli::addNumber(app, "--reps", reps, 1, 1000, "timed imports per setting, median reported");
    app.add_flag("--no-plots", noPlots, "print the table only");
    app.add_flag("--validation", valid, "write DIR/validation.vdb, print its reference for tools/validate/vdb_reference.py, and stop");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    const splatfx::VdbImportDesc only{.temperatureGrid = "", .velocityGrid = ""};

    if (valid) {
        // DIR/validation.vdb is written by tools/validate/vdb_reference.py --write (pyopenvdb).
        auto v = splatfx::readVdbDensity(out + "/validation.vdb", only);
        if (!v) return std::fprintf(stderr, "vdb: %s\n", v.error().c_str()), 1;
        const splatfx::Materials mat = whiteMaterials(splatfx::Kernel::CrawfisMax);
        splatfx::VolumeField f(mat);
        f.addMedium(splatfx::denseMedium(std::make_shared<splatfx::DenseVoxels>(*v), splatfx::DenseFilter::Trilinear, 1.0));
        // Rays along -z through x = (i + 1/2) 0.45, y = -0.45 + (4 - 1 - j + 1/2) 0.5 (row 0 on top):
        // the grid's voxels (x < 1.25), the gap, and the tile (x in [1.875, 3.875]).
        const splatfx::Camera cam = splatfx::Camera::fromMatrices(glm::lookAt(glm::vec3(1.8f, 0.55f, 8.0f), glm::vec3(1.8f, 0.55f, 0.0f), {0, 1, 0}),
                                                                  glm::ortho(-1.8f, 1.8f, -1.0f, 1.0f, 0.01f, 16.0f), {8, 4});
        splatfx::VolumeExactStats st;
        auto img = splatfx::renderVolumeExact(f, cam, {.tolerance = 1e-9, .maxHalvings = 14}, &st);
        if (!img) return std::fprintf(stderr, "vdb: %s\n", img.error().c_str()), 1;
        std::printf("# %s/validation.vdb, trilinear, extinction 1, rays along -z; reference error estimate %.1e, unconverged %llu\nx,y,alpha\n",
                    out.c_str(), st.maxErrorEstimate, (unsigned long long)st.unconverged);
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 8; ++i)
                std::printf("%.17g,%.17g,%.9f\n", (i + 0.5) * 0.45, -0.45 + (4 - 1 - j + 0.5) * 0.5, double(img->at(i, j, 3)));
        return 0;
    }

    auto fine = splatfx::readVdbDensity(file, only);
    if (!fine) return std::fprintf(stderr, "vdb: %s\n", fine.error().c_str()), 1;
    const auto voxels = std::make_shared<splatfx::DenseVoxels>(*fine);
    // A camera in front of the grid's box, looking at its centre, the box filling the view.
    const glm::dvec3 lo = voxels->origin, hi = voxels->origin + glm::dvec3(voxels->dims - 1) * voxels->voxelSize;
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double extent = glm::length(hi - lo);
    const splatfx::Camera cam =
        splatfx::Camera::lookAt(glm::vec3(centre + glm::dvec3(0.35, 0.2, 1.0) * 1.6 * extent), glm::vec3(centre), {0, 1, 0}, 0.7f, size);
    const splatfx::Materials crawfis = whiteMaterials(splatfx::Kernel::CrawfisMax), gaussian = whiteMaterials(splatfx::Kernel::Gaussian);
    splatfx::VolumeField truthField(crawfis);
    truthField.addMedium(splatfx::denseMedium(voxels, splatfx::DenseFilter::Trilinear, 1.0));
    const auto t0 = Clock::now();
    splatfx::VolumeExactStats st;
    auto truth = splatfx::renderVolumeExact(truthField, cam, {.tolerance = 1e-5}, &st);
    if (!truth) return std::fprintf(stderr, "vdb: %s\n", truth.error().c_str()), 1;
    std::printf("splatfx-bench vdb: %s, %d x %d x %d voxels of %.4g, %dx%d; reference %.1f s, error estimate %.1e, unconverged %llu\n", file.c_str(),
                voxels->dims.x, voxels->dims.y, voxels->dims.z, voxels->voxelSize, size.x, size.y,
                std::chrono::duration<double>(Clock::now() - t0).count(), st.maxErrorEstimate, (unsigned long long)st.unconverged);

    // Default: voxelsPerCell 0 with maxCellsPerAxis 24.
    auto defSeq = splatfx::loadVdb(file, only);
    if (!defSeq) return std::fprintf(stderr, "vdb: %s\n", defSeq.error().c_str()), 1;
    const int defaultN = int(std::lround(double(defSeq->spacing.x) / voxels->voxelSize));
    std::vector<bench::KnobRow> rows;
    std::vector<std::string> cubes;
    for (int pass = 0; pass < 2; ++pass)
        for (int n : {1, 2, 3, 4, 6, 8}) {
            const bool gauss = pass == 1;
            if (gauss && n != defaultN) continue;
            splatfx::VdbImportDesc d = only;
            d.voxelsPerCell = n;
            std::vector<double> importMs, frameMs;
            splatfx::Result<splatfx::GridSequence> seq = splatfx::makeError("not run");
            for (int r = 0; r < reps; ++r) {
                const auto a = Clock::now();
                seq = splatfx::loadVdb(file, d);
                importMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
            }
            if (!seq) return std::fprintf(stderr, "vdb: %s\n", seq.error().c_str()), 1;
            splatfx::Grid g;
            // The per-frame cost: the sequence sampled at a time and its splats built (what
            // grows with the lattice; the GPU's work grows with the splat count shown).
            splatfx::SplatBuilder builder;
            for (int r = 0; r < 4 * reps; ++r) {
                const auto a = Clock::now();
                seq->sample(0.0, g);
                builder.begin(cam);
                builder.add(g, crawfis, {.colorTable = 0});
                frameMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
            }
            splatfx::VolumeField f(gauss ? gaussian : crawfis);
            f.add(g, {.colorTable = 0});
            auto img = splatfx::renderVolumeExact(f, cam, {.tolerance = 1e-4});
            splatfx::VolumeField c(crawfis);
            c.addMedium(latticeCubes(*seq));
            auto cub = splatfx::renderVolumeExact(c, cam, {.tolerance = 1e-5});
            if (!img || !cub) return std::fprintf(stderr, "vdb: render failed\n"), 1;
            bench::KnobRow row;
            row.knob = gauss ? "splat filter" : "voxels per cell";
            row.setting = gauss ? "Gaussian" : std::to_string(n);
            row.ms = bench::median(frameMs);
            bench::imageError(*img, *truth, row.rmse, row.maxErr);
            double cr = 0.0, cm = 0.0;
            bench::imageError(*cub, *truth, cr, cm);
            char buf[96];
            std::snprintf(buf, sizeof buf, "%zu | %.5f | %.2f", g.voxels.size(), cr, bench::median(importMs));
            row.extra = buf;
            row.isDefault = !gauss && n == defaultN;
            rows.push_back(row);
            if (row.isDefault) {
                bench::KnobRow r = row;
                r.knob = "splat filter";
                r.setting = "Crawfis-Max";
                rows.push_back(r);
            }
            std::fprintf(stderr, "  %s %s: %.3f ms, RMSE %.5f (cubes %.5f)\n", row.knob.c_str(), row.setting.c_str(), row.ms, row.rmse, cr);
        }
    // The filter rows after the block-size rows.
    std::stable_partition(rows.begin(), rows.end(), [](const bench::KnobRow& r) { return r.knob == "voxels per cell"; });
    bench::markPareto(rows);
    bench::printTable(rows, "CPU ms/frame (sample + splats)", "splats | RMSE as cubes | import ms");
    if (noPlots) return 0;
    return bench::writePlot(rows, out, "vdb", "OpenVDB import: error vs the file at full resolution per knob",
                            "CPU ms per frame: sample + build splats (median)")
               ? 0
               : 1;
}

#else

int runVdb(int, char**) {
    std::fprintf(stderr, "vdb: splatfx was built without OpenVDB (libopenvdb-dev); nothing to measure\n");
    return 1;
}

#endif
} // namespace vdb_cmd

int runVdb(int argc, char** argv) { return vdb_cmd::runVdb(argc, argv); }
