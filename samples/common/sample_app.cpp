#include "sample_app.hpp"
#include "sample_options.hpp"

#include "splatfx/output_set.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

#include <unistd.h>

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
           [&o](const std::string& text) {
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
    // The engines' colour targets (docs/integration.md, "Depth buffers that are not textures, and colour targets").
    app.add_option("--msaa", o.msaa, "draw into an N-sample (MSAA) colour and depth target, resolved for the PNG and the window")
        ->check(CLI::IsMember({1, 2, 4, 8, 16}))
        ->type_name("N");
    auto* srgb = app.add_flag("--srgb", o.srgb, "draw into an sRGB colour target with GL_FRAMEBUFFER_SRGB on (blending in linear; the PNG holds sRGB)");
    app.add_flag("--hdr", o.hdr,
                 "draw into an RGBA16F colour target and write each frame also as DIR/<name>_NNNN.exr (linear, unclamped); the PNG and "
                 "GIF clamp at 1")
        ->excludes(srgb);
    app.add_option("--scale", o.scale, "draw the volumes at 1/N resolution per axis (1, 2 or 4; default 1) with depth-aware upsampling")
        ->check(CLI::IsMember({1, 2, 4}))
        ->type_name("N");
    return parseCommandLine(app, argc, argv);
}

void Notes::add(const std::vector<std::string>& lines) {
    for (const std::string& line : lines)
        if (std::find(mLines.begin(), mLines.end(), line) == mLines.end()) {
            mLines.push_back(line);
            std::printf("%s%s: note: %s\n", mMidLine ? "\n" : "", mName.c_str(), line.c_str());
            mMidLine = false;
        }
}

namespace {

// The host's colour and depth target for the options (the one splatfx-render draws into for the same flags).
splatfx::Result<splatfx::gl::Framebuffer> createTarget(const Options& o, glm::ivec2 size) {
    return splatfx::gl::Framebuffer::create({.width = size.x,
                                             .height = size.y,
                                             .color = o.hdr ? splatfx::gl::Precision::F16 : splatfx::gl::Precision::U8,
                                             .floatDepth = o.depth.reversed,
                                             .samples = o.msaa,
                                             .srgb = o.srgb});
}

// One line naming the target when it is not the default RGBA8 one.
void describeTarget(const Options& o, const char* name) {
    if (o.msaa > 1 || o.srgb || o.hdr)
        std::printf("%s: colour target %s%s%s%s\n", name, o.hdr ? "RGBA16F" : "RGBA8", o.msaa > 1 ? (", " + std::to_string(o.msaa) + "x MSAA").c_str() : "",
                    o.srgb ? ", sRGB (GL_FRAMEBUFFER_SRGB)" : "", o.hdr ? ", frames also as EXR" : "");
}

int runHeadless(const Options& o, const char* name, const std::function<bool()>& setup, const std::function<bool(const FrameContext&)>& frame) {
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "%s: %s\n", name, ctx.error().c_str());
        return 1;
    }
    std::printf("%s: headless on %s, %d frames at %dx%d -> %s/\n", name, ctx->renderer().c_str(), o.frames, o.size.x, o.size.y, o.out.c_str());
    auto fb = createTarget(o, o.size);
    glClipControl(GL_LOWER_LEFT, o.depth.clip == splatfx::ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    if (!fb) {
        std::fprintf(stderr, "%s: %s\n", name, fb.error().c_str());
        return 1;
    }
    // An sRGB target: GL blends in linear and stores sRGB codes (no effect on the other targets).
    if (o.srgb) glEnable(GL_FRAMEBUFFER_SRGB);
    describeTarget(o, name);
    if (!setup()) return 1;
    // Frames, GIF and any extra output are one set, published when all are written.
    auto outputs = splatfx::OutputSet::begin(o.out, name);
    if (!outputs) {
        std::fprintf(stderr, "%s: %s\n", name, outputs.error().c_str());
        return 1;
    }
    splatfx::AnimationWriter gif(outputs->path(std::string(name) + ".gif"), o.fps);
    Notes notes(name);
    const bool tty = isatty(fileno(stdout)) != 0;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < o.frames; ++i) {
        FrameContext fc;
        fc.notes = &notes;
        fc.index = i;
        fc.timeSec = i / double(o.fps);
        fc.size = o.size;
        fc.target = {.framebuffer = fb->handle(), .width = o.size.x, .height = o.size.y};
        fc.outputs = &*outputs;
        fc.depth = o.depth;
        fc.hdr = o.hdr;
        glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
        if (!frame(fc)) return 1;
        splatfx::Image img = fb->read(); // resolved when multisampled
        char file[64];
        std::snprintf(file, sizeof file, "%s_%04d.png", name, i);
        if (auto s = splatfx::writeImage(outputs->path(file), img); !s) {
            std::fprintf(stderr, "%s: %s\n", name, s.error().c_str());
            return 1;
        }
        outputs->add(file);
        if (o.hdr) {
            // The target's half floats as a 32-bit float EXR (exactly), linear and unclamped.
            std::snprintf(file, sizeof file, "%s_%04d.exr", name, i);
            if (auto s = splatfx::writeImage(outputs->path(file), img); !s) {
                std::fprintf(stderr, "%s: %s\n", name, s.error().c_str());
                return 1;
            }
            outputs->add(file);
        }
        if (auto s = gif.add(img); !s) {
            std::fprintf(stderr, "%s: %s\n", name, s.error().c_str());
            return 1;
        }
        // A terminal gets a live line; a log (CI, a pipe) about ten whole lines.
        if (tty) {
            std::printf("\r%s: frame %d/%d", name, i + 1, o.frames);
            notes.setMidLine(true);
        } else if ((i + 1) % std::max(1, o.frames / 10) == 0 || i + 1 == o.frames) {
            std::printf("%s: frame %d/%d\n", name, i + 1, o.frames);
        }
        std::fflush(stdout);
    }
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%s%s: writing %s/%s.gif\n", tty ? "\n" : "", name, o.out.c_str(), name);
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
    for (const std::string& line : notes.lines()) std::printf("%s:   note %s\n", name, line.c_str());
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
    // --msaa, --srgb, --hdr: the window's default framebuffer is single-sampled RGBA8, so the frame
    // is drawn into a target of that kind (as headless), resolved and copied to the window.
    const bool ownTarget = o.msaa > 1 || o.srgb || o.hdr;
    std::optional<splatfx::gl::Framebuffer> target, resolved;
    describeTarget(o, name);
    Notes notes(name);
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; !window->shouldClose(); ++i) {
        if (glfwGetKey(window->handle(), GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
        FrameContext fc;
        fc.notes = &notes;
        fc.index = i;
        // Windowed playback follows real time so motion looks right at any frame rate.
        fc.timeSec = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        fc.size = window->framebufferSize();
        fc.depth = o.depth;
        fc.hdr = o.hdr;
        if (ownTarget && (fc.size.x <= 0 || fc.size.y <= 0)) { // minimised: no target of size 0
            window->pollEvents();
            continue;
        }
        if (ownTarget && (!target || target->width() != fc.size.x || target->height() != fc.size.y)) {
            target.reset(), resolved.reset();
            auto fb = createTarget(o, fc.size);
            if (!fb) {
                std::fprintf(stderr, "%s: %s\n", name, fb.error().c_str());
                return 1;
            }
            target.emplace(std::move(*fb));
            if (o.msaa > 1) {
                Options single = o;
                single.msaa = 0;
                auto r = createTarget(single, fc.size);
                if (!r) {
                    std::fprintf(stderr, "%s: %s\n", name, r.error().c_str());
                    return 1;
                }
                resolved.emplace(std::move(*r));
            }
        }
        const unsigned drawn = ownTarget ? target->handle() : 0u;
        fc.target = {.framebuffer = drawn, .width = fc.size.x, .height = fc.size.y};
        if (o.srgb) glEnable(GL_FRAMEBUFFER_SRGB);
        glBindFramebuffer(GL_FRAMEBUFFER, drawn);
        if (!frame(fc)) return 1;
        if (ownTarget) {
            unsigned shown = drawn;
            if (resolved) {
                // Resolved as Framebuffer::read resolves (GL_FRAMEBUFFER_SRGB as while drawing: an
                // sRGB target's samples are averaged in linear), then the stored codes copied.
                glBlitNamedFramebuffer(shown, resolved->handle(), 0, 0, fc.size.x, fc.size.y, 0, 0, fc.size.x, fc.size.y, GL_COLOR_BUFFER_BIT,
                                       GL_NEAREST);
                shown = resolved->handle();
            }
            glDisable(GL_FRAMEBUFFER_SRGB); // the window gets the stored codes, as the PNG; RGBA16F clamps at 1
            glBlitNamedFramebuffer(shown, 0, 0, 0, fc.size.x, fc.size.y, 0, 0, fc.size.x, fc.size.y, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        }
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
