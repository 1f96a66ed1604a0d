#include "header_checks.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <vector>

#include "splatfx/image_io.hpp"

namespace splatfx::detail {

namespace {

// Headers hold a few attributes; anything longer than this is not an image header.
constexpr std::size_t kMaxHeaderBytes = 1 << 20;

std::int32_t readInt32(const unsigned char* p) {
    std::uint32_t v = std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
    std::int32_t s;
    std::memcpy(&s, &v, 4);
    return s;
}

struct Part {
    bool hasWindow = false;
    std::int64_t width = 0, height = 0;
    std::int64_t tileX = 0, tileY = 0; // 0: scanlines
    int levelMode = 0;                 // 0 one level, 1 mipmap, 2 ripmap
    std::int64_t chunkCount = -1;      // multi-part files state it; OpenEXR trusts it
};

// Scanlines per chunk, by compression (OpenEXR's file layout); an unknown
// code counts as one line per chunk, the most chunks.
std::int64_t linesPerChunk(unsigned char compression) {
    switch (compression) {
    case 3:
    case 5: return 16; // ZIP, PXR24
    case 4:
    case 6:
    case 7:
    case 8: return 32;  // PIZ, B44, B44A, DWAA
    case 9: return 256; // DWAB
    default: return 1;  // none, RLE, ZIPS
    }
}

} // namespace

Status checkExrHeader(const std::string& path);
Status checkGifHeader(const std::string& path);
Status checkBmpHeader(const std::string& path);

bool looksLikeExr(const unsigned char* head, std::size_t size) {
    return size >= 4 && head[0] == 0x76 && head[1] == 0x2f && head[2] == 0x31 && head[3] == 0x01;
}

Status checkExrHeader(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char magic[4] = {};
    in.read(reinterpret_cast<char*>(magic), 4);
    if (!looksLikeExr(magic, std::size_t(in.gcount()))) return {}; // not OpenEXR: only four bytes read
    std::vector<unsigned char> buf(kMaxHeaderBytes);
    std::copy(magic, magic + 4, buf.begin());
    in.read(reinterpret_cast<char*>(buf.data() + 4), std::streamsize(buf.size() - 4));
    const std::size_t n = 4 + std::size_t(in.gcount());
    const std::string what = "cannot read image '" + path + "': OpenEXR header ";
    if (n < 8) return makeError(what + "is truncated");
    const std::uint32_t flags = std::uint32_t(readInt32(&buf[4]));
    const bool singleTiled = flags & 0x200, multipart = flags & 0x1000;
    std::size_t at = 8;
    auto readString = [&](std::string& out) {
        const auto end = std::find(buf.begin() + std::ptrdiff_t(at), buf.begin() + std::ptrdiff_t(n), 0);
        if (end == buf.begin() + std::ptrdiff_t(n) || end - (buf.begin() + std::ptrdiff_t(at)) > 255) return false;
        out.assign(buf.begin() + std::ptrdiff_t(at), end);
        at = std::size_t(end - buf.begin()) + 1;
        return true;
    };
    for (int partIndex = 0;; ++partIndex) {
        Part part;
        unsigned char compression = 0;
        std::string name, type;
        for (;;) {
            if (!readString(name)) return makeError(what + "does not end within " + std::to_string(kMaxHeaderBytes) + " bytes");
            if (name.empty()) break; // end of this part's header
            if (!readString(type) || at + 4 > n) return makeError(what + "is truncated in attribute '" + name + "'");
            const std::int32_t size = readInt32(&buf[at]);
            at += 4;
            if (size < 0 || at + std::size_t(size) > n) return makeError(what + "attribute '" + name + "' has a bad size");
            const unsigned char* v = &buf[at];
            if (name == "dataWindow" && type == "box2i" && size == 16) {
                const std::int64_t x0 = readInt32(v), y0 = readInt32(v + 4), x1 = readInt32(v + 8), y1 = readInt32(v + 12);
                part.hasWindow = true;
                part.width = x1 - x0 + 1;
                part.height = y1 - y0 + 1;
            } else if (name == "tiles" && type == "tiledesc" && size == 9) {
                part.tileX = std::uint32_t(readInt32(v));
                part.tileY = std::uint32_t(readInt32(v + 4));
                part.levelMode = v[8] & 0x0f;
            } else if (name == "chunkCount" && type == "int" && size == 4) {
                part.chunkCount = readInt32(v);
            } else if (name == "compression" && type == "compression" && size == 1) {
                compression = v[0];
            }
            at += std::size_t(size);
        }
        if (partIndex > 0 && !part.hasWindow && multipart) break; // the empty header closing a multi-part file
        if (!part.hasWindow) return makeError(what + "has no data window");
        const std::string partName = multipart ? "part " + std::to_string(partIndex) + " " : "";
        if (part.width <= 0 || part.height <= 0) return makeError(what + partName + "has an empty data window");
        if (part.width > kMaxImageSide || part.height > kMaxImageSide || part.width * part.height > kMaxImagePixels)
            return makeError(what + partName + "claims " + std::to_string(part.width) + "x" + std::to_string(part.height) +
                             " pixels, over the image budget (" + std::to_string(kMaxImageSide) + " on a side, " + std::to_string(kMaxImagePixels) +
                             " in all)");
        std::int64_t chunks;
        if (part.tileX > 0 || part.tileY > 0 || singleTiled) {
            if (part.tileX <= 0 || part.tileY <= 0) return makeError(what + partName + "has tiles of zero size");
            const std::int64_t tiles = ((part.width + part.tileX - 1) / part.tileX) * ((part.height + part.tileY - 1) / part.tileY);
            // Mip levels add at most a third, rip levels at most three times (geometric sums).
            chunks = part.levelMode == 0 ? tiles : part.levelMode == 1 ? tiles * 2 : tiles * 4;
        } else {
            chunks = (part.height + linesPerChunk(compression) - 1) / linesPerChunk(compression);
        }
        chunks = std::max(chunks, part.chunkCount);
        if (std::uint64_t(chunks) > kMaxExrChunks)
            return makeError(what + partName + "claims " + std::to_string(chunks) + " chunks, over the budget of " + std::to_string(kMaxExrChunks));
        if (!multipart) break;
        if (partIndex > 64) return makeError(what + "has more than 64 parts");
    }
    return {};
}

Status checkGifHeader(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<unsigned char> buf(kMaxHeaderBytes);
    in.read(reinterpret_cast<char*>(buf.data()), std::streamsize(buf.size()));
    const std::size_t n = std::size_t(in.gcount());
    // giflib (and so OpenImageIO) takes any file starting "GIF" as one, whatever follows.
    if (n < 3 || std::memcmp(buf.data(), "GIF", 3) != 0) return {};
    const std::string what = "cannot read image '" + path + "': GIF ";
    auto u16 = [&](std::size_t at) { return std::int64_t(buf[at]) | std::int64_t(buf[at + 1]) << 8; };
    auto within = [&](const char* which, std::int64_t w, std::int64_t h) -> Status {
        if (w > kMaxImageSide || h > kMaxImageSide || w * h > kMaxImagePixels)
            return makeError(what + which + " claims " + std::to_string(w) + "x" + std::to_string(h) + " pixels, over the image budget (" +
                             std::to_string(kMaxImageSide) + " on a side, " + std::to_string(kMaxImagePixels) + " in all)");
        return {};
    };
    if (n < 13) return makeError(what + "header is truncated");
    if (Status s = within("logical screen", u16(6), u16(8)); !s) return s;
    std::size_t at = 13;
    if (buf[10] & 0x80) at += 3u << ((buf[10] & 7) + 1); // global colour table
    // Walk the blocks within what was read: image descriptors state their size.
    auto skipSubBlocks = [&]() {
        while (at < n && buf[at] != 0) at += 1 + std::size_t(buf[at]);
        ++at;
    };
    while (at < n) {
        const unsigned char b = buf[at];
        if (b == 0x3B) break; // trailer
        if (b == 0x21) {      // extension: label, then sub-blocks
            at += 2;
            skipSubBlocks();
        } else if (b == 0x2C) { // image descriptor
            if (at + 10 > n) break;
            if (Status s = within("frame", u16(at + 5), u16(at + 7)); !s) return s;
            const unsigned char flags = buf[at + 9];
            at += 10;
            if (flags & 0x80) at += 3u << ((flags & 7) + 1); // local colour table
            ++at;                                            // LZW minimum code size
            skipSubBlocks();
        } else {
            break; // not a block: the decoder reports the corrupt file
        }
    }
    return {};
}

Status checkBmpHeader(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char buf[34] = {};
    in.read(reinterpret_cast<char*>(buf), std::streamsize(sizeof buf));
    const std::size_t n = std::size_t(in.gcount());
    if (n < 2 || buf[0] != 'B' || buf[1] != 'M') return {};
    const std::string what = "cannot read image '" + path + "': BMP ";
    auto u16 = [&](std::size_t at) { return std::uint32_t(buf[at]) | std::uint32_t(buf[at + 1]) << 8; };
    auto u32 = [&](std::size_t at) { return u16(at) | u16(at + 2) << 16; };
    if (n < 18) return makeError(what + "header is truncated");
    std::int64_t w = 0, h = 0;
    std::uint32_t bpp = 0, compression = 0;
    if (u32(14) == 12) { // OS/2 core header: 16-bit sizes, no compression
        if (n < 26) return makeError(what + "header is truncated");
        w = u16(18), h = u16(20), bpp = u16(24);
    } else {
        if (n < 34) return makeError(what + "header is truncated");
        w = std::int32_t(u32(18)), h = std::int32_t(u32(22)), bpp = u16(28), compression = u32(30);
    }
    const std::int64_t rows = h < 0 ? -h : h; // negative height: rows stored top down
    if (w <= 0 || rows == 0) return makeError(what + "claims " + std::to_string(w) + "x" + std::to_string(h) + " pixels");
    if (w > kMaxImageSide || rows > kMaxImageSide || w * rows > kMaxImagePixels)
        return makeError(what + "claims " + std::to_string(w) + "x" + std::to_string(rows) + " pixels, over the image budget (" +
                         std::to_string(kMaxImageSide) + " on a side, " + std::to_string(kMaxImagePixels) + " in all)");
    // Run-length data is 8 or 4 bits a pixel by definition; OpenImageIO 2.4 decodes any other
    // depth's runs into a buffer it sizes wrongly (a length_error thrown through open).
    if ((compression == 1 && bpp != 8) || (compression == 2 && bpp != 4))
        return makeError(what + "claims RLE" + std::string(compression == 1 ? "8" : "4") + " compression with " + std::to_string(bpp) +
                         " bits per pixel");
    return {};
}

Status checkImageHeader(const std::string& path) {
    if (Status s = checkExrHeader(path); !s) return s;
    if (Status s = checkBmpHeader(path); !s) return s;
    return checkGifHeader(path);
}

} // namespace splatfx::detail
