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
    void SetUp() override;
};

// Folder for actual/diff images of failing comparisons: <build>/test-output/<suite>.<test>/
std::string outputDir();
// A file under the source tree (e.g. "tests/golden/campfire.png").
std::string sourcePath(const std::string& relative);

} // namespace splatfx::test
