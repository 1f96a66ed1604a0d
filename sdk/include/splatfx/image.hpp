// splatfx/image.hpp: float images in and out of files (OpenImageIO).
//
// Reads anything OpenImageIO reads; writes PNG (8-bit) or EXR/TIFF by
// extension. Writes are atomic: the file appears complete or not at all.
// It does not resize or colour-manage.
// Targets: the Image struct and Alpha are plain data used throughout
// splatfx::core; readImage, writeImage and AnimationWriter are splatfx::io.
//
//   auto img = splatfx::readImage("photo.jpg");
//   if (!img) return fail(img.error());
//   splatfx::writeImage("out/frame.png", *img);
//
// Threading: free functions; safe from any thread on distinct files.
#pragma once

#include <string>
#include <vector>

#include "splatfx/result.hpp"

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

// Fails with the file name and the reason: missing, unreadable, zero-size,
// or more than 16384 pixels on a side.
Result<Image> readImage(const std::string& path, Alpha alpha = Alpha::Premultiplied);
// Values are clamped to [0, 1] for 8-bit formats. Written to a temporary
// name beside the target and renamed into place.
Status writeImage(const std::string& path, const Image& image, Alpha alpha = Alpha::Premultiplied);

} // namespace splatfx

namespace splatfx {

// Writes frames into one animated GIF (looping), through OpenImageIO. Frames
// are kept in memory and written by finish(), so a run that fails halfway
// leaves no file behind; the file is written to a temporary name and renamed.
class AnimationWriter {
public:
    explicit AnimationWriter(std::string path, int framesPerSecond = 24);
    // Expects every frame to have the first frame's size. Uses RGB only.
    Status add(const Image& frame);
    Status finish();
    int frames() const { return static_cast<int>(mFrames.size()); }

private:
    std::string mPath;
    int mFps;
    std::vector<Image> mFrames;
};

} // namespace splatfx
