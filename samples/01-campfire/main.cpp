// Sample 01: the paper's campfire (King et al. 1999, Figure 1): a 7x20x5 grid
// drawn as textured splats, made by splatfx::presets::fire and animated at
// two scales: global dynamics (sec. 3.2, texture detail propagating upwards
// one voxel per step) and local dynamics (sec. 3.3, ordered texture cycling
// with cross-fades). Every frame is computed directly from its time (the
// fire is stateless), so frames can be rendered in any order. The frame is
// the SDK's: Scene::prepare, then gl::FrameRenderer with the clear as the
// host's opaque pass; its fallbacks (stats().notes) are printed once each.
// Headless it also writes campfire_figure1.png: traditional splatting (left,
// Fig. 1a) beside textured splatting (right, Fig. 1b) of the same grid.
#include <cstdio>
#include <optional>

#include <epoxy/gl.h>

#include "sample_app.hpp"

namespace {

struct Campfire {
    samples::Options options;
    splatfx::Materials materials{splatfx::Footprint{}};
    splatfx::Scene scene;
    splatfx::Frame splatFrame;
    std::optional<splatfx::gl::FrameRenderer> renderer;
    bool figureWritten = false;

    bool setup() {
        // --extra paper-lattice: every splat on its voxel with its texture upright, as in
        // the paper (the before of docs/samples.md); default the preset's SplatVariation.
        if (!options.extra.empty() && options.extra != "paper-lattice")
            return fail("--extra expects paper-lattice (splats on the voxel lattice, as in the paper), got '" + options.extra + "'");
        splatfx::presets::FireDesc desc{.dims = {7, 20, 5},
                                        .spacing = glm::vec3(0.5f),
                                        .propagationStepsPerSec = 8.0f,
                                        .texturesPerSec = 6.0f,
                                        .crossfade = true,
                                        .seed = options.seed};
        if (options.extra == "paper-lattice") desc.variation = {};
        // The preset registers its turbulence set and fire colour table in materials.
        auto f = splatfx::presets::fire(materials, desc);
        if (!f) return fail(f.error());
        scene.add(std::move(*f), {.name = "campfire"});
        auto r = splatfx::gl::FrameRenderer::create({.resolutionScale = options.scale});
        if (!r) return fail(r.error());
        renderer = std::move(*r);
        if (auto s = renderer->upload(materials); !s) return fail(s.error());
        return true;
    }

    static bool fail(const std::string& why) {
        std::fprintf(stderr, "campfire: %s\n", why.c_str());
        return false;
    }

    // The host's depth convention (--reverse-z, --clip-01, --infinite-far) shapes its projection.
    splatfx::Camera camera(glm::ivec2 size) const {
        return splatfx::Camera::lookAt({0.0f, 4.8f, 15.0f}, {0.0f, 4.6f, 0.0f}, {0, 1, 0}, glm::radians(45.0f), size, 0.05f, 1000.0f,
                                       options.depth);
    }

    // The host's opaque pass: this sample has no geometry, only a background (depth: the far plane's value).
    void clearBackground() const {
        glClearColor(0.02f, 0.02f, 0.04f, 1.0f);
        glClearDepth(options.depth.farWindow());
        glDepthMask(GL_TRUE);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glClearDepth(1.0);
    }

    // What the frame renderer could not do as asked goes to `notes` (printed once each).
    void draw(double timeSec, glm::ivec2 size, unsigned framebuffer, bool textured, samples::Notes& notes) {
        if (auto s = scene.prepare(timeSec, camera(size), materials, splatFrame, {.textured = textured}); !s) {
            std::fprintf(stderr, "campfire: %s\n", s.error().c_str());
            return;
        }
        renderer->render(splatFrame, {.framebuffer = framebuffer, .drawOpaque = [this] { clearBackground(); }});
        notes.add(renderer->stats().notes);
    }

    bool frame(const samples::FrameContext& fc) {
        draw(fc.timeSec, fc.size, fc.target.framebuffer, !options.traditional, *fc.notes);
        return figureWritten || !fc.outputs || writeFigure1(fc);
    }

    // Fig. 1a vs 1b: the same grid and frame, traditional then textured.
    bool writeFigure1(const samples::FrameContext& fc) {
        figureWritten = true;
        splatfx::Image halves[2];
        for (int textured = 0; textured < 2; ++textured) {
            auto fb = splatfx::gl::Framebuffer::create({.width = fc.size.x, .height = fc.size.y, .floatDepth = options.depth.reversed});
            if (!fb) return fail(fb.error());
            draw(fc.timeSec, fc.size, fb->handle(), textured == 1, *fc.notes);
            halves[textured] = fb->read();
        }
        splatfx::Image both;
        both.width = 2 * fc.size.x;
        both.height = fc.size.y;
        both.channels = 4;
        both.pixels.resize(size_t(both.width) * both.height * 4);
        for (int y = 0; y < both.height; ++y)
            for (int x = 0; x < both.width; ++x)
                for (int c = 0; c < 4; ++c) both.at(x, y, c) = halves[x / fc.size.x].at(x % fc.size.x, y, c);
        if (auto s = splatfx::writeImage(fc.outputs->path("campfire_figure1.png"), both); !s) return fail(s.error());
        fc.outputs->add("campfire_figure1.png");
        std::printf("campfire: %s/campfire_figure1.png (left: traditional splats, right: textured splats)\n", options.out.c_str());
        return true;
    }
};

} // namespace

int main(int argc, char** argv) {
    Campfire app;
    if (const int code = samples::parseOptions(argc, argv, "campfire", "the paper's 7x20x5 fire as textured splats (Figure 1)", app.options);
        code >= 0)
        return code;
    return samples::run(
        app.options, "campfire", [&] { return app.setup(); }, [&](const samples::FrameContext& fc) { return app.frame(fc); });
}
