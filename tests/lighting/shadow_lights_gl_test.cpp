// Every light casts, on the GPU (issue 27 item 1): a Scene with a sun and a
// torch fills two slots of Frame::shadows(); FrameRenderer binds both, and a
// host ground shader with shadowGlsl() reads each light's transmittance with
// splatfx_shadowTo(light, p), matching each light's CPU ShadowTable.
#include <algorithm>
#include <cmath>
#include <string>

#include <epoxy/gl.h>

#include "gl_fixture.hpp"
#include "ground_gl.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// Each channel one light's transmittance: the sun (scene light 0), the torch (1), and a light
// the scene does not have (5): no table, so 1.
const char* kFragmentBody = R"(
in vec3 vWorldPos;
out vec4 fragColor;
void main() {
    fragColor = vec4(splatfx_shadowTo(0, vWorldPos), splatfx_shadowTo(1, vWorldPos), splatfx_shadowTo(5, vWorldPos), splatfx_shadow(vWorldPos));
}
)";

constexpr int kW = 64, kH = 48;
constexpr float kHalfX = 6.0f, kHalfZ = 4.5f;

// Straight down on the ground, so each pixel centre is a known world point.
Camera topDown() { return test::topDown({kW, kH}, {kHalfX, kHalfZ}); }

class ShadowLightsGL : public test::GLTest {};

} // namespace

TEST_F(ShadowLightsGL, ASunAndATorchCastTwoShadowsEachAsItsTableSays) {
    Materials materials{Footprint{}};
    const std::uint32_t row = materials.addColorTable(ColorTable::constant({0.8f, 0.8f, 0.8f, 1.0f}));
    Scene scene;
    const Grid g = test::floatingBlob();
    (void)test::addLitEffect(scene, g, row, "gas", {.enabled = true, .selfShadow = SelfShadow::Off});
    const Light sun = test::shadowSun(), torch = test::shadowTorch();
    ASSERT_TRUE(scene.addLight(sun));
    ASSERT_TRUE(scene.addLight(torch));
    scene.setSceneShadow({.dims = glm::ivec3(24)});
    Frame frame;
    ASSERT_TRUE(scene.prepare(0.0, topDown(), materials, frame));
    ASSERT_TRUE(frame.shadows()[0].valid && frame.shadows()[1].valid);

    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr);
    ASSERT_TRUE(fr->upload(materials));
    const std::string include = shadowGlsl();
    auto prog = gl::linkProgram({test::kGroundVertex}, {"#version 450 core\n", include.c_str(), kFragmentBody}, "ground");
    ASSERT_TRUE(prog) << prog.error();
    const Camera cam = topDown();
    // The host draws only its ground: no splats (the gas is drawn too, but after the opaque hook;
    // the image is read from the hook's own target below).
    Frame groundOnly;
    groundOnly.begin(0.0, cam);
    groundOnly.end();
    for (std::size_t k = 0; k < frame.shadows().size(); ++k) groundOnly.shadows()[k] = frame.shadows()[k];
    const test::GroundDrawn drawn = test::drawGround(*fr, groundOnly, *prog, cam, 8.0f);
    glDeleteProgram(*prog);
    const Image& image = drawn.image;
    const gl::ShadowBinding& binding = drawn.binding;
    EXPECT_EQ(binding.light, 0);
    EXPECT_EQ(binding.slots[0].light, 1);
    EXPECT_EQ(binding.slots[0].textureUnit, 14);
    EXPECT_EQ(binding.slots[1].light, -1) << "an empty slot names no light";
    EXPECT_EQ(fr->stats().shadow.tables, 2);

    // The CPU tables for each light over the same gas.
    auto field = DensityField::fromGrid(g);
    ASSERT_TRUE(field);
    ShadowTable tSun({.dims = glm::ivec3(24)}), tTorch({.dims = glm::ivec3(24)});
    ASSERT_TRUE(tSun.update(*field, sun));
    ASSERT_TRUE(tTorch.update(*field, torch));
    ASSERT_EQ(tSun.data(), frame.shadows()[0].depth);
    ASSERT_EQ(tTorch.data(), frame.shadows()[1].depth);
    // Tolerance as tests/lighting/shadow_gl_test.cpp: GL may filter with 8-bit weights, an error
    // of 3/256 of the largest node step in depth, i.e. ln 2 times that in transmittance (T <= 1),
    // plus float rounding; per table.
    const float tolSun = std::log(2.0f) * 3.0f / 256.0f * test::maxNeighbourStep(tSun) + 1e-5f;
    const float tolTorch = std::log(2.0f) * 3.0f / 256.0f * test::maxNeighbourStep(tTorch) + 1e-5f;
    float worstSun = 0.0f, worstTorch = 0.0f, darkSun = 1.0f, darkTorch = 1.0f;
    glm::vec3 atSun(0.0f), atTorch(0.0f);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const glm::vec3 world = test::groundPoint(cam, x, y);
            const float a = tSun.transmittance(world), b = tTorch.transmittance(world);
            worstSun = std::max(worstSun, std::abs(image.at(x, y, 0) - a));
            worstTorch = std::max(worstTorch, std::abs(image.at(x, y, 1) - b));
            ASSERT_EQ(image.at(x, y, 2), 1.0f) << "a light without a table is unshadowed";
            ASSERT_EQ(image.at(x, y, 3), image.at(x, y, 0)) << "splatfx_shadow is slot 0's light";
            if (a < darkSun) darkSun = a, atSun = world;
            if (b < darkTorch) darkTorch = b, atTorch = world;
        }
    EXPECT_LE(worstSun, tolSun);
    EXPECT_LE(worstTorch, tolTorch);
    // Two visible shadows, apart: the sun's near the gas, the torch's thrown to -x.
    EXPECT_LT(darkSun, 0.7f);
    EXPECT_LT(darkTorch, 0.7f);
    EXPECT_GT(glm::length(atSun - atTorch), 2.0f);
}
