#include "splatfx/texture_set.hpp"

#include <algorithm>
#include <cassert>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "noise.hpp"

namespace splatfx {

namespace fs = std::filesystem;
using json = nlohmann::json;

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
            return makeError("texture " + std::to_string(i) + " is " + std::to_string(img.width) + "x" +
                             std::to_string(img.height) + "; textures must be square");
        if (img.width != set.size)
            return makeError("texture " + std::to_string(i) + " is " + std::to_string(img.width) +
                             " texels wide but texture 0 is " + std::to_string(set.size) + "; all must match");
        if (img.width < kMinSize || img.width > kMaxSize)
            return makeError("texture " + std::to_string(i) + " size " + std::to_string(img.width) + " is outside [" +
                             std::to_string(kMinSize) + ", " + std::to_string(kMaxSize) + "]");
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

Result<TextureSet> TextureSet::load(const std::string& folder) {
    const fs::path dir(folder);
    const fs::path manifestPath = dir / "manifest.json";
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return makeError("texture set '" + folder + "': no such folder");
    std::ifstream in(manifestPath);
    if (!in) return makeError("texture set '" + folder + "': cannot open manifest.json");
    json m;
    try {
        m = json::parse(in);
    } catch (const json::exception& e) {
        return makeError(manifestPath.string() + ": not valid JSON (" + e.what() + ")");
    }
    const std::string where = manifestPath.string() + ": ";
    if (!m.is_object()) return makeError(where + "expected a JSON object at the top level");
    if (m.value("format", std::string()) != "splatfx-texture-set")
        return makeError(where + "field 'format' must be \"splatfx-texture-set\"");
    if (!m.contains("version") || !m["version"].is_number_integer() || m["version"].get<int>() != 1)
        return makeError(where + "field 'version' must be 1 (this build reads texture-set version 1)");
    if (!m.contains("textures") || !m["textures"].is_array() || m["textures"].empty())
        return makeError(where + "field 'textures' must be a non-empty array of image file names");
    if (m["textures"].size() > 4096) return makeError(where + "field 'textures' lists more than 4096 images");
    const bool color = m.contains("color") && m["color"].is_boolean() && m["color"].get<bool>();
    const bool windowed = m.contains("windowed") && m["windowed"].is_boolean() && m["windowed"].get<bool>();
    std::vector<Image> images;
    for (size_t i = 0; i < m["textures"].size(); ++i) {
        const json& t = m["textures"][i];
        if (!t.is_string()) return makeError(where + "textures[" + std::to_string(i) + "] must be a file name string");
        const fs::path file = dir / t.get<std::string>();
        // Windowed sets store straight colour with opacity in alpha; raw sets
        // made from photos keep alpha as coverage (composited over black).
        auto img = readImage(file.string(), windowed ? Alpha::Straight : Alpha::Premultiplied);
        if (!img) return makeError("texture set '" + folder + "': " + img.error());
        images.push_back(std::move(*img));
    }
    auto set = fromImages(images, color);
    if (!set) return makeError("texture set '" + folder + "': " + set.error());
    if (windowed) {
        // A windowed set stores the footprint-weighted detail in alpha.
        for (size_t k = 0; k < images.size(); ++k) {
            const Image& img = images[k];
            for (int p = 0; p < set->size * set->size; ++p) {
                float* t = &set->layers[k][size_t(p) * 4];
                const float a = img.channels == 4 ? img.pixels[size_t(p) * 4 + 3] : img.pixels[size_t(p) * img.channels];
                t[3] = a;
                // Alpha is opacity here, not coverage: colour stays as stored.
                for (int c = 0; c < 3; ++c)
                    t[c] = !color ? 1.0f : std::clamp(img.pixels[size_t(p) * img.channels + size_t(std::min(c, img.channels - 1))], 0.0f, 1.0f);
            }
        }
        set->isWindowed = true;
    }
    return set;
}

Status TextureSet::save(const std::string& folder, const std::string& provenanceJson) const {
    if (layers.empty()) return makeError("cannot save texture set '" + folder + "': it has no textures");
    json provenance;
    try {
        provenance = json::parse(provenanceJson);
    } catch (const json::exception& e) {
        return makeError("cannot save texture set '" + folder + "': provenance is not valid JSON (" + e.what() + ")");
    }
    const fs::path target = fs::path(folder).lexically_normal();
    const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    std::error_code ec;
    fs::create_directories(parent, ec);
    // Built with append() rather than "." + name: GCC 12 warns falsely (-Wrestrict) on the latter.
    std::string tmpName = ".";
    tmpName.append(target.filename().string()).append(".tmp-").append(std::to_string(getpid()));
    const fs::path tmp = parent / tmpName;
    fs::remove_all(tmp, ec);
    if (!fs::create_directory(tmp, ec)) return makeError("cannot create '" + tmp.string() + "': " + ec.message());
    auto fail = [&](const std::string& why) {
        fs::remove_all(tmp, ec);
        return Status(makeError("cannot save texture set '" + folder + "': " + why));
    };
    json m;
    m["format"] = "splatfx-texture-set";
    m["version"] = 1;
    m["color"] = color;
    m["windowed"] = isWindowed;
    m["size"] = size;
    m["textures"] = json::array();
    for (size_t k = 0; k < layers.size(); ++k) {
        char name[32];
        std::snprintf(name, sizeof name, "t%03zu.png", k);
        Image img;
        img.width = img.height = size;
        img.channels = isWindowed ? 4 : (color ? 3 : 1);
        img.pixels.resize(size_t(size) * size * img.channels);
        for (int p = 0; p < size * size; ++p)
            for (int c = 0; c < img.channels; ++c) {
                const float* t = &layers[k][size_t(p) * 4];
                img.pixels[size_t(p) * img.channels + c] = t[img.channels == 1 ? 0 : c];
            }
        // Windowed RGBA: alpha is opacity, colour is independent of it.
        if (Status s = writeImage((tmp / name).string(), img, Alpha::Straight); !s) return fail(s.error());
        m["textures"].push_back(name);
    }
    m["provenance"] = provenance;
    {
        std::ofstream out(tmp / "manifest.json");
        out << m.dump(2) << "\n";
        if (!out) return fail("cannot write manifest.json");
    }
    const fs::path old = parent / ("." + target.filename().string() + ".old-" + std::to_string(getpid()));
    if (fs::exists(target, ec)) {
        fs::rename(target, old, ec);
        if (ec) return fail("cannot replace the existing folder: " + ec.message());
    }
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::rename(old, target, ec);
        return fail("cannot move the finished set into place");
    }
    fs::remove_all(old, ec);
    return {};
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
