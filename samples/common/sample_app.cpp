#include "sample_app.hpp"
#include "sample_options.hpp"

#include "splatfx/output_set.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include "splatfx/context.hpp"

namespace samples {

int parseOptions(int argc, char** argv, const char* name, const char* about, Options& o) {
    CLI::App app{std::string(about) + "\n(no --frames: open a window; Esc quits)", name};
    addNumber(app, "--frames", o.frames, 1, 100000, "render this many frames headless, then exit");
    app.add_option("--out", o.out, "output folder (headless)")->type_name("DIR")->capture_default_str();
    addSize(app, "--size", o.size.x, o.size.y, 16, 8192, "frame size");
    addNumber(app, "--seed", o.seed, 0u, 4294967295u, "seed of every random choice");
    app.add_option_function<std::string>(
           "--fps",
           [&o, name](const std::string& text) {
               float fps = 0.0f;
               if (!option_text::readAll(text, fps) || !(fps > 0.0f && fps <= 240.0f))
                   throw CLI::ValidationError(std::string("--fps must be in (0, 240], got '") + text + "'");
               o.fps = fps;
           },
           "frames per second of the animation (default 24)")
        ->type_name("F");
    app.add_flag("--traditional", o.traditional, "untextured splats (Fig. 1a)");
    app.add_option("--extra", o.extra, "a sample-specific value (see the sample)")->type_name("VALUE");
    // The engines' depth conventions (docs/integration.md, "Depth conventions").
    app.add_flag_callback(
        "--reverse-z", [&o] { o.depth.reversed = true, o.depth.clip = splatfx::ClipDepth::ZeroToOne; },
        "draw as a reverse-Z engine: glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), near at depth 1, far at 0, float depth");
    app.add_flag_callback("--clip-01", [&o] { o.depth.clip = splatfx::ClipDepth::ZeroToOne; }, "clip depth [0, 1] without reversing");
    app.add_flag_callback("--infinite-far", [&o] { o.depth.infiniteFar = true; }, "an infinite far plane");
    return parseCommandLine(app, argc, argv);
}

namespace {

int runHeadless(const Options& o, const char* name, const std::function<bool()>& setup, const std::function<bool(const FrameContext&)>& frame) {
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "%s: %s\n", name, ctx.error().c_str());
        return 1;
    }
    std::printf("%s: headless on %s, %d frames at %dx%d -> %s/\n", name, ctx->renderer().c_str(), o.frames, o.size.x, o.size.y, o.out.c_str());
    auto fb = splatfx::gl::Framebuffer::create({.width = o.size.x, .height = o.size.y, .floatDepth = o.depth.reversed});
    glClipControl(GL_LOWER_LEFT, o.depth.clip == splatfx::ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    if (!fb) {
        std::fprintf(stderr, "%s: %s\n", name, fb.error().c_str());
        return 1;
    }
    if (!setup()) return 1;
    // Frames, GIF and any extra output are one set, published when all are written.
    auto outputs = splatfx::OutputSet::begin(o.out, name);
    if (!outputs) {
        std::fprintf(stderr, "%s: %s\n", name, outputs.error().c_str());
        return 1;
    }
    splatfx::AnimationWriter gif(outputs->path(std::string(name) + ".gif"), o.fps);
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < o.frames; ++i) {
        FrameContext fc;
        fc.index = i;
        fc.timeSec = i / double(o.fps);
        fc.size = o.size;
        fc.target = {.framebuffer = fb->handle(), .width = o.size.x, .height = o.size.y};
        fc.outputs = &*outputs;
        fc.depth = o.depth;
        glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
        if (!frame(fc)) return 1;
        splatfx::Image img = fb->read();
        char file[64];
        std::snprintf(file, sizeof file, "%s_%04d.png", name, i);
        if (auto s = splatfx::writeImage(outputs->path(file), img); !s) {
            std::fprintf(stderr, "%s: %s\n", name, s.error().c_str());
            return 1;
        }
        outputs->add(file);
        if (auto s = gif.add(img); !s) {
            std::fprintf(stderr, "%s: %s\n", name, s.error().c_str());
            return 1;
        }
        std::printf("\r%s: frame %d/%d", name, i + 1, o.frames);
        std::fflush(stdout);
    }
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("\n%s: writing %s/%s.gif\n", name, o.out.c_str(), name);
    if (auto s = gif.finish(); !s) {
        std::fprintf(stderr, "%s: %s\n", name, s.error().c_str());
        return 1;
    }
    outputs->add(std::string(name) + ".gif");
    if (auto s = outputs->publish(); !s) {
        std::fprintf(stderr, "%s: %s\n", name, s.error().c_str());
        return 1;
    }
    std::printf("%s: %d frames in %.2f s (%.1f ms per frame including PNG writes)\n", name, o.frames, sec, 1000.0 * sec / o.frames);
    return 0;
}

int runWindowed(const Options& o, const char* name, const std::function<bool()>& setup, const std::function<bool(const FrameContext&)>& frame) {
    auto window = splatfx::Window::create({.width = o.size.x, .height = o.size.y, .title = std::string("splatfx: ") + name});
    if (!window) {
        std::fprintf(stderr, "%s: %s\n%s: without a display, run headless: %s --frames N --out DIR\n", name, window.error().c_str(), name, name);
        return 1;
    }
    if (!setup()) return 1;
    // A window's default framebuffer has the depth format it was created with (24-bit here):
    // reverse-Z works there, with a fixed-point buffer's precision.
    glClipControl(GL_LOWER_LEFT, o.depth.clip == splatfx::ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; !window->shouldClose(); ++i) {
        if (glfwGetKey(window->handle(), GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
        FrameContext fc;
        fc.index = i;
        // Windowed playback follows real time so motion looks right at any frame rate.
        fc.timeSec = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        fc.size = window->framebufferSize();
        fc.target = {.framebuffer = 0, .width = fc.size.x, .height = fc.size.y};
        fc.depth = o.depth;
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        if (!frame(fc)) return 1;
        window->swapBuffers();
        window->pollEvents();
    }
    return 0;
}

} // namespace

int run(const Options& o, const char* name, const std::function<bool()>& setup, const std::function<bool(const FrameContext&)>& frame) {
    // Any exception from a sample's setup or frame (std::bad_alloc at a huge --size) becomes a message and exit code 1.
    return runGuarded(name, [&] { return o.frames > 0 ? runHeadless(o, name, setup, frame) : runWindowed(o, name, setup, frame); });
}

} // namespace samples
