// Every light casts, on the GPU (issue 27 item 1): a Scene with a sun and a
// torch fills two slots of Frame::shadows(); FrameRenderer binds both, and a
// host ground shader with shadowGlsl() reads each light's transmittance with
// splatfx_shadowTo(light, p), matching each light's CPU ShadowTable.
#include <algorithm>
#include <cmath>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "gl_fixture.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

const char* kVertex = R"(#version 450 core
uniform mat4 uViewProj;
uniform float uHalf;
out vec3 vWorldPos;
void main() {
    vec2 c = vec2((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0) * uHalf;
    vWorldPos = vec3(c.x, 0.0, c.y);
    gl_Position = uViewProj * vec4(vWorldPos, 1.0);
}
)";
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
Camera topDown() {
    const glm::mat4 view = glm::lookAt(glm::vec3(0, 10, 0), glm::vec3(0), glm::vec3(0, 0, -1));
    const glm::mat4 proj = glm::ortho(-kHalfX, kHalfX, -kHalfZ, kHalfZ, 0.1f, 100.0f);
    return Camera::fromMatrices(view, proj, {kW, kH});
}

class ShadowLightsGL : public test::GLTest {};

} // namespace

TEST_F(ShadowLightsGL, ASunAndATorchCastTwoShadowsEachAsItsTableSays) {
    Materials materials{Footprint{}};
    const std::uint32_t row = materials.addColorTable(ColorTable::constant({0.8f, 0.8f, 0.8f, 1.0f}));
    Scene scene;
    Grid g = test::gaussianBlob(12, 0.2f, 0.9f);
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-1.1f, 1.5f, -1.1f));
    EffectDesc desc;
    desc.layers = {EffectLayer{.style = {.colorTable = row, .textured = false}}};
    scene.add(*Effect::fromGrid(g, desc), {.name = "gas", .lighting = {.enabled = true, .selfShadow = SelfShadow::Off}});
    const Light sun = Light::directional({0.3f, -1.0f, 0.2f});
    const Light torch = Light::point({2.5f, 4.5f, 0.0f}, {1.0f, 0.6f, 0.3f}, 6.0f);
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
    auto prog = gl::linkProgram({kVertex}, {"#version 450 core\n", include.c_str(), kFragmentBody}, "ground");
    ASSERT_TRUE(prog) << prog.error();
    auto fb = gl::Framebuffer::create({.width = kW, .height = kH, .color = gl::Precision::F32});
    ASSERT_TRUE(fb);
    const Camera cam = topDown();
    const glm::mat4 vp = cam.proj * cam.view;
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    gl::ShadowBinding binding;
    // The host draws only its ground: no splats (the gas is drawn too, but after the opaque hook;
    // the image is read from the hook's own target below).
    Frame groundOnly;
    groundOnly.begin(0.0, cam);
    groundOnly.end();
    for (std::size_t k = 0; k < frame.shadows().size(); ++k) groundOnly.shadows()[k] = frame.shadows()[k];
    fr->render(groundOnly, {.framebuffer = fb->handle(), .drawOpaque = [&] {
                                glClearColor(0, 0, 0, 1);
                                glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                                glDisable(GL_BLEND);
                                glDisable(GL_DEPTH_TEST);
                                glUseProgram(*prog);
                                binding = fr->shadowBinding();
                                gl::setShadowUniforms(*prog, binding);
                                glUniformMatrix4fv(glGetUniformLocation(*prog, "uViewProj"), 1, GL_FALSE, glm::value_ptr(vp));
                                glUniform1f(glGetUniformLocation(*prog, "uHalf"), 8.0f);
                                glBindVertexArray(vao);
                                glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
                                glBindVertexArray(0);
                                glUseProgram(0);
                            }});
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(*prog);
    const Image image = fb->read();
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
    const glm::mat4 inv = glm::inverse(vp);
    float worstSun = 0.0f, worstTorch = 0.0f, darkSun = 1.0f, darkTorch = 1.0f;
    glm::vec3 atSun(0.0f), atTorch(0.0f);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const glm::vec4 ndc((x + 0.5f) / kW * 2.0f - 1.0f, 1.0f - (y + 0.5f) / kH * 2.0f, 0.0f, 1.0f);
            const glm::vec4 w = inv * ndc;
            const glm::vec3 world(w.x / w.w, 0.0f, w.z / w.w);
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
