// splatfx-bench obstacles: what solids cost the gas solver. The smoke of
// samples/26-locomotive-bridge (a 46x18x22 domain, the emitter riding the
// locomotive) stepped for the sample's 4 s at 24 Hz with no obstacle, with
// the bridge (boxes), the bridge and the moving locomotive (a box and a
// cylinder), the same as triangle meshes (winding-number voxelization), and
// with no-slip. Each configuration is one run of the same steps; the table
// gives the mean CPU time per step, its ratio to no obstacles, the solid
// cells and the mean conjugate-gradient iterations (obstacles change the
// pressure system, so the iteration count is part of the cost).
//
//   splatfx-bench obstacles [--steps N] [--validation]
#include <chrono>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "commands.hpp"
#include "options.hpp"
#include "splatfx/solver.hpp"

namespace obstacles_cmd { // one namespace per command: the commands build as one unity translation unit

using namespace splatfx;

namespace {

// The 12 triangles of a box of full extents `size`, centred on the origin.
std::vector<glm::vec3> boxMesh(glm::vec3 size) {
    const glm::vec3 h = 0.5f * size;
    const glm::vec3 v[8] = {{-h.x, -h.y, -h.z}, {h.x, -h.y, -h.z}, {h.x, h.y, -h.z}, {-h.x, h.y, -h.z},
                            {-h.x, -h.y, h.z},  {h.x, -h.y, h.z},  {h.x, h.y, h.z},  {-h.x, h.y, h.z}};
    const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4}, {3, 6, 2}, {3, 7, 6}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
    std::vector<glm::vec3> out;
    for (const auto& t : f)
        for (int i : t) out.push_back(v[i]);
    return out;
}

Obstacle box(glm::vec3 size, glm::vec3 at, bool asMesh, Slip slip, Motion motion = {}) {
    Obstacle o;
    o.desc.transform = glm::translate(glm::mat4(1.0f), at);
    o.desc.slip = slip;
    if (asMesh) {
        o.desc.shape = ObstacleShape::Mesh;
        o.desc.triangles = boxMesh(size);
    } else {
        o.desc.shape = ObstacleShape::Box;
        o.desc.size = size;
    }
    o.motion = std::move(motion);
    return o;
}

struct Config {
    const char* name;
    bool bridge, locomotive, mesh;
    Slip slip;
};

} // namespace

// The channel case of Obstacles.ChannelFlowAroundABox... projected once
// (step(0)), every face velocity as CSV (axis, i, j, k, u) for
// tools/validate/obstacle_projection.py.
int validation() {
    auto s = FluidSolver::create({.dims = {8, 14, 6},
                                  .spacing = glm::vec3(0.5f),
                                  .buoyancy = 0.0f,
                                  .pressureIterations = 2000,
                                  .pressureTolerance = 1e-10f,
                                  .closedFloor = false,
                                  .closedWalls = true,
                                  .closedCeiling = false});
    if (!s) return std::fprintf(stderr, "obstacles: %s\n", s.error().c_str()), 1;
    // Cells x 2..5, y 5..7, z 1..4: local centres (x - 3.5, y, z - 2.5) * 0.5.
    Obstacle o;
    o.desc.size = {2.0f, 1.5f, 2.0f};
    o.desc.transform = glm::translate(glm::mat4(1.0f), {0.0f, 3.0f, 0.0f});
    if (Status st = s->addObstacle(o); !st) return std::fprintf(stderr, "obstacles: %s\n", st.error().c_str()), 1;
    s->setUniformVelocity({0, 1, 0});
    s->step(0.0);
    std::printf("axis,i,j,k,u\n");
    for (int a = 0; a < 3; ++a) {
        glm::ivec3 fd = s->dims();
        fd[a] += 1;
        for (int k = 0; k < fd.z; ++k)
            for (int j = 0; j < fd.y; ++j)
                for (int i = 0; i < fd.x; ++i) std::printf("%d,%d,%d,%d,%.9g\n", a, i, j, k, s->faceVelocity(a, {i, j, k}));
    }
    std::fprintf(stderr, "solid cells %llu, CG %d iterations, relative residual %.3g\n", static_cast<unsigned long long>(s->stats().solidCells),
                 s->stats().lastPressureIterations, double(s->stats().lastResidual));
    return 0;
}

int runObstacles(int argc, char** argv) {
    int steps = 96;
    CLI::App app{"Solver step cost with obstacles against none: the smoke of samples/26-locomotive-bridge (46x18x22 cells) stepped at 24 Hz",
                 "splatfx-bench obstacles"};
    bool validate = false;
    cli::addNumber(app, "--steps", steps, 1, 100000, "steps per configuration (96: the sample's 4 s)");
    app.add_flag("--validation", validate, "print the projected face velocities of a small channel case as CSV for tools/validate/obstacle_projection.py");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (validate) return validation();

    const Motion train({{.timeSec = 0, .pose = {.position = {-8, 0.22f, 0}}}, {.timeSec = 4, .pose = {.position = {6, 0.22f, 0}}}});
    const Config configs[] = {
        {"none", false, false, false, Slip::Free},
        {"bridge: deck and 2 piers (boxes)", true, false, false, Slip::Free},
        {"bridge + moving locomotive (box, cylinder)", true, true, false, Slip::Free},
        {"bridge + locomotive, no-slip", true, true, false, Slip::None},
        {"bridge + locomotive as meshes (12 triangles each)", true, true, true, Slip::Free},
    };
    std::printf("obstacles: %d steps of 1/24 s per configuration, one run, CPU time (std::clock)\n", steps);
    std::printf("\n| obstacles | solid cells (last step) | ms/step | vs none | CG iterations/step |\n| --- | ---: | ---: | ---: | ---: |\n");
    double noneMs = 0.0;
    for (const Config& c : configs) {
        auto solver = FluidSolver::create({.dims = {46, 18, 22},
                                           .spacing = glm::vec3(0.3f),
                                           .transform = glm::translate(glm::mat4(1.0f), {0, 0.2f, 0}),
                                           .buoyancy = 3.0f,
                                           .windWorld = {-0.4f, 0, 0},
                                           .windCoupling = 0.6f,
                                           .velocityDamping = 0.3f,
                                           .densityDissipation = 0.12f,
                                           .temperatureDissipation = 0.6f});
        if (!solver) {
            std::fprintf(stderr, "obstacles: %s\n", solver.error().c_str());
            return 1;
        }
        solver->addEmitter({.desc = {.offset = {1.45f, 2.7f, 0}, .radius = 0.4f, .density = 1.0f, .temperature = 1.0f, .rate = 6.0f}, .motion = train});
        std::vector<Obstacle> obs;
        if (c.bridge) {
            obs.push_back(box({1.6f, 0.4f, 8.0f}, {1.5f, 3.75f, 0}, c.mesh, c.slip));
            obs.push_back(box({1.2f, 3.55f, 0.8f}, {1.5f, 1.775f, 3.2f}, c.mesh, c.slip));
            obs.push_back(box({1.2f, 3.55f, 0.8f}, {1.5f, 1.775f, -3.2f}, c.mesh, c.slip));
        }
        if (c.locomotive) {
            obs.push_back(box({1.3f, 1.7f, 1.4f}, {-1.6f, 1.65f, 0}, c.mesh, c.slip, train)); // the cab
            Obstacle boiler;
            if (c.mesh) {
                boiler = box({3.0f, 1.1f, 1.1f}, {0.5f, 1.35f, 0}, true, c.slip, train); // the boiler's bounding box as a mesh
            } else {
                boiler.desc = {.shape = ObstacleShape::Cylinder,
                               .size = {1.1f, 3.0f, 1.1f},
                               .transform = glm::rotate(glm::translate(glm::mat4(1.0f), {-1.0f, 1.35f, 0}), -1.5707963f, glm::vec3(0, 0, 1)),
                               .slip = c.slip};
                boiler.motion = train;
            }
            obs.push_back(boiler);
        }
        for (const Obstacle& o : obs)
            if (Status s = solver->addObstacle(o); !s) {
                std::fprintf(stderr, "obstacles: %s\n", s.error().c_str());
                return 1;
            }
        long iterations = 0;
        const std::clock_t t0 = std::clock();
        for (int i = 0; i < steps; ++i) {
            solver->step(1.0 / 24.0);
            iterations += solver->stats().lastPressureIterations;
        }
        const double msPerStep = 1000.0 * double(std::clock() - t0) / CLOCKS_PER_SEC / steps;
        if (noneMs == 0.0) noneMs = msPerStep;
        std::printf("| %s | %llu | %.2f | %.2fx | %.1f |\n", c.name, static_cast<unsigned long long>(solver->stats().solidCells), msPerStep,
                    msPerStep / noneMs, double(iterations) / steps);
        std::fflush(stdout);
    }
    return 0;
}
} // namespace obstacles_cmd

int runObstacles(int argc, char** argv) { return obstacles_cmd::runObstacles(argc, argv); }
