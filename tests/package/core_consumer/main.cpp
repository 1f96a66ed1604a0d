// Builds the splats of a 4x8x4 box on the CPU with only splatfx::core (no GL
// context anywhere) and checks what a host would rely on: one splat per
// voxel, ordered back to front, finite and on the texture set registered.
#include <cmath>
#include <cstdio>

#include <splatfx/camera.hpp>
#include <splatfx/color_table.hpp>
#include <splatfx/grid.hpp>
#include <splatfx/materials.hpp>
#include <splatfx/splats.hpp>
#include <splatfx/texture_set.hpp>

int main() {
    splatfx::Materials materials{splatfx::Footprint{}};
    const auto set = materials.addTextureSet(splatfx::TextureSet::turbulence({.count = 4, .size = 16}));
    const auto lut = materials.addColorTable(splatfx::ColorTable::fire());
    auto grid = splatfx::Grid::box({4, 8, 4});
    if (!grid) return std::fprintf(stderr, "core consumer: %s\n", grid.error().c_str()), 1;
    const auto camera = splatfx::Camera::lookAt({0, 4, 14}, {0, 4, 0}, {0, 1, 0}, 0.8f, {64, 64});
    splatfx::SplatBuilder builder;
    builder.begin(camera);
    builder.add(*grid, materials, {.textureSet = set, .colorTable = lut});
    builder.sort();
    const auto& splats = builder.splats();
    if (splats.size() != grid->voxels.size())
        return std::fprintf(stderr, "core consumer: %zu splats for %zu voxels\n", splats.size(), grid->voxels.size()), 1;
    for (std::size_t i = 0; i < splats.size(); ++i) {
        const splatfx::Splat& s = splats[i];
        if (!std::isfinite(s.depth) || !std::isfinite(s.center.x) || !(s.density > 0.0f))
            return std::fprintf(stderr, "core consumer: splat %zu is not finite and positive\n", i), 1;
        if (i > 0 && splats[i - 1].depth < s.depth) return std::fprintf(stderr, "core consumer: splat %zu is out of back-to-front order\n", i), 1;
    }
    std::printf("consumer: ok (%zu splats, core only)\n", splats.size());
    return 0;
}
