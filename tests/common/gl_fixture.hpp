// Headless GL for tests: one EGL context per test binary, made current for every GL test.
#pragma once

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/context.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/renderer.hpp"
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

// `splats` drawn by `r` from `cam` into a new framebuffer of the viewport's
// size and colour `precision`, cleared to `bg`; the image read back.
Image drawSplats(gl::Renderer& r, const std::vector<Splat>& splats, const Camera& cam, gl::Precision precision, glm::vec4 bg);

} // namespace splatfx::test
