// Volumes as light (issue 27, item 3): point lights fitted to an emissive
// effect's splats against the exact irradiance the same splats give
// (reference::emittedIrradianceExact, every ray composited with occlusion).
#include <cmath>
#include <cstdio>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/emitted_light.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

// The fire preset's splats as seen from `eye` (every splat: no frustum culling).
std::vector<Splat> splatsFrom(Effect& fire, const Materials& m, glm::vec3 eye, glm::vec3 target) {
    SplatBuilder b({.frustumCull = false});
    b.begin(Camera::lookAt(eye, target, std::abs(glm::normalize(target - eye).y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0),
                           glm::radians(60.0f), {64, 64}, 1e-4f, 1e5f));
    fire.emit(b, m);
    return b.splats();
}

struct Receiver {
    glm::vec3 point, normal;
};

} // namespace

TEST(EmittedLight, Explore) {
    Materials m{Footprint{}};
    Effect fire = *presets::fire(m, {.dims = {7, 20, 5}, .spacing = glm::vec3(0.45f)});
    fire.update(0.5);
    const glm::vec3 centre(0.0f, 4.0f, 0.0f);
    const std::vector<Receiver> receivers{{{2.5f, 0.0f, 0.0f}, {0, 1, 0}},  {{0.0f, 0.0f, 3.5f}, {0, 1, 0}}, {{4.0f, 0.0f, 0.0f}, {0, 1, 0}},
                                          {{3.0f, 2.0f, 0.0f}, {-1, 0, 0}}, {{0.0f, 4.0f, 6.0f}, {0, 0, -1}}, {{0.0f, 3.0f, 40.0f}, {0, 0, -1}}};
    std::vector<Splat> main = splatsFrom(fire, m, {0.0f, 4.0f, 15.0f}, centre);
    for (const Receiver& r : receivers) {
        std::vector<Splat> s = splatsFrom(fire, m, r.point, centre);
        auto ex = emittedIrradianceExact(s, m, glm::dvec3(r.point), glm::dvec3(r.normal), {.faceSize = 96});
        ASSERT_TRUE(ex) << ex.error();
        std::printf("receiver (%.1f %.1f %.1f): exact %.4f %.4f %.4f (est %.2e)\n", r.point.x, r.point.y, r.point.z, ex->irradiance.x,
                    ex->irradiance.y, ex->irradiance.z, ex->errorEstimate);
        for (int k : {1, 2, 4, 8})
            for (bool occ : {false, true}) {
                auto lights = fitEmittedLights(main, m, {.enabled = true, .lights = k, .occlusion = occ});
                ASSERT_TRUE(lights);
                glm::vec3 e = emittedIrradiance(*lights, r.point, r.normal);
                std::printf("   K=%d occ=%d: %.4f %.4f %.4f  ratio %.3f\n", k, int(occ), e.x, e.y, e.z, e.x / ex->irradiance.x);
            }
    }
}
