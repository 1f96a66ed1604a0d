// A budget check of OpenEXR headers before OpenEXR sees them (private to the
// image module).
//
// OpenEXR sizes its chunk-offset table from the header's data window and tile
// size when a file is opened, before a single pixel is asked for: a 300-byte
// file claiming 2^30 scanlines or one-pixel tiles makes it allocate gigabytes
// (found by tools/fuzz.sh). So the header is walked here first (magic,
// version, then name/type/size/value attributes per part) and the claimed
// pixel and chunk counts are checked against the image budgets.
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
// OK for a file that is not OpenEXR (the decoders judge it), or an OpenEXR
// file whose every part is within the budgets; otherwise why not.
Status checkExrHeader(const std::string& path);

} // namespace splatfx::detail
