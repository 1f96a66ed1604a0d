// splatfx-bench cut: the depth cut (issue 15). Cost of cut vs plain depth-
// tested splats on the Table I rows, accuracy against the exact reference per
// partial-table size, the popping metric while a surface moves slowly
// through a fire (GL cut, GL plain, the reference's own change), and the
// same metric on samples/03-cow-through-fire.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "options.hpp"
#include "scene_player.hpp"
#include "splatfx/context.hpp"
#include "splatfx/splatfx.hpp"

namespace cut_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using Clock = std::chrono::steady_clock;

// Table I's fire (King et al. 1999): the rows and grid proportions of
// table1.cpp, 3.5 x 10 x 2.5 world units, seen from 14 units.
struct Row {
    glm::ivec2 window;
    int voxels;
};
const Row kRows[] = {{{320, 240}, 1560}, {{640, 480}, 1560}, {{1280, 960}, 1560}, {{320, 240}, 780}, {{320, 240}, 390}, {{320, 240}, 195}};

glm::ivec3 dimsFor(int voxels) {
    switch (voxels) {
    case 195: return {3, 13, 5};
    case 390: return {6, 13, 5};
    case 780: return {6, 26, 5};
    default: return {12, 26, 5};
    }
}

splatfx::Grid fireGrid(int voxels) {
    const glm::ivec3 d = dimsFor(voxels);
    splatfx::Grid g = *splatfx::Grid::box(d, glm::vec3(3.5f / d.x, 10.0f / d.y, 2.5f / d.z));
    std::uint32_t h = 1;
    for (splatfx::Voxel& v : g.voxels) {
        const float t = float(v.cell.y) / float(std::max(d.y - 1, 1));
        v.opacity = 0.5f * (1.0f - 0.6f * t);
        h = h * 1664525u + 1013904223u;
        v.texture = h >> 8;
    }
    return g;
}

splatfx::Camera fireCamera(glm::ivec2 window) {
    return splatfx::Camera::lookAt({0, 5.0f, 14.0f}, {0, 5.0f, 0}, {0, 1, 0}, glm::radians(45.0f), window, 0.1f, 100.0f);
}

splatfx::Materials fireMaterials(int rows, int cols) {
    splatfx::Materials m{splatfx::Footprint{{.partialRadialSize = rows, .partialDepthSize = cols}}};
    m.addTextureSet(splatfx::TextureSet::turbulence({.count = 8, .size = 32, .seed = 1}));
    m.addColorTable(splatfx::ColorTable::fire());
    return m;
}

float windowDepth(const splatfx::Camera& cam, float viewZ) {
    const glm::vec4 c = cam.proj * glm::vec4(0.0f, 0.0f, -viewZ, 1.0f);
    return 0.5f * c.z / c.w + 0.5f;
}

// The host: colour cleared, and a wall facing the camera at view depth
// wallZ over the columns [wallFromX, width) (none: wallZ <= 0).
void host(splatfx::gl::Framebuffer& fb, const splatfx::Camera& cam, float wallZ, int wallFromX) {
    fb.clear({0.02f, 0.02f, 0.04f, 1.0f}, 1.0f);
    if (wallZ <= 0.0f) return;
    glBindFramebuffer(GL_FRAMEBUFFER, fb.handle());
    glEnable(GL_SCISSOR_TEST);
    glScissor(wallFromX, 0, cam.viewport.x - wallFromX, cam.viewport.y);
    glClearDepth(windowDepth(cam, wallZ));
    glClear(GL_DEPTH_BUFFER_BIT);
    glClearDepth(1.0);
    glDisable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

std::vector<splatfx::Splat> buildSplats(const splatfx::Grid& grid, const splatfx::Materials& m, const splatfx::Camera& cam) {
    splatfx::SplatBuilder b;
    b.begin(cam);
    b.add(grid, m, {.textureSet = 0, .colorTable = 0});
    b.sort();
    return b.splats();
}

struct Err {
    double rmse = 0.0, max = 0.0;
};
Err compare(const splatfx::Image& a, const splatfx::Image& b) {
    Err e;
    double sum = 0.0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        const double d = double(a.pixels[i]) - double(b.pixels[i]);
        sum += d * d;
        e.max = std::max(e.max, std::abs(d));
    }
    e.rmse = std::sqrt(sum / double(std::max<size_t>(a.pixels.size(), 1)));
    return e;
}

// The popping metric over consecutive frames: per pixel, the largest channel
// change; over the pixels in `mask`, the largest and the 99th percentile.
struct Popping {
    double max = 0.0, p99 = 0.0;
};
Popping popping(const std::vector<splatfx::Image>& frames, const std::vector<char>& mask) {
    std::vector<double> changes;
    for (size_t f = 1; f < frames.size(); ++f)
        for (size_t p = 0; p < mask.size(); ++p) {
            if (!mask[p]) continue;
            double c = 0.0;
            for (int ch = 0; ch < 4; ++ch) c = std::max(c, double(std::abs(frames[f].pixels[p * 4 + ch] - frames[f - 1].pixels[p * 4 + ch])));
            changes.push_back(c);
        }
    Popping out;
    if (changes.empty()) return out;
    const size_t k = std::min(changes.size() - 1, size_t(std::floor(0.99 * double(changes.size()))));
    std::nth_element(changes.begin(), changes.begin() + std::ptrdiff_t(k), changes.end());
    out.p99 = changes[k];
    out.max = *std::max_element(changes.begin(), changes.end());
    return out;
}

double drawMs(splatfx::gl::Renderer& r, const std::vector<splatfx::Splat>& splats, const splatfx::Camera& cam, splatfx::gl::Framebuffer& fb,
              float wallZ) {
    host(fb, cam, wallZ, cam.viewport.x / 2);
    glFinish();
    const auto a = Clock::now();
    r.draw(splats, cam, {.framebuffer = fb.handle(), .width = cam.viewport.x, .height = cam.viewport.y});
    glFinish();
    return std::chrono::duration<double, std::milli>(Clock::now() - a).count();
}

void costRows(int frames) {
    std::printf("Cost: the splat pass alone (draw + glFinish), median of %d frames, plain and cut interleaved in one run;\n"
                "host: none (depth 1) and a wall at the fire's middle depth over the right half of the window.\n\n",
                frames);
    std::printf("%-9s %6s | %9s %9s %6s | %9s %9s %6s | %6s %6s %5s\n", "window", "voxels", "plain ms", "cut ms", "ratio", "plain ms", "cut ms",
                "ratio", "cut", "hidden", "draws");
    std::printf("%-9s %6s | %-26s | %-26s | %s\n", "", "", "  no host surface", "  wall through the fire",
                "(with the wall: splats drawn with the host cut, skipped)");
    auto plain = splatfx::gl::Renderer::create({.depthCut = false});
    auto cut = splatfx::gl::Renderer::create({.depthCut = true});
    const splatfx::Materials m = fireMaterials(32, 64);
    if (!plain || !cut || !plain->upload(m) || !cut->upload(m)) {
        std::fprintf(stderr, "cut: GL setup failed\n");
        return;
    }
    for (const Row& row : kRows) {
        const splatfx::Camera cam = fireCamera(row.window);
        const auto splats = buildSplats(fireGrid(row.voxels), m, cam);
        auto fb = splatfx::gl::Framebuffer::create({.width = row.window.x, .height = row.window.y});
        if (!fb) continue;
        double med[2][2];
        for (int wall = 0; wall < 2; ++wall) {
            std::vector<double> t[2];
            for (int i = 0; i < frames + 2; ++i)
                for (int k = 0; k < 2; ++k) {
                    const double ms = drawMs(k ? *cut : *plain, splats, cam, *fb, wall ? 14.0f : 0.0f);
                    if (i >= 2) t[k].push_back(ms); // two warm-up frames
                }
            for (int k = 0; k < 2; ++k) {
                std::sort(t[k].begin(), t[k].end());
                med[wall][k] = t[k][t[k].size() / 2];
            }
        }
        char win[16];
        std::snprintf(win, sizeof win, "%dx%d", row.window.x, row.window.y);
        const splatfx::gl::DrawStats& st = cut->stats(); // the last draw: with the wall
        std::printf("%-9s %6d | %9.2f %9.2f %5.2fx | %9.2f %9.2f %5.2fx | %5.0f%% %5.0f%% %5llu\n", win, row.voxels, med[0][0], med[0][1],
                    med[0][1] / med[0][0], med[1][0], med[1][1], med[1][1] / med[1][0], 100.0 * double(st.cutHost) / double(splats.size()),
                    100.0 * double(st.cutHidden) / double(splats.size()), static_cast<unsigned long long>(st.drawCalls));
        std::fflush(stdout);
    }
}

splatfx::Image glFrame(splatfx::gl::Renderer& r, const std::vector<splatfx::Splat>& splats, const splatfx::Camera& cam, splatfx::gl::Framebuffer& fb,
                       float wallZ, int wallFromX) {
    host(fb, cam, wallZ, wallFromX);
    r.draw(splats, cam, {.framebuffer = fb.handle(), .width = cam.viewport.x, .height = cam.viewport.y});
    return fb.read();
}

splatfx::Image refFrame(const std::vector<splatfx::Splat>& splats, const splatfx::Camera& cam, const splatfx::Materials& m,
                        splatfx::gl::Framebuffer& fb, float wallZ, int wallFromX, bool cut) {
    host(fb, cam, wallZ, wallFromX);
    const splatfx::Image depth = fb.readDepth(), bg = fb.read();
    splatfx::SplatExactDesc rd;
    rd.host.backgroundImage = &bg;
    rd.host.depth = &depth;
    rd.depthCut = cut;
    auto ref = splatfx::renderSplatExact(splats, cam, m, rd);
    return ref ? *ref : splatfx::Image{};
}

void accuracy(int frames) {
    const glm::ivec2 size{640, 480};
    const splatfx::Camera cam = fireCamera(size);
    const splatfx::Grid grid = fireGrid(1560);
    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y, .color = splatfx::gl::Precision::F32});
    if (!fb) return;
    std::printf("\nAccuracy: 640x480, 1560 voxels, a wall at view depth 14 (the fire's middle) over the right half; F32 target;\n"
                "error against the exact reference with the cut (renderSplatExact, depthCut, exactFractionBefore) on the same input.\n\n");
    std::printf("%-22s %10s %10s %9s\n", "setting", "RMSE", "max", "draw ms");
    const splatfx::Materials m0 = fireMaterials(32, 64);
    const auto splats = buildSplats(grid, m0, cam); // the same list for every setting (the table does not change it)
    const auto t0 = Clock::now();
    const splatfx::Image ref = refFrame(splats, cam, m0, *fb, 14.0f, size.x / 2, true);
    const double refSec = std::chrono::duration<double>(Clock::now() - t0).count();
    const splatfx::Image refPlain = refFrame(splats, cam, m0, *fb, 14.0f, size.x / 2, false);
    auto row = [&](const char* name, const splatfx::Materials& m, bool cutOn, const splatfx::Image& against) {
        auto r = splatfx::gl::Renderer::create({.sampling = splatfx::gl::TextureSampling::Bilinear, .depthCut = cutOn});
        if (!r || !r->upload(m)) return;
        const splatfx::Image img = glFrame(*r, splats, cam, *fb, 14.0f, size.x / 2);
        std::vector<double> t;
        for (int i = 0; i < frames; ++i) t.push_back(drawMs(*r, splats, cam, *fb, 14.0f));
        std::sort(t.begin(), t.end());
        const Err e = compare(img, against);
        std::printf("%-22s %10.2e %10.2e %9.2f\n", name, e.rmse, e.max, t[t.size() / 2]);
        std::fflush(stdout);
    };
    for (int s : {4, 8, 16, 32, 64}) {
        char name[40];
        std::snprintf(name, sizeof name, "cut, table %dx%d", s, 2 * s);
        row(name, fireMaterials(s, 2 * s), true, ref);
    }
    row("plain depth test", m0, false, ref);
    row("plain vs plain ref", m0, false, refPlain);
    const Err truthGap = compare(refPlain, ref);
    std::printf("%-22s %10.2e %10.2e %9s   (the plain test's own error: reference plain vs reference cut)\n", "reference plain", truthGap.rmse,
                truthGap.max, "-");
    std::printf("(reference: %.1f s per frame)\n", refSec);
}

void planePopping(int steps) {
    const glm::ivec2 size{320, 240};
    const splatfx::Camera cam = fireCamera(size);
    const splatfx::Grid grid = fireGrid(1560);
    const splatfx::Materials m = fireMaterials(32, 64);
    const auto splats = buildSplats(grid, m, cam);
    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y, .color = splatfx::gl::Precision::F32});
    auto cut = splatfx::gl::Renderer::create({.sampling = splatfx::gl::TextureSampling::Bilinear, .depthCut = true});
    auto plain = splatfx::gl::Renderer::create({.sampling = splatfx::gl::TextureSampling::Bilinear, .depthCut = false});
    if (!fb || !cut || !plain || !cut->upload(m) || !plain->upload(m)) return;
    // The wall crosses two voxel layers (spacing 0.5 in depth) in `steps` frames.
    const float z0 = 13.5f, z1 = 14.5f;
    std::printf("\nPopping: 320x240, 1560 voxels, a full-screen wall facing the camera moving from view depth %.1f to %.1f in %d\n"
                "frames (%.4f per frame, 1/%d of the voxel spacing); per-pixel largest channel change between consecutive frames,\n"
                "over the pixels the fire covers (reference alpha >= 1/255 without the wall); F32 target.\n\n",
                z0, z1, steps, (z1 - z0) / steps, int(std::lround(0.5f / ((z1 - z0) / steps))));
    std::vector<splatfx::Image> gc, gp, rc;
    for (int i = 0; i <= steps; ++i) {
        const float z = z0 + (z1 - z0) * float(i) / float(steps);
        gc.push_back(glFrame(*cut, splats, cam, *fb, z, 0));
        gp.push_back(glFrame(*plain, splats, cam, *fb, z, 0));
        rc.push_back(refFrame(splats, cam, m, *fb, z, 0, true));
    }
    const splatfx::Image open = refFrame(splats, cam, m, *fb, 0.0f, 0, true);
    std::vector<char> mask(size_t(size.x) * size.y, 0);
    for (size_t p = 0; p < mask.size(); ++p) mask[p] = open.pixels[p * 4 + 3] >= 1.0f / 255.0f;
    const Popping c = popping(gc, mask), pl = popping(gp, mask), r = popping(rc, mask);
    std::printf("%-18s %10s %10s %14s\n", "", "max", "p99", "p99 / ref p99");
    std::printf("%-18s %10.3e %10.3e %13.2fx\n", "reference (cut)", r.max, r.p99, 1.0);
    std::printf("%-18s %10.3e %10.3e %13.2fx   (max / ref max %.2fx)\n", "GL cut", c.max, c.p99, c.p99 / r.p99, c.max / r.max);
    std::printf("%-18s %10.3e %10.3e %13.2fx   (max / ref max %.2fx)\n", "GL plain", pl.max, pl.p99, pl.p99 / r.p99, pl.max / r.max);
}

int cowPopping(const std::string& scenePath, int steps) {
    std::ifstream in(scenePath);
    if (!in) {
        std::fprintf(stderr, "cut: cannot read '%s'\n", scenePath.c_str());
        return 1;
    }
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    // Freeze the fire (toggles: no global or local motion), so consecutive
    // frames differ by the cow's step alone.
    const std::string key = "\"kind\": \"fire\",";
    const size_t at = text.find(key);
    if (at == std::string::npos) {
        std::fprintf(stderr, "cut: '%s' has no fire effect\n", scenePath.c_str());
        return 1;
    }
    text.insert(at + key.size(), " \"toggles\": {\"global\": false, \"local\": false},");
    const glm::ivec2 size{480, 360};
    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y, .color = splatfx::gl::Precision::F32});
    if (!fb) return 1;
    std::printf("\nThe cow through the fire (%s, fire frozen, %dx%d, F32): the fire's contribution (frame minus the same frame\n"
                "with the fire's opacity 0) between consecutive frames 1/240 s apart (the cow moves %.4f units, 1/%d of a voxel)\n"
                "while the cow is inside the fire (t = 1.3 .. 1.7 s); pixels where the fire is drawn.\n\n",
                scenePath.c_str(), size.x, size.y, 13.0 / 3.0 / 240.0, int(std::lround(0.45 / (13.0 / 3.0 / 240.0))));
    std::printf("%-18s %10s %10s\n", "", "max", "p99");
    double p99[2] = {0, 0};
    for (int cutOn = 1; cutOn >= 0; --cutOn) {
        splatfx::gl::FrameRendererDesc desc;
        desc.splats.depthCut = cutOn != 0;
        scenehost::PlayerOptions po;
        po.renderer = desc;
        auto player = scenehost::ScenePlayer::fromText(text, scenePath, po);
        if (!player) {
            std::fprintf(stderr, "cut: %s\n", player.error().c_str());
            return 1;
        }
        std::vector<splatfx::Image> frames;
        std::vector<char> mask(size_t(size.x) * size.y, 0);
        for (int i = 0; i <= steps; ++i) {
            const double t = 1.3 + i / 240.0;
            const splatfx::Camera cam = player->cameraAt(t, size);
            if (auto st = player->renderFrame(t, cam, fb->handle(), {.opacityScale = 0.0f}); !st)
                return std::fprintf(stderr, "%s\n", st.error().c_str()), 1;
            const splatfx::Image bare = fb->read();
            if (auto st = player->renderFrame(t, cam, fb->handle()); !st) return std::fprintf(stderr, "%s\n", st.error().c_str()), 1;
            splatfx::Image img = fb->read();
            for (size_t p = 0; p < img.pixels.size(); ++p) {
                if (p % 4 == 0 && std::abs(img.pixels[p] - bare.pixels[p]) + std::abs(img.pixels[p + 1] - bare.pixels[p + 1]) > 1e-6f)
                    mask[p / 4] = 1;
                img.pixels[p] -= bare.pixels[p];
            }
            frames.push_back(std::move(img));
        }
        const Popping pop = popping(frames, mask);
        p99[cutOn] = pop.p99;
        std::printf("%-18s %10.3e %10.3e\n", cutOn ? "after (cut)" : "before (plain)", pop.max, pop.p99);
    }
    std::printf("p99 before / after: %.2fx\n", p99[0] / std::max(p99[1], 1e-30));
    return 0;
}

} // namespace

int runCut(int argc, char** argv) {
    int frames = 15, steps = 32;
    bool doCost = true, doAccuracy = true, doPlane = true, doCow = true;
    std::string cowPath = "samples/03-cow-through-fire/scene.json";
    CLI::App app{"The depth cut: cut vs plain depth-tested splats on the Table I rows (cost ratio in one run), error against the exact\n"
                 "reference per partial-table size and for the plain test, the popping metric while a wall moves slowly through a fire\n"
                 "(GL cut, GL plain, the reference), and on the cow sample (run from the repository root, or pass --cow).",
                 "splatfx-bench cut"};
    cli::addNumber(app, "--frames", frames, 1, 1000, "timed frames per row");
    cli::addNumber(app, "--steps", steps, 2, 1000, "positions of the moving wall");
    app.add_option("--cow", cowPath, "the cow sample's scene file")->type_name("SCENE")->capture_default_str();
    cli::addChecked(
        app, "--only",
        [&](const std::string&, const std::string& w) -> splatfx::Status {
            doCost = w == "cost", doAccuracy = w == "accuracy", doPlane = w == "popping", doCow = w == "cow";
            if (!(doCost || doAccuracy || doPlane || doCow))
                return splatfx::makeError("--only expects cost, accuracy, popping or cow, got '" + w + "'");
            return {};
        },
        "run one part only: cost, accuracy, popping or cow", "PART");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "cut: %s\n", ctx.error().c_str());
        return 1;
    }
    std::printf("splatfx-bench cut on %s (figures on a shared machine are noisy; compare ratios within one run)\n\n", ctx->renderer().c_str());
    if (doCost) costRows(frames);
    if (doAccuracy) accuracy(frames);
    if (doPlane) planePopping(steps);
    if (doCow) return cowPopping(cowPath, steps);
    return 0;
}
} // namespace cut_cmd

int runCut(int argc, char** argv) { return cut_cmd::runCut(argc, argv); }
