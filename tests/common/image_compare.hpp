// Image comparison for golden-image tests: max and mean absolute difference,
// and the fraction of pixels that differ by more than a threshold.
#pragma once

#include <string>

#include "splatfx/image.hpp"

namespace splatfx::test {

struct ImageDiff {
    bool sameSize = false;
    double maxAbs = 0.0;       // largest per-channel difference, [0, 1]
    double meanAbs = 0.0;      // mean per-channel difference, [0, 1]
    double fractionOver = 0.0; // fraction of pixels with any channel over `threshold`
    Image diff;                // |a - b| per channel, amplified x8 for viewing
};

ImageDiff compareImages(const Image& actual, const Image& expected, double threshold);
// Writes actual.png and diff.png into outputDir(); returns a line naming them.
std::string writeFailureImages(const Image& actual, const ImageDiff& diff);

} // namespace splatfx::test
