// Volumes as light on the GPU (issue 27 item 3): shadowGlsl()'s
// splatfx_emittedIrradiance, with the uniforms gl::setShadowUniforms sets
// from a gl::ShadowBinding, equals the CPU emittedIrradiance on the same lights.
#include <algorithm>
#include <cmath>
#include <span>
#include <string>

#include <epoxy/gl.h>

#include "gl_fixture.hpp"
#include "splatfx/emitted_light.hpp"
#include "splatfx/frame.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/lighting.hpp"

using namespace splatfx;

namespace {

const char* kVertex = R"(#version 450 core
void main() {
    gl_Position = vec4((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0, 0.0, 1.0);
}
)";
// Each pixel a ground point and a normal, from the pixel's index as the CPU
// side computes them (same float operations), so both evaluate the same input.
const char* kFragmentBody = R"(
uniform vec2 uSize;
out vec4 fragColor;
void main() {
    vec2 f = floor(gl_FragCoord.xy) / uSize;
    vec3 p = vec3(-3.0 + 6.0 * f.x, 0.2 * f.y, -2.0 + 4.0 * f.y);
    vec3 n = normalize(vec3(f.x - 0.5, 1.0, 0.5 - f.y));
    fragColor = vec4(splatfx_emittedIrradiance(p, n), 1.0);
}
)";

constexpr int kW = 32, kH = 24;

class EmittedLightGL : public test::GLTest {};

// One fragment per pixel of a kW x kH RGBA32F target, running shadowGlsl()
// and `body` with `binding`'s uniforms; the image read back (empty on a link
// or framebuffer failure, which is reported).
Image drawEveryPixel(const char* body, const char* label, const gl::ShadowBinding& binding) {
    const std::string include = shadowGlsl();
    auto prog = gl::linkProgram({kVertex}, {"#version 450 core\n", include.c_str(), body}, label);
    EXPECT_TRUE(prog) << prog.error();
    auto fb = gl::Framebuffer::create({.width = kW, .height = kH, .color = gl::Precision::F32});
    EXPECT_TRUE(fb);
    if (!prog || !fb) return {};
    gl::setShadowUniforms(*prog, binding);
    glProgramUniform2f(*prog, glGetUniformLocation(*prog, "uSize"), float(kW), float(kH));
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
    glViewport(0, 0, kW, kH);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(*prog);
    glBindVertexArray(vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(*prog);
    return fb->read();
}

} // namespace

TEST_F(EmittedLightGL, GlslIrradianceEqualsTheCpuOnTheSameLights) {
    // Every code path: escape shares below 1 on either side, a light with and
    // without radius, one below the ground (its light comes from behind some normals).
    std::vector<EmittedLight> lights;
    lights.push_back({.position = {0.2f, 0.6f, 0.1f}, .radius = 0.3f, .intensity = {2.0f, 1.2f, 0.4f}, .escapePlus = {0.9f, 0.5f, 0.8f},
                      .escapeMinus = {0.7f, 0.95f, 0.6f}});
    lights.push_back({.position = {-1.5f, 1.1f, 0.8f}, .radius = 0.0f, .intensity = {0.5f, 0.3f, 0.1f}});
    lights.push_back({.position = {1.0f, -0.5f, -1.0f}, .radius = 0.1f, .intensity = {0.3f, 0.2f, 0.6f}, .escapePlus = {0.4f, 1.0f, 0.2f},
                      .escapeMinus = {1.0f, 0.3f, 0.9f}});
    gl::ShadowBinding binding;
    binding.emittedLights = lights;
    const Image image = drawEveryPixel(kFragmentBody, "emitted", binding);
    ASSERT_EQ(image.width, kW);
    // GLSL 4.50 (sec. 4.7.1): +, -, * correctly rounded, division 2.5 ulp,
    // inversesqrt 2 ulp, normalize built from those; about 20 operations per
    // light, three lights summed: under 3 x 20 x 3 ulp = 2^-23 x 180 relative
    // to the largest term, which the sum of each term's magnitude bounds.
    float worst = 0.0f, lit = 0.0f;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const glm::vec2 f = glm::vec2(float(x), float(y)) / glm::vec2(kW, kH);
            const glm::vec3 p(-3.0f + 6.0f * f.x, 0.2f * f.y, -2.0f + 4.0f * f.y);
            const glm::vec3 n = glm::normalize(glm::vec3(f.x - 0.5f, 1.0f, 0.5f - f.y));
            const glm::vec3 cpu = emittedIrradiance(lights, p, n);
            // Each term's magnitude at most: its light with the normal turned towards it.
            glm::vec3 scale(0.0f);
            for (const EmittedLight& l : lights) scale += emittedIrradiance(std::span<const EmittedLight>(&l, 1), p, glm::normalize(l.position - p));
            // Fetched rows: Framebuffer::read puts the top row first.
            const int row = kH - 1 - y;
            for (int c = 0; c < 3; ++c) {
                const float tol = 180.0f * 0x1p-23f * scale[c] + 1e-30f;
                worst = std::max(worst, std::abs(image.at(x, row, c) - cpu[c]) / tol);
            }
            lit = std::max(lit, cpu.x);
        }
    EXPECT_LE(worst, 1.0f) << "largest GPU-CPU difference in units of its tolerance";
    EXPECT_GT(lit, 0.5f);
}

// The frame's lights reach the host's binding through FrameRenderer: at most
// kMaxEmittedLights of them (the brightest first, as the frame orders them),
// and none the next frame when it has none (no light lingering from the last).
TEST_F(EmittedLightGL, FrameRendererBindsTheFramesLightsAndDropsThemTheNextFrame) {
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr) << fr.error();
    Materials materials{Footprint{}};
    ASSERT_TRUE(fr->upload(materials));
    auto fb = gl::Framebuffer::create({.width = 16, .height = 16});
    ASSERT_TRUE(fb);
    const Camera cam = Camera::lookAt({0, 1, 4}, {0, 0, 0}, {0, 1, 0}, 1.0f, {16, 16});
    auto render = [&](const std::vector<EmittedLight>& lights) {
        Frame frame;
        frame.begin(0.0, cam);
        frame.end();
        frame.emittedLights() = lights;
        gl::ShadowBinding seen;
        fr->render(frame, {.framebuffer = fb->handle(), .drawOpaque = [&] { seen = fr->shadowBinding(); }});
        return seen.emittedLights;
    };
    std::vector<EmittedLight> ten;
    for (int i = 0; i < kMaxEmittedLights + 2; ++i)
        ten.push_back({.position = {float(i), 0.5f, 0.0f}, .radius = 0.1f, .intensity = glm::vec3(float(20 - i))});
    const std::vector<EmittedLight> bound = render(ten);
    ASSERT_EQ(int(bound.size()), kMaxEmittedLights);
    for (int i = 0; i < kMaxEmittedLights; ++i) EXPECT_EQ(bound[std::size_t(i)].intensity, ten[std::size_t(i)].intensity);
    EXPECT_TRUE(render({}).empty()) << "a frame without emitters binds no light";
}

namespace {

// Pixels as points from well inside to well outside the grid's box, normals
// turning through every octant.
const char* kGridFragmentBody = R"(
uniform vec2 uSize;
out vec4 fragColor;
void main() {
    vec2 f = floor(gl_FragCoord.xy) / uSize;
    vec3 p = vec3(-3.0 + 6.0 * f.x, -1.0 + 3.0 * f.y, 1.5 - 3.0 * f.x * f.y);
    vec3 n = normalize(vec3(f.x - 0.45, 0.55 - f.y, 0.3 - f.x * f.y));
    fragColor = vec4(splatfx_emittedGridIrradiance(p, n), 1.0);
}
)";

} // namespace

TEST_F(EmittedLightGL, GlslGridIrradianceEqualsTheCpuOnTheSameGrid) {
    EmittedGrid g;
    g.dims = {3, 2, 4}; // 24 nodes: not cubic, so a swapped axis shows
    g.boxMin = {-1.0f, 0.0f, -0.8f}, g.boxMax = {1.2f, 1.5f, 0.9f};
    g.centre = {0.1f, 0.6f, 0.0f};
    g.nodes.resize(24);
    float largest = 0.0f;
    for (std::size_t i = 0; i < g.nodes.size(); ++i)
        for (std::size_t k = 0; k < 6; ++k) {
            g.nodes[i][k] = glm::vec3(float((i * 7 + k * 3) % 11) + 0.5f, float((i * 5 + k) % 13) * 0.3f, float((i + k * 11) % 7) * 0.7f + 0.1f);
            largest = std::max(largest, std::max(g.nodes[i][k].x, std::max(g.nodes[i][k].y, g.nodes[i][k].z)));
        }
    gl::ShadowBinding binding;
    binding.emittedGrid = g;
    const Image image = drawEveryPixel(kGridFragmentBody, "emitted grid", binding);
    ASSERT_EQ(image.width, kW);
    // The value is a convex combination of node values (trilinear weights
    // >= 0 summing to 1, n_a^2 summing to |n|^2 = 1 up to normalize's
    // rounding) times the falloff ratio (<= 1). GLSL 4.50 (sec. 4.7.1): +, -,
    // * correctly rounded, division 2.5 ulp. Each weight's coordinate t comes
    // from a subtraction, a division and a multiplication by dims - 1 <= 3:
    // off by at most (2 + 2.5 + 1) ulp x 3 = 2^-24 x 17 absolute, which moves
    // the result by 3 axes x 2 x that x the largest node value; the 8 corners'
    // 3 products and 2 sums, the 3 normal terms and the falloff's 6 operations
    // add under 64 ulp of the value, itself under the largest node value; the
    // normal's own rounding (normalize: 2 + 3 ulp per component, squared)
    // under 16 ulp. The GPU may contract the point's a + b * f into an fma
    // (1 ulp of |p| <= 3: 2^-22, moving t by <= 2^-22 x 3 / 1.5 = 2^-21, so
    // 3 axes x 2 x 2^-21 = 12 x 2^-24 of the largest value). The ratio
    // outside the box scales all of it by <= 1.
    const float tol = (6.0f * 17.0f + 64.0f + 16.0f + 12.0f) * 0x1p-24f * largest;
    // Outside, every intermediate (the six values' trilinear sum, the
    // intensity over d^2, the point source at q and at p, the departure) is
    // at most 6 x the largest node value (sum_a |w_a| >= 1, r <= 1, cosines
    // <= 1): the inside bound for the six-value sum (6 x), plus under 96 ulp
    // of 6 x the largest value for the 30 further operations (sqrt 3 ulp,
    // division 2.5 ulp) and the direction's rounding.
    const float tolOutside = 6.0f * tol + 6.0f * 96.0f * 0x1p-24f * largest;
    float worst = 0.0f, outsideLit = 0.0f, insideLit = 0.0f;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const glm::vec2 f = glm::vec2(float(x), float(y)) / glm::vec2(kW, kH);
            const glm::vec3 p(-3.0f + 6.0f * f.x, -1.0f + 3.0f * f.y, 1.5f - 3.0f * f.x * f.y);
            const glm::vec3 n = glm::normalize(glm::vec3(f.x - 0.45f, 0.55f - f.y, 0.3f - f.x * f.y));
            const glm::vec3 cpu = emittedIrradiance(g, p, n);
            const int row = kH - 1 - y; // Framebuffer::read puts the top row first
            const bool inside = glm::all(glm::greaterThanEqual(p, g.boxMin)) && glm::all(glm::lessThanEqual(p, g.boxMax));
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(image.at(x, row, c) - cpu[c]) / (inside ? tol : tolOutside));
            (inside ? insideLit : outsideLit) = std::max(inside ? insideLit : outsideLit, cpu.x);
        }
    EXPECT_LE(worst, 1.0f) << "largest GPU-CPU difference in units of its tolerance";
    EXPECT_GT(insideLit, 0.5f) << "points inside the box were sampled";
    EXPECT_GT(outsideLit, 0.0f) << "points outside the box were sampled";
}

// The frame's grid reaches the host's binding through FrameRenderer, and
// none the next frame when it has none.
TEST_F(EmittedLightGL, FrameRendererBindsTheFramesGridAndDropsItTheNextFrame) {
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr) << fr.error();
    Materials materials{Footprint{}};
    ASSERT_TRUE(fr->upload(materials));
    auto fb = gl::Framebuffer::create({.width = 16, .height = 16});
    ASSERT_TRUE(fb);
    const Camera cam = Camera::lookAt({0, 1, 4}, {0, 0, 0}, {0, 1, 0}, 1.0f, {16, 16});
    auto render = [&](const EmittedGrid& grid) {
        Frame frame;
        frame.begin(0.0, cam);
        frame.end();
        frame.emittedGrid() = grid;
        gl::ShadowBinding seen;
        fr->render(frame, {.framebuffer = fb->handle(), .drawOpaque = [&] { seen = fr->shadowBinding(); }});
        return seen.emittedGrid;
    };
    EmittedGrid g;
    g.dims = {2, 2, 2};
    g.boxMax = glm::vec3(1.0f);
    g.nodes.assign(8, {glm::vec3(1.0f), glm::vec3(2.0f), glm::vec3(3.0f), glm::vec3(4.0f), glm::vec3(5.0f), glm::vec3(6.0f)});
    const EmittedGrid bound = render(g);
    EXPECT_EQ(bound.dims, g.dims);
    ASSERT_EQ(bound.nodes.size(), g.nodes.size());
    EXPECT_EQ(bound.nodes[7][5], glm::vec3(6.0f));
    EXPECT_EQ(render({}).dims, glm::ivec3(0)) << "a frame without a grid binds none";
}
