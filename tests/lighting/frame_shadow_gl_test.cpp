// The frame's shadow on host geometry (issue 16, item 4): FrameRenderer
// uploads Frame::shadow() before the opaque hook, binds it, and a host surface
// shader with shadowGlsl() (the docs/integration.md snippet) darkens the
// ground under the gas exactly as ShadowTable::transmittance says.
#include <cmath>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "gl_fixture.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// docs/integration.md, "Shadows of the gas": the host's ground shader. Keep the two in step.
const char* kVertex = R"(#version 450 core
uniform mat4 uViewProj;
uniform float uHalf;          // the ground quad: [-uHalf, uHalf]^2 at y = 0
out vec3 vWorldPos;
void main() {
    vec2 c = vec2((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0) * uHalf;
    vWorldPos = vec3(c.x, 0.0, c.y);
    gl_Position = uViewProj * vec4(vWorldPos, 1.0);
}
)";
const char* kFragmentBody = R"(
in vec3 vWorldPos;
uniform vec3 uAlbedo;
out vec4 fragColor;
void main() {
    // The sun's direct light times the gas's transmittance towards it, plus a little sky.
    float sun = splatfx_shadow(vWorldPos);
    fragColor = vec4(uAlbedo * (0.2 + 0.8 * sun), 1.0);
}
)";

// The docs' ground shader: version line + shadowGlsl() + body, built with the SDK's own helper.
GLuint groundProgram(std::string& log) {
    const std::string include = shadowGlsl();
    auto p = gl::linkProgram({kVertex}, {"#version 450 core\n", include.c_str(), kFragmentBody}, "ground");
    if (!p) return log = p.error(), 0u;
    return *p;
}

constexpr int kSize = 64;
constexpr float kHalf = 3.0f;
const glm::vec3 kAlbedo{0.9f, 0.8f, 0.7f};

// Looking straight down on the ground: pixel centres map to known world points.
Camera topDown() {
    const glm::mat4 view = glm::lookAt(glm::vec3(0, 10, 0), glm::vec3(0), glm::vec3(0, 0, -1));
    const glm::mat4 proj = glm::ortho(-kHalf, kHalf, -kHalf, kHalf, 0.1f, 100.0f);
    return Camera::fromMatrices(view, proj, {kSize, kSize});
}

// A gas blob floating 1.5 above the ground, its table for an oblique sun.
struct Shadowed {
    ShadowTable table{{.dims = glm::ivec3(32)}};
    Frame frame;
    Shadowed() {
        Grid g = test::gaussianBlob(12, 0.2f, 0.9f);
        g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-1.1f, 1.5f, -1.1f));
        auto field = DensityField::fromGrid(g);
        EXPECT_TRUE(field);
        EXPECT_TRUE(table.update(*field, Light::directional({0.3f, -1.0f, 0.2f})));
        frame.begin(0.0, topDown());
        frame.end();
        FrameShadow& s = frame.shadow(); // by hand, as a host without a Scene would
        s.valid = true;
        s.depth = table.data();
        s.dims = table.dims();
        s.worldToTable = table.worldToTable();
        s.lightInTable = table.lightInTable();
        s.version = 1;
    }
};

class FrameShadowGL : public test::GLTest {};

struct Drawn {
    Image image;
    gl::ShadowBinding binding;
};

Drawn draw(gl::FrameRenderer& fr, const Frame& frame, GLuint prog, const Camera& cam = topDown(), float half = kHalf) {
    auto fb = gl::Framebuffer::create({.width = kSize, .height = kSize, .color = gl::Precision::F32});
    EXPECT_TRUE(fb);
    const glm::mat4 vp = cam.proj * cam.view;
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    Drawn out;
    fr.render(frame, {.framebuffer = fb->handle(), .drawOpaque = [&] {
                          glClearColor(0, 0, 0, 1);
                          glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                          glDisable(GL_BLEND);
                          glDisable(GL_DEPTH_TEST);
                          glUseProgram(prog);
                          gl::setShadowUniforms(prog, fr.shadowBinding());
                          glUniformMatrix4fv(glGetUniformLocation(prog, "uViewProj"), 1, GL_FALSE, glm::value_ptr(vp));
                          glUniform1f(glGetUniformLocation(prog, "uHalf"), half);
                          glUniform3fv(glGetUniformLocation(prog, "uAlbedo"), 1, glm::value_ptr(kAlbedo));
                          glBindVertexArray(vao);
                          glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
                          glBindVertexArray(0);
                          glUseProgram(0);
                      }});
    glDeleteVertexArrays(1, &vao);
    out.image = fb->read();
    out.binding = fr.shadowBinding();
    return out;
}

} // namespace

TEST_F(FrameShadowGL, HostGroundShaderDarkensUnderTheGasAsTheTableSays) {
    std::string log;
    const GLuint prog = groundProgram(log);
    ASSERT_NE(prog, 0u) << log;
    Shadowed s;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr);
    const Drawn d = draw(*fr, s.frame, prog);
    EXPECT_TRUE(d.binding.valid);
    EXPECT_EQ(d.binding.textureUnit, 15);
    EXPECT_EQ(fr->stats().shadow.uploads, 1u);
    // Tolerance as tests/lighting/shadow_gl_test.cpp: GL may filter with 8-bit weights, an error of
    // 3/256 of the largest node step in depth, i.e. ln 2 times that in transmittance (T <= 1);
    // times 0.8 (the shader's sun share) in colour, plus float rounding.
    const float tol = 0.8f * std::log(2.0f) * 3.0f / 256.0f * test::maxNeighbourStep(s.table) + 1e-5f;
    const Camera cam = topDown();
    const glm::mat4 inv = glm::inverse(cam.proj * cam.view);
    float darkest = 1.0f, worst = 0.0f;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const glm::vec4 ndc((x + 0.5f) / kSize * 2.0f - 1.0f, 1.0f - (y + 0.5f) / kSize * 2.0f, 0.0f, 1.0f);
            glm::vec4 w = inv * ndc;
            const glm::vec3 world(w.x / w.w, 0.0f, w.z / w.w);
            const float T = s.table.transmittance(world);
            darkest = std::min(darkest, T);
            for (int c = 0; c < 3; ++c) {
                const float expected = kAlbedo[c] * (0.2f + 0.8f * T);
                worst = std::max(worst, std::abs(d.image.at(x, y, c) - expected));
            }
        }
    EXPECT_LE(worst, tol);
    EXPECT_LT(darkest, 0.6f) << "the blob should cast a visible shadow on the ground";
    // The same frame again: nothing uploaded.
    draw(*fr, s.frame, prog);
    EXPECT_EQ(fr->stats().shadow.uploads, 1u);
    glDeleteProgram(prog);
}

TEST_F(FrameShadowGL, WithoutAShadowTheIncludeReturnsOne) {
    std::string log;
    const GLuint prog = groundProgram(log);
    ASSERT_NE(prog, 0u) << log;
    Frame frame;
    frame.begin(0.0, topDown());
    frame.end();
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr);
    const Drawn d = draw(*fr, frame, prog);
    EXPECT_FALSE(d.binding.valid);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x)
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(d.image.at(x, y, c), kAlbedo[c], 1e-6f) << x << "," << y;
    glDeleteProgram(prog);
}

TEST_F(FrameShadowGL, BadShadowUnitIsRefusedByName) {
    auto fr = gl::FrameRenderer::create({.shadowTextureUnit = 16});
    ASSERT_FALSE(fr);
    EXPECT_NE(fr.error().find("shadowTextureUnit"), std::string::npos) << fr.error();
    // Slots 1 to 3 take the units below it: 2 would put slot 3 on unit -1.
    fr = gl::FrameRenderer::create({.shadowTextureUnit = 2});
    ASSERT_FALSE(fr);
    EXPECT_EQ(fr.error(), "FrameRendererDesc::shadowTextureUnit must be in [3, 15] (the other shadow slots take the units below it), got 2");
}

TEST_F(FrameShadowGL, TurningTheCameraOffACasterLeavesTheGroundsShadowInViewUnchanged) {
    // Issue 24 item 4 / issue 27: shadows are scheduled by light influence. A lit plume at height 3 to
    // 5.2 with the sun travelling along +x and down shadows the ground 3 to 5 units to its right.
    // Camera A sees the plume; camera B, turned right from the same eye, sees only its shadow.
    std::string log;
    const GLuint prog = groundProgram(log);
    ASSERT_NE(prog, 0u) << log;
    Materials materials{Footprint{}};
    const std::uint32_t row = materials.addColorTable(ColorTable::constant({0.8f, 0.8f, 0.8f, 1.0f}));
    Scene scene;
    const Light sun = Light::directional({1.0f, -1.0f, 0.0f});
    ASSERT_TRUE(scene.addLight(sun));
    Grid g = test::gaussianBlob(12, 0.2f, 0.9f);
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-4.0f, 3.0f, -1.1f));
    EffectDesc desc;
    desc.layers = {EffectLayer{.style = {.colorTable = row, .textured = false}}};
    const EffectId plume =
        scene.add(*Effect::fromGrid(g, desc), {.name = "plume", .lighting = {.enabled = true, .selfShadow = SelfShadow::Off}});
    const glm::vec3 eye(1.0f, 9.0f, 6.0f);
    const Camera a = Camera::lookAt(eye, {-1.5f, 2.0f, 0.0f}, {0, 1, 0}, glm::radians(36.0f), {kSize, kSize}, 0.1f, 100.0f);
    const Camera b = Camera::lookAt(eye, {1.5f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(36.0f), {kSize, kSize}, 0.1f, 100.0f);
    Frame frameA, frameB;
    ASSERT_TRUE(scene.prepare(0.0, a, materials, frameA));
    ASSERT_TRUE(scene.status(plume).inView);
    ASSERT_TRUE(scene.prepare(1 / 30.0, b, materials, frameB));
    ASSERT_FALSE(scene.status(plume).inView) << "camera B must not see the plume";
    ASSERT_TRUE(scene.status(plume).castsIntoView);
    ASSERT_EQ(frameB.splats().size(), 0u);
    // What camera B would see with the plume's shadow as the frame that drew the plume had it.
    Frame withCasterDrawn;
    withCasterDrawn.begin(1 / 30.0, b);
    withCasterDrawn.end();
    withCasterDrawn.shadow() = frameA.shadow();
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr);
    const Drawn turned = draw(*fr, frameB, prog, b, 20.0f);
    const Drawn reference = draw(*fr, withCasterDrawn, prog, b, 20.0f);
    ASSERT_TRUE(turned.binding.valid);
    // The same table, camera and shader: the same pixels, bit for bit (tolerance 0).
    float darkest = 1.0f;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            for (int c = 0; c < 3; ++c) ASSERT_EQ(turned.image.at(x, y, c), reference.image.at(x, y, c)) << x << "," << y;
            if (turned.image.at(x, y, 0) > 0.0f) darkest = std::min(darkest, turned.image.at(x, y, 0) / kAlbedo.r);
        }
    // The shadow is there in view (0.2 sky + 0.8 T; T < 0.6 under the plume's shadow): the test would
    // fail if the caster were dropped from the table when it left the view.
    EXPECT_LT(darkest, 0.2f + 0.8f * 0.6f);
    glDeleteProgram(prog);
}
