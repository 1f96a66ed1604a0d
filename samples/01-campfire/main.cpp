// Sample 01: the paper's campfire (King et al. 1999, Figure 1): a 7x20x5 grid
// drawn as textured splats, animated by texture cycling with cross-fades.
// Headless it also writes campfire_figure1.png: traditional splatting (left,
// Fig. 1a) beside textured splatting (right, Fig. 1b) of the same grid.
#include <cmath>
#include <cstdio>
#include <optional>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>

#include "sample_app.hpp"

namespace {

// A flame-shaped opacity on the box: dense at the base and centre, thinning
// and narrowing with height.
void shapeFlame(splatfx::Grid& grid, std::uint32_t seed) {
    for (splatfx::Voxel& v : grid.voxels) {
        const float h = v.cell.y / float(grid.dims.y - 1);
        const float rx = (v.cell.x - 0.5f * (grid.dims.x - 1)) / (0.5f * grid.dims.x);
        const float rz = (v.cell.z - 0.5f * (grid.dims.z - 1)) / (0.5f * grid.dims.z);
        const float r = std::sqrt(rx * rx + rz * rz);
        const float width = 1.0f - 0.75f * h;
        const float edge = std::clamp((width - r) / 0.35f + 0.3f, 0.0f, 1.0f);
        v.opacity = 0.55f * (1.0f - 0.6f * h) * edge;
        // Deterministic per-voxel start texture (sec. 2 step 3: initially random).
        std::uint32_t x = std::uint32_t(v.cell.x * 73856093) ^ std::uint32_t(v.cell.y * 19349663) ^ std::uint32_t(v.cell.z * 83492791) ^ seed;
        x ^= x >> 13;
        x *= 0x5bd1e995u;
        x ^= x >> 15;
        v.texture = x;
    }
}

struct Campfire {
    samples::Options options;
    splatfx::Materials materials{splatfx::Footprint{}};
    std::uint32_t fireSet = 0, fireTable = 0;
    splatfx::Grid base;
    splatfx::Grid grid;
    splatfx::SplatBuilder builder;
    std::optional<splatfx::gl::Renderer> renderer;
    bool figureWritten = false;

    bool setup() {
        fireSet = materials.addTextureSet(splatfx::TextureSet::turbulence({.count = 8, .size = 32, .seed = options.seed}));
        fireTable = materials.addColorTable(splatfx::ColorTable::fire());
        auto g = splatfx::Grid::box({7, 20, 5}, glm::vec3(0.5f));
        if (!g) return fail(g.error());
        base = std::move(*g);
        shapeFlame(base, options.seed);
        grid = base;
        auto r = splatfx::gl::Renderer::create();
        if (!r) return fail(r.error());
        renderer = std::move(*r);
        if (auto s = renderer->upload(materials); !s) return fail(s.error());
        return true;
    }

    static bool fail(const std::string& why) {
        std::fprintf(stderr, "campfire: %s\n", why.c_str());
        return false;
    }

    splatfx::Camera camera(glm::ivec2 size) const {
        return splatfx::Camera::lookAt({0.0f, 4.8f, 15.0f}, {0.0f, 4.6f, 0.0f}, {0, 1, 0}, glm::radians(45.0f), size);
    }

    // Local dynamics by texture cycling: 6 textures per second, cross-faded.
    void animate(double timeSec) {
        const double steps = timeSec * 6.0;
        const auto whole = std::uint32_t(std::floor(steps));
        for (size_t i = 0; i < grid.voxels.size(); ++i) {
            grid.voxels[i].texture = base.voxels[i].texture + whole;
            grid.voxels[i].phase = float(steps - std::floor(steps));
        }
    }

    void draw(const splatfx::Camera& cam, const splatfx::gl::Target& target, bool textured) {
        builder.begin(cam);
        builder.add(grid, materials, {.textureSet = fireSet, .colorTable = fireTable, .textured = textured, .crossfade = true});
        builder.sort();
        renderer->draw(builder.splats(), cam, target);
    }

    void frame(const samples::FrameContext& fc) {
        animate(fc.timeSec);
        const splatfx::Camera cam = camera(fc.size);
        glBindFramebuffer(GL_FRAMEBUFFER, fc.target.framebuffer);
        glViewport(0, 0, fc.size.x, fc.size.y);
        glClearColor(0.02f, 0.02f, 0.04f, 1.0f);
        glClearDepth(1.0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        draw(cam, fc.target, !options.traditional);
        if (options.frames > 0 && !figureWritten) writeFigure1(fc);
    }

    // Fig. 1a vs 1b: the same grid and frame, traditional then textured.
    void writeFigure1(const samples::FrameContext& fc) {
        figureWritten = true;
        splatfx::Image halves[2];
        for (int textured = 0; textured < 2; ++textured) {
            auto fb = splatfx::gl::Framebuffer::create({.width = fc.size.x, .height = fc.size.y});
            if (!fb) return void(fail(fb.error()));
            fb->clear({0.02f, 0.02f, 0.04f, 1.0f});
            draw(camera(fc.size), {.framebuffer = fb->handle(), .width = fc.size.x, .height = fc.size.y}, textured == 1);
            halves[textured] = fb->read();
        }
        splatfx::Image both;
        both.width = 2 * fc.size.x;
        both.height = fc.size.y;
        both.channels = 4;
        both.pixels.resize(size_t(both.width) * both.height * 4);
        for (int y = 0; y < both.height; ++y)
            for (int x = 0; x < both.width; ++x)
                for (int c = 0; c < 4; ++c)
                    both.at(x, y, c) = halves[x / fc.size.x].at(x % fc.size.x, y, c);
        const std::string path = options.out + "/campfire_figure1.png";
        if (auto s = splatfx::writeImage(path, both); !s) return void(fail(s.error()));
        std::printf("campfire: wrote %s (left: traditional splats, right: textured splats)\n", path.c_str());
    }
};

} // namespace

int main(int argc, char** argv) {
    Campfire app;
    if (!samples::parseOptions(argc, argv, "campfire", "the paper's 7x20x5 fire as textured splats (Figure 1)", app.options))
        return 2;
    return samples::run(
        app.options, "campfire", [&] { return app.setup(); }, [&](const samples::FrameContext& fc) { app.frame(fc); });
}
