// Headless GL for tests: one EGL context per test binary, made current for every GL test.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "splatfx/context.hpp"
#include "splatfx/splatfx.hpp"

namespace splatfx::test {

// Derive GL tests from this: SetUp() makes the shared context current (or
// fails the test with EGL's message when there is none).
class GLTest : public ::testing::Test {
protected:
    // Also clears the GL error flag, so TearDown's check blames this test only.
    void SetUp() override;
    // Fails the test if any GL call in it raised an error.
    void TearDown() override;
};

// Folder for actual/diff images of failing comparisons: <build>/test-output/<suite>.<test>/
std::string outputDir();
// A file under the source tree (e.g. "tests/golden/campfire.png").
std::string sourcePath(const std::string& relative);

} // namespace splatfx::test
