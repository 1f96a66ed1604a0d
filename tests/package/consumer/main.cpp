// Renders a small fire headless through the README's two snippets (the bare
// core, then a preset in a Scene) and checks each drew something.
#include <algorithm>
#include <cstdio>

#include <splatfx/context.hpp>
#include <splatfx/splatfx.hpp>
#if CONSUMER_HAS_VDB
#include <splatfx/vdb.hpp>
#endif

int main() {
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "consumer: %s\n", ctx.error().c_str()), 1;
    splatfx::Materials materials{splatfx::Footprint{}};
    const auto set = materials.addTextureSet(splatfx::TextureSet::turbulence({}));
    const auto lut = materials.addColorTable(splatfx::ColorTable::fire());
    auto grid = splatfx::Grid::box({4, 8, 4});
    auto fb = splatfx::gl::Framebuffer::create({.width = 64, .height = 64});
    auto renderer = splatfx::gl::Renderer::create();
    if (!grid || !fb || !renderer || !renderer->upload(materials)) return std::fprintf(stderr, "consumer: setup failed\n"), 1;
    const auto camera = splatfx::Camera::lookAt({0, 4, 14}, {0, 4, 0}, {0, 1, 0}, 0.8f, {64, 64});
    splatfx::SplatBuilder builder;
    builder.begin(camera);
    builder.add(*grid, materials, {.textureSet = set, .colorTable = lut});
    builder.sort();
    fb->clear({0, 0, 0, 1});
    renderer->draw(builder.splats(), camera, {.framebuffer = fb->handle(), .width = 64, .height = 64});
    const splatfx::Image img = fb->read();
    const float centre = img.at(32, 32, 0);
    if (!(centre > 0.1f)) return std::fprintf(stderr, "consumer: nothing drawn (centre red %f)\n", centre), 1;
    // The README's second snippet: a preset effect in a Scene, drawn as one frame.
    splatfx::Scene scene;
    auto fire = splatfx::presets::fire(materials, {.dims = {7, 20, 5}});
    if (!fire) return std::fprintf(stderr, "consumer: %s\n", fire.error().c_str()), 1;
    scene.add(std::move(*fire), {.name = "campfire", .rangeWorld = 80});
    auto frameRenderer = splatfx::gl::FrameRenderer::create();
    if (!frameRenderer || !frameRenderer->upload(materials)) return std::fprintf(stderr, "consumer: frame renderer setup failed\n"), 1;
    splatfx::Frame frame;
    bool opaqueDrawn = false;
    if (auto s = scene.prepare(0.5, camera, materials, frame); !s) return std::fprintf(stderr, "consumer: %s\n", s.error().c_str()), 1;
    frameRenderer->render(frame, {.framebuffer = fb->handle(), .drawOpaque = [&] {
                                      fb->clear({0, 0, 0, 1});
                                      opaqueDrawn = true;
                                  }});
    const splatfx::Image lit = fb->read();
    float brightest = 0.0f;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) brightest = std::max(brightest, lit.at(x, y, 0));
    if (!opaqueDrawn || frame.counters().needed != 1 || frame.splats().empty() || !(brightest > 0.1f))
        return std::fprintf(stderr, "consumer: the scene drew nothing\n"), 1;
#if CONSUMER_HAS_VDB
    // splatfx::vdb links OpenVDB: a missing file is an error naming it, not a crash.
    auto vdb = splatfx::loadVdb("no-such-smoke.vdb");
    if (vdb || vdb.error().find("no-such-smoke.vdb' (frame 0): no such file") == std::string::npos)
        return std::fprintf(stderr, "consumer: loadVdb: unexpected answer '%s'\n", vdb.error().c_str()), 1;
#endif
    std::printf("consumer: ok (%zu splats on %s)\n", frame.splats().size(), ctx->renderer().c_str());
    return 0;
}
