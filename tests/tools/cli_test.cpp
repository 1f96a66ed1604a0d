// tools/common: the strict number parser and the argument-vector spawner that
// every tool and sample uses at its command-line boundary (issue 13, items 5, 6).
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <stdexcept>

#include <gtest/gtest.h>

#include "cli.hpp"
#include "spawn.hpp"

namespace fs = std::filesystem;

TEST(CliParseInt, AcceptsWholeNumbersInRange) {
    int v = 0;
    ASSERT_TRUE(cli::parseInt("--frames", "12", 1, 100, v));
    EXPECT_EQ(v, 12);
    ASSERT_TRUE(cli::parseInt("--frames", "+7", 1, 100, v));
    EXPECT_EQ(v, 7);
    long long big = 0;
    ASSERT_TRUE(cli::parseInt("--n", "-9223372036854775808", std::numeric_limits<long long>::min(), 0ll, big));
    EXPECT_EQ(big, std::numeric_limits<long long>::min());
    std::uint32_t seed = 0;
    ASSERT_TRUE(cli::parseInt("--seed", "4294967295", 0u, 4294967295u, seed));
    EXPECT_EQ(seed, 4294967295u);
}

TEST(CliParseInt, RefusesPartialGarbageAndOutOfRangeNamingTheOption) {
    int v = 42;
    for (const char* bad : {"12abc", "", " 12", "12 ", "0x10", "1e3", "++1", "-", "1.5", "99999999999", "99999999999999999999999"}) {
        const splatfx::Status s = cli::parseInt("--frames", bad, 1, 100000, v);
        ASSERT_FALSE(s) << "'" << bad << "'";
        EXPECT_EQ(s.error(), std::string("--frames expects a whole number in [1, 100000], got '") + bad + "'" +
                                 (std::string(bad) == "99999999999999999999999" ? " (far out of range)" : ""));
    }
    EXPECT_EQ(v, 42) << "a refused value must not be stored";
    std::uint32_t seed = 5;
    EXPECT_FALSE(cli::parseInt("--seed", "-1", 0u, 4294967295u, seed)) << "no wrap-around to 4294967295";
    EXPECT_FALSE(cli::parseInt("--seed", "4294967296", 0u, 4294967295u, seed));
    EXPECT_EQ(seed, 5u);
}

TEST(CliParseReal, AcceptsFiniteNumbersInRange) {
    float f = 0.0f;
    ASSERT_TRUE(cli::parseReal("--fps", "23.976", 0.0f, 240.0f, f));
    EXPECT_FLOAT_EQ(f, 23.976f);
    double d = 0.0;
    ASSERT_TRUE(cli::parseReal("--step", "1e-3", 1e-3, 1e6, d));
    EXPECT_EQ(d, 1e-3);
}

TEST(CliParseReal, RefusesNonFiniteGarbageAndOutOfRange) {
    double d = 3.0;
    for (const char* bad : {"nan", "inf", "-inf", "1e999", "0.5x", "", " 1", "1,5", "240.0001"}) {
        const splatfx::Status s = cli::parseReal("--fps", bad, 0.0, 240.0, d);
        ASSERT_FALSE(s) << "'" << bad << "'";
        EXPECT_EQ(s.error(), std::string("--fps expects a number in [0, 240], got '") + bad + "'");
    }
    EXPECT_EQ(d, 3.0);
}

TEST(CliParseSize, ParsesWxHAndRefusesEachBadSide) {
    int w = 0, h = 0;
    ASSERT_TRUE(cli::parseSize("--size", "640x480", 16, 8192, w, h));
    EXPECT_EQ(w, 640);
    EXPECT_EQ(h, 480);
    for (const char* bad : {"100000x100000", "640x", "x480", "640x480x2", "640*480", "640x480 ", "15x480", "640x-1"}) {
        const splatfx::Status s = cli::parseSize("--size", bad, 16, 8192, w, h);
        ASSERT_FALSE(s) << bad;
        EXPECT_EQ(s.error(), std::string("--size expects WxH with each side a whole number in [16, 8192], got '") + bad + "'");
    }
    EXPECT_EQ(w, 640);
}

TEST(CliGuardedMain, ExceptionsBecomeExitCodeOne) {
    EXPECT_EQ(cli::guardedMain("t", [] { return 3; }), 3);
    EXPECT_EQ(cli::guardedMain("t", []() -> int { throw std::bad_alloc(); }), 1);
    EXPECT_EQ(cli::guardedMain("t", []() -> int { throw std::runtime_error("boom"); }), 1);
    EXPECT_EQ(cli::guardedMain("t", []() -> int { throw 7; }), 1);
}

// The shell-injection string of issue 13, passed as one argument: it must
// arrive byte for byte and nothing in it may run.
constexpr const char* kHostile = "o'; touch INJECTED; echo '$(touch INJECTED2)`touch INJECTED3`";

fs::path scratch(const char* name) {
    const fs::path dir = fs::path(SPLATFX_TEST_OUTPUT_DIR) / "cli_test" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

TEST(CliSpawn, HostileArgumentArrivesVerbatimAndDoesNotRun) {
    const fs::path dir = scratch("argument");
    auto r = cli::spawn({.argv = {"printf", "%s", kHostile}, .workingDir = dir.string(), .output = cli::ChildOutput::Capture});
    ASSERT_TRUE(r.started) << r.error;
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_EQ(r.output, kHostile);
    for (const char* f : {"INJECTED", "INJECTED2", "INJECTED3"}) EXPECT_FALSE(fs::exists(dir / f)) << f;
}

TEST(CliSpawn, HostileWorkingFolderIsEnteredNotInterpreted) {
    // The accuracy bench's plot step: gnuplot runs inside --out, whatever its name.
    const fs::path base = scratch("folder");
    const fs::path dir = base / kHostile;
    fs::create_directories(dir);
    auto r = cli::spawn({.argv = {"pwd", "-P"}, .workingDir = dir.string(), .output = cli::ChildOutput::Capture});
    ASSERT_TRUE(r.started) << r.error;
    EXPECT_EQ(r.output, fs::canonical(dir).string() + "\n");
    for (const char* f : {"INJECTED", "INJECTED2", "INJECTED3"}) {
        EXPECT_FALSE(fs::exists(base / f)) << f;
        EXPECT_FALSE(fs::exists(dir / f)) << f;
    }
}

TEST(CliSpawn, ExitCodesEnvironmentAndFailuresToStart) {
    auto fail = cli::spawn({.argv = {"false"}});
    ASSERT_TRUE(fail.started);
    EXPECT_EQ(fail.exitCode, 1);
    auto env = cli::spawn({.argv = {"printenv", "SPLATFX_SPAWN_TEST"}, .env = {"SPLATFX_SPAWN_TEST=a b;c"}, .output = cli::ChildOutput::Capture});
    ASSERT_TRUE(env.started);
    EXPECT_EQ(env.output, "a b;c\n");
    auto missing = cli::spawn({.argv = {"splatfx-no-such-program-anywhere"}});
    EXPECT_FALSE(missing.started);
    EXPECT_NE(missing.error.find("cannot run 'splatfx-no-such-program-anywhere': No such file or directory"), std::string::npos) << missing.error;
    auto noDir = cli::spawn({.argv = {"true"}, .workingDir = "/nonexistent/splatfx"});
    EXPECT_FALSE(noDir.started);
    EXPECT_NE(noDir.error.find("cannot enter folder '/nonexistent/splatfx'"), std::string::npos) << noDir.error;
    EXPECT_FALSE(cli::spawn({}).started);
}

// Farm task ranges (issue 18, item 3).
TEST(CliFrameRange, AcceptsRangesAndSteps) {
    cli::FrameRange r;
    ASSERT_TRUE(cli::parseFrameRange("--range", "8-15", 99999, r));
    EXPECT_EQ(r.first, 8);
    EXPECT_EQ(r.last, 15);
    EXPECT_EQ(r.step, 1);
    EXPECT_EQ(r.count(), 8);
    ASSERT_TRUE(cli::parseFrameRange("--range", "2-23:7", 99999, r));
    EXPECT_EQ(r.count(), 4); // 2, 9, 16, 23
    for (int i = 0; i < 30; ++i) EXPECT_EQ(r.contains(i), i == 2 || i == 9 || i == 16 || i == 23) << i;
    ASSERT_TRUE(cli::parseFrameRange("--range", "5-5", 99999, r));
    EXPECT_EQ(r.count(), 1);
    ASSERT_TRUE(cli::parseFrameRange("--range", "0-6:4", 99999, r));
    EXPECT_EQ(r.count(), 2); // 0, 4: the last index need not be on the step
    EXPECT_TRUE(cli::checkFrameRange("--range", r, 7));
}

TEST(CliFrameRange, RefusesBackwardsZeroStepGarbageAndBeyondTheSequence) {
    cli::FrameRange r{3, 4, 1};
    const std::string head = "--range expects A-B or A-B:STEP (frame indices from 0, e.g. 0-23 or 0-95:4), got ";
    EXPECT_EQ(cli::parseFrameRange("--range", "8-3", 99999, r).error(), head + "'8-3' (the last frame 3 comes before the first 8)");
    EXPECT_EQ(cli::parseFrameRange("--range", "0-7:0", 99999, r).error(), head + "'0-7:0' (STEP must be at least 1)");
    EXPECT_EQ(cli::parseFrameRange("--range", "0-100000", 99999, r).error(), head + "'0-100000' (frame indices go from 0 to 99999)");
    for (const char* bad : {"", "7", "-", "3-", "-3", "-3-5", "3-+5", "+3-5", "3-5:", "3-5:x", "3-5:-1", "a-b", "1-2-3", " 1-2", "1-2 ", "0x1-2",
                            "1.5-2", "1-2:1:1", "99999999999999999999-1"}) {
        const splatfx::Status s = cli::parseFrameRange("--range", bad, 99999, r);
        ASSERT_FALSE(s) << "'" << bad << "'";
        EXPECT_EQ(s.error().rfind(head + "'" + bad + "'", 0), 0u) << s.error();
    }
    EXPECT_EQ(r.first, 3) << "a refused range must not be stored";
    EXPECT_EQ(r.last, 4);
    const cli::FrameRange beyond{20, 30, 5};
    EXPECT_EQ(cli::checkFrameRange("--range", beyond, 24).error(), "--range 20-30:5 goes beyond the sequence: it has 24 frame(s), indices 0-23 "
                                                                   "(set the sequence's length with --frames, the same for every task)");
    EXPECT_TRUE(cli::checkFrameRange("--range", cli::FrameRange{20, 23, 1}, 24));
}
