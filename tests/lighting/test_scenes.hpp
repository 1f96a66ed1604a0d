// Grids, lights and scenes shared by the lighting tests and the shadow benchmark.
#pragma once

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/emitted_light.hpp"
#include "splatfx/grid.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/scene.hpp"

namespace splatfx::test {

// Two fits' lights, equal field for field and bit for bit.
inline bool sameLights(const std::vector<EmittedLight>& a, const std::vector<EmittedLight>& b) {
    auto fields = [](const EmittedLight& l) { return std::tie(l.position, l.radius, l.intensity, l.escapePlus, l.escapeMinus); };
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [&](const EmittedLight& x, const EmittedLight& y) { return fields(x) == fields(y); });
}

// A smooth Gaussian blob of opacity (peak `peak` at the centre), n^3 cells of `spacing`.
inline Grid gaussianBlob(int n, float spacing, float peak = 0.6f) {
    Grid g = *Grid::box({n, n, n}, glm::vec3(spacing));
    const float c = 0.5f * float(n - 1), sigma = 0.22f * float(n);
    for (Voxel& v : g.voxels) {
        const glm::vec3 d = glm::vec3(v.cell) - c;
        v.opacity = peak * std::exp(-glm::dot(d, d) / (2.0f * sigma * sigma));
    }
    return g;
}

// The shadow tests' caster: gaussianBlob(12, 0.2, 0.9), 2.2 wide, floating from
// y = 1.5 to 3.7 over the origin.
inline Grid floatingBlob() {
    Grid g = gaussianBlob(12, 0.2f, 0.9f);
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-1.1f, 1.5f, -1.1f));
    return g;
}
// The lights that shadow it: an oblique sun, and a torch up and to the right of it.
inline Light shadowSun() { return Light::directional({0.3f, -1.0f, 0.2f}); }
inline Light shadowTorch() { return Light::point({2.5f, 4.5f, 0.0f}, {1.0f, 0.6f, 0.3f}, 6.0f); }

// The lit reference tests' 3x3x3 blob (small enough for the lit volume
// reference), its base colour, camera and sun direction.
inline Grid smallLitBlob() { return gaussianBlob(3, 0.25f, 0.7f); }
inline glm::vec4 smallLitBlobBase() { return {0.8f, 0.7f, 0.6f, 1.0f}; }
inline glm::vec3 smallLitBlobSunDir() { return {0.6f, -0.7f, -0.4f}; }
inline glm::vec3 gridCentre(const Grid& g) {
    glm::vec3 mid(0.0f);
    for (const Voxel& v : g.voxels) mid += g.worldPosition(v.cell) / float(g.voxels.size());
    return mid;
}
inline Camera smallLitBlobCamera(const Grid& g, glm::ivec2 size) {
    const glm::vec3 mid = gridCentre(g);
    return Camera::lookAt(mid + glm::vec3(0.9f, 0.5f, 2.4f), mid, {0, 1, 0}, 0.55f, size, 0.1f, 20.0f);
}
// `grid` as a Scene's untextured effect named `name` on colour table `row`, lit as `lighting` says.
inline EffectId addLitEffect(Scene& scene, const Grid& grid, std::uint32_t row, const char* name, const EffectLighting& lighting) {
    EffectDesc desc;
    desc.name = name;
    desc.layers = {EffectLayer{.style = {.colorTable = row, .textured = false}}};
    return scene.add(*Effect::fromGrid(grid, desc), {.name = name, .lighting = lighting});
}

// The paper's 1560-voxel effect size (12x26x5, as tools/bench/table1): a
// fire-shaped, smoothly varying opacity, densest low in the middle.
inline Grid effect1560(float spacing = 0.25f) {
    Grid g = *Grid::box({12, 26, 5}, glm::vec3(spacing));
    for (Voxel& v : g.voxels) {
        const float x = (float(v.cell.x) - 5.5f) / 6.0f, z = (float(v.cell.z) - 2.0f) / 2.5f, y = float(v.cell.y) / 25.0f;
        v.opacity = 0.7f * std::exp(-2.0f * (x * x + z * z)) * (1.0f - 0.8f * y);
    }
    return g;
}

// Largest difference between neighbouring table nodes along any axis (what
// GL's filter-weight precision scales).
inline float maxNeighbourStep(const ShadowTable& t) {
    const glm::ivec3 n = t.dims();
    const auto& d = t.data();
    float m = 0.0f;
    auto at = [&](int i, int j, int k) { return d[std::size_t(i + n.x * (j + n.y * k))]; };
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j)
            for (int i = 0; i < n.x; ++i) {
                if (i + 1 < n.x) m = std::max(m, std::abs(at(i + 1, j, k) - at(i, j, k)));
                if (j + 1 < n.y) m = std::max(m, std::abs(at(i, j + 1, k) - at(i, j, k)));
                if (k + 1 < n.z) m = std::max(m, std::abs(at(i, j, k + 1) - at(i, j, k)));
            }
    return m;
}

} // namespace splatfx::test
