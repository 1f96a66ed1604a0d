// Reading images refuses what could hang or exhaust memory (issue 13), with
// messages naming the file and the reason.
#include <filesystem>
#include <fstream>

#include <sys/stat.h>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/image.hpp"
#include "splatfx/texture_set.hpp"

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
    ASSERT_TRUE(TextureSet::turbulence({.count = 2, .size = 8}).save(set.string(), "{}"));
    fs::remove(set / "t000.png");
    ASSERT_EQ(mkfifo((set / "t000.png").c_str(), 0600), 0);
    auto loaded = TextureSet::load(set.string());
    ASSERT_FALSE(loaded);
    EXPECT_NE(loaded.error().find("t000.png"), std::string::npos) << loaded.error();
}
