// Shadow-table build time and accuracy against shadow tracing, for the
// paper's 1560-voxel effect size (Ebert & Parent 1990, Table 2's question on
// this machine). Prints one table; not a test (speed is never asserted).
//
//   build/tests/lighting/splatfx_shadow_bench [repeats]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <vector>

#include "splatfx/lighting.hpp"
#include "test_scenes.hpp"

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

} // namespace

int main(int argc, char** argv) {
    const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
    const Grid grid = test::effect1560();
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
