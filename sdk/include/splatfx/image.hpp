// splatfx/image.hpp: a float image in memory (plain data, splatfx::core).
//
// Float pixels (one to four channels, row-major) and how their colour relates to
// alpha. It reads and writes no files: readImage, writeImage and
// AnimationWriter are in splatfx/image_io.hpp (splatfx::io).
//
//   splatfx::Image img{.width = 2, .height = 1, .channels = 4, .pixels = std::vector<float>(8, 1.0f)};
//   img.at(1, 0, 3) = 0.5f; // the right pixel's alpha
//
// Threading: a plain value.
#pragma once

#include <cstddef>
#include <vector>

namespace splatfx {

// Row-major, top row first, channels interleaved, values nominally in [0, 1].
struct Image {
    int width = 0;
    int height = 0;
    int channels = 0;
    std::vector<float> pixels;

    float& at(int x, int y, int c) { return pixels[(static_cast<size_t>(y) * width + x) * channels + c]; }
    float at(int x, int y, int c) const { return pixels[(static_cast<size_t>(y) * width + x) * channels + c]; }
};

// How the colour of an RGBA image relates to its alpha, in memory.
enum class Alpha {
    Premultiplied, // colour already multiplied by alpha (OpenImageIO's convention; photos composite over black)
    Straight,      // colour independent of alpha (texture sets whose alpha is opacity, not coverage)
};

} // namespace splatfx
