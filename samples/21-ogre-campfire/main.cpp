// Sample 21: splatfx's campfire drawn inside OGRE 1.12 (GL3Plus), in OGRE's
// frame (a RenderQueueListener at the end of the main queue), into OGRE's
// render target against OGRE's depth, with OGRE's camera. OGRE draws the
// ground, a log in front of the fire and a wall behind it, lit by a sun whose
// light the fire's smoke shadows (splatfx's shadow table in OGRE's material).
//   ogre-campfire [--frames N] [--size WxH] [--scale 1|2|4] [--seed S] [--time SECONDS] [--screenshot out.png]
//                 [--reverse-z] [--msaa N] [--srgb]
// Needs an X display: headless, run it under xvfb-run -a.
#include <cstdio>
#include <string>

#include "ogre_campfire.hpp"
#include "sample_options.hpp"
#include "splatfx/image_io.hpp"

namespace {

int fail(const std::string& why) {
    std::fprintf(stderr, "ogre-campfire: %s\n", why.c_str());
    return 1;
}

int run(int argc, char** argv) {
    ogrefx::OgreCampfireDesc desc;
    int frames = 24;
    double timeSec = 6.0; // the smoke has risen and drifts over the ground by then
    std::string screenshot;
    CLI::App cli{"splatfx's campfire drawn inside OGRE 1.12 (GL3Plus); needs an X display (headless: xvfb-run -a)", "ogre-campfire"};
    samples::addNumber(cli, "--frames", frames, 1, 100000, "frames rendered, 24 per second, ending at --time");
    samples::addSize(cli, "--size", desc.width, desc.height, 16, 8192, "window size");
    samples::addNumber(cli, "--scale", desc.resolutionScale, 1, 4, "splat resolution divisor (1, 2 or 4)");
    samples::addNumber(cli, "--seed", desc.seed, 0u, 0xffffffffu, "seed of every random choice");
    samples::addNumber(cli, "--time", timeSec, 0.0, 1.0e6, "scene time of the last frame, seconds");
    cli.add_option("--screenshot", screenshot, "write the last frame here (PNG)")->type_name("FILE");
    // An engine's frame (docs/integration.md, "What your engine does"), OGRE's own way.
    cli.add_flag("--reverse-z", desc.reverseZ, "OGRE's \"Reversed Z-Buffer\": [0, 1] clip depth, near at depth 1 (glClipControl)");
    cli.add_option("--msaa", desc.msaa, "OGRE's FSAA on the render texture: N samples, resolved by OGRE")
        ->check(CLI::IsMember({1, 2, 4, 8}))
        ->type_name("N");
    cli.add_flag("--srgb", desc.srgb, "an sRGB render texture (OGRE's hardware gamma; blending in linear; the PNG holds sRGB)");
    if (const int code = samples::parseCommandLine(cli, argc, argv); code >= 0) return code;
    auto app = ogrefx::OgreCampfire::create(desc);
    if (!app) return fail(app.error());
    // Frames at 24 per second ending at --time; the screenshot is the last.
    for (int f = 0; f < frames; ++f) {
        const double t = timeSec - double(frames - 1 - f) / 24.0;
        if (auto s = (*app)->render({.timeSec = t < 0.0 ? 0.0 : t}); !s) return fail(s.error());
    }
    const ogrefx::HookInfo& h = (*app)->hook();
    std::printf("ogre-campfire: %s; %d frames; OGRE framebuffer %u (OGRE says %u), depth %s 0x%x %s, viewport %d %d %d %d, "
                "scissor %s %d %d %d %d%s; %zu splats%s%s%s\n",
                h.glRenderer.c_str(), frames, h.framebuffer, h.framebufferFromOgre, h.depthObjectType == 0x8D41 ? "renderbuffer" : "texture",
                h.depthInternalFormat, h.depthCopied ? "(copied to a texture)" : "(handed over as it is)", h.viewport[0], h.viewport[1],
                h.viewport[2], h.viewport[3], h.scissor ? "on" : "off", h.scissorBox[0], h.scissorBox[1], h.scissorBox[2], h.scissorBox[3],
                h.flipped ? ", flipped" : "", h.splats, h.clipZeroToOne ? "; clip depth [0, 1]" : "",
                h.msaaSamples > 1 ? ("; " + std::to_string(h.msaaSamples) + "x MSAA, drawn per sample").c_str() : "",
                h.framebufferSrgb ? "; GL_FRAMEBUFFER_SRGB on" : "");
    for (const std::string& n : h.notes) std::printf("ogre-campfire: note: %s\n", n.c_str());
    if (!screenshot.empty()) {
        auto image = (*app)->readColour();
        if (!image) return fail(image.error());
        if (auto s = splatfx::writeImage(screenshot, *image); !s) return fail(s.error());
        std::printf("ogre-campfire: wrote %s\n", screenshot.c_str());
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    return samples::runGuarded("ogre-campfire", [&] { return run(argc, argv); });
}
