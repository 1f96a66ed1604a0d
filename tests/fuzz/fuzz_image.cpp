// libFuzzer target for images through the SDK's loader (splatfx::readImage,
// OpenImageIO behind it). The bytes are written to a file whose extension
// follows their magic number (so a plain PNG or JPEG input is read as one),
// then read. Any bytes must give an image or a message.
#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"
#include "splatfx/image_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using fuzz::startsWith;
    const char* ext = startsWith(data, size, "\x89PNG")                               ? ".png"
                      : startsWith(data, size, "\xFF\xD8")                            ? ".jpg"
                      : startsWith(data, size, "\x76\x2F\x31\x01")                    ? ".exr"
                      : startsWith(data, size, "GIF8")                                ? ".gif"
                      : startsWith(data, size, "BM")                                  ? ".bmp"
                      : startsWith(data, size, "II*") || startsWith(data, size, "MM") ? ".tif"
                      : startsWith(data, size, "#?")                                  ? ".hdr"
                      : startsWith(data, size, "P")                                   ? ".pnm"
                                                                                      : ".tga";
    const std::string path = fuzz::writeFile(std::string("image") + ext, data, size);
    auto img = splatfx::readImage(path);
    if (!img && img.error().empty()) __builtin_trap();
    if (img && img->pixels.size() != std::size_t(img->width) * img->height * img->channels) __builtin_trap();
    return 0;
}
