#include "sample_app.hpp"

#include "splatfx/output_set.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include "cli.hpp"
#include "splatfx/context.hpp"

namespace samples {

bool parseOptions(int argc, char** argv, const char* name, const char* about, Options& o) {
    auto usage = [&] {
        std::printf("%s: %s\n\nusage: %s [--frames N --out DIR] [--size WxH] [--seed S] [--fps F] [--traditional]\n"
                    "  (no --frames: open a window; Esc quits)\n",
                    name, about, name);
    };
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> const char* {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "%s: %s needs a value\n", name, a.c_str());
                return nullptr;
            }
            return argv[++i];
        };
        const char* v = nullptr;
        if (a == "--help" || a == "-h") {
            usage();
            return false;
        } else if (a == "--traditional") {
            o.traditional = true;
        } else if (a == "--frames" && (v = next())) {
            if (auto st = cli::parseInt("--frames", v, 1, 100000, o.frames); !st) {
                std::fprintf(stderr, "%s: %s\n", name, st.error().c_str());
                return false;
            }
        } else if (a == "--out" && (v = next())) {
            o.out = v;
        } else if (a == "--size" && (v = next())) {
            if (auto st = cli::parseSize("--size", v, 16, 8192, o.size.x, o.size.y); !st) {
                std::fprintf(stderr, "%s: %s (e.g. 640x480)\n", name, st.error().c_str());
                return false;
            }
        } else if (a == "--seed" && (v = next())) {
            if (auto st = cli::parseInt("--seed", v, 0u, 4294967295u, o.seed); !st) {
                std::fprintf(stderr, "%s: %s\n", name, st.error().c_str());
                return false;
            }
        } else if (a == "--fps" && (v = next())) {
            if (!cli::parseReal("--fps", v, 0.0f, 240.0f, o.fps) || !(o.fps > 0.0f)) {
                std::fprintf(stderr, "%s: --fps must be in (0, 240], got '%s'\n", name, v);
                return false;
            }
        } else if (a == "--extra" && (v = next())) {
            o.extra = v;
        } else {
            if (!v) std::fprintf(stderr, "%s: unknown or incomplete option '%s' (try --help)\n", name, a.c_str());
            return false;
        }
    }
    return true;
}

namespace {

int runHeadless(const Options& o, const char* name, const std::function<bool()>& setup, const std::function<bool(const FrameContext&)>& frame) {
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "%s: %s\n", name, ctx.error().c_str());
        return 1;
    }
    std::printf("%s: headless on %s, %d frames at %dx%d -> %s/\n", name, ctx->renderer().c_str(), o.frames, o.size.x, o.size.y, o.out.c_str());
    auto fb = splatfx::gl::Framebuffer::create({.width = o.size.x, .height = o.size.y});
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
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; !window->shouldClose(); ++i) {
        if (glfwGetKey(window->handle(), GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
        FrameContext fc;
        fc.index = i;
        // Windowed playback follows real time so motion looks right at any frame rate.
        fc.timeSec = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        fc.size = window->framebufferSize();
        fc.target = {.framebuffer = 0, .width = fc.size.x, .height = fc.size.y};
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
    return cli::guardedMain(name, [&] { return o.frames > 0 ? runHeadless(o, name, setup, frame) : runWindowed(o, name, setup, frame); });
}

} // namespace samples
