// texpick: loading photographs, patch spectra, and the four selection modes.
//
// [SECTION] Source images
// [SECTION] Spectra
// [SECTION] Selection: positions, random, spectral, path
// [SECTION] Parsing
#include <limits>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "texpick.hpp"

namespace texpick {

namespace fs = std::filesystem;
using splatfx::makeError;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string str(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

std::string describe(const Patch& p) { return std::to_string(p.size) + "-px patch at (" + std::to_string(p.x) + ", " + std::to_string(p.y) + ")"; }

bool inside(const Source& s, const Patch& p) { return p.size >= 1 && p.x >= 0 && p.y >= 0 && p.x + p.size <= s.width && p.y + p.size <= s.height; }

splatfx::Status checkPatchFits(const Source& s, int patch, const std::string& option) {
    if (patch < kMinPatch) return makeError(option + " must be at least " + std::to_string(kMinPatch) + " pixels, got " + std::to_string(patch));
    if (std::min(s.width, s.height) < kMinPatch)
        return makeError("image '" + s.path + "' is " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                         " pixels, smaller than the smallest patch (" + std::to_string(kMinPatch) + " px); use a larger image");
    if (patch > s.width || patch > s.height)
        return makeError("image '" + s.path + "' is " + std::to_string(s.width) + "x" + std::to_string(s.height) + " pixels, too small for one " +
                         std::to_string(patch) + "-px patch; use " + option + " " + std::to_string(std::max(kMinPatch, std::min(s.width, s.height))) +
                         " or less");
    return {};
}

} // namespace

// [SECTION] Source images

const char* alphaUseName(AlphaUse use) {
    switch (use) {
    case AlphaUse::Auto: return "auto";
    case AlphaUse::Coverage: return "coverage";
    case AlphaUse::Density: return "density";
    }
    return "?";
}

Source sourceFromImage(const splatfx::Image& img, const std::string& name, const SourceDesc& desc) {
    assert((img.channels == 1 || img.channels == 3 || img.channels == 4) && "image must have 1, 3 or 4 channels");
    Source s;
    // What the alpha is: the share of covered pixels that are semi-transparent.
    if (img.channels == 4) {
        std::size_t covered = 0, soft = 0;
        for (std::size_t p = 0; p < std::size_t(img.width) * img.height; ++p) {
            const float a = img.pixels[p * 4 + 3];
            if (!(a > kCoveredAlpha)) continue; // NaN counts as empty
            ++covered;
            if (a < 1.0 - kCoveredAlpha) ++soft;
        }
        s.softAlphaFraction = covered ? double(soft) / double(covered) : 0.0;
    }
    const bool sprite = img.channels == 4 && s.softAlphaFraction > kSpriteSoftFraction;
    s.alpha = desc.alpha != AlphaUse::Auto ? desc.alpha : (sprite ? AlphaUse::Density : AlphaUse::Coverage);
    const bool density = s.alpha == AlphaUse::Density;
    s.path = name;
    s.width = img.width;
    s.height = img.height;
    s.fileChannels = img.channels;
    s.rgb.create(img.height, img.width, CV_32FC3);
    s.luminance.create(img.height, img.width, CV_32FC1);
    s.coverage.create(img.height, img.width, CV_32FC1);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            float rgb[3];
            for (int c = 0; c < 3; ++c) {
                const float v = img.at(x, y, img.channels == 1 ? 0 : c);
                rgb[c] = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
            }
            const float a = img.channels == 4 ? std::clamp(img.at(x, y, 3), 0.0f, 1.0f) : 1.0f;
            cv::Vec3f& p = s.rgb.at<cv::Vec3f>(y, x);
            for (int c = 0; c < 3; ++c) p[c] = rgb[c] * (std::isfinite(a) ? a : 0.0f);
            s.luminance.at<float>(y, x) = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
            // Density alpha is already in the luminance (colour x density); it covers everything.
            s.coverage.at<float>(y, x) = density ? 1.0f : (std::isfinite(a) ? a : 0.0f);
        }
    double lo = 0.0, hi = 0.0;
    if (img.width > 0 && img.height > 0) cv::minMaxLoc(s.luminance, &lo, &hi);
    s.luminanceMin = float(lo);
    s.luminanceMax = float(hi);
    return s;
}

splatfx::Result<Source> loadSource(const std::string& path, const SourceDesc& desc) {
    std::error_code ec;
    const std::string what = "cannot read image '" + path + "': ";
    if (!fs::exists(path, ec)) return makeError(what + "no such file");
    if (fs::is_directory(path, ec)) return makeError(what + "it is a folder, not an image file");
    // Opening a FIFO would block forever and a device never ends: regular files only.
    if (!fs::is_regular_file(path, ec)) return makeError(what + "not a regular file (a FIFO, device or socket is never read as an image)");
    {
        std::ifstream probe(path, std::ios::binary);
        if (!probe) return makeError(what + "the file cannot be opened (check its permissions)");
        if (probe.peek() == std::ifstream::traits_type::eof()) return makeError(what + "the file is empty");
    }
    // Straight alpha, as stored: sourceFromImage multiplies the colour by it
    // once (a premultiplied read would multiply twice, squaring a sprite's density).
    auto img = splatfx::readImage(path, splatfx::Alpha::Straight);
    if (!img) {
        // OpenImageIO first (it knows EXR, HDR, DPX...), OpenCV only for what it
        // cannot open at all: a file whose header OpenImageIO read was refused
        // on its merits (a budget, corrupt data), and OpenCV must not bypass that.
        if (splatfx::readImageInfo(path)) return makeError(img.error());
        cv::Mat m = cv::imread(path, cv::IMREAD_UNCHANGED);
        if (m.empty()) return makeError(img.error() + " (OpenCV cannot decode it either)");
        cv::Mat f;
        const double scale = m.depth() == CV_16U ? 1.0 / 65535.0 : (m.depth() == CV_8U ? 1.0 / 255.0 : 1.0);
        m.convertTo(f, CV_32F, scale);
        if (f.channels() == 3) cv::cvtColor(f, f, cv::COLOR_BGR2RGB);
        if (f.channels() == 4) cv::cvtColor(f, f, cv::COLOR_BGRA2RGBA);
        if (f.channels() == 2) cv::cvtColor(f, f, cv::COLOR_GRAY2RGB); // drop a gray image's alpha
        splatfx::Image im;
        im.width = f.cols;
        im.height = f.rows;
        im.channels = f.channels();
        im.pixels.assign(f.ptr<float>(0), f.ptr<float>(0) + size_t(f.total()) * f.channels());
        img = std::move(im);
    }
    splatfx::Image im = std::move(*img);
    if (im.channels == 2) { // gray + alpha: widen to RGBA
        splatfx::Image rgba;
        rgba.width = im.width;
        rgba.height = im.height;
        rgba.channels = 4;
        rgba.pixels.resize(size_t(im.width) * im.height * 4);
        for (size_t p = 0; p < size_t(im.width) * im.height; ++p) {
            for (int c = 0; c < 3; ++c) rgba.pixels[p * 4 + c] = im.pixels[p * 2];
            rgba.pixels[p * 4 + 3] = im.pixels[p * 2 + 1];
        }
        im = std::move(rgba);
    }
    return sourceFromImage(im, path, desc);
}

// [SECTION] Spectra

namespace {

// Hann-windowed, weighted-mean-free luminance of the patch, and its power spectrum.
struct Spectrum {
    cv::Mat power; // CV_64F, size x size, unshifted (DC at (0, 0))
    double total = 0.0;
};

Spectrum spectrum(const Source& s, const Patch& p) {
    assert(inside(s, p) && "patch must lie inside the source");
    const int n = p.size;
    std::vector<double> w(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) w[size_t(i)] = 0.5 - 0.5 * std::cos(2.0 * kPi * (i + 0.5) / n);
    cv::Mat lum;
    s.luminance(cv::Rect(p.x, p.y, n, n)).convertTo(lum, CV_64F);
    // Removing the window-weighted mean makes the windowed patch sum to zero,
    // so no power sits at DC and none leaks from it into the lowest band.
    double sw = 0.0, swx = 0.0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double ww = w[size_t(x)] * w[size_t(y)];
            sw += ww;
            swx += ww * lum.at<double>(y, x);
        }
    const double mean = swx / sw;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) lum.at<double>(y, x) = (lum.at<double>(y, x) - mean) * w[size_t(x)] * w[size_t(y)];
    cv::Mat f;
    cv::dft(lum, f, cv::DFT_COMPLEX_OUTPUT);
    Spectrum out;
    out.power.create(n, n, CV_64F);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const cv::Vec2d c = f.at<cv::Vec2d>(y, x);
            const double pw = (x == 0 && y == 0) ? 0.0 : c[0] * c[0] + c[1] * c[1];
            out.power.at<double>(y, x) = pw;
            out.total += pw;
        }
    return out;
}

// Radial frequency of DFT bin (x, y) of an n x n transform, cycles per pixel.
double radius(int x, int y, int n) {
    const double fx = (x <= n / 2 ? x : x - n) / double(n);
    const double fy = (y <= n / 2 ? y : y - n) / double(n);
    return std::sqrt(fx * fx + fy * fy);
}

} // namespace

SpectralStats analyze(const Source& s, const Patch& p) {
    const Spectrum sp = spectrum(s, p);
    const std::vector<double>& edges = bandEdges();
    SpectralStats st;
    st.bandEnergy.assign(edges.size() - 1, 0.0);
    double weighted = 0.0;
    for (int y = 0; y < p.size; ++y)
        for (int x = 0; x < p.size; ++x) {
            const double pw = sp.power.at<double>(y, x);
            if (pw == 0.0) continue;
            const double r = radius(x, y, p.size);
            weighted += pw * r;
            for (size_t b = 0; b + 1 < edges.size(); ++b)
                if (r >= edges[b] && (r < edges[b + 1] || b + 2 == edges.size())) {
                    st.bandEnergy[b] += pw;
                    break;
                }
        }
    if (sp.total > 0.0) {
        for (double& e : st.bandEnergy) e /= sp.total;
        st.centroid = weighted / sp.total;
    }
    // Parseval: sum |F|^2 = N * sum |f|^2 for an N-point DFT.
    st.power = sp.total / (double(p.size) * p.size) / (double(p.size) * p.size);
    cv::Scalar mean, dev;
    cv::meanStdDev(s.luminance(cv::Rect(p.x, p.y, p.size, p.size)), mean, dev);
    st.mean = mean[0];
    st.stddev = dev[0];
    st.coverage = cv::mean(s.coverage(cv::Rect(p.x, p.y, p.size, p.size)))[0];
    return st;
}

double bandFraction(const Source& s, const Patch& p, double lo, double hi) {
    const Spectrum sp = spectrum(s, p);
    if (sp.total <= 0.0) return 0.0;
    double in = 0.0;
    for (int y = 0; y < p.size; ++y)
        for (int x = 0; x < p.size; ++x) {
            const double r = radius(x, y, p.size);
            if (r >= lo && r < hi) in += sp.power.at<double>(y, x);
        }
    return in / sp.total;
}

// [SECTION] Selection

namespace {

enum class Reject { None, Coverage, Empty, Flat };

// Why a candidate fails `t`, the first test it fails in this order.
Reject rejection(const SpectralStats& st, const Thresholds& t) {
    if (st.coverage < t.minCoverage) return Reject::Coverage;
    if (st.mean < t.minMean) return Reject::Empty;
    if (st.stddev < t.minStd) return Reject::Flat;
    return Reject::None;
}

void count(Selection& sel, Reject why) {
    ++sel.rejected;
    if (why == Reject::Coverage) ++sel.rejectedCoverage;
    else if (why == Reject::Empty) ++sel.rejectedEmpty;
    else if (why == Reject::Flat) ++sel.rejectedFlat;
}

bool farEnough(const std::vector<Patch>& picked, const Patch& p, double minDistance) {
    for (const Patch& q : picked)
        if (std::hypot(q.centerX() - p.centerX(), q.centerY() - p.centerY()) < minDistance) return false;
    return true;
}

// Which threshold rejected how many candidates, with each threshold as given
// and as applied to this source, then what to change.
std::string rejectionText(const Source& s, const Selection& sel, const Acceptance& a, double minDistance) {
    const Thresholds t = effectiveThresholds(s, a);
    auto unit = [&](double applied) {
        return a.relative ? " (" + str(applied) + " for this source's luminance " + str(s.luminanceMin) + ".." + str(s.luminanceMax) + ")"
                          : std::string(" (absolute)");
    };
    std::string text = "of " + std::to_string(sel.candidates) + " candidates, " + std::to_string(sel.rejectedCoverage) +
                       " were rejected by --min-coverage " + str(a.minCoverage) + " (mean alpha; alpha read as " + alphaUseName(s.alpha) +
                       (s.alpha == AlphaUse::Density ? ", so never" : "") + "), " + std::to_string(sel.rejectedEmpty) + " by --min-mean " +
                       str(a.minMean) + unit(t.minMean) + ", " + std::to_string(sel.rejectedFlat) + " by --min-std " + str(a.minStd) + unit(t.minStd);
    if (minDistance > 0) text += ", " + std::to_string(sel.rejectedDistance) + " by --min-distance " + str(minDistance);
    // Advice for the threshold that did the most.
    const int most = std::max({sel.rejectedCoverage, sel.rejectedEmpty, sel.rejectedFlat, sel.rejectedDistance});
    std::string advice;
    if (most == 0) advice = "use a smaller --patch or a lower --count";
    else if (most == sel.rejectedCoverage) advice = "lower --min-coverage, or give --alpha density if the alpha is the gas's density (a sprite)";
    else if (most == sel.rejectedEmpty) advice = "lower --min-mean or use a smaller --patch";
    else if (most == sel.rejectedFlat) advice = "lower --min-std or use a smaller --patch";
    else advice = "lower --min-distance or --count";
    return text + "; " + advice;
}

} // namespace

Thresholds effectiveThresholds(const Source& s, const Acceptance& a) {
    Thresholds t;
    t.minCoverage = a.minCoverage;
    if (!a.relative) {
        t.minStd = a.minStd;
        t.minMean = a.minMean;
        return t;
    }
    // Flatness against the source's contrast (its range), emptiness against
    // its brightest texel (empty is black, wherever the source's darkest
    // lies). A source flatter or darker than one 8-bit step is judged as if
    // it reached one, so a constant image stays flat instead of passing a
    // zero threshold.
    constexpr double kStep = 1.0 / 255.0;
    t.minStd = a.minStd * std::max(double(s.luminanceMax) - double(s.luminanceMin), kStep);
    t.minMean = a.minMean * std::max(double(s.luminanceMax), kStep);
    return t;
}

namespace {} // namespace

splatfx::Result<Selection> pickPositions(const Source& s, const PositionsDesc& d) {
    if (d.centers.empty()) return makeError("positions: give at least one position (--at X,Y[,SIZE])");
    Selection sel;
    for (size_t i = 0; i < d.centers.size(); ++i) {
        const cv::Point3i c = d.centers[i];
        const int size = c.z > 0 ? c.z : d.defaultSize;
        if (size < kMinPatch)
            return makeError("position " + std::to_string(i + 1) + ": patch size must be at least " + std::to_string(kMinPatch) + " pixels, got " +
                             std::to_string(size));
        // The centre of an even patch is a texel corner: top-left = centre - size / 2.
        const Patch p{c.x - size / 2, c.y - size / 2, size};
        if (!inside(s, p))
            return makeError("position " + std::to_string(i + 1) + " (" + std::to_string(c.x) + ", " + std::to_string(c.y) + "): its " + describe(p) +
                             " leaves the " + std::to_string(s.width) + "x" + std::to_string(s.height) + " image '" + s.path + "'");
        sel.patches.push_back(p);
        sel.stats.push_back(analyze(s, p));
        ++sel.candidates;
    }
    return sel;
}

splatfx::Result<Selection> pickRandom(const Source& s, const RandomDesc& d) {
    if (d.count < 1) return makeError("random: --count must be at least 1, got " + std::to_string(d.count));
    if (auto st = checkPatchFits(s, d.patch, "--patch"); !st) return makeError(st.error());
    std::mt19937 rng(d.seed);
    const auto spanX = std::uint32_t(s.width - d.patch + 1), spanY = std::uint32_t(s.height - d.patch + 1);
    const int maxTries = d.maxTries > 0 ? d.maxTries : 2000 * d.count;
    const Thresholds th = effectiveThresholds(s, d.accept);
    Selection sel;
    while (int(sel.patches.size()) < d.count && sel.candidates < maxTries) {
        // Raw mt19937 words modulo the span: the standard fixes mt19937's
        // output, unlike uniform_int_distribution's, so a seed means the same
        // set on every platform. The modulo bias is below 1e-5 for any image.
        const Patch p{int(rng() % spanX), int(rng() % spanY), d.patch};
        ++sel.candidates;
        const SpectralStats st = analyze(s, p);
        if (const Reject why = rejection(st, th); why != Reject::None) {
            count(sel, why);
            continue;
        }
        if (!farEnough(sel.patches, p, d.minDistance)) {
            ++sel.rejected;
            ++sel.rejectedDistance;
            continue;
        }
        sel.patches.push_back(p);
        sel.stats.push_back(st);
    }
    if (int(sel.patches.size()) < d.count)
        return makeError("random: only " + std::to_string(sel.patches.size()) + " of " + std::to_string(d.count) + " " + std::to_string(d.patch) +
                         "-px patches of '" + s.path + "' passed after " + std::to_string(sel.candidates) +
                         " tries: " + rejectionText(s, sel, d.accept, d.minDistance));
    return sel;
}

splatfx::Result<Selection> pickSpectral(const Source& s, const SpectralDesc& d) {
    if (d.count < 1) return makeError("spectral: --count must be at least 1, got " + std::to_string(d.count));
    if (auto st = checkPatchFits(s, d.patch, "--patch"); !st) return makeError(st.error());
    if (!d.spread && !(d.bandLo >= 0.0 && d.bandHi > d.bandLo))
        return makeError("spectral: --band must be LO:HI cycles per pixel with 0 <= LO < HI, got " + str(d.bandLo) + ":" + str(d.bandHi));
    const int stride = d.stride > 0 ? d.stride : std::max(1, d.patch / 4);
    const double minDistance = d.minDistance >= 0.0f ? d.minDistance : 0.5 * d.patch;
    struct Candidate {
        Patch patch;
        SpectralStats stats;
        double score = 0.0;
    };
    std::vector<Candidate> cands;
    const Thresholds th = effectiveThresholds(s, d.accept);
    Selection sel;
    for (int y = 0; y + d.patch <= s.height; y += stride)
        for (int x = 0; x + d.patch <= s.width; x += stride) {
            Candidate c{{x, y, d.patch}, {}, 0.0};
            c.stats = analyze(s, c.patch);
            ++sel.candidates;
            if (const Reject why = rejection(c.stats, th); why != Reject::None) {
                count(sel, why);
                continue;
            }
            if (!d.spread) c.score = bandFraction(s, c.patch, d.bandLo, d.bandHi);
            cands.push_back(std::move(c));
        }
    auto take = [&](size_t i) {
        sel.patches.push_back(cands[i].patch);
        sel.stats.push_back(cands[i].stats);
    };
    auto distance2 = [](const SpectralStats& a, const SpectralStats& b) {
        double d2 = 0.0;
        for (size_t k = 0; k < a.bandEnergy.size(); ++k) d2 += (a.bandEnergy[k] - b.bandEnergy[k]) * (a.bandEnergy[k] - b.bandEnergy[k]);
        return d2;
    };
    if (!d.spread) {
        // Highest share of power in the band first; ties go to the earlier
        // (top-left-most) candidate so the choice is deterministic.
        std::vector<size_t> idx(cands.size());
        for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
        std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return cands[a].score > cands[b].score; });
        for (size_t i : idx) {
            if (int(sel.patches.size()) == d.count) break;
            if (farEnough(sel.patches, cands[i].patch, minDistance)) take(i);
            else ++sel.rejected, ++sel.rejectedDistance;
        }
    } else if (!cands.empty()) {
        // Farthest-point selection on the band-energy vectors: start with the
        // candidate least like the average, then repeatedly add the one whose
        // nearest picked neighbour is farthest away.
        SpectralStats mean;
        mean.bandEnergy.assign(bandEdges().size() - 1, 0.0);
        for (const Candidate& c : cands)
            for (size_t k = 0; k < mean.bandEnergy.size(); ++k) mean.bandEnergy[k] += c.stats.bandEnergy[k] / double(cands.size());
        std::vector<double> nearest(cands.size(), 0.0);
        for (size_t i = 0; i < cands.size(); ++i) nearest[i] = distance2(cands[i].stats, mean);
        std::vector<bool> used(cands.size(), false);
        while (int(sel.patches.size()) < d.count) {
            size_t best = cands.size();
            for (size_t i = 0; i < cands.size(); ++i) {
                if (used[i] || !farEnough(sel.patches, cands[i].patch, minDistance)) continue;
                if (best == cands.size() || nearest[i] > nearest[best]) best = i;
            }
            if (best == cands.size()) break;
            used[best] = true;
            if (sel.patches.empty()) std::fill(nearest.begin(), nearest.end(), 1e300);
            take(best);
            for (size_t i = 0; i < cands.size(); ++i) nearest[i] = std::min(nearest[i], distance2(cands[i].stats, cands[best].stats));
        }
        // Short of the count: every candidate left over was too close to a pick.
        const int blocked = int(cands.size() - sel.patches.size());
        if (int(sel.patches.size()) < d.count) sel.rejected += blocked, sel.rejectedDistance += blocked;
    }
    if (int(sel.patches.size()) < d.count)
        return makeError("spectral: only " + std::to_string(sel.patches.size()) + " of " + std::to_string(d.count) + " " + std::to_string(d.patch) +
                         "-px patches of '" + s.path + "' are usable: " + rejectionText(s, sel, d.accept, minDistance));
    return sel;
}

splatfx::Result<Selection> pickPath(const Source& s, const PathDesc& d) {
    if (d.points.size() < 2) return makeError("path: --path needs at least 2 points, got " + std::to_string(d.points.size()));
    if (auto st = checkPatchFits(s, d.patch, "--patch"); !st) return makeError(st.error());
    if (!(d.step > 0.0)) return makeError("path: --step must be greater than 0 pixels, got " + str(d.step));
    // Every centre on the path lies between two vertices, and the centres
    // whose patch fits form a rectangle (convex), so checking the vertices
    // checks the whole path.
    const double lo = 0.5 * d.patch, hiX = s.width - 0.5 * d.patch, hiY = s.height - 0.5 * d.patch;
    for (size_t i = 0; i < d.points.size(); ++i) {
        const cv::Point2d q = d.points[i];
        if (!(q.x >= lo && q.x <= hiX && q.y >= lo && q.y <= hiY))
            return makeError("path: point " + std::to_string(i + 1) + " (" + str(q.x) + ", " + str(q.y) + ") leaves the " + std::to_string(s.width) +
                             "x" + std::to_string(s.height) + " image '" + s.path + "': a " + std::to_string(d.patch) +
                             "-px patch needs its centre within [" + str(lo) + ", " + str(hiX) + "] x [" + str(lo) + ", " + str(hiY) + "]");
    }
    std::vector<double> along{0.0};
    for (size_t i = 1; i < d.points.size(); ++i) along.push_back(along.back() + cv::norm(d.points[i] - d.points[i - 1]));
    const double length = along.back();
    const double fitReal = std::floor(length / d.step + 1e-9) + 1.0;
    if (d.count <= 0 && fitReal > kMaxTextures)
        return makeError("path: --step " + str(d.step) + " along a path " + str(length) + " px long gives " + str(fitReal) +
                         " patches, more than the " + std::to_string(kMaxTextures) + " a texture set may hold; raise --step or give --count");
    const int fit = int(std::min(fitReal, double(std::numeric_limits<int>::max())));
    const int count = d.count > 0 ? d.count : fit;
    if (count > fit)
        return makeError("path: " + std::to_string(count) + " patches " + str(d.step) + " px apart need a path " + str((count - 1) * d.step) +
                         " px long, but the path is " + str(length) + " px; lower --count or --step, or lengthen --path");
    Selection sel;
    size_t seg = 1;
    for (int k = 0; k < count; ++k) {
        const double t = k * d.step;
        while (seg + 1 < along.size() && t > along[seg]) ++seg;
        const double segLen = along[seg] - along[seg - 1];
        const double u = segLen > 0.0 ? std::clamp((t - along[seg - 1]) / segLen, 0.0, 1.0) : 0.0;
        const cv::Point2d c = d.points[seg - 1] + u * (d.points[seg] - d.points[seg - 1]);
        const Patch p{int(std::lround(c.x - 0.5 * d.patch)), int(std::lround(c.y - 0.5 * d.patch)), d.patch};
        sel.patches.push_back(p);
        sel.stats.push_back(analyze(s, p));
        ++sel.candidates;
    }
    return sel;
}

// [SECTION] Parsing

splatfx::Result<cv::Point2d> parsePoint(const std::string& text, const std::string& option) {
    double x = 0, y = 0;
    char comma = 0, extra = 0;
    std::istringstream in(text);
    if (!(in >> x >> comma >> y) || comma != ',' || (in >> extra) || !std::isfinite(x) || !std::isfinite(y))
        return makeError(option + " expects X,Y in pixels, got '" + text + "'");
    return cv::Point2d(x, y);
}

splatfx::Result<std::vector<cv::Point2d>> parsePath(const std::string& text, const std::string& option) {
    std::vector<cv::Point2d> pts;
    std::string part;
    std::istringstream in(text);
    while (std::getline(in, part, ':')) {
        auto p = parsePoint(part, option);
        if (!p) return makeError(option + " expects X,Y:X,Y[:X,Y...], got '" + text + "' ('" + part + "' is not X,Y)");
        pts.push_back(*p);
    }
    if (pts.size() < 2) return makeError(option + " needs at least 2 points X,Y:X,Y, got '" + text + "'");
    return pts;
}

std::string baseName(const std::string& path) { return fs::path(path).filename().string(); }

} // namespace texpick
