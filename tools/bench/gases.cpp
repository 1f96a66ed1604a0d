// splatfx-bench gases: the procedural gases' quality knobs (grid spacing,
// threshold, octaves) against their exact reference, the continuous
// turbulence density integrated through renderVolumeExact
// (proceduralGasMedium): no lattice, no threshold, all --truth-octaves.
// Each setting's sampled grid is drawn as untextured splatting's field (its
// voxel kernels, VolumeField::add) through the same integrator, so the error
// is the sampling's and the kernels', not a quadrature's; a second error
// column reads the same samples trilinearly (no kernel): the sampling alone.
// Time: the gas's per-frame CPU cost, sampleProceduralGas on the lattice and
// SplatBuilder::add of the result (median of --reps).
// The density is the opacity of one cell of the default spacing
// (GasMediumDesc::cellLength): a lattice of another spacing, sampled as the
// SDK samples (opacity = density per cell), is thicker or thinner by their
// ratio; the rows "spacing, depth-scaled" show what the spacing costs when
// the opacity is scaled to the cell (ProceduralGasDesc::cellLength = s0:
// 1 - (1 - d)^(s / s0)).
// --validation prints a 4 x 3 orthographic case (pixel centre, reference
// alpha) for tools/validate/gas_reference.py.
#include <chrono>
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
#include "splatfx/procedural_gas.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/splatfx.hpp"

namespace gases_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kTime = 2.5;      // scene time of the measured frame
constexpr double kSpacing = 0.125; // the default lattice spacing, and the gas's cellLength

// The steam's lattice over [-1, 1] x [0, 2] x [-1, 1] at spacing h.
splatfx::Grid lattice(double h) {
    const int n = int(std::lround(2.0 / h)) + 1;
    return *splatfx::Grid::box({n, n, n}, glm::vec3(float(h)));
}

splatfx::Materials whiteMaterials(splatfx::Kernel kernel = splatfx::Kernel::CrawfisMax) {
    splatfx::FootprintDesc fd;
    fd.kernel = kernel;
    splatfx::Materials m{splatfx::Footprint{fd}};
    m.addColorTable(splatfx::ColorTable::constant({1.0f, 1.0f, 1.0f, 1.0f}));
    return m;
}

// A sampled grid's voxels as extinction per unit at the lattice points
// (-ln(1 - opacity) / cellLength), read trilinearly between them.
splatfx::ContinuousMedium trilinearSamples(const splatfx::Grid& g, double cellLength) {
    auto v = std::make_shared<splatfx::DenseVoxels>();
    v->dims = g.dims;
    v->voxelSize = g.spacing.x;
    v->origin = glm::dvec3(g.worldPosition({0, 0, 0}));
    v->values.assign(std::size_t(g.dims.x) * g.dims.y * g.dims.z, 0.0f);
    for (const splatfx::Voxel& x : g.voxels)
        v->values[(std::size_t(x.cell.z) * g.dims.y + x.cell.y) * g.dims.x + x.cell.x] = float(-std::log1p(-double(x.opacity)) / cellLength);
    return splatfx::denseMedium(v, splatfx::DenseFilter::Trilinear, 1.0);
}

int validation() {
    // Orthographic along -z through the plume: pixel (i, j) (row 0 on top) at
    // x = -0.3 + (i + 1/2) 0.15, y = 0.35 + (3 - 1 - j + 1/2) 0.3.
    const splatfx::Materials mat = whiteMaterials();
    const splatfx::ProceduralGasDesc gas{.kind = splatfx::GasKind::Steam};
    splatfx::VolumeField f(mat);
    f.addMedium(splatfx::proceduralGasMedium(gas, lattice(kSpacing), kTime, mat, {.cellLength = kSpacing}));
    // 0.15 x 0.3 pixels over x in [-0.3, 0.3], y in [0.35, 1.25].
    const splatfx::Camera cam = splatfx::Camera::fromMatrices(glm::lookAt(glm::vec3(0.0f, 0.8f, 3.0f), glm::vec3(0.0f, 0.8f, 0.0f), {0, 1, 0}),
                                                              glm::ortho(-0.3f, 0.3f, -0.45f, 0.45f, 0.01f, 6.0f), {4, 3});
    splatfx::VolumeExactStats st;
    auto img = splatfx::renderVolumeExact(f, cam, {.tolerance = 1e-8, .initialStep = 1.0 / 256, .maxHalvings = 14, .threads = 0}, &st);
    if (!img) return std::fprintf(stderr, "gases: %s\n", img.error().c_str()), 1;
    std::printf("# steam (ProceduralGasDesc defaults) at t = %.1f s, cellLength %.3f, white; rays along -z through z in [-1.0625, 1.0625]\n", kTime,
                kSpacing);
    std::printf("# reference error estimate %.2e, unconverged %llu\n", st.maxErrorEstimate, (unsigned long long)st.unconverged);
    std::printf("x,y,alpha\n");
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i)
            std::printf("%.17g,%.17g,%.9f\n", -0.3 + (i + 0.5) * 0.15, 0.35 + (3 - 1 - j + 0.5) * 0.3, double(img->at(i, j, 3)));
    return 0;
}

} // namespace

int runGases(int argc, char** argv) {
    CLI::App app{"Procedural gases: grid spacing, threshold and octaves against the continuous gas.", "splatfx-bench gases"};
    std::string out = "bench-gases";
    glm::ivec2 size{48, 36};
    int reps = 5, truthOctaves = 6;
    bool noPlots = false, valid = false;
    app.add_option("--out", out, "where gases.dat, gases.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    cli::addSize(app, "--size", size.x, size.y, 8, 512, "image size");
    cli::addNumber(app, "--reps", reps, 1, 1000, "timed samplings per setting, median reported");
    cli::addNumber(app, "--truth-octaves", truthOctaves, 1, 12, "turbulence octaves of the reference gas");
    app.add_flag("--no-plots", noPlots, "print the table only");
    app.add_flag("--validation", valid, "print the small case tools/validate/gas_reference.py checks, and stop");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (valid) return validation();

    const splatfx::Materials mat = whiteMaterials();
    const splatfx::Camera cam = splatfx::Camera::lookAt({0.4f, 1.2f, 4.5f}, {0.0f, 1.0f, 0.0f}, {0, 1, 0}, 0.55f, size);
    const splatfx::ProceduralGasDesc base{.kind = splatfx::GasKind::Steam};
    std::printf("splatfx-bench gases: steam at t = %.1f s, %dx%d, reference with %d octaves, no threshold, cellLength %.3f\n", kTime, size.x, size.y,
                truthOctaves, kSpacing);
    splatfx::ProceduralGasDesc truthGas = base;
    truthGas.turbulence.octaves = truthOctaves;
    splatfx::VolumeField truthField(mat);
    truthField.addMedium(splatfx::proceduralGasMedium(truthGas, lattice(kSpacing), kTime, mat, {.cellLength = kSpacing}));
    const auto t0 = Clock::now();
    splatfx::VolumeExactStats st;
    auto truth = splatfx::renderVolumeExact(truthField, cam, {.tolerance = 1e-4, .initialStep = 1.0 / 128}, &st);
    if (!truth) return std::fprintf(stderr, "gases: %s\n", truth.error().c_str()), 1;
    std::printf("reference: %.1f s, error estimate %.1e, unconverged pixels %llu\n", std::chrono::duration<double>(Clock::now() - t0).count(),
                st.maxErrorEstimate, (unsigned long long)st.unconverged);

    struct Setting {
        std::string knob, setting;
        double spacing = kSpacing;
        float threshold = 0.01f;
        int octaves = 4;
        bool depthScaled = false;
        bool isDefault = false;
    };
    std::vector<Setting> settings;
    for (double h : {0.25, 0.125, 0.0625}) settings.push_back({"grid spacing", std::to_string(h).substr(0, 6), h, 0.01f, 4, false, h == kSpacing});
    for (double h : {0.25, 0.0625}) settings.push_back({"spacing, depth-scaled", std::to_string(h).substr(0, 6), h, 0.01f, 4, true});
    for (float th : {0.0f, 0.01f, 0.05f, 0.1f, 0.2f})
        settings.push_back({"threshold", std::to_string(th).substr(0, 4), kSpacing, th, 4, false, th == 0.01f});
    for (int o : {1, 2, 3, 4, 5, 6}) settings.push_back({"octaves", std::to_string(o), kSpacing, 0.01f, o, false, o == 4});

    std::vector<bench::KnobRow> rows;
    bool defaultDone = false;
    bench::KnobRow defaultRow;
    for (const Setting& s : settings) {
        if (s.isDefault && defaultDone) { // the default is measured once and shown in each knob's block
            bench::KnobRow r = defaultRow;
            r.knob = s.knob;
            r.setting = s.setting;
            rows.push_back(r);
            continue;
        }
        splatfx::ProceduralGasDesc gas = base;
        gas.threshold = s.threshold;
        gas.turbulence.octaves = s.octaves;
        if (s.depthScaled) gas.cellLength = float(kSpacing);
        const splatfx::Grid l = lattice(s.spacing);
        std::vector<double> ms;
        splatfx::Grid g;
        splatfx::SplatBuilder builder;
        for (int r = 0; r < reps; ++r) {
            const auto a = Clock::now();
            g = *splatfx::sampleProceduralGas(gas, l, kTime);
            builder.begin(cam);
            builder.add(g, mat, {.colorTable = 0});
            ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
        }
        splatfx::VolumeField f(mat);
        f.add(g, {.colorTable = 0});
        auto img = splatfx::renderVolumeExact(f, cam, {.tolerance = 1e-4});
        if (!img) return std::fprintf(stderr, "gases: %s\n", img.error().c_str()), 1;
        bench::KnobRow row;
        row.knob = s.knob;
        row.setting = s.setting;
        row.ms = bench::median(ms);
        bench::imageError(*img, *truth, row.rmse, row.maxErr);
        // The same samples read trilinearly (no splat kernel): the lattice sampling's own share.
        splatfx::VolumeField tf(mat);
        tf.addMedium(trilinearSamples(g, s.depthScaled ? s.spacing : kSpacing)); // a depth-scaled opacity is per cell of s
        auto tri = splatfx::renderVolumeExact(tf, cam, {.tolerance = 1e-4});
        if (!tri) return std::fprintf(stderr, "gases: %s\n", tri.error().c_str()), 1;
        double tr = 0.0, tm = 0.0;
        bench::imageError(*tri, *truth, tr, tm);
        char buf[96];
        std::snprintf(buf, sizeof buf, "%zu | %.5f", g.voxels.size(), tr);
        row.extra = buf;
        row.isDefault = s.isDefault;
        rows.push_back(row);
        if (s.isDefault) defaultDone = true, defaultRow = row;
        std::fprintf(stderr, "  %s %s: %.3f ms, RMSE %.5f\n", s.knob.c_str(), s.setting.c_str(), row.ms, row.rmse);
    }
    bench::markPareto(rows);
    bench::printTable(rows, "CPU ms/frame (sample + splats)", "voxels | RMSE, samples trilinear");
    if (noPlots) return 0;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    return bench::writePlot(rows, out, "gases", "procedural gas (steam): error vs the continuous gas per knob",
                            "CPU ms per frame: sample + build splats (median)")
               ? 0
               : 1;
}
} // namespace gases_cmd

int runGases(int argc, char** argv) { return gases_cmd::runGases(argc, argv); }
