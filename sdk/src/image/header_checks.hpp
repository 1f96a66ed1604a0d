// Budget checks of image headers before the decoders see them (private to the
// image module).
//
// Some decoders allocate from the header when a file is opened, before a
// single pixel is asked for (all found by tools/fuzz.sh):
//  - OpenEXR sizes its chunk-offset table from the data window and tile size:
//    a 300-byte file claiming 2^30 scanlines or one-pixel tiles costs
//    gigabytes. The header is walked (magic, version, then name/type/size/
//    value attributes per part) and the claimed pixels and chunks checked.
//  - OpenImageIO's GIF reader allocates its canvas from the logical screen
//    size: a 68-byte GIF claiming 25964x19827 costs 2 GB. The screen and every
//    image descriptor are checked.
//  - OpenImageIO's BMP reader decodes run-length images when the file is
//    opened, into a buffer sized from the header: an 87-byte BMP claiming
//    RLE8 data at 24 bits a pixel threw std::length_error through open. The
//    size and the compression's pixel depth are checked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "splatfx/result.hpp"

namespace splatfx::detail {

// Most chunks (scanline blocks or tiles) an OpenEXR part may claim: 2^22
// offsets are 32 MiB of table, far above any image within kMaxImagePixels
// stored with ordinary block sizes.
inline constexpr std::uint64_t kMaxExrChunks = 1ull << 22;

bool looksLikeExr(const unsigned char* head, std::size_t size);
// OK for a file that is neither OpenEXR, BMP nor GIF (the decoders judge it), or
// one whose header's claims are within the budgets; otherwise why not.
Status checkImageHeader(const std::string& path);

} // namespace splatfx::detail
