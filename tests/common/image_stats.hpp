// Extremes of images, for tests that bound a whole image by one number.
#pragma once

#include <algorithm>
#include <cmath>

#include "splatfx/image.hpp"

namespace splatfx::test {

// The largest value of channels [first, first + count) over the image.
inline double maxChannels(const Image& img, int first, int count) {
    double m = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = first; c < first + count; ++c) m = std::max(m, double(img.at(x, y, c)));
    return m;
}
inline double maxRgb(const Image& img) { return maxChannels(img, 0, 3); }
inline double maxAlpha(const Image& img) { return maxChannels(img, 3, 1); }

// The largest |a - scaleB b| over the first `channels` channels (a and b of one size).
inline double maxDiff(const Image& a, const Image& b, int channels = 3, double scaleB = 1.0) {
    double m = 0.0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < channels; ++c) m = std::max(m, std::abs(double(a.at(x, y, c)) - scaleB * double(b.at(x, y, c))));
    return m;
}

} // namespace splatfx::test
