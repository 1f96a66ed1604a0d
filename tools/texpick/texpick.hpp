// tools/texpick/texpick.hpp: cutting texture sets out of photographs (the library behind splatfx-texpick).
//
// King et al. 1999, sec. 4: a set of textures is cut out of one large image,
// at positions the artist gives, at random, by spectral analysis (patches
// whose frequencies lie in a band, or a set that varies as much as possible
// in frequency), or along a linear or piecewise-linear path whose overlapping
// patches give coherent motion when cycled. The patches are converted to
// grayscale (sec. 2 step 1), contrast-normalized, optionally ordered for
// smooth cycling, and written as a texture-set folder splatfx::loadTextureSet
// reads, with a contact sheet and a preview animation of textured splats.
// It does not track motion in video, and it does not synthesize texture: every
// texel comes from the photograph (or from splatfx::TextureSet::turbulence).
//
//   auto src = texpick::loadSource("fire.png");
//   auto pick = texpick::pickRandom(*src, {.count = 8, .patch = 64, .seed = 3});
//   auto made = texpick::makeSet(*src, pick->patches, {.textureSize = 32});
//
// Errors come back as splatfx::Result / Status with a message naming the file,
// option or value; no exception leaves this library. Threading: plain functions
// on plain values; previews need a GL context (renderPreview makes its own).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "splatfx/footprint.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/result.hpp"
#include "splatfx/texture_set_io.hpp"

namespace texpick {

inline constexpr const char* kToolName = "splatfx-texpick";
inline constexpr const char* kToolVersion = "1.0.0";
// Version of the "provenance" object texpick writes into manifest.json.
inline constexpr int kProvenanceVersion = 1;
inline constexpr int kMinPatch = 4;       // smallest patch side, source pixels
inline constexpr int kMaxTextures = 4096; // most textures in one set (--count, and patches a path may give)
// Most texels (per channel) in one set: 64 Mi, 256 MB as floats, kept a few
// times over while the set, its windowed copy and the contact sheet are built.
inline constexpr long long kMaxSetTexels = 64ll << 20;

// [SECTION] Source images

// What a source's alpha channel means (issue 18, item 4).
enum class AlphaUse {
    Auto,     // Density when the alpha looks like a sprite's (see kSpriteSoftFraction), else Coverage (default)
    Coverage, // a cut-out (a photographed stamp): patches mostly outside it are rejected (Acceptance::minCoverage)
    Density,  // a game particle sprite: alpha is how much gas there is, part of the texture, never a cut-out
};
const char* alphaUseName(AlphaUse use); // "auto" | "coverage" | "density"

// Auto takes the alpha as density (the source is a sprite) when more than
// kSpriteSoftFraction of the pixels it covers (alpha > kCoveredAlpha) are
// semi-transparent (alpha below 1 - kCoveredAlpha): a cut-out photograph is
// opaque inside and soft only along its edge, a particle puff or a
// translucent stamp is soft almost everywhere (a radial falloff: over 90%;
// textures/sources/fire.png, a Tux Paint stamp of translucent flames: 63%).
// A hard-edged (binary) alpha is a cut-out; --alpha density overrides.
inline constexpr double kSpriteSoftFraction = 0.5;
inline constexpr double kCoveredAlpha = 2.0 / 255.0; // two 8-bit steps: below is empty, whatever the encoder left

struct SourceDesc {
    AlphaUse alpha = AlphaUse::Auto; // default Auto
};

// A source ready for cutting: RGB times alpha (composited over black: a
// cut-out's outside becomes black, i.e. empty, which the thresholds reject;
// a sprite's thin gas becomes dark), its luminance, and its coverage (alpha
// when the alpha is a cut-out; 1 where the file has none or the alpha is
// density, which the luminance then already carries).
struct Source {
    std::string path{}; // as given
    int width = 0, height = 0;
    int fileChannels = 0;

    cv::Mat rgb{}; // CV_32FC3, [0, 1], premultiplied by alpha (straight alpha read from the file, multiplied once)

    cv::Mat luminance{}; // CV_32FC1, Rec. 709 weights

    cv::Mat coverage{}; // CV_32FC1, [0, 1]
    // The alpha's meaning as used (never Auto here) and the evidence for Auto.
    AlphaUse alpha = AlphaUse::Coverage;
    double softAlphaFraction = 0.0; // of the covered pixels, the semi-transparent ones (0 without alpha)
    // The source's own luminance range (every pixel): relative thresholds
    // (Acceptance::relative) scale with it, so a dark sprite is judged
    // against its own contrast, not a photograph's.
    float luminanceMin = 0.0f, luminanceMax = 0.0f;
};

// Reads any format OpenImageIO reads (falling back to OpenCV), alpha as
// stored (straight). On failure the message names the file and the reason:
// no such file, a folder, empty, unreadable, corrupt or of an unknown format.
splatfx::Result<Source> loadSource(const std::string& path, const SourceDesc& desc = {});
// Wraps an image made in memory (tests, turbulence), colour not
// premultiplied by its alpha. Expects 1, 3 or 4 channels.
Source sourceFromImage(const splatfx::Image& image, const std::string& name, const SourceDesc& desc = {});

// [SECTION] Patches and their spectra

// A square cut from the source: top-left corner and side, in source pixels.
struct Patch {
    int x = 0, y = 0;
    int size = 0;
    double centerX() const { return x + 0.5 * size; }
    double centerY() const { return y + 0.5 * size; }
    bool operator==(const Patch&) const = default;
};

// Radial frequency bands, in cycles per source pixel (octaves below Nyquist).
// The last band also holds the spectrum's corners (radius up to sqrt(2)/2).
inline const std::vector<double>& bandEdges() {
    static const std::vector<double> edges{0.0, 1.0 / 32, 1.0 / 16, 1.0 / 8, 1.0 / 4, 0.75};
    return edges;
}

// Summary of a patch's luminance power spectrum. The patch's weighted mean is
// removed and it is multiplied by a separable Hann window first, so the edges
// of the square do not leak power into every band.
struct SpectralStats {
    std::vector<double> bandEnergy{}; // fraction of (non-DC) power per band of bandEdges(); sums to 1 (all 0 when flat)
    double power = 0.0;               // total non-DC power per pixel (windowed luminance variance)
    double centroid = 0.0;            // power-weighted mean radial frequency, cycles per pixel
    double mean = 0.0;                // luminance mean over the patch
    double stddev = 0.0;              // luminance standard deviation over the patch
    double coverage = 1.0;            // mean alpha over the patch
};

// Expects the patch inside the source.
SpectralStats analyze(const Source& source, const Patch& patch);
// Fraction of the patch's non-DC power at radial frequency in [lo, hi) cycles per pixel.
double bandFraction(const Source& source, const Patch& patch, double lo, double hi);

// [SECTION] Selection

// What makes a patch worth keeping (random and spectral modes).
// Relative (the default): minStd is a fraction of the source's own
// luminance range (Source::luminanceMax - luminanceMin) and minMean of its
// brightest luminance (luminanceMax), so a particle sprite whose brightest
// texel is 68/255 is judged by its own contrast; a source spanning 0..1
// gets the absolute thresholds texpick always had.
struct Acceptance {
    float minStd = 0.03f;     // luminance std below this x the source's range is flat; default 0.03
    float minMean = 0.03f;    // luminance mean below this x the source's brightest is near-empty (black or cut-out); default 0.03
    float minCoverage = 0.9f; // mean alpha below this is mostly outside a cut-out (coverage alpha only); default 0.9
    bool relative = true;     // scale minStd, minMean by the source's range; default true
};

// The thresholds in the source's luminance units, as applied.
struct Thresholds {
    double minStd = 0.0, minMean = 0.0, minCoverage = 0.0;
};
Thresholds effectiveThresholds(const Source& source, const Acceptance& accept);

struct Selection {
    std::vector<Patch> patches{};

    std::vector<SpectralStats> stats{}; // one per patch
    int candidates = 0;                 // patches considered
    int rejected = 0;                   // flat, near-empty, outside a cut-out or too close to a pick
    // ... by reason (each rejected candidate counted once, for the first test it fails in this order).
    int rejectedCoverage = 0; // mean alpha below --min-coverage
    int rejectedEmpty = 0;    // mean luminance below --min-mean
    int rejectedFlat = 0;     // luminance std below --min-std
    int rejectedDistance = 0; // closer than --min-distance to a pick
};

// Each position is a patch centre; size 0 takes `defaultSize`. Errors name
// the position that leaves the image.
struct PositionsDesc {
    std::vector<cv::Point3i> centers{}; // (x, y, size) in source pixels
    int defaultSize = 64;               // default 64
};
splatfx::Result<Selection> pickPositions(const Source& source, const PositionsDesc& desc);

struct RandomDesc {
    int count = 8;          // default 8
    int patch = 64;         // source pixels; default 64
    std::uint32_t seed = 1; // default 1
    Acceptance accept{};
    float minDistance = 0.0f; // smallest distance between picked centres, pixels; default 0 (overlap allowed)
    int maxTries = 0;         // default 0 = 2000 per texture
};
// Deterministic per seed (std::mt19937, whose sequence the C++ standard fixes).
splatfx::Result<Selection> pickRandom(const Source& source, const RandomDesc& desc);

struct SpectralDesc {
    int count = 8;  // default 8
    int patch = 64; // default 64
    int stride = 0; // candidate grid step, pixels; default 0 = patch / 4
    // Band mode: keep the patches with the largest share of power in [bandLo, bandHi) cycles per pixel.
    double bandLo = 0.125, bandHi = 0.75; // default: the upper two octaves
    // Spread mode (true): greedily maximize the spectral variation across the
    // set instead (farthest-point selection on band energies).
    bool spread = false;       // default false
    float minDistance = -1.0f; // smallest distance between picked centres; default -1 = patch / 2
    Acceptance accept{};
};
splatfx::Result<Selection> pickSpectral(const Source& source, const SpectralDesc& desc);

// Patch centres walk the polyline through `points` by arc length, `step`
// pixels apart (so consecutive patches overlap by patch - step pixels along
// the path), rounded to whole pixels so each is an exact cut of the photo.
struct PathDesc {
    std::vector<cv::Point2d> points{}; // at least 2 vertices, source pixels
    int patch = 64;                    // default 64
    double step = 4.0;                 // pixels along the path between consecutive patches; default 4
    int count = 0;                     // default 0 = as many as fit on the path
};
splatfx::Result<Selection> pickPath(const Source& source, const PathDesc& desc);

// [SECTION] Processing

enum class Contrast {
    Patch, // each patch's luminance to mean 0.5, std `contrastStd` (default)
    Set,   // one mean/std for the whole set: keeps relative brightness, no flicker
    None,  // the photograph's values
};

struct ProcessDesc {
    int textureSize = 32;                // texels on a side; default 32
    bool color = false;                  // keep RGB (default false: grayscale, sec. 2 step 1)
    Contrast contrast = Contrast::Patch; // default Patch
    float contrastStd = 0.25f;           // target standard deviation; default 0.25 (about 2 std either side of 0.5 fit in [0, 1])
    bool order = false;                  // reorder for smooth cycling; default false
    bool window = false;                 // bake the footprint into the saved set (else the renderer windows it); default false
    splatfx::FootprintDesc footprint{};  // kernel for the window, the contact sheet and the preview
};

// The textures, before windowing unless desc.window. `order[k]` is the index
// (in the input patch list) of texture k.
struct MadeSet {
    splatfx::TextureSet set{};

    std::vector<int> order{};
};
splatfx::Result<MadeSet> makeSet(const Source& source, const std::vector<Patch>& patches, const ProcessDesc& desc);

// A cycle through all textures (starting at 0) with a small total
// frame-to-frame difference, the last leading back to the first: nearest
// neighbour then 2-opt on mean squared texel difference. Deterministic.
std::vector<int> smoothCycle(const splatfx::TextureSet& set);
// Sum of mean squared differences between consecutive textures of `order`, closing the cycle.
double cycleCost(const splatfx::TextureSet& set, const std::vector<int>& order);

// [SECTION] Output

// What manifest.json's "provenance" records (versioned by kProvenanceVersion).
struct Provenance {
    std::string sourceFile{}; // file name only (baseName) or an artist-given name

    std::string credit{}; // author / origin of the photograph; default empty

    std::string license{}; // licence of the photograph; default empty
    int sourceWidth = 0, sourceHeight = 0;

    std::string method{};                 // positions | random | spectral | path | turbulence | merge
    std::string parametersJson = "{}";    // the method's parameters, as given
    const Selection* selection = nullptr; // patches and their spectra (photo methods)
    const ProcessDesc* process = nullptr;

    std::vector<int> order{}; // texture k came from patch order[k]
};
std::string provenanceJson(const Provenance& p);

struct OutputDesc {
    bool contactSheet = true;            // write contact.png; default true
    bool preview = true;                 // write preview.gif (needs headless GL); default true
    int previewFrames = 0;               // default 0 = 3 per texture (one full cycle)
    int previewFps = 12;                 // default 12
    int previewSize = 192;               // height in pixels; the GIF is twice as wide; default 192
    std::string previewColors = "smoke"; // fire | smoke | steam | dust | white; default smoke
    splatfx::FootprintDesc footprint{};
};

// Writes folder/ (textures, manifest.json with `provenanceJson` under
// "provenance", contact.png, preview.gif) through a staging folder beside it
// that is renamed into place only when everything is written. An existing
// texture-set folder is replaced; any other existing path is refused. On
// failure nothing is left behind (staging and any parent folders it created
// are removed) and the message says why.
splatfx::Status writeOutput(const std::string& folder, const splatfx::TextureSet& set, const std::string& provenanceJson, const OutputDesc& desc,
                            const Source* source = nullptr, const std::vector<Patch>* patches = nullptr);

// The contact sheet: the source with numbered patch outlines (when given),
// then each texture above its windowed splat (Fig. 2). RGB float, top row first.
splatfx::Image contactSheet(const splatfx::TextureSet& set, const splatfx::FootprintDesc& footprint, const Source* source = nullptr,
                            const std::vector<Patch>* patches = nullptr);

// Renders the cycling preview headless: one large textured splat (left) and
// a puff of textured splats (right), cross-fading through the set in order.
// Fails when no headless GL 4.5 context can be created. Each frame goes to
// `sink` as it is drawn (memory: one frame); the sink's failure stops it.
splatfx::Status renderPreview(const splatfx::TextureSet& set, const OutputDesc& desc,
                              const std::function<splatfx::Status(const splatfx::Image&)>& sink);
// The same, collected (small previews and tests).
splatfx::Result<std::vector<splatfx::Image>> renderPreview(const splatfx::TextureSet& set, const OutputDesc& desc);

// [SECTION] Command line and interactive mode

// Everything the command line can say; defaults match `splatfx-texpick --help`.
struct Options {
    std::string mode{}; // positions | random | spectral | path | interactive | turbulence | merge

    std::string input{}; // the photograph (merge: unused)

    std::vector<std::string> sets{}; // merge: the texture-set folders to concatenate

    std::string out{}; // --out
    int patch = 64, count = 8;
    bool countGiven = false;
    std::uint32_t seed = 1;

    std::vector<cv::Point3i> at{}; // positions
    SourceDesc source{};           // --alpha
    Acceptance accept{};
    float minDistance = -1.0f; // -1: the mode's default
    double bandLo = 0.125, bandHi = 0.75;
    bool spread = false;
    int stride = 0;

    std::vector<cv::Point2d> path{};
    double step = 4.0;
    splatfx::TurbulenceDesc turbulence{};
    ProcessDesc process{};
    OutputDesc output{};

    std::string sourceName{}, credit{}, license{};
    bool quiet = false;
    int autoQuitAfter = 0; // interactive: close after this many frames (0 = wait for the user)

    std::string events{}; // interactive: scripted input, e.g. "click:120,80;key:s"

    std::string screenshot{}; // interactive: write the window's image here before quitting
};

// Parses argv into options; on --help prints usage and returns an empty error.
splatfx::Result<Options> parseOptions(int argc, const char* const* argv);
// Picks, processes and writes; prints progress and a summary. Returns the exit code.
int run(const Options& options);
// The HighGUI window (OpenCV): click positions or draw a path, watch the
// patches and the cycling preview, press s to write the same output as the
// command line. Returns the exit code.
int runInteractive(const Options& options);
// Builds the set for a selection and writes it: what `run` and the interactive
// mode's save both do, so their outputs match.
splatfx::Status produce(const Options& options, const Source& source, const Selection& selection, const std::string& method,
                        const std::string& parametersJson);

// [SECTION] Helpers shared by the command line and the interactive mode

// Parses "x,y" / "x,y,size" lists and "lo:hi" bands; messages name the option.
splatfx::Result<cv::Point2d> parsePoint(const std::string& text, const std::string& option);
splatfx::Result<std::vector<cv::Point2d>> parsePath(const std::string& text, const std::string& option);
// The file name without its folders, for provenance (no machine-specific paths).
std::string baseName(const std::string& path);

} // namespace texpick
