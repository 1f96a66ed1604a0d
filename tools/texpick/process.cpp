// texpick: patches to textures (resampling, grayscale, contrast, window) and ordering for smooth cycling.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "texpick.hpp"

namespace texpick {

using splatfx::makeError;

splatfx::Result<MadeSet> makeSet(const Source& s, const std::vector<Patch>& patches, const ProcessDesc& d) {
    if (patches.empty()) return makeError("no patches to make a texture set from");
    if (d.textureSize < 4 || d.textureSize > 1024) return makeError("--size must be between 4 and 1024 texels, got " + std::to_string(d.textureSize));
    // saveTextureSet writes a windowed colour set as RGBA PNG; reading that
    // back premultiplies colour by alpha (OpenImageIO's default for PNG) and
    // loadTextureSet multiplies again, so such a set would not load as made.
    if (d.window && d.color)
        return makeError("--window with --color is not supported: texture-set version 1 cannot store a windowed colour "
                         "set faithfully; leave out --window (the renderer windows the set with the same footprint)");
    if (!(d.contrastStd > 0.0f && d.contrastStd <= 0.5f))
        return makeError("--contrast-std must be in (0, 0.5], got " + std::to_string(d.contrastStd));
    // Each patch cut and resampled to the texture size: area averaging when
    // shrinking (no aliasing of the photo's fine grain), bilinear when growing.
    std::vector<cv::Mat> rgb;
    for (size_t i = 0; i < patches.size(); ++i) {
        const Patch& p = patches[i];
        if (p.x < 0 || p.y < 0 || p.size < 1 || p.x + p.size > s.width || p.y + p.size > s.height)
            return makeError("patch " + std::to_string(i + 1) + " (" + std::to_string(p.size) + " px at " + std::to_string(p.x) + ", " +
                             std::to_string(p.y) + ") leaves the " + std::to_string(s.width) + "x" + std::to_string(s.height) + " image");
        cv::Mat cut = s.rgb(cv::Rect(p.x, p.y, p.size, p.size)).clone();
        if (p.size != d.textureSize)
            cv::resize(cut, cut, cv::Size(d.textureSize, d.textureSize), 0, 0, p.size > d.textureSize ? cv::INTER_AREA : cv::INTER_LINEAR);
        rgb.push_back(cut);
    }
    auto lum = [](const cv::Vec3f& v) { return 0.2126f * v[0] + 0.7152f * v[1] + 0.0722f * v[2]; };
    auto meanStd = [&](const std::vector<const cv::Mat*>& mats) {
        double sum = 0.0, sum2 = 0.0, n = 0.0;
        for (const cv::Mat* m : mats)
            for (auto it = m->begin<cv::Vec3f>(); it != m->end<cv::Vec3f>(); ++it) {
                const double l = lum(*it);
                sum += l;
                sum2 += l * l;
                n += 1.0;
            }
        const double mean = sum / n;
        return std::pair<double, double>(mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean)));
    };
    // Contrast normalization is one affine map of luminance per patch (or per
    // set), applied to R, G and B alike so colour patches keep their hue.
    std::vector<std::pair<double, double>> affine(rgb.size(), {0.0, 1.0}); // offset, gain
    if (d.contrast != Contrast::None) {
        std::vector<const cv::Mat*> all;
        for (const cv::Mat& m : rgb) all.push_back(&m);
        const auto setStats = meanStd(all);
        for (size_t i = 0; i < rgb.size(); ++i) {
            const auto [mean, dev] = d.contrast == Contrast::Set ? setStats : meanStd({&rgb[i]});
            // A flat patch (no deviation) stays flat at the target mean.
            const double gain = dev > 1e-6 ? d.contrastStd / dev : 0.0;
            affine[i] = {0.5 - gain * mean, gain};
        }
    }
    std::vector<splatfx::Image> images;
    for (size_t i = 0; i < rgb.size(); ++i) {
        splatfx::Image im;
        im.width = im.height = d.textureSize;
        im.channels = 3;
        im.pixels.resize(size_t(d.textureSize) * d.textureSize * 3);
        for (int y = 0; y < d.textureSize; ++y)
            for (int x = 0; x < d.textureSize; ++x) {
                const cv::Vec3f v = rgb[i].at<cv::Vec3f>(y, x);
                for (int c = 0; c < 3; ++c) im.at(x, y, c) = float(std::clamp(affine[i].first + affine[i].second * v[c], 0.0, 1.0));
            }
        images.push_back(std::move(im));
    }
    // fromImages converts to grayscale (Rec. 709 luminance) unless colour is kept.
    auto set = splatfx::TextureSet::fromImages(images, d.color);
    if (!set) return makeError(set.error());
    MadeSet made;
    made.order.resize(patches.size());
    std::iota(made.order.begin(), made.order.end(), 0);
    if (d.order && set->count() > 2) {
        made.order = smoothCycle(*set);
        std::vector<std::vector<float>> layers;
        for (int k : made.order) layers.push_back(set->layers[size_t(k)]);
        set->layers = std::move(layers);
    }
    made.set = d.window ? set->windowed(splatfx::Footprint(d.footprint)) : std::move(*set);
    return made;
}

namespace {

double distance(const splatfx::TextureSet& set, int a, int b) {
    const std::vector<float>& la = set.layers[size_t(a)];
    const std::vector<float>& lb = set.layers[size_t(b)];
    double sum = 0.0;
    for (size_t i = 0; i < la.size(); ++i) sum += double(la[i] - lb[i]) * (la[i] - lb[i]);
    return sum / double(la.size());
}

} // namespace

double cycleCost(const splatfx::TextureSet& set, const std::vector<int>& order) {
    double cost = 0.0;
    for (size_t i = 0; i < order.size(); ++i) cost += distance(set, order[i], order[(i + 1) % order.size()]);
    return cost;
}

std::vector<int> smoothCycle(const splatfx::TextureSet& set) {
    const int n = set.count();
    std::vector<int> tour(size_t(std::max(n, 0)));
    std::iota(tour.begin(), tour.end(), 0);
    if (n <= 3) return tour; // every cycle through 3 or fewer textures costs the same
    std::vector<double> dist(size_t(n) * n);
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) dist[size_t(a) * n + b] = a == b ? 0.0 : distance(set, a, b);
    auto D = [&](int a, int b) { return dist[size_t(a) * n + b]; };
    // Nearest neighbour from texture 0 (ties to the lower index)...
    std::vector<bool> used(size_t(n), false);
    used[0] = true;
    for (int i = 1; i < n; ++i) {
        int best = -1;
        for (int c = 0; c < n; ++c)
            if (!used[size_t(c)] && (best < 0 || D(tour[size_t(i - 1)], c) < D(tour[size_t(i - 1)], best))) best = c;
        tour[size_t(i)] = best;
        used[size_t(best)] = true;
    }
    // ...then 2-opt: reverse tour[i..j] while that shortens the closed cycle.
    // Sets hold at most a few dozen textures, so O(n^2) sweeps are instant.
    for (bool improved = true; improved;) {
        improved = false;
        for (int i = 1; i < n - 1; ++i)
            for (int j = i + 1; j < n; ++j) {
                const int a = tour[size_t(i - 1)], b = tour[size_t(i)], c = tour[size_t(j)], e = tour[size_t((j + 1) % n)];
                if (D(a, c) + D(b, e) < D(a, b) + D(c, e) - 1e-12) {
                    std::reverse(tour.begin() + i, tour.begin() + j + 1);
                    improved = true;
                }
            }
    }
    return tour;
}

} // namespace texpick
