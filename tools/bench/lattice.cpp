// splatfx-bench lattice: how visible the voxel lattice is in the effect
// samples (issue 25). For each sample its effects alone are drawn (no
// geometry, black background) along its own camera for N frames; the
// lattice measure (lattice_measure.hpp) reads the frames' spectrum at the
// projected voxel spacing, its diagonals and harmonics against the same
// frequencies' ring, and a lattice-free control (animated turbulence in the
// same mask, at the same mean brightness) calibrates what "no lattice"
// reads. --variation redraws every effect with another SplatVariation (none:
// the paper's lattice), to compare the options.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <epoxy/gl.h>

#include "bench_gl.hpp"
#include "camera_path.hpp"
#include "lattice_measure.hpp"
#include "options.hpp"
#include "splatfx/context.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/splatfx.hpp"

namespace lattice_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

struct Sample {
    const char* name;
    const char* scene; // scene file under samples/, or nullptr: the campfire of samples/01-campfire (C++)
};
const Sample kSamples[] = {
    {"campfire", nullptr},
    {"cow-through-fire", "samples/03-cow-through-fire/scene.json"},
    {"herd-dust", "samples/04-herd-dust/scene.json"},
    {"teapot-steam", "samples/05-teapot-steam/scene.json"},
    {"locomotive-smoke", "samples/06-locomotive-smoke/scene.json"},
    {"ghosts", "samples/07-ghosts/scene.json"},
    {"chess-fog", "samples/14-chess-fog/scene.json"},
    {"sunlit-smoke", "samples/15-campfire-sunlit-smoke/scene.json"},
    {"vdb-smoke", "samples/20-vdb-smoke/scene.json"},
    {"campfire-embers", "samples/24-campfire-embers/scene.json"},
    {"photo-fire", "samples/25-photo-fire/scene.json"},
    {"locomotive-bridge", "samples/26-locomotive-bridge/scene.json"},
    {"sun-and-torch", "samples/27-sun-and-torch/scene.json"},
    // 28-cloud-shadows' plume is left out: its 1-unit cells, 122 units from
    // the camera, project to 2.6 px at 640x480, under the 3-px period the
    // measure resolves (no lattice to see).
};

// "none", "default" or a list like "jitter=0.5,rotation=180,mirror,scale=0.3"
// (seed=N adds N to every effect's own variation seed: another realisation).
splatfx::Status parseVariation(const std::string& text, std::optional<splatfx::SplatVariation>& out) {
    if (text == "default") {
        out.reset();
        return {};
    }
    splatfx::SplatVariation v;
    if (text != "none") {
        std::stringstream ss(text);
        std::string item;
        while (std::getline(ss, item, ',')) {
            const size_t eq = item.find('=');
            const std::string key = item.substr(0, eq);
            const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
            double x = 0.0;
            auto number = [&](double lo, double hi) { return cli::parseReal("--variation " + key, value, lo, hi, x); };
            if (key == "mirror" && value.empty()) v.mirror = true;
            else if (key == "jitter") {
                if (auto s = number(0.0, splatfx::SplatVariation::kMaxJitter); !s) return s;
                v.jitter = float(x);
            } else if (key == "rotation") {
                if (auto s = number(0.0, 180.0); !s) return s;
                v.rotationRad = float(x * 3.14159265358979 / 180.0);
            } else if (key == "seed") {
                if (auto s = number(0.0, 1e6); !s) return s;
                v.seed = std::uint32_t(x);
            } else if (key == "scale") {
                if (auto s = number(0.0, 1.0); !s) return s;
                v.scaleLog2 = float(x);
            } else {
                return splatfx::makeError("--variation expects none, default or a list of jitter=X, rotation=DEG, mirror, scale=X, seed=N, got '" + text + "'");
            }
        }
    }
    out = v;
    return {};
}

// The built sample: its scene, materials and camera.
struct Loaded {
    splatfx::Materials materials{splatfx::Footprint{}};
    std::optional<splatfx::SceneFile> file;
    splatfx::Scene ownScene; // the campfire's
    std::vector<splatfx::EffectId> effects;
    splatfx::Scene& scene() { return file ? file->scene : ownScene; }
    splatfx::Camera camera(double t, glm::ivec2 size) const {
        if (file) return scenehost::evaluate(file->camera, t, size);
        return splatfx::Camera::lookAt({0.0f, 4.8f, 15.0f}, {0.0f, 4.6f, 0.0f}, {0, 1, 0}, glm::radians(45.0f), size); // samples/01-campfire
    }
};

splatfx::Result<std::unique_ptr<Loaded>> load(const Sample& s, const std::optional<splatfx::SplatVariation>& variation) {
    auto l = std::make_unique<Loaded>();
    if (s.scene) {
        auto f = splatfx::loadSceneFile(s.scene, l->materials);
        if (!f) return splatfx::makeError(f.error());
        l->file.emplace(std::move(*f));
        for (const splatfx::SceneEffectInfo& e : l->file->effects) l->effects.push_back(e.id);
    } else {
        auto f = splatfx::presets::fire(l->materials, {.dims = {7, 20, 5}, .spacing = glm::vec3(0.5f), .seed = 1});
        if (!f) return splatfx::makeError(f.error());
        l->effects.push_back(l->ownScene.add(std::move(*f), {.name = "campfire"}));
    }
    if (variation)
        for (splatfx::EffectId id : l->effects)
            if (splatfx::Effect* e = l->scene().findEffect(id)) {
                splatfx::SplatVariation v = *variation;
                v.seed = e->layer(0).style.variation.seed + variation->seed; // each effect's own seed (seed=N: another realisation)
                if (auto st = e->setSplatVariation(v); !st) return splatfx::makeError(st.error());
            }
    return l;
}

glm::vec2 toPixels(const splatfx::Camera& cam, glm::vec3 p) {
    const glm::vec4 c = cam.proj * cam.view * glm::vec4(p, 1.0f);
    const glm::vec2 ndc = glm::vec2(c) / c.w;
    return {(0.5f * ndc.x + 0.5f) * float(cam.viewport.x), (0.5f - 0.5f * ndc.y) * float(cam.viewport.y)};
}

// The projected lattice of the grid effect drawing the most splats, at the
// opacity-weighted centre of its voxels (particle effects have no lattice).
std::optional<lattice::Basis> basisOf(Loaded& l, const splatfx::Camera& cam) {
    const splatfx::Effect* best = nullptr;
    std::uint64_t most = 0;
    for (splatfx::EffectId id : l.effects) {
        const splatfx::Effect* e = l.scene().findEffect(id);
        if (e && !e->grid().voxels.empty() && l.scene().status(id).splatsDrawn > most) best = e, most = l.scene().status(id).splatsDrawn;
    }
    if (!best) return std::nullopt;
    const splatfx::Grid& g = best->grid();
    glm::dvec3 sum(0.0);
    double w = 0.0;
    for (const splatfx::Voxel& v : g.voxels) sum += double(v.opacity) * glm::dvec3(g.localPosition(v.cell)), w += v.opacity;
    if (!(w > 0.0)) return std::nullopt;
    const glm::vec3 local = glm::vec3(sum / w);
    lattice::Basis b;
    for (int i = 0; i < 3; ++i) {
        glm::vec3 step(0.0f);
        step[i] = g.spacing[i];
        const glm::vec3 a = glm::vec3(g.transform * glm::vec4(local - step, 1.0f)), c = glm::vec3(g.transform * glm::vec4(local + step, 1.0f));
        b.axis[i] = 0.5f * (toPixels(cam, c) - toPixels(cam, a));
    }
    // The view direction in cells: the null vector of the 2 x 3 projection.
    const glm::vec3 r0(b.axis[0].x, b.axis[1].x, b.axis[2].x), r1(b.axis[0].y, b.axis[1].y, b.axis[2].y);
    b.viewCells = glm::cross(r0, r1);
    if (!(glm::length(b.viewCells) > 0.0f)) return std::nullopt;
    b.viewCells = glm::normalize(b.viewCells);
    return b;
}

std::vector<float> luminance(const splatfx::Image& im) {
    std::vector<float> out(std::size_t(im.width) * im.height);
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = 0.2126f * im.pixels[i * 4] + 0.7152f * im.pixels[i * 4 + 1] + 0.0722f * im.pixels[i * 4 + 2];
    return out;
}

struct Row {
    std::string name;
    double measure = 0.0, controlLo = 0.0, controlHi = 0.0;
    double peak = 0.0, peakLo = 0.0, peakHi = 0.0; // the largest probe over its own direction at other periods
    float periodPx = 0.0f;
    int frames = 0;
    std::string probes;
    double rmse = -1.0, maxErr = -1.0; // --error: the GL frame against the splat-exact reference
};

// RGB RMSE and largest difference of two images of one size.
std::pair<double, double> rgbError(const splatfx::Image& a, const splatfx::Image& b) {
    double sum = 0.0, worst = 0.0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double d = double(a.at(x, y, c)) - double(b.at(x, y, c));
                sum += d * d, worst = std::max(worst, std::abs(d));
            }
    return {std::sqrt(sum / double(std::max(1, a.width * a.height * 3))), worst};
}

} // namespace

int runLattice(int argc, char** argv) {
    CLI::App app{"How visible the voxel lattice is in each effect sample: spectral peaks at the projected voxel spacing\n"
                 "(its diagonals and harmonics) over the same frequencies' ring, against a lattice-free turbulence control.",
                 "splatfx-bench lattice"};
    int frames = 48, controls = 3, width = 640, height = 480;
    float fps = 24.0f;
    std::string variationText = "default";
    std::vector<std::string> only;
    bool verbose = false, error = false;
    cli::addNumber(app, "--frames", frames, 4, 10000, "frames per sample");
    cli::addNumber(app, "--fps", fps, 1.0f, 1000.0f, "frames per second of animation time");
    cli::addNumber(app, "--controls", controls, 1, 64, "turbulence seeds of the control (its range)");
    cli::addSize(app, "--size", width, height, 64, 2048, "frame size");
    app.add_option("--variation", variationText,
                   "every effect redrawn with this SplatVariation: default (the scene's), none (the paper's lattice), or e.g. "
                   "jitter=0.5,rotation=180,mirror,scale=0.3")
        ->capture_default_str();
    app.add_option("--sample", only, "only these samples (campfire, cow-through-fire, herd-dust, teapot-steam, locomotive-smoke, ghosts, "
                                     "chess-fog, sunlit-smoke, vdb-smoke, campfire-embers, photo-fire, locomotive-bridge, sun-and-torch); default all");
    app.add_flag("--verbose", verbose, "every probe's ratio");
    app.add_flag("--error", error, "also the middle frame's RGB error against the splat-exact reference (renderSplatExact of the same splats)");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    std::optional<splatfx::SplatVariation> variation;
    if (auto s = parseVariation(variationText, variation); !s) {
        std::fprintf(stderr, "lattice: %s\n", s.error().c_str());
        return 2;
    }
    for (const std::string& n : only)
        if (std::none_of(std::begin(kSamples), std::end(kSamples), [&](const Sample& s) { return n == s.name; })) {
            std::fprintf(stderr, "lattice: --sample expects one of the effect samples (see --help), got '%s'\n", n.c_str());
            return 2;
        }

    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "lattice: %s\n", ctx.error().c_str());
        return 1;
    }
    auto fb = splatfx::gl::Framebuffer::create({.width = width, .height = height});
    if (!fb) {
        std::fprintf(stderr, "lattice: %s\n", fb.error().c_str());
        return 1;
    }
    std::printf("lattice visibility: %d frames at %g fps, %dx%d, effects only on black, variation %s; control: %d turbulence seeds; on %s\n\n",
                frames, double(fps), width, height, variationText.c_str(), controls, ctx->renderer().c_str());

    std::vector<Row> rows;
    bool failed = false;
    for (const Sample& s : kSamples) {
        if (!only.empty() && std::find(only.begin(), only.end(), s.name) == only.end()) continue;
        auto l = load(s, variation);
        if (!l) {
            std::fprintf(stderr, "lattice: %s: %s\n", s.name, l.error().c_str());
            failed = true;
            continue;
        }
        Loaded& L = **l;
        auto fr = splatfx::gl::FrameRenderer::create();
        if (!fr) {
            std::fprintf(stderr, "lattice: %s\n", fr.error().c_str());
            return 1;
        }
        if (auto st = fr->upload(L.materials); !st) {
            std::fprintf(stderr, "lattice: %s: %s\n", s.name, st.error().c_str());
            return 1;
        }
        splatfx::Frame frame;
        lattice::Accumulator measured({width, height});
        std::vector<lattice::Accumulator> control(std::size_t(controls), lattice::Accumulator({width, height}));
        std::vector<lattice::Turbulence> noise;
        for (int c = 0; c < controls; ++c) noise.emplace_back(glm::ivec2(width, height), 2.5f, std::uint32_t(c + 1));
        std::optional<lattice::Basis> basis;
        int used = 0;
        double errorRmse = -1.0, errorMax = -1.0;
        for (int f = 0; f < frames; ++f) {
            const double t = f / double(fps);
            const splatfx::Camera cam = L.camera(t, {width, height});
            if (auto st = L.scene().prepare(t, cam, L.materials, frame); !st) {
                std::fprintf(stderr, "lattice: %s: %s\n", s.name, st.error().c_str());
                failed = true;
                break;
            }
            fr->render(frame, bench::clearedTarget(*fb, {0.0f, 0.0f, 0.0f, 1.0f}));
            if (error && f == frames / 2) {
                auto ref = splatfx::renderSplatExact(frame.splats(), cam, L.materials);
                if (!ref) {
                    std::fprintf(stderr, "lattice: %s: %s\n", s.name, ref.error().c_str());
                    return 1;
                }
                std::tie(errorRmse, errorMax) = rgbError(fb->read(), *ref);
            }
            const std::optional<lattice::Basis> b = basisOf(L, cam);
            if (!b || b->probes().empty()) continue; // nothing drawn yet (a smoke before it rises)
            if (!basis) basis = b;
            const std::vector<float> lum = luminance(fb->read());
            const float period = b->shortestPeriodPx();
            // The frame's large-scale brightness (its blur at twice the lattice
            // period) gives the mask; the control is that brightness modulated
            // by lattice-free turbulence, in the same mask.
            const std::vector<float> mean = lattice::blur(lum, width, height, 2.0f * period);
            const std::vector<float> mask = lattice::maskOfBlurred(mean);
            measured.add(lum, mask, *b);
            for (int c = 0; c < controls; ++c) {
                const std::vector<float> n = noise[std::size_t(c)].frame(t);
                std::vector<float> img(mean.size());
                for (std::size_t i = 0; i < img.size(); ++i) img[i] = mean[i] * (1.0f + 0.4f * n[i]);
                control[std::size_t(c)].add(img, mask, *b);
            }
            ++used;
        }
        if (!basis || used == 0) {
            std::fprintf(stderr, "lattice: %s: no frame drew a resolvable lattice\n", s.name);
            failed = true;
            continue;
        }
        // The last frame's basis scores the averages (the cameras of these samples move little in 2 s).
        const lattice::Score m = measured.score(*basis);
        Row r{s.name, m.ratio, 1e30, 0.0, m.peak, 1e30, 0.0, basis->probes().empty() ? 0.0f : 1.0f / glm::length(basis->probes()[0].frequency), used, "", errorRmse, errorMax};
        for (const lattice::Accumulator& c : control) {
            const lattice::Score cs = c.score(*basis);
            r.controlLo = std::min(r.controlLo, cs.ratio), r.controlHi = std::max(r.controlHi, cs.ratio);
            r.peakLo = std::min(r.peakLo, cs.peak), r.peakHi = std::max(r.peakHi, cs.peak);
        }
        for (const lattice::ProbeScore& p : m.probes) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%s%s %.2f/%.2f", r.probes.empty() ? "" : ", ", p.probe.label.c_str(), p.ratio, p.peak);
            r.probes += buf;
        }
        std::printf("  %-17s %5.2f  (control %.2f-%.2f), peak %.2f (%.2f-%.2f)%s%s\n", r.name.c_str(), r.measure, r.controlLo, r.controlHi, r.peak,
                    r.peakLo, r.peakHi, verbose ? "  ring/peak: " : "", verbose ? r.probes.c_str() : "");
        std::fflush(stdout);
        rows.push_back(r);
    }

    std::printf("\n%-17s %8s %15s %6s %15s %10s %7s  %-40s%s\n", "sample", "measure", "control range", "peak", "control range", "period px", "frames",
                "verdict", error ? "  RMSE / max vs exact (middle frame)" : "");
    for (const Row& r : rows) {
        char err[64] = "";
        if (error) std::snprintf(err, sizeof err, "  %.5f / %.4f", r.rmse, r.maxErr);
        const char* verdict = r.measure <= r.controlHi ? "invisible (within the control)"
                              : r.peak <= r.peakHi  ? "direction, no peak (above the ring only)"
                                                    : "VISIBLE (above the control)";
        std::printf("%-17s %8.2f %7.2f-%-7.2f %6.2f %7.2f-%-7.2f %10.1f %7d  %-40s%s\n", r.name.c_str(), r.measure, r.controlLo, r.controlHi, r.peak,
                    r.peakLo, r.peakHi, double(r.periodPx), r.frames, verdict, err);
    }
    std::printf("\nmeasure: the largest, over the lattice's frequencies (fundamentals, diagonals, second harmonics), of the mean\n"
                "power within 8 %% of the frequency over the mean power of the ring at that frequency (spectra of the\n"
                "high-passed, flame-masked luminance averaged over the frames); peak: the same disc over its own direction's\n"
                "power at 0.75 and 4/3 of the frequency (a lattice is a peak in period; a texture's preferred direction, such as\n"
                "upright flame tongues, raises the disc and its neighbours alike); control: the same for animated turbulence.\n");
    return failed ? 1 : 0;
}
} // namespace lattice_cmd

int runLattice(int argc, char** argv) { return lattice_cmd::runLattice(argc, argv); }
