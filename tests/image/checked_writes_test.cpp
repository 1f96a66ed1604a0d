// Every write is checked (issue 13): a file size limit stands in for a full
// disk (both make write() fail part-way; RLIMIT_FSIZE needs no root). The
// writers must report it, leave no file at the target and keep the previous one.
#include <csignal>
#include <filesystem>
#include <fstream>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/image_io.hpp"

using namespace splatfx;
namespace fs = std::filesystem;

namespace {

Image noise(int w, int h) {
    Image img{w, h, 3, {}};
    img.pixels.resize(std::size_t(w) * h * 3);
    std::uint32_t x = 12345;
    for (float& v : img.pixels) {
        x = x * 1664525u + 1013904223u;
        v = float(x >> 8) / float(1u << 24); // incompressible: the PNG is about as large as the pixels
    }
    return img;
}

// Runs `body` in a child whose files may not grow past `limitBytes`; returns
// the child's exit code (body's return), or -1 if it crashed.
template <class Body>
int withFileSizeLimit(rlim_t limitBytes, Body body) {
    const pid_t pid = fork();
    if (pid == 0) {
        std::signal(SIGXFSZ, SIG_IGN); // write() then fails with EFBIG instead of killing us
        rlimit r{limitBytes, limitBytes};
        setrlimit(RLIMIT_FSIZE, &r);
        _exit(body());
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

} // namespace

TEST(CheckedWrites, AFailedImageWriteIsAnErrorAndKeepsThePreviousFile) {
    const fs::path dir = fs::path(test::outputDir());
    fs::create_directories(dir);
    const std::string path = (dir / "frame.png").string();
    ASSERT_TRUE(writeImage(path, noise(16, 16)));
    const auto before = fs::file_size(path);
    const int rc = withFileSizeLimit(64 * 1024, [&] {
        const Status s = writeImage(path, noise(512, 512)); // ~770 KB of PNG, past the 64 KB limit
        if (s) return 1;                                    // reported success: the bug
        return s.error().find("frame") != std::string::npos && s.error().find("File too large") != std::string::npos ? 0 : 2;
    });
    EXPECT_EQ(rc, 0) << "1: a truncated write was reported as success; 2: the message names neither the file nor the reason";
    EXPECT_EQ(fs::file_size(path), before) << "the previous file must survive";
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << "temporary left: " << e.path();
}

TEST(CheckedWrites, AFailedAnimationLeavesNoGif) {
    const fs::path dir = fs::path(test::outputDir());
    fs::create_directories(dir);
    const std::string path = (dir / "anim.gif").string();
    const int rc = withFileSizeLimit(32 * 1024, [&] {
        AnimationWriter gif(path, 12.0);
        for (int i = 0; i < 8; ++i)
            if (!gif.add(noise(128, 128))) return 0; // reported while streaming: fine
        return gif.finish() ? 1 : 0;                 // or at the end; success would be the bug
    });
    EXPECT_EQ(rc, 0) << "a GIF past the size limit was reported as written";
    EXPECT_FALSE(fs::exists(path));
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << "temporary left: " << e.path();
}

TEST(CheckedWrites, AGifShowsItsRealRateEvenBelowOneFramePerSecond) {
    const std::string path = (fs::path(test::outputDir()) / "slow.gif").string();
    fs::create_directories(test::outputDir());
    AnimationWriter gif(path, 0.5); // 2 s per frame: an integer rate would have made the delay 0
    ASSERT_TRUE(gif.add(noise(8, 8)));
    ASSERT_TRUE(gif.add(noise(8, 8)));
    ASSERT_TRUE(gif.finish());
    // The GIF graphic control extension (21 F9 04 flags delayLo delayHi ...) holds the delay in 1/100 s.
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const std::size_t gce = bytes.find("\x21\xF9\x04");
    ASSERT_NE(gce, std::string::npos);
    const int delay = (unsigned char)bytes[gce + 4] | ((unsigned char)bytes[gce + 5] << 8);
    EXPECT_EQ(delay, 200);
}

TEST(CheckedWrites, ARateAGifCannotShowIsRefused) {
    AnimationWriter gif((fs::path(test::outputDir()) / "fast.gif").string(), 1000.0);
    const Status s = gif.add(noise(8, 8));
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("frames per second"), std::string::npos) << s.error();
}
