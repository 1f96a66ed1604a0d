// splatfx/image_io.hpp: float images in and out of files (OpenImageIO, splatfx::io).
//
// Reads anything OpenImageIO reads; writes PNG (8-bit) or EXR/TIFF by
// extension. Writes are checked and atomic: every write, the fsync and the
// close are checked (a full disk is an error, not a truncated file), the file
// is written under a temporary name beside the target and renamed into place
// only when complete, so it appears complete or not at all and a previous
// file of that name survives a failure. It does not resize or colour-manage.
// The Image struct itself is plain data in splatfx/image.hpp (splatfx::core).
//
//   auto img = splatfx::readImage("photo.jpg");
//   if (!img) return fail(img.error());
//   splatfx::writeImage("out/frame.png", *img);
//
// Threading: free functions; safe from any thread on distinct files.
#pragma once

#include <memory>
#include <string>

#include "splatfx/image.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

// Budgets checked before anything is decoded.
inline constexpr int kMaxImageSide = 16384;                          // pixels on a side
inline constexpr long long kMaxImagePixels = 1ll << 26;              // 8192x8192: 1 GiB as float RGBA
inline constexpr unsigned long long kMaxImageFileBytes = 1ull << 30; // 1 GiB of file

// Fails with the file name and the reason: missing, a symbolic-link loop, not
// a regular file (FIFOs and devices are never read: they could block or never
// end), empty, over kMaxImageFileBytes, unreadable, more than kMaxImageSide
// pixels on a side or more than kMaxImagePixels in all (a few hundred bytes
// of header can claim any size). Only the first four channels are decoded.
Result<Image> readImage(const std::string& path, Alpha alpha = Alpha::Premultiplied);

// What an image file says about itself, from its header alone (nothing is
// decoded): to check a budget before reading. Same file checks as readImage.
struct ImageInfo {
    int width = 0, height = 0, channels = 0;
};
Result<ImageInfo> readImageInfo(const std::string& path);
// Values are clamped to [0, 1] for 8-bit formats (NaN becomes 0).
Status writeImage(const std::string& path, const Image& image, Alpha alpha = Alpha::Premultiplied);
// Any other file (a manifest, a record of outputs) with the same guarantees.
Status writeFileAtomically(const std::string& path, const std::string& bytes);

// Writes frames into one animated GIF (looping), through OpenImageIO,
// streamed: each frame is encoded as it is added (8-bit RGB), so memory does
// not grow with the number of frames. The file is written under a temporary
// name and renamed into place by finish(); a writer destroyed before finish()
// (a failed run) removes it, so no partial GIF is ever left at the target.
// Move-only.
class AnimationWriter {
public:
    // framesPerSecond in [1/600, 100]: a GIF's frame delay is a whole number of
    // hundredths of a second, from 1 to 65535 (add() reports a rate outside).
    explicit AnimationWriter(std::string path, double framesPerSecond = 24.0);
    AnimationWriter(AnimationWriter&&) noexcept;
    AnimationWriter& operator=(AnimationWriter&&) noexcept;
    ~AnimationWriter();
    // Expects every frame to have the first frame's size. Uses RGB only.
    Status add(const Image& frame);
    Status finish();
    int frames() const;

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

} // namespace splatfx
