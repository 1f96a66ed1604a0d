// Reading images refuses what could hang or exhaust memory (issue 13), with
// messages naming the file and the reason.
#include <cstdint>
#include <filesystem>
#include <fstream>

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/texture_set_io.hpp"

using namespace splatfx;
namespace fs = std::filesystem;

namespace {

fs::path dir() {
    const fs::path d = fs::path(test::outputDir());
    fs::create_directories(d);
    return d;
}

void expectRefused(const std::string& path, const std::string& fragment) {
    auto img = readImage(path);
    ASSERT_FALSE(img) << path;
    EXPECT_NE(img.error().find(path), std::string::npos) << img.error();
    EXPECT_NE(img.error().find(fragment), std::string::npos) << img.error();
}

// A PNG that claims width x height: a valid IHDR, then an empty IDAT and
// IEND. About 60 bytes that a decoder would take at their word.
std::string pngHeader(std::uint32_t width, std::uint32_t height) {
    std::string s("\x89PNG\r\n\x1a\n", 8);
    auto be32 = [](std::string& out, std::uint32_t v) {
        for (int i = 3; i >= 0; --i) out.push_back(char((v >> (8 * i)) & 0xff));
    };
    auto chunk = [&](const char* type, const std::string& data) {
        be32(s, std::uint32_t(data.size()));
        const std::string body = std::string(type) + data;
        s += body;
        std::uint32_t crc = 0xffffffffu; // CRC-32 over type and data
        for (unsigned char c : body) {
            crc ^= c;
            for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
        }
        be32(s, crc ^ 0xffffffffu);
    };
    std::string ihdr;
    be32(ihdr, width);
    be32(ihdr, height);
    ihdr += std::string("\x08\x02\x00\x00\x00", 5);
    chunk("IHDR", ihdr);
    chunk("IDAT", "");
    chunk("IEND", "");
    return s;
}

// The start of an OpenEXR file: magic, version flags, and a header with the
// given data window (and tiles, when tileSide > 0). A few dozen bytes that
// OpenEXR sizes its chunk table from when the file is opened.
std::string exrHeader(std::int32_t width, std::int32_t height, std::uint32_t tileSide = 0) {
    std::string s("\x76\x2f\x31\x01", 4);
    auto le32 = [](std::string& out, std::uint32_t v) {
        for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xff));
    };
    le32(s, tileSide ? 0x202u : 2u);
    auto attribute = [&](const std::string& name, const std::string& type, const std::string& value) {
        s += name + '\0' + type + '\0';
        le32(s, std::uint32_t(value.size()));
        s += value;
    };
    std::string window;
    for (std::uint32_t v : {0u, 0u, std::uint32_t(width - 1), std::uint32_t(height - 1)}) le32(window, v);
    attribute("dataWindow", "box2i", window);
    attribute("displayWindow", "box2i", window);
    if (tileSide) {
        std::string tiles;
        le32(tiles, tileSide), le32(tiles, tileSide);
        tiles.push_back('\0');
        attribute("tiles", "tiledesc", tiles);
    }
    s.push_back('\0');
    s += std::string(64, '\0'); // where the chunk table would start
    return s;
}

} // namespace

TEST(ImageRead, AFifoIsNeverOpened) {
    const std::string fifo = (dir() / "t.fifo.png").string();
    fs::remove(fifo);
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    expectRefused(fifo, "not a regular file");
}

TEST(ImageRead, ALinkToADeviceIsNeverRead) {
    const fs::path link = dir() / "zero.png";
    fs::remove(link);
    fs::create_symlink("/dev/zero", link);
    expectRefused(link.string(), "not a regular file");
}

TEST(ImageRead, ASymbolicLinkLoopIsNamed) {
    const fs::path a = dir() / "loop_a.png", b = dir() / "loop_b.png";
    fs::remove(a), fs::remove(b);
    fs::create_symlink(b, a);
    fs::create_symlink(a, b);
    expectRefused(a.string(), "symbolic links form a loop");
}

TEST(ImageRead, AHeaderClaimingHugeSidesIsRefusedBeforeDecoding) {
    const fs::path p = dir() / "huge.png";
    std::ofstream(p, std::ios::binary) << pngHeader(20000, 20000);
    auto info = readImageInfo(p.string());
    ASSERT_TRUE(info) << info.error();
    EXPECT_EQ(info->width, 20000);
    expectRefused(p.string(), "larger than 16384 on a side");
}

TEST(ImageRead, ATextureSetWhoseFirstTextureIsAFifoFailsInsteadOfHanging) {
    const fs::path set = dir() / "fifo_set";
    fs::remove_all(set);
    ASSERT_TRUE(saveTextureSet(TextureSet::turbulence({.count = 2, .size = 8}), set.string(), "{}"));
    fs::remove(set / "t000.png");
    ASSERT_EQ(mkfifo((set / "t000.png").c_str(), 0600), 0);
    auto loaded = loadTextureSet(set.string());
    ASSERT_FALSE(loaded);
    EXPECT_NE(loaded.error().find("t000.png"), std::string::npos) << loaded.error();
}

TEST(ImageRead, AHeaderClaimingTooManyPixelsIsRefusedBeforeDecoding) {
    // Within the side limit, over the pixel budget: 10000^2 float RGBA would be 1.6 GB.
    const fs::path p = dir() / "many.png";
    std::ofstream(p, std::ios::binary) << pngHeader(10000, 10000);
    expectRefused(p.string(), "over the budget of 67108864 pixels");
}

TEST(ImageRead, AnExrHeaderClaimingAHugeWindowIsRefusedBeforeOpenExrSeesIt) {
    // OpenEXR allocates its chunk table from the window when the file is
    // opened: this 120-byte file would cost gigabytes there (tools/fuzz.sh found it).
    const fs::path p = dir() / "window.exr";
    std::ofstream(p, std::ios::binary) << exrHeader(16000, 16000);
    expectRefused(p.string(), "over the image budget");
}

TEST(ImageRead, AnExrHeaderClaimingOnePixelTilesIsRefusedBeforeOpenExrSeesIt) {
    // 8192^2 is within the pixel budget, but as 1x1 tiles it is 2^26 chunks.
    const fs::path p = dir() / "tiles.exr";
    std::ofstream(p, std::ios::binary) << exrHeader(8192, 8192, 1);
    expectRefused(p.string(), "chunks, over the budget");
}

TEST(ImageRead, AnExrWithinTheBudgetsStillReads) {
    const fs::path p = dir() / "small.exr";
    Image img;
    img.width = 5, img.height = 3, img.channels = 4;
    img.pixels.assign(5 * 3 * 4, 0.25f);
    ASSERT_TRUE(writeImage(p.string(), img));
    auto back = readImage(p.string());
    ASSERT_TRUE(back) << back.error();
    EXPECT_EQ(back->width, 5);
    EXPECT_EQ(back->channels, 4);
    EXPECT_FLOAT_EQ(back->at(4, 2, 3), 0.25f);
}

TEST(ImageRead, AGifClaimingAHugeScreenIsRefusedBeforeTheDecoderSeesIt) {
    // OpenImageIO's GIF reader allocates its canvas from the logical screen
    // when the file is opened: 68 bytes claiming 25964x19827 cost 2 GB there
    // (tools/fuzz.sh found it; the input is a fuzz regression).
    const fs::path p = dir() / "screen.gif";
    std::string gif("GIF89a", 6);
    gif += std::string("\x6c\x65\x73\x4d", 4); // 25964 x 19827, little-endian
    gif += std::string("\x00\x00\x00", 3);     // no global colour table
    gif += std::string("\x3b", 1);             // trailer
    std::ofstream(p, std::ios::binary) << gif;
    expectRefused(p.string(), "GIF logical screen claims 25964x19827 pixels, over the image budget");
}

// OpenImageIO 2.4 decodes a run-length BMP when it is opened, into a buffer
// sized from the header: RLE8 runs at 24 bits a pixel threw length_error
// through open (found by tools/fuzz.sh in CI; the input is a fuzz regression).
static std::string bmpHeader(std::int32_t w, std::int32_t h, std::uint16_t bpp, std::uint32_t compression) {
    auto le = [](std::uint64_t v, int bytes) {
        std::string out;
        for (int i = 0; i < bytes; ++i) out += char((v >> (8 * i)) & 0xff);
        return out;
    };
    std::string b = "BM" + le(14 + 40 + 64, 4) + le(0, 4) + le(14 + 40, 4);
    b += le(40, 4) + le(std::uint32_t(w), 4) + le(std::uint32_t(h), 4) + le(1, 2) + le(bpp, 2) + le(compression, 4);
    b += le(0, 4) + le(2835, 4) + le(2835, 4) + le(0, 4) + le(0, 4);
    return b + std::string(64, '\0');
}

TEST(ImageRead, ABmpWhoseRunLengthDepthOrSizeIsImpossibleIsRefusedBeforeTheDecoder) {
    const fs::path rle = dir() / "rle24.bmp", huge = dir() / "huge.bmp", flat = dir() / "flat.bmp";
    std::ofstream(rle, std::ios::binary) << bmpHeader(8, 6, 24, 1);
    std::ofstream(huge, std::ios::binary) << bmpHeader(536870920, 6, 24, 0);
    std::ofstream(flat, std::ios::binary) << bmpHeader(8, 0, 24, 0);
    expectRefused(rle.string(), "BMP claims RLE8 compression with 24 bits per pixel");
    expectRefused(huge.string(), "BMP claims 536870920x6 pixels, over the image budget");
    expectRefused(flat.string(), "BMP claims 8x0 pixels");
}

// A small image of a checked format written by OpenImageIO reads back whole.
static void expectSmallImageReads(const std::string& name) {
    const fs::path p = dir() / name;
    Image img;
    img.width = 6, img.height = 4, img.channels = 3;
    img.pixels.assign(6 * 4 * 3, 1.0f);
    ASSERT_TRUE(writeImage(p.string(), img));
    auto back = readImage(p.string());
    ASSERT_TRUE(back) << back.error();
    EXPECT_EQ(back->width, 6);
    EXPECT_EQ(back->height, 4);
}

TEST(ImageRead, ABmpWithinTheBudgetsStillReads) { expectSmallImageReads("small.bmp"); }

TEST(ImageRead, AGifWithinTheBudgetsStillReads) { expectSmallImageReads("small.gif"); }
