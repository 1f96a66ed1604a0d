// splatfx-bench ebert: Ebert & Parent 1990's Table 1 on this machine. The
// paper's scenes as the samples draw them (Fig. 3: the gallery's gas
// sculpture, samples/19-gallery; Fig. 6: steam from a glass,
// samples/13-steam-glass-shadow; Fig. 7: fog rolling in over a chess board,
// samples/14-chess-fog) at the paper's resolutions, each frame simulated,
// drawn and glFinish'ed by the sample host: with their volumes and with every
// effect disabled (the paper's "same scene without the volume", which it gives
// for Fig. 3 only). Figs. 4 and 5 have no sample (a surface-textured fog and
// a scene from "Getting Into Art"): they are listed, not run.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "options.hpp"
#include "scene_player.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/framebuffer.hpp"

namespace ebert_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using Clock = std::chrono::steady_clock;

struct PaperRow {
    const char* figure;
    const char* scene; // empty: no sample
    glm::ivec2 size;
    double minutes;        // the paper's rendering time of one image
    double minutesWithout; // without the volume (Fig. 3 only), else 0
};

} // namespace

int runEbert(int argc, char** argv) {
    int frames = 12, rounds = 3;
    bool quick = false;
    CLI::App app{"Ebert & Parent 1990's Table 1: the paper's scenes at its resolutions, ms per frame with and without their volumes.",
                 "splatfx-bench ebert"};
    CLI::Option* framesOption = cli::addNumber(app, "--frames", frames, 3, 100000, "timed frames per scene and mode");
    CLI::Option* roundsOption = cli::addNumber(app, "--rounds", rounds, 1, 1000, "rounds over the scenes");
    app.add_flag("--quick", quick, "4 frames x 1 round (unless given)");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (quick && framesOption->count() == 0) frames = 4;
    if (quick && roundsOption->count() == 0) rounds = 1;
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return std::fprintf(stderr, "ebert: %s\n", ctx.error().c_str()), 1;

    const std::vector<PaperRow> rows{
        {"3 (gas sculpture in a gallery)", "samples/19-gallery/scene.json", {1024, 682}, 71.0, 59.0},
        {"4 (fog by solid texturing)", "", {1024, 768}, 105.0, 0.0},
        {"5 (Getting Into Art)", "", {1024, 682}, 260.0, 0.0},
        {"6 (steam from a glass)", "samples/13-steam-glass-shadow/scene.json", {420, 400}, 95.0, 0.0},
        {"7 (chess fog rolling in)", "samples/14-chess-fog/scene.json", {320, 240}, 165.0, 0.0},
    };
    struct Run {
        scenehost::ScenePlayer player;
        splatfx::gl::Framebuffer fb;
        double t0 = 0.0, dt = 1.0 / 24.0;
        double with = 1e30, without = 1e30; // least of the rounds' medians, ms
    };
    std::vector<std::optional<Run>> runs(rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        if (!*rows[i].scene) continue;
        auto player = scenehost::ScenePlayer::load(rows[i].scene);
        if (!player) return std::fprintf(stderr, "ebert: %s\n", player.error().c_str()), 1;
        auto fb = splatfx::gl::Framebuffer::create({.width = rows[i].size.x, .height = rows[i].size.y});
        if (!fb) return std::fprintf(stderr, "ebert: %s\n", fb.error().c_str()), 1;
        const double fps = player->file().output.fps > 0.0f ? player->file().output.fps : 24.0;
        // The middle of the sample's clip: the volume is grown and in view there.
        const double middle = 0.5 * player->file().output.frames / fps;
        runs[i].emplace(Run{std::move(*player), std::move(*fb), middle, 1.0 / fps});
    }
    // Median ms of `frames` frames (after 2 warm-ups) from the clip's middle, the scene's effects on or off.
    auto time = [&](Run& r, bool volumes) -> double {
        splatfx::SceneFile& file = r.player.file();
        for (const splatfx::SceneEffectInfo& e : file.effects) file.scene.setEnabled(e.id, volumes);
        std::vector<double> ms;
        double t = r.t0;
        for (int f = 0; f < frames + 2; ++f, t += r.dt) {
            const splatfx::Camera cam = r.player.cameraAt(t, {r.fb.width(), r.fb.height()});
            const auto a = Clock::now();
            if (auto s = r.player.renderFrame(t, cam, r.fb.handle()); !s) {
                std::fprintf(stderr, "ebert: %s\n", s.error().c_str());
                return -1.0;
            }
            glFinish();
            if (f >= 2) ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
        }
        std::sort(ms.begin(), ms.end());
        return ms[ms.size() / 2];
    };
    for (int round = 0; round < rounds; ++round)
        for (std::optional<Run>& r : runs) {
            if (!r) continue;
            const double with = time(*r, true), without = time(*r, false);
            if (with < 0.0 || without < 0.0) return 1;
            r->with = std::min(r->with, with), r->without = std::min(r->without, without);
        }

    std::printf("Ebert & Parent 1990, Table 1, on %s: each scene as its sample draws it (simulate, draw, glFinish), least of %d rounds' "
                "medians of %d frames from the clip's middle\n"
                "The paper: an HP 9000/370, minutes per image; \"without\" is the same scene with its volume removed (given for Fig. 3 "
                "only).\n\n",
                ctx->renderer().c_str(), rounds, frames);
    std::printf("| figure | sample | resolution | paper: min | paper: without | paper: with / without | ms/frame | without | with / without "
                "| paper's time / this |\n| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const PaperRow& p = rows[i];
        char paperWithout[32] = "-", paperRatio[32] = "-";
        if (p.minutesWithout > 0.0) {
            std::snprintf(paperWithout, sizeof paperWithout, "%.0f", p.minutesWithout);
            std::snprintf(paperRatio, sizeof paperRatio, "%.2f", p.minutes / p.minutesWithout);
        }
        std::string sample = *p.scene ? std::string(p.scene).substr(8, std::string(p.scene).find('/', 8) - 8) : "none (not run)";
        if (!runs[i]) {
            std::printf("| %s | %s | %dx%d | %.0f | %s | %s | - | - | - | - |\n", p.figure, sample.c_str(), p.size.x, p.size.y, p.minutes, paperWithout,
                        paperRatio);
            continue;
        }
        const Run& r = *runs[i];
        std::printf("| %s | %s | %dx%d | %.0f | %s | %s | %.1f | %.1f | %.2f | %.2g |\n", p.figure, sample.c_str(), p.size.x, p.size.y,
                    p.minutes, paperWithout, paperRatio, r.with, r.without, r.with / r.without, p.minutes * 60000.0 / r.with);
    }
    return 0;
}
} // namespace ebert_cmd

int runEbert(int argc, char** argv) { return ebert_cmd::runEbert(argc, argv); }
