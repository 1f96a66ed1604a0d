#include "splatfx/texture_set.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "noise.hpp"

// The in-memory and procedural parts of TextureSet. Folder load/save read and
// write images, so they are in splatfx::io (sdk/src/image/texture_set_folder.cpp).
namespace splatfx {

namespace {

constexpr double kTwoPi = 6.28318530717958647692;
constexpr int kMinSize = 4, kMaxSize = 1024;

float luminance(const float* p) { return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; }

std::vector<float> blankLayer(int size) { return std::vector<float>(size_t(size) * size * 4, 1.0f); }

} // namespace

TextureSet TextureSet::turbulence(const TurbulenceDesc& d) {
    assert(d.count >= 1 && d.size >= kMinSize && d.octaves >= 1 && d.contrast > 0.0f);
    detail::Noise4 noise(d.seed);
    TextureSet set;
    set.size = d.size;
    std::vector<std::vector<double>> raw(size_t(d.count), std::vector<double>(size_t(d.size) * d.size));
    double lo = 1e30, hi = -1e30;
    for (int k = 0; k < d.count; ++k) {
        // Texture k sits at angle 2 pi k / count on a circle in the (z, w)
        // plane of the noise: consecutive textures are close, and the last
        // leads smoothly back to the first.
        const double a = kTwoPi * k / d.count;
        const double z0 = 17.31 + d.loopRadius * std::cos(a), w0 = 5.77 + d.loopRadius * std::sin(a);
        for (int y = 0; y < d.size; ++y)
            for (int x = 0; x < d.size; ++x) {
                double sum = 0.0, amp = 1.0, f = d.baseFrequency;
                for (int o = 0; o < d.octaves; ++o) {
                    // Perlin 1985 turbulence: sum of |noise| over octaves, each half as strong.
                    // Each octave walks its own loop (offset, same radius) so fine
                    // detail stays as coherent from texture to texture as coarse detail.
                    sum += amp * std::abs(noise(f * x / d.size, f * y / d.size, z0 + 31.7 * o, w0 + 11.3 * o));
                    amp *= 0.5;
                    f *= 2.0;
                }
                raw[size_t(k)][size_t(y) * d.size + x] = sum;
                lo = std::min(lo, sum);
                hi = std::max(hi, sum);
            }
    }
    // One normalization for the whole set so cycling does not flicker.
    const double scale = hi > lo ? 1.0 / (hi - lo) : 0.0;
    for (int k = 0; k < d.count; ++k) {
        std::vector<float> layer = blankLayer(d.size);
        for (size_t i = 0; i < raw[size_t(k)].size(); ++i) {
            const float v = float(std::pow((raw[size_t(k)][i] - lo) * scale, double(d.contrast)));
            layer[i * 4 + 0] = layer[i * 4 + 1] = layer[i * 4 + 2] = v;
        }
        set.layers.push_back(std::move(layer));
    }
    return set;
}

Result<TextureSet> TextureSet::fromImages(const std::vector<Image>& images, bool keepColor) {
    if (images.empty()) return makeError("a texture set needs at least one image");
    TextureSet set;
    set.color = keepColor;
    set.size = images[0].width;
    for (size_t i = 0; i < images.size(); ++i) {
        const Image& img = images[i];
        if (img.width != img.height)
            return makeError("texture " + std::to_string(i) + " is " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                             "; textures must be square");
        if (img.width != set.size)
            return makeError("texture " + std::to_string(i) + " is " + std::to_string(img.width) + " texels wide but texture 0 is " +
                             std::to_string(set.size) + "; all must match");
        if (img.width < kMinSize || img.width > kMaxSize)
            return makeError("texture " + std::to_string(i) + " size " + std::to_string(img.width) + " is outside [" + std::to_string(kMinSize) +
                             ", " + std::to_string(kMaxSize) + "]");
        std::vector<float> layer = blankLayer(set.size);
        for (int p = 0; p < set.size * set.size; ++p) {
            float rgb[3];
            for (int c = 0; c < 3; ++c) rgb[c] = img.pixels[size_t(p) * img.channels + size_t(std::min(c, img.channels - 1))];
            // An image alpha channel is kept as coverage: the patch is only detail where it is opaque.
            const float a = img.channels == 4 ? img.pixels[size_t(p) * 4 + 3] : 1.0f;
            for (int c = 0; c < 3; ++c) {
                const float v = keepColor ? rgb[c] : luminance(rgb);
                layer[size_t(p) * 4 + c] = std::isfinite(v) ? std::clamp(v * a, 0.0f, 1.0f) : 0.0f;
            }
        }
        set.layers.push_back(std::move(layer));
    }
    return set;
}

TextureSet TextureSet::windowed(const Footprint& footprint) const {
    TextureSet out = *this;
    if (isWindowed) return out;
    out.isWindowed = true;
    const std::vector<float> w = footprint.image(size);
    for (auto& layer : out.layers)
        for (int p = 0; p < size * size; ++p) {
            float* t = &layer[size_t(p) * 4];
            // Figure 2: detail (luminance) times the footprint becomes the splat's opacity.
            const float detail = luminance(t) * t[3];
            if (!color) t[0] = t[1] = t[2] = 1.0f;
            t[3] = std::clamp(detail, 0.0f, 1.0f) * w[size_t(p)];
        }
    return out;
}

TextureSet TextureSet::resized(int newSize) const {
    assert(newSize >= 1);
    if (newSize == size) return *this;
    TextureSet out = *this;
    out.size = newSize;
    for (auto& layer : out.layers) {
        const std::vector<float> src = layer;
        layer.assign(size_t(newSize) * newSize * 4, 0.0f);
        // Area average when shrinking (no aliasing), bilinear when growing.
        const float ratio = float(size) / newSize;
        const int taps = std::max(1, int(std::ceil(ratio)));
        for (int y = 0; y < newSize; ++y)
            for (int x = 0; x < newSize; ++x)
                for (int c = 0; c < 4; ++c) {
                    float sum = 0.0f;
                    for (int j = 0; j < taps; ++j)
                        for (int i = 0; i < taps; ++i) {
                            const float sx = std::clamp((x + (i + 0.5f) / taps) * ratio - 0.5f, 0.0f, float(size - 1));
                            const float sy = std::clamp((y + (j + 0.5f) / taps) * ratio - 0.5f, 0.0f, float(size - 1));
                            const int x0 = int(sx), y0 = int(sy);
                            const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
                            const float fx = sx - x0, fy = sy - y0;
                            auto at = [&](int xx, int yy) { return src[(size_t(yy) * size + xx) * 4 + c]; };
                            sum += (at(x0, y0) * (1 - fx) + at(x1, y0) * fx) * (1 - fy) + (at(x0, y1) * (1 - fx) + at(x1, y1) * fx) * fy;
                        }
                    layer[(size_t(y) * newSize + x) * 4 + c] = sum / float(taps * taps);
                }
    }
    return out;
}

TextureSet TextureSet::footprintOnly(const Footprint& footprint, int size) {
    TextureSet set;
    set.size = size;
    set.isWindowed = true;
    const std::vector<float> w = footprint.image(size);
    std::vector<float> layer = blankLayer(size);
    for (int p = 0; p < size * size; ++p) layer[size_t(p) * 4 + 3] = w[size_t(p)];
    set.layers.push_back(std::move(layer));
    return set;
}

} // namespace splatfx
