// texpick: the command line (parsing, the modes, progress and summary).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "options.hpp"
#include "texpick.hpp"

namespace texpick {

using json = nlohmann::json;
using splatfx::makeError;

namespace {

const char* kUsage = R"(splatfx-texpick: cut a texture set for splatfx out of a photograph (King et al. 1999, sec. 4)

usage:
  splatfx-texpick positions  IMAGE --out DIR --at X,Y[,SIZE] [--at ...]
  splatfx-texpick random     IMAGE --out DIR [--count 8] [--seed 1]
  splatfx-texpick spectral   IMAGE --out DIR [--count 8] (--band LO:HI | --spread)
  splatfx-texpick path       IMAGE --out DIR --path X,Y:X,Y[:X,Y...] [--step 4] [--count N]
  splatfx-texpick interactive IMAGE --out DIR [--patch 64]
  splatfx-texpick turbulence --out DIR [--count 8] [--size 32] [--seed 1]
  splatfx-texpick merge SET SET... --out DIR

DIR gets t000.png..., manifest.json (provenance: source, method, parameters,
each patch's position, size and spectrum), contact.png and preview.gif. It is
written to a temporary folder and moved into place only when complete; an
existing texture-set folder is replaced, any other existing path is refused.
Coordinates are source pixels from the top-left corner; X,Y are patch centres.

selection:
  --patch P            patch side in source pixels (default 64)
  --count N            textures in the set (default 8; path: as many as fit)
  --seed S             random seed (default 1)
  --at X,Y[,SIZE]      positions: one patch centre (and side); repeat
  --min-std F          reject flat patches: luminance std below F of the source's own luminance range (default 0.03)
  --min-mean F         reject near-empty patches: mean luminance below F of the source's brightest (default 0.03)
  --min-coverage F     reject patches mostly outside an alpha cut-out: mean alpha below F (default 0.9)
  --absolute-thresholds  --min-std and --min-mean in luminance units (0..1), not relative to the source's range
  --alpha MODE         auto | coverage | density: what the source's alpha is. coverage: a cut-out (--min-coverage
                       applies); density: a game sprite's alpha, the gas itself (colour x alpha is the texture,
                       never a cut-out); auto (default): density when over half the covered pixels are semi-transparent
  --min-distance D     smallest distance between picked centres (random 0, spectral P/2)
  --band LO:HI         spectral: frequency band in cycles per pixel (default 0.125:0.75)
  --spread             spectral: maximize spectral variation across the set instead
  --stride S           spectral: candidate grid step in pixels (default P/4)
  --path X,Y:X,Y...    path: polyline of patch centres
  --step S             path: pixels between consecutive patches (default 4)
processing:
  --size S             texture side in texels (default 32)
  --color              keep colour (default: grayscale, as in the paper)
  --contrast MODE      patch | set | none (default patch: mean 0.5, std --contrast-std)
  --contrast-std F     target standard deviation (default 0.25)
  --order              reorder for smooth cycling (closing the cycle)
  --window             bake the footprint into the saved textures (default: the renderer windows them)
  --kernel K           crawfis-max | gaussian footprint (default crawfis-max)
turbulence:
  --octaves N --base-frequency F --loop-radius F   (defaults 4, 3, 0.6)
output:
  --no-preview         skip preview.gif (it needs headless EGL / GL 4.5)
  --no-contact         skip contact.png
  --preview-frames N   (default 3 per texture)  --preview-fps N (default 12)
  --preview-size N     preview height in pixels (default 192)
  --preview-colors C   fire | smoke | steam | dust | white (default smoke)
  --source-name NAME   name recorded for the source (default: its file name)
  --credit TEXT        author / origin of the photograph, recorded in the manifest
  --license TEXT       licence of the photograph, recorded in the manifest
  --quiet              print only errors
interactive:
  --auto-quit-after N  close after N frames (smoke tests)
  --events LIST        scripted input, e.g. "click:120,80;key:p;click:60,60;key:s"
  --screenshot FILE    write the window's picture to FILE before closing
)";

} // namespace

// The command line through CLI11 (tools/common/options.hpp): every number
// whole and range-checked, every message naming the option. --help prints
// kUsage, the modes and options laid out by topic.
splatfx::Result<Options> parseOptions(int argc, const char* const* argv) {
    Options o;
    if (argc < 2) return makeError(std::string("no mode given\n\n") + kUsage);
    std::vector<std::string> positional;
    CLI::App app{"cut a texture set for splatfx out of a photograph", kToolName};
    app.set_help_flag();
    bool help = false;
    app.add_flag("-h,--help", help);
    app.add_option("mode", positional)->expected(0, -1);
    auto text = [&](const char* name, std::string& field) { app.add_option(name, field)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast); };
    auto choice = [&](const char* name, std::function<splatfx::Status(const std::string&)> set) {
        cli::addChecked(
            app, name, [set = std::move(set)](const std::string&, const std::string& v) { return set(v); }, "");
    };
    text("--out", o.out);
    cli::addNumber(app, "--patch", o.patch, 1, 16384, "");
    CLI::Option* count = cli::addNumber(app, "--count", o.count, 1, kMaxTextures, "");
    cli::addNumber(app, "--seed", o.seed, 0u, 4294967295u, "");
    cli::addNumber(app, "--min-std", o.accept.minStd, 0.0f, 1.0f, "");
    cli::addNumber(app, "--min-mean", o.accept.minMean, 0.0f, 1.0f, "");
    cli::addNumber(app, "--min-coverage", o.accept.minCoverage, 0.0f, 1.0f, "");
    app.add_flag_callback("--absolute-thresholds", [&o] { o.accept.relative = false; });
    cli::addOneOf<AlphaUse>(app, "--alpha", o.source.alpha,
                            {{"auto", AlphaUse::Auto}, {"coverage", AlphaUse::Coverage}, {"density", AlphaUse::Density}},
                            "--alpha expects auto, coverage or density", "");
    cli::addNumber(app, "--min-distance", o.minDistance, 0.0f, 1e6f, "");
    cli::addNumber(app, "--stride", o.stride, 1, 16384, "");
    cli::addNumber(app, "--step", o.step, 1e-3, 1e6, "");
    cli::addNumber(app, "--size", o.process.textureSize, 4, 1024, "");
    cli::addNumber(app, "--contrast-std", o.process.contrastStd, 1e-3f, 0.5f, "");
    cli::addNumber(app, "--octaves", o.turbulence.octaves, 1, 12, "");
    cli::addNumber(app, "--base-frequency", o.turbulence.baseFrequency, 0.01f, 1000.0f, "");
    cli::addNumber(app, "--loop-radius", o.turbulence.loopRadius, 0.0f, 100.0f, "");
    cli::addNumber(app, "--preview-frames", o.output.previewFrames, 1, 1000, "");
    cli::addNumber(app, "--preview-fps", o.output.previewFps, 1, 100, "");
    cli::addNumber(app, "--preview-size", o.output.previewSize, 32, 2048, "");
    cli::addNumber(app, "--auto-quit-after", o.autoQuitAfter, 1, 1000000, "");
    // Repeatable: one patch centre (and side) each.
    app.add_option_function<std::vector<std::string>>(
           "--at",
           [&o](const std::vector<std::string>& values) {
               for (const std::string& v : values) {
                   int x = 0, y = 0, s = 0;
                   char c1 = 0, c2 = 0, extra = 0;
                   std::istringstream in(v);
                   if (!(in >> x >> c1 >> y) || c1 != ',' || ((in >> c2) && (c2 != ',' || !(in >> s) || s < 1)) || (in >> extra))
                       throw CLI::ValidationError("--at expects X,Y or X,Y,SIZE in whole pixels, got '" + v + "'");
                   o.at.emplace_back(x, y, s);
               }
           })
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    choice("--band", [&o](const std::string& v) -> splatfx::Status {
        char colon = 0, extra = 0;
        std::istringstream in(v);
        if (!(in >> o.bandLo >> colon >> o.bandHi) || colon != ':' || (in >> extra) || !(o.bandLo >= 0.0) || !(o.bandHi > o.bandLo))
            return makeError("--band expects LO:HI cycles per pixel with 0 <= LO < HI (e.g. 0.125:0.75), got '" + v + "'");
        return {};
    });
    choice("--path", [&o](const std::string& v) -> splatfx::Status {
        auto p = parsePath(v, "--path");
        if (!p) return makeError(p.error());
        o.path = *p;
        return {};
    });
    cli::addOneOf<Contrast>(app, "--contrast", o.process.contrast, {{"patch", Contrast::Patch}, {"set", Contrast::Set}, {"none", Contrast::None}},
                            "--contrast must be patch, set or none", "");
    cli::addOneOf<splatfx::Kernel>(app, "--kernel", o.process.footprint.kernel,
                                   {{"crawfis-max", splatfx::Kernel::CrawfisMax}, {"gaussian", splatfx::Kernel::Gaussian}},
                                   "--kernel must be crawfis-max or gaussian", "");
    std::vector<std::pair<std::string, std::string>> colors;
    for (const char* c : {"fire", "smoke", "steam", "dust", "white"}) colors.emplace_back(c, c);
    cli::addOneOf(app, "--preview-colors", o.output.previewColors, colors, "--preview-colors must be fire, smoke, steam, dust or white", "");
    text("--source-name", o.sourceName);
    text("--credit", o.credit);
    text("--license", o.license);
    text("--events", o.events);
    text("--screenshot", o.screenshot);
    app.add_flag("--spread", o.spread);
    app.add_flag("--color", o.process.color);
    app.add_flag("--order", o.process.order);
    app.add_flag("--window", o.process.window);
    app.add_flag_callback("--no-preview", [&o] { o.output.preview = false; });
    app.add_flag_callback("--no-contact", [&o] { o.output.contactSheet = false; });
    app.add_flag("--quiet", o.quiet);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        std::string why = e.what();
        if (dynamic_cast<const CLI::ExtrasError*>(&e)) why += " (try --help)";
        return makeError(why);
    }
    if (help) {
        std::fputs(kUsage, stdout);
        return makeError("");
    }
    o.countGiven = count->count() > 0;
    if (positional.empty()) return makeError("no mode given (try --help)");
    o.mode = positional[0];
    static const char* modes[] = {"positions", "random", "spectral", "path", "interactive", "turbulence", "merge"};
    if (std::find(std::begin(modes), std::end(modes), o.mode) == std::end(modes))
        return makeError("unknown mode '" + o.mode + "': use positions, random, spectral, path, interactive, turbulence or merge");
    if (o.mode == "merge") {
        o.sets.assign(positional.begin() + 1, positional.end());
        if (o.sets.size() < 2) return makeError("merge: give at least two texture-set folders");
    } else if (o.mode == "turbulence") {
        if (positional.size() > 1) return makeError("turbulence takes no image, got '" + positional[1] + "'");
    } else {
        if (positional.size() < 2) return makeError(o.mode + ": give the photograph to cut from");
        if (positional.size() > 2) return makeError(o.mode + ": one photograph only, got '" + positional[2] + "' too");
        o.input = positional[1];
    }
    if (o.out.empty()) return makeError("--out DIR is required: the texture-set folder to write");
    if (o.mode == "positions" && o.at.empty()) return makeError("positions: give at least one --at X,Y[,SIZE]");
    if (o.mode == "path" && o.path.empty()) return makeError("path: give --path X,Y:X,Y[:X,Y...]");
    if (o.spread && o.mode != "spectral") return makeError("--spread only applies to the spectral mode");
    // Each texel is kept as a float per channel several times over (the set, its
    // windowed copy, the contact sheet), so bound the set before anything is built.
    const double texels = double(o.count) * o.process.textureSize * o.process.textureSize * (o.process.color ? 3 : 1);
    if (texels > kMaxSetTexels)
        return makeError("--count " + std::to_string(o.count) + " x --size " + std::to_string(o.process.textureSize) +
                         (o.process.color ? " (colour)" : "") + " asks for " + std::to_string((long long)texels) + " texels, more than the " +
                         std::to_string(kMaxSetTexels) + " a texture set may hold (about 256 MB as floats); lower --count or --size");
    o.output.footprint = o.process.footprint;
    return o;
}

splatfx::Status produce(const Options& o, const Source& src, const Selection& sel, const std::string& method, const std::string& parametersJson) {
    auto made = makeSet(src, sel.patches, o.process);
    if (!made) return makeError(made.error());
    Provenance p;
    p.sourceFile = o.sourceName.empty() ? baseName(src.path) : o.sourceName;
    p.credit = o.credit;
    p.license = o.license;
    p.sourceWidth = src.width;
    p.sourceHeight = src.height;
    p.method = method;
    p.parametersJson = parametersJson;
    p.selection = &sel;
    p.process = &o.process;
    p.order = made->order;
    std::vector<Patch> ordered;
    for (int k : made->order) ordered.push_back(sel.patches[size_t(k)]);
    if (!o.quiet)
        std::printf("%s: writing %s/ (%d textures, %dx%d%s)\n", kToolName, o.out.c_str(), made->set.count(), made->set.size, made->set.size,
                    o.output.preview ? ", rendering the preview" : "");
    return writeOutput(o.out, made->set, provenanceJson(p), o.output, &src, &ordered);
}

namespace {

// Floats as the artist typed them (0.03, not 0.029999999329447746).
double f6(float v) { return std::round(double(v) * 1e6) / 1e6; }

int fail(const std::string& why) {
    std::fprintf(stderr, "%s: %s\n", kToolName, why.c_str());
    return 1;
}

int runTurbulence(const Options& o) {
    splatfx::TurbulenceDesc d = o.turbulence;
    d.count = o.count;
    d.size = o.process.textureSize;
    d.seed = o.seed;
    splatfx::TextureSet set = splatfx::TextureSet::turbulence(d);
    if (o.process.window) set = set.windowed(splatfx::Footprint(o.process.footprint));
    json params{{"count", d.count},
                {"size", d.size},
                {"seed", d.seed},
                {"octaves", d.octaves},
                {"baseFrequency", f6(d.baseFrequency)},
                {"loopRadius", f6(d.loopRadius)}};
    Provenance p;
    p.sourceFile = "splatfx::TextureSet::turbulence (procedural, no photograph)";
    p.method = "turbulence";
    p.parametersJson = params.dump();
    if (!o.quiet) std::printf("%s: turbulence: %d textures, %dx%d, seed %u -> %s/\n", kToolName, d.count, d.size, d.size, d.seed, o.out.c_str());
    json prov = json::parse(provenanceJson(p));
    prov["processing"] = {
        {"windowed", o.process.window}, {"ordered", false}, {"note", "turbulence textures are already a closed loop (TurbulenceDesc::loopRadius)"}};
    if (auto s = writeOutput(o.out, set, prov.dump(), o.output); !s) return fail(s.error());
    return 0;
}

int runMerge(const Options& o) {
    splatfx::TextureSet merged;
    json parts = json::array();
    for (const std::string& folder : o.sets) {
        auto set = splatfx::loadTextureSet(folder);
        if (!set) return fail("merge: " + set.error());
        if (merged.layers.empty()) {
            merged.size = set->size;
            merged.color = set->color;
            merged.isWindowed = set->isWindowed;
        } else if (set->size != merged.size || set->color != merged.color || set->isWindowed != merged.isWindowed) {
            return fail("merge: '" + folder + "' is " + std::to_string(set->size) + "x" + std::to_string(set->size) +
                        (set->color ? " colour" : " grayscale") + (set->isWindowed ? " windowed" : "") + " but '" + o.sets[0] + "' is " +
                        std::to_string(merged.size) + "x" + std::to_string(merged.size) + (merged.color ? " colour" : " grayscale") +
                        (merged.isWindowed ? " windowed" : "") + "; merge sets made alike (same --size, --color and --window)");
        }
        for (auto& l : set->layers) merged.layers.push_back(std::move(l));
        json part{{"folder", baseName(folder)}, {"textures", set->count()}};
        std::ifstream in(folder + "/manifest.json");
        json m = json::parse(in, nullptr, false);
        if (!m.is_discarded() && m.contains("provenance")) part["provenance"] = m["provenance"];
        parts.push_back(part);
    }
    Provenance p;
    p.sourceFile = "(merged sets, see parameters.parts)";
    p.method = "merge";
    p.parametersJson = json{{"parts", parts}}.dump();
    if (!o.quiet) std::printf("%s: merge: %zu sets, %d textures -> %s/\n", kToolName, o.sets.size(), merged.count(), o.out.c_str());
    if (auto s = writeOutput(o.out, merged, provenanceJson(p), o.output); !s) return fail(s.error());
    return 0;
}

} // namespace

int run(const Options& o) {
    if (o.mode == "turbulence") return runTurbulence(o);
    if (o.mode == "merge") return runMerge(o);
    if (o.mode == "interactive") return runInteractive(o);
    auto src = loadSource(o.input, o.source);
    if (!src) return fail(src.error());
    if (!o.quiet) {
        std::printf("%s: %s: %s, %dx%d, luminance %.3g..%.3g", kToolName, o.mode.c_str(), o.input.c_str(), src->width, src->height, src->luminanceMin,
                    src->luminanceMax);
        if (src->fileChannels == 4)
            std::printf(", alpha as %s (%s; %.0f%% of covered pixels semi-transparent)", alphaUseName(src->alpha),
                        o.source.alpha == AlphaUse::Auto ? "detected" : "--alpha", 100.0 * src->softAlphaFraction);
        std::printf("\n");
    }
    // What the thresholds were read against, for the manifest.
    auto sourceParams = [&](json& params) {
        params["alpha"] = alphaUseName(src->alpha);
        params["thresholds"] = o.accept.relative ? "relative" : "absolute";
        params["luminanceRange"] = {f6(src->luminanceMin), f6(src->luminanceMax)};
    };
    splatfx::Result<Selection> sel = makeError("unreachable");
    json params;
    if (o.mode == "positions") {
        sel = pickPositions(*src, {.centers = o.at, .defaultSize = o.patch});
        json at = json::array();
        for (const cv::Point3i& c : o.at) at.push_back({c.x, c.y, c.z > 0 ? c.z : o.patch});
        params = {{"at", at}, {"patch", o.patch}};
    } else if (o.mode == "random") {
        const float minDistance = o.minDistance >= 0.0f ? o.minDistance : 0.0f;
        sel = pickRandom(*src, {.count = o.count, .patch = o.patch, .seed = o.seed, .accept = o.accept, .minDistance = minDistance});
        params = {{"count", o.count},
                  {"patch", o.patch},
                  {"seed", o.seed},
                  {"minStd", f6(o.accept.minStd)},
                  {"minMean", f6(o.accept.minMean)},
                  {"minCoverage", f6(o.accept.minCoverage)},
                  {"minDistance", f6(minDistance)},
                  {"rng", "std::mt19937, raw words modulo the span"}};
        sourceParams(params);
    } else if (o.mode == "spectral") {
        SpectralDesc d{.count = o.count,
                       .patch = o.patch,
                       .stride = o.stride,
                       .bandLo = o.bandLo,
                       .bandHi = o.bandHi,
                       .spread = o.spread,
                       .minDistance = o.minDistance,
                       .accept = o.accept};
        sel = pickSpectral(*src, d);
        params = {{"count", o.count},
                  {"patch", o.patch},
                  {"stride", o.stride > 0 ? o.stride : std::max(1, o.patch / 4)},
                  {"minDistance", o.minDistance >= 0.0f ? f6(o.minDistance) : 0.5 * o.patch},
                  {"minStd", f6(o.accept.minStd)},
                  {"minMean", f6(o.accept.minMean)},
                  {"minCoverage", f6(o.accept.minCoverage)}};
        sourceParams(params);
        if (o.spread) params["spread"] = true;
        else params["bandCyclesPerPixel"] = {o.bandLo, o.bandHi};
    } else if (o.mode == "path") {
        sel = pickPath(*src, {.points = o.path, .patch = o.patch, .step = o.step, .count = o.countGiven ? o.count : 0});
        json pts = json::array();
        for (const cv::Point2d& q : o.path) pts.push_back({q.x, q.y});
        params = {{"path", pts}, {"patch", o.patch}, {"step", o.step}, {"overlap", o.patch - o.step}};
        if (o.countGiven) params["count"] = o.count;
    }
    if (!sel) return fail(sel.error());
    if (!o.quiet)
        std::printf("%s: %s: picked %zu patches of %d px (%d candidates considered, %d rejected)\n", kToolName, o.mode.c_str(), sel->patches.size(),
                    sel->patches.empty() ? 0 : sel->patches[0].size, sel->candidates, sel->rejected);
    if (auto s = produce(o, *src, *sel, o.mode, params.dump()); !s) return fail(s.error());
    if (!o.quiet)
        std::printf("%s: done: %s/ (manifest.json, t000.png..., contact.png%s)\n", kToolName, o.out.c_str(), o.output.preview ? ", preview.gif" : "");
    return 0;
}

} // namespace texpick
