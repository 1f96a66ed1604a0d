// splatfx-bench msaa: a sample scene drawn into a single-sampled and into
// 2x, 4x and 8x multisampled host targets (FramebufferDesc::samples; the
// frame renderer runs the host fog and the volumes once per sample), each
// frame timed with its resolve and glFinish, its error the RMSE against the
// anti-aliased reference: the mean of 16 single-sampled frames whose pixel
// centres sit on a 4x4 grid inside each pixel (the same scene, the
// projection shifted). Settings the driver cannot make are listed, not run.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "knob_table.hpp"
#include "options.hpp"
#include "scene_player.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/framebuffer.hpp"

namespace msaa_cmd { // one namespace per command: the commands build as one unity translation unit

int runMsaa(int argc, char** argv) {
    std::string scene = "samples/09-fog-countryside/scene.json", out = "bench-msaa";
    int width = 320, height = 240, frames = 5;
    double timeSec = 1.0;
    bool noPlots = false;
    CLI::App app{"MSAA host targets: ms per frame and error against a 16-sample anti-aliased reference, 1x to 8x.", "splatfx-bench msaa"};
    app.add_option("--scene", scene, "the scene file")->type_name("SCENE.json")->capture_default_str();
    cli::addNumber(app, "--width", width, 16, 4096, "frame width");
    cli::addNumber(app, "--height", height, 16, 4096, "frame height");
    cli::addNumber(app, "--frames", frames, 1, 1000, "timed frames per setting, median reported");
    app.add_option("--time", timeSec, "scene time of the frame, s")->capture_default_str();
    app.add_option("--out", out, "where msaa.dat, msaa.gp and the PNG plots go")->type_name("DIR")->capture_default_str();
    app.add_flag("--no-plots", noPlots, "print the table only");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "msaa: %s\n", ctx.error().c_str()), 1;
    auto player = scenehost::ScenePlayer::load(scene);
    if (!player) return std::fprintf(stderr, "msaa: %s\n", player.error().c_str()), 1;
    const glm::ivec2 size{width, height};

    // One frame at timeSec into `fb`, the projection shifted by `shiftPixels` (x right, y up).
    auto draw = [&](splatfx::gl::Framebuffer& fb, glm::vec2 shiftPixels) -> bool {
        splatfx::Camera cam = player->cameraAt(timeSec, size);
        glm::mat4 shift(1.0f);
        shift[3][0] = 2.0f * shiftPixels.x / float(width), shift[3][1] = 2.0f * shiftPixels.y / float(height);
        cam.proj = shift * cam.proj;
        if (auto s = player->renderFrame(timeSec, cam, fb.handle()); !s) {
            std::fprintf(stderr, "msaa: %s\n", s.error().c_str());
            return false;
        }
        return true;
    };
    auto single = splatfx::gl::Framebuffer::create({.width = width, .height = height});
    if (!single) return std::fprintf(stderr, "msaa: %s\n", single.error().c_str()), 1;
    splatfx::Image reference;
    constexpr int kGrid = 4;
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
            // Pixel centre moved to ((i + 0.5) / 4, (j + 0.5) / 4) of the pixel: the image shifts the other way.
            if (!draw(*single, {0.5f - (float(i) + 0.5f) / kGrid, 0.5f - (float(j) + 0.5f) / kGrid})) return 1;
            const splatfx::Image img = single->read();
            if (reference.pixels.empty()) reference = img, std::fill(reference.pixels.begin(), reference.pixels.end(), 0.0f);
            for (std::size_t k = 0; k < img.pixels.size(); ++k) reference.pixels[k] += img.pixels[k] / float(kGrid * kGrid);
        }

    GLint maxSamples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
    std::vector<bench::KnobRow> rows;
    std::vector<int> skipped;
    for (int samples : {1, 2, 4, 8}) {
        if (samples > maxSamples) {
            skipped.push_back(samples);
            continue;
        }
        auto fb = splatfx::gl::Framebuffer::create({.width = width, .height = height, .samples = samples});
        if (!fb) return std::fprintf(stderr, "msaa: %s\n", fb.error().c_str()), 1;
        std::vector<double> ms;
        splatfx::Image img;
        for (int f = 0; f < frames + 1; ++f) {
            const auto a = std::chrono::steady_clock::now();
            if (!draw(*fb, {0.0f, 0.0f})) return 1;
            img = fb->read(); // the resolve (multisampled) and the read-back: part of what a frame costs a host that shows it
            if (f > 0) ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
        }
        std::sort(ms.begin(), ms.end());
        const splatfx::gl::FrameRenderStats& st = player->renderer().stats();
        // A driver may round a count up (llvmpipe makes 2 samples 4): the count drawn is the frame renderer's.
        std::string setting = samples == 1 ? "1 (single-sampled)" : std::to_string(samples) + "x MSAA";
        if (samples > 1 && st.msaa.samples != samples) setting += " (the driver made " + std::to_string(st.msaa.samples) + ")";
        bench::KnobRow r;
        r.knob = "host target samples";
        r.setting = setting;
        r.ms = ms[ms.size() / 2];
        r.isDefault = samples == 1;
        bench::imageError(img, reference, r.rmse, r.maxErr);
        r.extra = std::to_string(st.msaa.sampleCopies) + " | " + std::to_string(st.notes.size());
        rows.push_back(r);
    }
    bench::markPareto(rows);
    std::printf("MSAA host targets: %s at %dx%d, t = %g s, on %s; median of %d frames (render, resolve, read-back); error vs the mean of %d "
                "single-sampled frames on a %dx%d sub-pixel grid\n",
                scene.c_str(), width, height, timeSec, ctx->renderer().c_str(), frames, kGrid * kGrid, kGrid, kGrid);
    bench::printTable(rows, "ms/frame", "depth samples copied | notes");
    for (int s : skipped) std::printf("| host target samples | %dx MSAA | - | - | - | - | not run: GL_MAX_SAMPLES is %d | |\n", s, maxSamples);
    if (!noPlots) {
        std::filesystem::create_directories(out);
        if (!bench::writePlot(rows, out, "msaa", "MSAA host targets", "ms per frame")) return 1;
    }
    return 0;
}
} // namespace msaa_cmd

int runMsaa(int argc, char** argv) { return msaa_cmd::runMsaa(argc, argv); }
