// splatfx-bench shadowtables: shadow-table build time and accuracy against
// shadow tracing, for the paper's 1560-voxel effect size (Ebert & Parent
// 1990, Table 2's question on this machine), on the CPU. Prints one table
// per light (docs/lighting.md).
//
//   splatfx-bench shadowtables [--repeats N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <vector>

#include "commands.hpp"
#include "options.hpp"
#include "splatfx/lighting.hpp"

namespace shadow_tables_cmd { // one namespace per command: the commands build as one unity translation unit

using namespace splatfx;
using Clock = std::chrono::steady_clock;

namespace {

double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

// Median wall time, and median process CPU time (std::clock): on a shared
// machine the CPU time is the steadier of the two.
struct Timing {
    double wallMs, cpuMs;
};
template <class F>
Timing medianMs(int repeats, F&& f) {
    std::vector<double> wall, cpu;
    for (int r = 0; r < repeats; ++r) {
        const auto a = Clock::now();
        const std::clock_t c = std::clock();
        f();
        cpu.push_back(1000.0 * double(std::clock() - c) / CLOCKS_PER_SEC);
        wall.push_back(ms(Clock::now() - a));
    }
    std::sort(wall.begin(), wall.end());
    std::sort(cpu.begin(), cpu.end());
    return {wall[wall.size() / 2], cpu[cpu.size() / 2]};
}

// 12x26x5 voxels at spacing 0.25, a soft column thinning upwards (the
// lighting tests' 1560-voxel effect).
Grid column1560() {
    Grid g = *Grid::box({12, 26, 5}, glm::vec3(0.25f));
    for (Voxel& v : g.voxels) {
        const glm::vec3 q((float(v.cell.x) - 5.5f) / 6.0f, float(v.cell.y) / 25.0f, (float(v.cell.z) - 2.0f) / 2.5f);
        v.opacity = 0.7f * std::exp(-2.0f * (q.x * q.x + q.z * q.z)) * (1.0f - 0.8f * q.y);
    }
    return g;
}

} // namespace

int runShadowTables(int argc, char** argv) {
    int repeats = 5;
    CLI::App app{"Shadow tables (16^3 .. 128^3) against tracing every voxel, for a 1560-voxel effect lit by a sun and by a point light\n"
                 "inside it: median build and lookup time (wall and CPU) and transmittance error, on the CPU.",
                 "splatfx-bench shadowtables"};
    cli::addNumber(app, "--repeats", repeats, 1, 1000, "runs per timing (the median is printed)");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    const Grid grid = column1560();
    auto field = DensityField::fromGrid(grid);
    if (!field) {
        std::fprintf(stderr, "%s\n", field.error().c_str());
        return 1;
    }
    const glm::vec3 c = 0.5f * (field->boundsMin() + field->boundsMax());
    struct Case {
        const char* name;
        Light light;
    } cases[] = {
        {"sun (directional, oblique)", Light::directional({0.35f, -1.0f, 0.25f})},
        {"point light inside the gas", Light::point(c + glm::vec3(0.3f, -0.6f, 0.1f))},
    };
    std::printf("shadows for a %zu-voxel effect (12x26x5, spacing 0.25), median of %d runs\n", grid.voxels.size(), repeats);
    for (const Case& k : cases) {
        std::vector<float> traced(grid.voxels.size());
        const Timing traceMs = medianMs(repeats, [&] {
            for (std::size_t i = 0; i < grid.voxels.size(); ++i)
                traced[i] = std::exp2(-field->opticalDepthToLight(grid.worldPosition(grid.voxels[i].cell), k.light));
        });
        std::printf("\n%s: tracing every voxel %.2f ms wall, %.2f ms CPU\n", k.name, traceMs.wallMs, traceMs.cpuMs);
        std::printf("  table  build wall ms  build CPU ms  lookups ms  (build+lookups)/trace (CPU)  mean err (1/255)  max err (1/255)\n");
        for (int n : {16, 32, 64, 128}) {
            ShadowTable table({.dims = glm::ivec3(n)});
            const Timing buildMs = medianMs(repeats, [&] {
                ShadowTable fresh({.dims = glm::ivec3(n)}); // a new object: no reuse, sorts its order too
                (void)fresh.update(*field, k.light);
            });
            if (Status s = table.update(*field, k.light); !s) {
                std::printf("  %d^3: %s\n", n, s.error().c_str());
                continue;
            }
            std::vector<float> fromTable(grid.voxels.size());
            const Timing lookMs = medianMs(repeats, [&] {
                for (std::size_t i = 0; i < grid.voxels.size(); ++i) fromTable[i] = table.transmittance(grid.worldPosition(grid.voxels[i].cell));
            });
            double mean = 0.0, mx = 0.0;
            for (std::size_t i = 0; i < traced.size(); ++i) {
                const double e = std::abs(double(fromTable[i]) - double(traced[i])) * 255.0;
                mean += e;
                mx = std::max(mx, e);
            }
            mean /= double(traced.size());
            std::printf("  %4d^3 %14.2f %13.2f %11.3f %28.2f %17.3f %16.3f\n", n, buildMs.wallMs, buildMs.cpuMs, lookMs.wallMs,
                        (buildMs.cpuMs + lookMs.cpuMs) / std::max(traceMs.cpuMs, 1e-3), mean, mx);
        }
    }
    return 0;
}
} // namespace shadow_tables_cmd

int runShadowTables(int argc, char** argv) { return shadow_tables_cmd::runShadowTables(argc, argv); }
