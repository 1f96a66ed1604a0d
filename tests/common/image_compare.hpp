// Image comparison for golden-image tests: max and mean absolute difference,
// and the fraction of pixels that differ by more than a threshold.
#pragma once

#include <string>

#include "splatfx/image.hpp"
#include "splatfx/result.hpp"

namespace splatfx::test {

struct ImageDiff {
    bool sameSize = false;
    double maxAbs = 0.0;       // largest per-channel difference, [0, 1]
    double meanAbs = 0.0;      // mean per-channel difference, [0, 1]
    double fractionOver = 0.0; // fraction of pixels with any channel over `threshold`
    Image diff;                // |a - b| per channel, amplified x8 for viewing
};

ImageDiff compareImages(const Image& actual, const Image& expected, double threshold);

// A golden image's tolerances, kept as data beside it (tests/golden/<name>.json,
// whose "why" explains each one). All values in 8-bit steps except the fraction.
struct GoldenThresholds {
    double pixelThreshold = 0.0;  // a pixel "differs" beyond this, [0, 1]
    double meanMax = 0.0;         // largest allowed mean difference, [0, 1]
    double fractionOverMax = 0.0; // largest allowed fraction of differing pixels
    double maxAbs = 0.0;          // largest allowed single difference, [0, 1]
};
// Reads the thresholds file; an error names the file and the missing field.
Result<GoldenThresholds> loadGoldenThresholds(const std::string& path);
// True when the difference is within the thresholds.
bool withinThresholds(const ImageDiff& diff, const GoldenThresholds& t);
// Writes actual.png and diff.png into outputDir(); returns a line naming them.
std::string writeFailureImages(const Image& actual, const ImageDiff& diff);

} // namespace splatfx::test
