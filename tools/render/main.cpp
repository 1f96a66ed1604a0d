// splatfx-render: renders a scene file headless (EGL) into PNG frames plus one
// animated GIF, with progress output and a summary.
//
//   splatfx-render samples/03-cow-through-fire/scene.json --out out/cow --frames 24 --size 320x240
//
// Frames and GIF are one output set (splatfx/output_set.hpp): staged in
// DIR/.<name>.partial/, every write checked, moved into DIR only when all were
// written; DIR/.<name>.outputs records them, so only files this tool wrote
// are ever replaced or removed, and a run killed while publishing is
// finished by the next one. A second run into the same set is refused while
// the first holds its lock, and a file of an output's name that no record
// lists (the user's own) is refused, named, before anything is rendered.
//
// Render farms (docs/render-farm.md): --range A-B[:STEP] writes only those
// frames, bit for bit the frames a full run writes, by replaying the frames
// before them without drawing (solver effects need their history). A range
// task is its own output set, DIR/.<name>.frames-A-B[-every-STEP].outputs, so
// it replaces only its own frames, never another task's, and writes no GIF;
// --assemble writes the GIF from the frames in DIR once every task is done.
// Every run also writes its run record (run_record.hpp): the settings that
// decide the pixels and each frame's hash, which --assemble checks.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include <epoxy/gl.h>

#include "options.hpp"
#include "run_record.hpp"
#include "scene_player.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/output_set.hpp"

namespace fs = std::filesystem;

namespace {

struct Args {
    std::string scene;
    std::string out = "out";
    std::optional<int> frames;
    std::optional<glm::ivec2> size;
    std::optional<std::uint32_t> seed;
    std::optional<float> fps;
    bool traditional = false;
    bool quiet = false;
    splatfx::gl::FrameRendererDesc renderer{}; // --scale, --sampling, --fog-texture
    int abortAfter = -1;                       // testing aid: fail after this many frames
    std::optional<cli::FrameRange> range;      // --range: only these frames, no GIF
    bool assemble = false;                     // --assemble: the GIF from the frames in --out
    splatfx::Budgets budgets{};                // --budget NAME=N
    splatfx::DepthConvention depth{};          // --reverse-z, --clip-01, --infinite-far (the host's depth convention)
    int msaa = 0;                              // --msaa N: the host's target multisampled
    bool srgb = false;                         // --srgb: the host's target sRGB, GL_FRAMEBUFFER_SRGB on
    bool hdr = false;                          // --hdr: an RGBA16F target, HDR lit colours, an EXR beside each PNG
};

// Returns -1 to go on, else the exit code (0 after --help, 2 after a bad command line).
int parse(int argc, char** argv, Args& a) {
    CLI::App app{"splatfx-render: render a splatfx scene file headless into PNG frames and an animated GIF.\n"
                 "Writes DIR/<name>_NNNN.png and DIR/<name>.gif; <name> is the scene's output.name (default: the scene file's folder name).",
                 "splatfx-render"};
    app.add_option("scene", a.scene, "the scene file")->type_name("SCENE.json");
    app.add_option("--out", a.out, "output folder")->type_name("DIR")->capture_default_str();
    int frames = 0, width = 0, height = 0;
    std::uint32_t seed = 0;
    CLI::Option* framesOption = cli::addNumber(app, "--frames", frames, 1, 100000, "frames to render (default: the scene's output.frames)");
    CLI::Option* sizeOption = cli::addChecked(
        app, "--size",
        [&](const std::string& option, const std::string& text) -> splatfx::Status {
            if (auto st = cli::parseSize(option, text, 16, 8192, width, height); !st) return splatfx::makeError(st.error() + " (e.g. 640x480)");
            return {};
        },
        "image size in pixels, each side in [16, 8192] (default: the scene's output.size)", "WxH");
    cli::addChecked(
        app, "--fps",
        [&a](const std::string& option, const std::string& text) -> splatfx::Status {
            float f = 0.0f;
            if (!cli::parseReal(option, text, 0.0f, 240.0f, f) || !(f > 0.0f))
                return splatfx::makeError(option + " expects a number in (0, 240], got '" + text + "'");
            a.fps = f;
            return {};
        },
        "animation rate; frame i shows time i / F (default: the scene's output.fps)", "F");
    CLI::Option* seedOption =
        cli::addNumber(app, "--seed", seed, 0u, 4294967295u, "scene seed (every effect's random choices derive from it; default: the file's)");
    app.add_flag("--traditional", a.traditional, "draw every effect with plain footprints, no textures (the paper's Fig. 1a)");
    cli::addChecked(
        app, "--scale",
        [&a](const std::string& option, const std::string& text) -> splatfx::Status {
            int n = 0;
            if (auto st = cli::parseInt(option, text, 1, 4, n); !st) return st;
            if (n == 3) return splatfx::makeError(option + " expects 1, 2 or 4, got '" + text + "'");
            a.renderer.resolutionScale = n;
            a.renderer.reduceTetrahedra = true; // every volume at the reduced resolution, in one order
            return {};
        },
        "draw the effects and volumes (splats, clouds, ground fog) at 1/N resolution per axis (1, 2 or 4; default 1) with "
        "depth-aware upsampling",
        "N");
    cli::addChecked(
        app, "--sampling",
        [&a](const std::string& option, const std::string& m) -> splatfx::Status {
            using splatfx::gl::TextureSampling;
            if (m == "auto") a.renderer.splats.sampling = TextureSampling::Auto;
            else if (m == "bilinear") a.renderer.splats.sampling = TextureSampling::Bilinear;
            else if (m == "nearest") a.renderer.splats.sampling = TextureSampling::Nearest;
            else if (m.rfind("upsampled", 0) == 0) {
                a.renderer.splats.sampling = TextureSampling::Upsampled;
                a.renderer.splats.upsample = 0;
                if (m.size() > 9) return cli::parseInt(option, m.substr(9), 2, 16, a.renderer.splats.upsample);
            } else {
                return splatfx::makeError(option + " expects auto, bilinear, nearest, upsampled or upsampledN, got '" + m + "'");
            }
            return {};
        },
        "texture sampling: auto (default), bilinear, nearest, upsampled, upsampledN (N = 2..16)", "M");
    // The host image's fog through a reduced fog texture (Biri et al. Table 1, Fig. 9).
    cli::addChecked(
        app, "--fog-texture",
        [&a](const std::string& option, const std::string& text) -> splatfx::Status {
            int fw = 0, fh = 0;
            if (!cli::parseSize(option, text, 1, 8192, fw, fh))
                return splatfx::makeError(option + " expects WxH (1 to 8192 each), got '" + text + "'");
            a.renderer.fogTextureSize = {fw, fh};
            return {};
        },
        "fog the host image through a reduced WxH fog texture (default: per pixel)", "WxH");
    cli::addChecked(
        app, "--range",
        [&a](const std::string& option, const std::string& text) -> splatfx::Status {
            cli::FrameRange r;
            if (auto st = cli::parseFrameRange(option, text, 99999, r); !st) return st;
            a.range = r;
            return {};
        },
        "render-farm task: write only frames A..B (every STEP-th; indices from 0), exactly as a full run writes them; no GIF "
        "(see --assemble; docs/render-farm.md)",
        "A-B[:STEP]");
    app.add_flag("--assemble", a.assemble,
                 "write DIR/<name>.gif from the frames DIR/<name>_NNNN.png the tasks wrote, each checked against the tasks' run records "
                 "(give the tasks' options; renders nothing)");
    app.add_option_function<std::vector<std::string>>(
           "--budget",
           [&a](const std::vector<std::string>& settings) {
               for (const std::string& text : settings)
                   if (auto st = splatfx::setBudget(a.budgets, text); !st) throw CLI::ValidationError("--budget: " + st.error());
           },
           "raise (or lower) one of the loader's budgets (splatfx/budget.hpp; repeatable): effectCells, solverCells, sampledTexels, "
           "textureLayers, meshElements, meshFileBytes, meshImportBytes, meshImportSeconds, fogShaderBytes, heightmapVertices, "
           "lightingBytes, volumeBytes")
        ->type_name("NAME=N")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    app.add_flag_callback(
        "--no-depth-cut", [&a] { a.renderer.splats.depthCut = false; },
        "the plain depth test at each splat's plane instead of the exact cut (RendererDesc::depthCut)");
    app.add_flag_callback(
        "--no-volume-layer", [&a] { a.renderer.volumeLayer = false; },
        "blend the tetrahedra straight into the 8-bit frame, each rounded on its own (FrameRendererDesc::volumeLayer off; the images "
        "before it)");
    app.add_flag("--quiet", a.quiet, "no per-frame progress");
    // The engines' depth conventions (docs/integration.md, "Depth conventions"): the host
    // draws with glClipControl and a reversed or infinite projection, splatfx follows.
    app.add_flag_callback(
        "--reverse-z", [&a] { a.depth.reversed = true, a.depth.clip = splatfx::ClipDepth::ZeroToOne; },
        "draw as a reverse-Z engine: glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), near at depth 1, far at 0, 32-bit float depth");
    app.add_flag_callback(
        "--clip-01", [&a] { a.depth.clip = splatfx::ClipDepth::ZeroToOne; }, "clip depth [0, 1] (glClipControl GL_ZERO_TO_ONE) without reversing");
    app.add_flag_callback(
        "--infinite-far", [&a] { a.depth.infiniteFar = true; }, "an infinite far plane (the scene's camera farPlane unused)");
    // The engines' colour targets (docs/integration.md, "Depth buffers that are not textures, and colour targets").
    app.add_option("--msaa", a.msaa, "draw into an N-sample (MSAA) colour and depth target, resolved for the PNG")
        ->check(CLI::IsMember({1, 2, 4, 8, 16}))
        ->type_name("N");
    auto* srgbFlag =
        app.add_flag("--srgb", a.srgb, "draw into an sRGB colour target with GL_FRAMEBUFFER_SRGB on (blending in linear; the PNG holds sRGB)");
    app.add_flag("--hdr", a.hdr,
                 "draw into an RGBA16F colour target with HDR lit colours (Scene::setHdrLit: values above 1 kept) and write each frame "
                 "also as DIR/<name>_NNNN.exr (linear, unclamped); the PNG and GIF clamp at 1")
        ->excludes(srgbFlag);
    cli::addNumber(app, "--abort-after", a.abortAfter, 0, 100000,
                   "testing aid: fail on purpose after N frames (checks that nothing partial is left)");
    // Unset, these come from the scene file: the help says so instead of showing the placeholder 0.
    framesOption->description("frames to render, in [1, 100000] (default: the scene's output.frames)");
    seedOption->description("scene seed, in [0, 4294967295] (every effect's random choices derive from it; default: the file's)");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (framesOption->count()) a.frames = frames;
    if (sizeOption->count()) a.size = glm::ivec2(width, height);
    if (seedOption->count()) a.seed = seed;
    if (a.scene.empty()) {
        std::fprintf(stderr, "splatfx-render: no scene file given (try --help)\n");
        return 2;
    }
    // An empty --out (an unset variable in a farm's command line) once wrote into the current folder.
    if (a.out.empty()) {
        std::fprintf(stderr, "splatfx-render: --out is empty: name the output folder ('.' for the current one)\n");
        return 2;
    }
    if (a.assemble && a.range) {
        std::fprintf(stderr, "splatfx-render: --assemble writes the GIF of the whole sequence; it takes no --range\n");
        return 2;
    }
    return -1;
}

int fail(const std::string& why) {
    std::fprintf(stderr, "splatfx-render: %s\n", why.c_str());
    return 1;
}

char* frameName(char (&buf)[128], const std::string& name, int i) {
    std::snprintf(buf, sizeof buf, "%s_%04d.png", name.c_str(), i);
    return buf;
}
// --hdr's EXR beside a frame's PNG.
std::string exrName(const std::string& png) { return png.substr(0, png.size() - 4) + ".exr"; }

// Everything that decides a frame's pixels besides its index: the scene
// file's bytes (not the meshes and images it names) and the options.
splatfx::Result<render::RunSettings> runSettings(const Args& a, const std::string& name, std::uint32_t seed, glm::ivec2 size, int frames, float fps) {
    auto scene = render::hashFile(a.scene);
    if (!scene) return splatfx::makeError(scene.error());
    char rate[32];
    std::snprintf(rate, sizeof rate, "%.9g", fps);
    const splatfx::gl::RendererDesc& sp = a.renderer.splats;
    using splatfx::gl::TextureSampling;
    std::string sampling = sp.sampling == TextureSampling::Bilinear    ? "bilinear"
                           : sp.sampling == TextureSampling::Nearest   ? "nearest"
                           : sp.sampling == TextureSampling::Upsampled ? "upsampled" + (sp.upsample ? std::to_string(sp.upsample) : std::string())
                                                                       : "auto";
    const glm::ivec2 fog = a.renderer.fogTextureSize;
    return render::RunSettings{
        {"name", name},
        {"scene", *scene},
        {"seed", std::to_string(seed)},
        {"size", std::to_string(size.x) + "x" + std::to_string(size.y)},
        {"frames", std::to_string(frames)},
        {"fps", rate},
        {"traditional", a.traditional ? "yes" : "no"},
        {"scale", std::to_string(a.renderer.resolutionScale)},
        {"sampling", sampling},
        {"fog-texture", fog.x > 0 ? std::to_string(fog.x) + "x" + std::to_string(fog.y) : std::string("per-pixel")},
        {"depth-cut", sp.depthCut ? "yes" : "no"},
        {"volume-layer", a.renderer.volumeLayer ? "yes" : "no"},
        {"hdr", a.hdr ? "yes" : "no"},
    };
}

// Why the frame at `path` (index i) is not one a run of `wanted` wrote, or
// "" when it is: a run record with these settings lists it with this hash.
std::string foreignFrame(const std::vector<render::RunRecord>& records, const render::RunSettings& wanted, const std::string& folder,
                         const std::string& file, int i, const std::string& hash) {
    std::string differ;
    bool listed = false;
    for (const render::RunRecord& r : records) {
        const auto it = r.frames.find(file);
        if (it == r.frames.end() || it->second.first != i) continue;
        listed = true;
        if (it->second.second != hash) continue;
        const std::string d = render::settingsDiffer(r.settings, wanted);
        if (d.empty()) return {};
        if (differ.empty()) differ = "rendered with " + d;
    }
    if (!differ.empty()) return differ;
    if (listed) return "it is not the file its run wrote (replaced or changed since)";
    return "no run record in '" + folder + "' lists it (not written by splatfx-render)";
}

// --assemble: the whole sequence's GIF from the frames in the output folder
// (written by range tasks, or a full run), as its own output set. Every
// frame must be there, listed unchanged by a run record with the sequence's
// settings, and of the sequence's size; the GIF is then byte for
// byte the one a full run writes (the frames are 8-bit PNGs of the same
// pixels the full run hands to its GIF writer, which keeps 8-bit RGB).
int assemble(const Args& a) {
    splatfx::Materials materials{splatfx::Footprint{}};
    splatfx::SceneFileOptions so;
    so.seed = a.seed;
    so.budgets = a.budgets;
    auto file = splatfx::loadSceneFile(a.scene, materials, so);
    if (!file) return fail(file.error());
    const glm::ivec2 size = a.size.value_or(file->output.size);
    const int frames = a.frames.value_or(file->output.frames);
    const float fps = a.fps.value_or(file->output.fps);
    const std::string name = file->output.name;
    std::vector<int> missing;
    char png[128];
    for (int i = 0; i < frames; ++i) {
        std::error_code ec;
        if (!fs::is_regular_file(fs::path(a.out) / frameName(png, name, i), ec)) missing.push_back(i);
    }
    if (!missing.empty()) {
        std::string list;
        for (std::size_t k = 0; k < missing.size() && k < 8; ++k) list += (k ? ", " : "") + std::to_string(missing[k]);
        if (missing.size() > 8) list += ", ...";
        return fail("--assemble: " + std::to_string(missing.size()) + " of the " + std::to_string(frames) + " frames are missing from '" + a.out +
                    "' (frame " + list + "); render them first (--range), with the same --frames");
    }
    // Every frame must be one a run of this sequence wrote (same scene,
    // seed, size and options; the file unchanged since), or the GIF would
    // not be the full run's.
    auto wanted = runSettings(a, name, file->seed, size, frames, fps);
    if (!wanted) return fail("--assemble: " + wanted.error());
    const std::vector<render::RunRecord> records = render::readRunRecords(a.out);
    std::vector<std::string> foreign;
    for (int i = 0; i < frames; ++i) {
        frameName(png, name, i);
        const std::string path = (fs::path(a.out) / png).string();
        auto hash = render::hashFile(path);
        if (!hash) return fail("--assemble: " + hash.error());
        if (std::string why = foreignFrame(records, *wanted, a.out, png, i, *hash); !why.empty()) foreign.push_back("'" + path + "': " + why);
    }
    if (!foreign.empty()) {
        std::string list;
        for (std::size_t k = 0; k < foreign.size() && k < 4; ++k) list += (k ? "; " : "") + foreign[k];
        if (foreign.size() > 4) list += "; ...";
        return fail("--assemble: " + std::to_string(foreign.size()) + " of the " + std::to_string(frames) +
                    " frames are not from this sequence: " + list + "; render them again with this sequence's options (--range)");
    }
    auto outputs = splatfx::OutputSet::begin(a.out, name + ".gif", {name + ".gif"});
    if (!outputs) return fail(outputs.error());
    splatfx::AnimationWriter gif(outputs->path(name + ".gif"), fps);
    for (int i = 0; i < frames; ++i) {
        const std::string path = (fs::path(a.out) / frameName(png, name, i)).string();
        auto img = splatfx::readImage(path);
        if (!img) return fail("--assemble: " + img.error());
        if (img->width != size.x || img->height != size.y)
            return fail("--assemble: '" + path + "' is " + std::to_string(img->width) + "x" + std::to_string(img->height) + ", the sequence is " +
                        std::to_string(size.x) + "x" + std::to_string(size.y) + " (a task rendered with another --size?)");
        if (auto w = gif.add(*img); !w) return fail(w.error());
    }
    if (auto w = gif.finish(); !w) return fail(w.error());
    outputs->add(name + ".gif");
    if (auto w = outputs->publish(); !w) return fail(w.error());
    std::printf("splatfx-render: assembled %s/%s.gif from %d frames at %g fps\n", a.out.c_str(), name.c_str(), frames, fps);
    return 0;
}

} // namespace

static int renderMain(int argc, char** argv) {
    Args a;
    if (const int code = parse(argc, argv, a); code >= 0) return code;
    if (a.assemble) return assemble(a);

    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return fail(ctx.error());
    auto player = scenehost::ScenePlayer::load(a.scene, {.seed = a.seed, .renderer = a.renderer, .budgets = a.budgets});
    if (!player) return fail(player.error());
    const splatfx::SceneFile& file = player->file();
    const glm::ivec2 size = a.size.value_or(file.output.size);
    const int frames = a.frames.value_or(file.output.frames);
    const float fps = a.fps.value_or(file.output.fps);
    const std::string name = file.output.name;
    // Frame i shows time i / fps; the scene refuses times past kMaxTimeSec (the file's own frames and fps are checked when it is read).
    if (const double last = (frames - 1) / double(fps); last > splatfx::kMaxTimeSec) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "%d frames at %g fps end at %g s, later than %g s (splatfx::kMaxTimeSec, about 72.8 hours); fewer --frames or a higher --fps",
                      frames, double(fps), last, splatfx::kMaxTimeSec);
        return fail(buf);
    }
    if (a.range)
        if (auto st = cli::checkFrameRange("--range", *a.range, frames); !st) return fail(st.error());
    const bool whole = !a.range;
    // The frames this run writes, and the last it must reach.
    const int toWrite = whole ? frames : a.range->count();
    const int lastIndex = whole ? frames - 1 : a.range->first + (a.range->count() - 1) * a.range->step;

    // A full run's frames and GIF are one set: staged, then published
    // together (output_set.hpp). A range task's frames are a set of their
    // own, so publishing it removes nothing another task wrote.
    std::string setName = name;
    if (a.range) {
        char buf[96];
        std::snprintf(buf, sizeof buf, ".frames-%04d-%04d", a.range->first, a.range->last);
        setName += buf;
        if (a.range->step > 1) setName += "-every-" + std::to_string(a.range->step);
    }
    auto settings = runSettings(a, name, file.seed, size, frames, fps);
    if (!settings) return fail(settings.error());
    // Every file this run will write, so that one of a user's is refused now, not after the work.
    const std::string runRecord = "." + setName + ".run";
    std::vector<std::string> planned;
    for (int i = 0; i <= lastIndex; ++i)
        if (whole || a.range->contains(i)) {
            char png[128];
            planned.push_back(frameName(png, name, i));
            if (a.hdr) planned.push_back(exrName(png));
        }
    if (whole) planned.push_back(name + ".gif");
    planned.push_back(runRecord);
    auto outputs = splatfx::OutputSet::begin(a.out, setName, planned);
    if (!outputs) return fail(outputs.error());
    std::map<std::string, std::pair<int, std::string>> hashes; // the run record's frames

    auto fb = splatfx::gl::Framebuffer::create(
        {.width = size.x,
         .height = size.y,
         .color = a.hdr ? splatfx::gl::Precision::F16 : splatfx::gl::Precision::U8,
         .floatDepth = a.depth.reversed,
         .samples = a.msaa,
         .srgb = a.srgb});
    // An HDR host: lit colours above 1 keep their brightness (docs/lighting.md, "HDR lit colour").
    player->file().scene.setHdrLit(a.hdr);
    if (!fb) return fail(fb.error());
    if (a.srgb) glEnable(GL_FRAMEBUFFER_SRGB);
    // The host's clip convention: GL state of this context, read by nothing in splatfx but the rasterizer.
    glClipControl(GL_LOWER_LEFT, a.depth.clip == splatfx::ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    std::printf("splatfx-render: %s (%s) on %s\n", a.scene.c_str(), file.title.empty() ? name.c_str() : file.title.c_str(), ctx->renderer().c_str());
    if (whole)
        std::printf("splatfx-render: %d frames at %dx%d, %g fps, seed %u, %s splats -> %s/%s_NNNN.png + %s.gif\n", frames, size.x, size.y, fps,
                    file.seed, a.traditional ? "traditional" : "textured", a.out.c_str(), name.c_str(), name.c_str());
    else
        std::printf("splatfx-render: frames %d-%d%s (%d of the sequence's %d) at %dx%d, %g fps, seed %u, %s splats -> %s/%s_NNNN.png "
                    "(no GIF: --assemble writes it)\n",
                    a.range->first, a.range->last, a.range->step > 1 ? (":" + std::to_string(a.range->step)).c_str() : "", toWrite, frames, size.x,
                    size.y, fps, file.seed, a.traditional ? "traditional" : "textured", a.out.c_str(), name.c_str());

    if (!(a.depth == splatfx::DepthConvention{})) std::printf("splatfx-render: depth convention %s\n", splatfx::describe(a.depth).c_str());
    if (a.msaa > 1 || a.srgb)
        std::printf("splatfx-render: colour target %s%s%s\n", a.msaa > 1 ? (std::to_string(a.msaa) + "x MSAA").c_str() : "",
                    a.msaa > 1 && a.srgb ? ", " : "", a.srgb ? "sRGB (GL_FRAMEBUFFER_SRGB)" : "");
    if (a.hdr) std::printf("splatfx-render: colour target RGBA16F, HDR lit colours; frames also as %s/%s_NNNN.exr\n", a.out.c_str(), name.c_str());
    std::optional<splatfx::AnimationWriter> gif;
    if (whole) gif.emplace(outputs->path(name + ".gif"), fps);
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    double renderMs = 0.0, prepareMs = 0.0, submitMs = 0.0;
    std::uint64_t splatsMin = ~0ull, splatsMax = 0, splatsSum = 0, voxelsMax = 0;
    std::vector<std::string> notes; // the frame renderer's fallbacks, each once
    std::size_t visibleMax = 0, simulatedMax = 0, drawnMax = 0, visibleSum = 0, simulatedSum = 0, drawnSum = 0;
    const bool tty = isatty(fileno(stdout)) != 0;
    int written = 0, replayed = 0;
    double replayMs = 0.0, reachMs = 0.0; // all the replay; the part before the first frame written
    for (int i = 0; i <= lastIndex; ++i) {
        // Frame i shows time i / fps in every mode, so a task's frame i is the full run's.
        const double t = i / double(fps);
        if (!whole && !a.range->contains(i)) {
            // Before or between this task's frames: the scene steps through
            // them as a full run does (same times, same cameras), undrawn.
            const auto r0 = Clock::now();
            if (auto st = player->advance(t, player->cameraAt(t, size, a.depth), {.traditional = a.traditional}); !st) return fail(st.error());
            if (!player->problem().empty()) return fail("frame " + std::to_string(i) + ": " + player->problem() + "; no output kept");
            replayMs += std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
            ++replayed;
            continue;
        }
        if (written == 0) reachMs = replayMs;
        if (written == a.abortAfter) return fail("aborted on purpose after " + std::to_string(written) + " frames (--abort-after); no output kept");
        const auto f0 = Clock::now();
        if (auto st = player->renderFrame(t, player->cameraAt(t, size, a.depth), fb->handle(), {.traditional = a.traditional}); !st) return fail(st.error());
        // Lighting, shadows or a terrain the frame lost: never published as if complete.
        if (!player->problem().empty()) return fail("frame " + std::to_string(i) + ": " + player->problem() + "; no output kept");
        splatfx::Image img = fb->read();
        // Every fallback of the frame renderer, said once, as it happens (FrameRenderStats::notes).
        for (const std::string& note : player->renderer().stats().notes)
            if (std::find(notes.begin(), notes.end(), note) == notes.end()) {
                notes.push_back(note);
                if (!a.quiet) std::printf("%ssplatfx-render: note: %s\n", tty ? "\n" : "", note.c_str());
            }
        renderMs += std::chrono::duration<double, std::milli>(Clock::now() - f0).count();
        const splatfx::FrameCounters& s = player->stats().counters;
        prepareMs += player->stats().prepareMs, submitMs += player->stats().renderMs;
        splatsMin = std::min(splatsMin, s.splats), splatsMax = std::max(splatsMax, s.splats), splatsSum += s.splats;
        voxelsMax = std::max(voxelsMax, s.voxels);
        visibleMax = std::max(visibleMax, s.needed), simulatedMax = std::max(simulatedMax, s.simulated), drawnMax = std::max(drawnMax, s.drawn);
        visibleSum += s.needed, simulatedSum += s.simulated, drawnSum += s.drawn;
        char png[128];
        frameName(png, name, i);
        if (auto w = splatfx::writeImage(outputs->path(png), img); !w) return fail(w.error());
        if (a.hdr) {
            // The target's half floats as 32-bit float EXR (exactly), linear and unclamped.
            const std::string exr = exrName(png);
            if (auto w = splatfx::writeImage(outputs->path(exr), img); !w) return fail(w.error());
            auto h = render::hashFile(outputs->path(exr));
            if (!h) return fail(h.error());
            hashes[exr] = {i, *h};
            outputs->add(exr);
        }
        auto hash = render::hashFile(outputs->path(png));
        if (!hash) return fail(hash.error());
        hashes[png] = {i, *hash};
        outputs->add(png);
        if (gif)
            if (auto w = gif->add(img); !w) return fail(w.error());
        ++written;
        // A terminal gets a live line; a log gets about ten lines.
        if (!a.quiet && (tty || written % std::max(1, toWrite / 10) == 0 || written == toWrite)) {
            std::printf("%ssplatfx-render: frame %d (%d/%d)  t=%.2fs  %llu splats  %zu/%zu effects visible", tty ? "\r" : "", i, written, toWrite, t,
                        (unsigned long long)s.splats, s.needed, s.declared);
            if (!tty) std::printf("\n");
            std::fflush(stdout);
        }
    }
    if (!a.quiet && tty) std::printf("\n");
    if (gif) {
        if (auto w = gif->finish(); !w) return fail(w.error());
        outputs->add(name + ".gif");
    }
    if (auto w = splatfx::writeFileAtomically(outputs->path(runRecord), render::recordText(*settings, hashes)); !w) return fail(w.error());
    outputs->add(runRecord);
    if (auto w = outputs->publish(); !w) return fail(w.error());

    const double sec = std::chrono::duration<double>(Clock::now() - start).count();
    const splatfx::FrameCounters& last = player->stats().counters;
    std::printf("splatfx-render: summary for %s\n", a.scene.c_str());
    const int n = written;
    std::printf("  frames            %d (%dx%d, %.3g s of animation at %g fps)\n", n, size.x, size.y, n / double(fps), fps);
    if (replayed > 0)
        std::printf("  replay            %d frame(s) before or between this task's stepped through undrawn, as a full run steps through them: "
                    "%.2f s (%.1f ms each), %.2f s of it to reach frame %d\n",
                    replayed, replayMs / 1000.0, replayMs / replayed, reachMs / 1000.0, a.range->first);
    std::printf("  time              %.2f s in all, %.1f ms per frame written (frame + readback %.1f ms: prepare %.2f, GL submission %.2f; PNG/GIF "
                "the rest)\n",
                sec, 1000.0 * sec / n, renderMs / n, prepareMs / n, submitMs / n);
    std::printf("  splats per frame  min %llu, mean %.0f, max %llu\n", (unsigned long long)splatsMin, double(splatsSum) / n,
                (unsigned long long)splatsMax);
    std::printf("  voxels            at most %llu per frame (of the effects needed)\n", (unsigned long long)voxelsMax);
    std::printf("  effects           %zu declared; per frame mean/max: %.1f/%zu simulated, %.1f/%zu visible, %.1f/%zu drawn\n", last.declared,
                double(simulatedSum) / n, simulatedMax, double(visibleSum) / n, visibleMax, double(drawnSum) / n, drawnMax);
    std::printf("  geometry          %zu objects, %zu triangles\n", player->geometry().stats().objects, player->geometry().stats().triangles);
    for (const std::string& note : notes) std::printf("  note              %s\n", note.c_str());
    if (whole)
        std::printf("  wrote             %s/%s_0000.png .. %s_%04d.png and %s/%s.gif\n", a.out.c_str(), name.c_str(), name.c_str(), frames - 1,
                    a.out.c_str(), name.c_str());
    else
        std::printf("  wrote             %s/%s_%04d.png .. %s_%04d.png (%d frames%s)\n", a.out.c_str(), name.c_str(), a.range->first, name.c_str(),
                    lastIndex, n, a.range->step > 1 ? (", step " + std::to_string(a.range->step)).c_str() : "");
    return 0;
}

// Any exception that escapes (std::bad_alloc included) becomes a message and exit code 1.
int main(int argc, char** argv) {
    return cli::guardedMain("splatfx-render", [&] { return renderMain(argc, argv); });
}
