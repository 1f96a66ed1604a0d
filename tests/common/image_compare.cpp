#include "image_compare.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "gl_fixture.hpp"

namespace splatfx::test {

ImageDiff compareImages(const Image& a, const Image& b, double threshold) {
    ImageDiff d;
    d.sameSize = a.width == b.width && a.height == b.height && a.channels == b.channels;
    if (!d.sameSize) return d;
    d.diff = a;
    const size_t pixels = size_t(a.width) * a.height;
    size_t over = 0;
    double sum = 0.0;
    for (size_t p = 0; p < pixels; ++p) {
        bool pixelOver = false;
        for (int c = 0; c < a.channels; ++c) {
            const size_t i = p * a.channels + c;
            const double e = std::abs(double(a.pixels[i]) - double(b.pixels[i]));
            d.maxAbs = std::max(d.maxAbs, e);
            sum += e;
            pixelOver = pixelOver || e > threshold;
            d.diff.pixels[i] = c == 3 ? 1.0f : float(std::min(1.0, e * 8.0));
        }
        over += pixelOver ? 1 : 0;
    }
    d.meanAbs = sum / double(pixels * a.channels);
    d.fractionOver = double(over) / double(pixels);
    return d;
}

std::string writeFailureImages(const Image& actual, const ImageDiff& diff) {
    const std::string dir = outputDir();
    (void)writeImage(dir + "/actual.png", actual);
    if (diff.sameSize) (void)writeImage(dir + "/diff.png", diff.diff);
    return "actual and diff images written to " + dir;
}

Result<GoldenThresholds> loadGoldenThresholds(const std::string& path) {
    std::ifstream in(path);
    if (!in) return makeError(path + ": cannot open the golden thresholds");
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return makeError(path + ": not a JSON object");
    for (const char* key : {"pixelThreshold255", "meanMax255", "fractionOverMax", "maxAbs255", "why"})
        if (!j.contains(key)) return makeError(path + ": missing \"" + key + "\"");
    GoldenThresholds t;
    t.pixelThreshold = j["pixelThreshold255"].get<double>() / 255.0;
    t.meanMax = j["meanMax255"].get<double>() / 255.0;
    t.fractionOverMax = j["fractionOverMax"].get<double>();
    t.maxAbs = j["maxAbs255"].get<double>() / 255.0;
    return t;
}

bool withinThresholds(const ImageDiff& d, const GoldenThresholds& t) {
    return d.sameSize && d.meanAbs <= t.meanMax && d.fractionOver <= t.fractionOverMax && d.maxAbs <= t.maxAbs;
}

} // namespace splatfx::test
