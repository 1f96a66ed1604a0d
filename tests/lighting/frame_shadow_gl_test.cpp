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
#include "ground_gl.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

// docs/integration.md, "Shadows of the gas": the host's ground shader (test::kGroundVertex and this). Keep the two in step.
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
    auto p = gl::linkProgram({test::kGroundVertex}, {"#version 450 core\n", include.c_str(), kFragmentBody}, "ground");
    if (!p) return log = p.error(), 0u;
    return *p;
}

constexpr int kSize = 64;
constexpr float kHalf = 3.0f;
const glm::vec3 kAlbedo{0.9f, 0.8f, 0.7f};

// Looking straight down on the ground: pixel centres map to known world points.
Camera topDown() { return test::topDown({kSize, kSize}, {kHalf, kHalf}); }

// A gas blob floating 1.5 above the ground, its table for an oblique sun.
struct Shadowed {
    ShadowTable table{{.dims = glm::ivec3(32)}};
    Frame frame;
    Shadowed() {
        auto field = DensityField::fromGrid(test::floatingBlob());
        EXPECT_TRUE(field);
        EXPECT_TRUE(table.update(*field, test::shadowSun()));
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

test::GroundDrawn draw(gl::FrameRenderer& fr, const Frame& frame, GLuint prog, const Camera& cam = topDown(), float half = kHalf) {
    return test::drawGround(fr, frame, prog, cam, half, [](GLuint p) { glUniform3fv(glGetUniformLocation(p, "uAlbedo"), 1, glm::value_ptr(kAlbedo)); });
}

} // namespace

TEST_F(FrameShadowGL, HostGroundShaderDarkensUnderTheGasAsTheTableSays) {
    std::string log;
    const GLuint prog = groundProgram(log);
    ASSERT_NE(prog, 0u) << log;
    Shadowed s;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr);
    const test::GroundDrawn d = draw(*fr, s.frame, prog);
    EXPECT_TRUE(d.binding.valid);
    EXPECT_EQ(d.binding.textureUnit, 15);
    EXPECT_EQ(fr->stats().shadow.uploads, 1u);
    // Tolerance as tests/lighting/shadow_gl_test.cpp: GL may filter with 8-bit weights, an error of
    // 3/256 of the largest node step in depth, i.e. ln 2 times that in transmittance (T <= 1);
    // times 0.8 (the shader's sun share) in colour, plus float rounding.
    const float tol = 0.8f * std::log(2.0f) * 3.0f / 256.0f * test::maxNeighbourStep(s.table) + 1e-5f;
    const Camera cam = topDown();
    float darkest = 1.0f, worst = 0.0f;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const glm::vec3 world = test::groundPoint(cam, x, y);
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
    const test::GroundDrawn d = draw(*fr, frame, prog);
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
    const EffectId plume = test::addLitEffect(scene, g, row, "plume", {.enabled = true, .selfShadow = SelfShadow::Off});
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
    const test::GroundDrawn turned = draw(*fr, frameB, prog, b, 20.0f);
    const test::GroundDrawn reference = draw(*fr, withCasterDrawn, prog, b, 20.0f);
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
