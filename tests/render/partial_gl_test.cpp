// partialGlsl() compiles and its lookup equals Footprint::fractionBefore
// (issue 15): the GL passes and the CPU read the same table the same way.
#include <algorithm>
#include <cmath>
#include <string>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "../../sdk/src/render/gl/partial_texture.hpp"
#include "gl_fixture.hpp"
#include "splatfx/footprint.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/program.hpp"

namespace splatfx {
namespace {

class PartialGL : public test::GLTest {};

constexpr const char* kVertex = R"(
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}
)";
constexpr const char* kFragment = R"(
uniform vec2 uSize;
uniform float uR;
out vec4 oColor;
void main() {
    // Pixel x: r over [0, 1.1 R]; pixel y: s over [-1.2 R, 1.2 R].
    float r = (gl_FragCoord.x / uSize.x) * 1.1 * uR;
    float s = (gl_FragCoord.y / uSize.y * 2.0 - 1.0) * 1.2 * uR;
    oColor = vec4(splatfx_partial_before(r, s), splatfx_ray_scale(vec3(0.3, 0.0, 0.0), vec3(0.0, 0.3, 0.0), 1.0), 0.0, 1.0);
}
)";

TEST_F(PartialGL, GlslLookupEqualsTheCpuTable) {
    for (const FootprintDesc& d : {FootprintDesc{}, FootprintDesc{.kernel = Kernel::Gaussian, .partialRadialSize = 9, .partialDepthSize = 17}}) {
        const Footprint fp(d);
        const std::string glsl = partialGlsl(fp, 3);
        auto prog = gl::linkProgram({"#version 450 core\n", kVertex}, {"#version 450 core\n", glsl.c_str(), kFragment}, "partial test");
        ASSERT_TRUE(prog) << prog.error();
        gl::detail::PartialTexture tex;
        tex.update(fp);
        const int W = 97, H = 61;
        auto fb = gl::Framebuffer::create({.width = W, .height = H, .color = gl::Precision::F32});
        ASSERT_TRUE(fb);
        fb->clear({0, 0, 0, 0});
        glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
        glViewport(0, 0, W, H);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_BLEND);
        glUseProgram(*prog);
        glUniform2f(glGetUniformLocation(*prog, "uSize"), float(W), float(H));
        glUniform1f(glGetUniformLocation(*prog, "uR"), fp.radius());
        glBindTextureUnit(3, tex.texture());
        GLuint vao = 0;
        glCreateVertexArrays(1, &vao);
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindVertexArray(0);
        glDeleteVertexArrays(1, &vao);
        glDeleteProgram(*prog);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        const Image img = fb->read(); // top row first
        // The GPU filters with fixed-point weights (llvmpipe: 8 bits): up to
        // 1/256 of the largest step between neighbouring entries, per axis.
        double step = 0.0;
        const auto& t = fp.partialTable();
        const int rows = fp.partialRows(), cols = fp.partialCols();
        for (int i = 0; i < rows; ++i)
            for (int j = 0; j + 1 < cols; ++j) step = std::max(step, double(std::abs(t[size_t(i) * cols + j + 1] - t[size_t(i) * cols + j])));
        for (int i = 0; i + 1 < rows; ++i)
            for (int j = 0; j < cols; ++j) step = std::max(step, double(std::abs(t[size_t(i + 1) * cols + j] - t[size_t(i) * cols + j])));
        const double bound = 2.0 * step / 256.0 + 1e-5;
        double worst = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const float r = ((x + 0.5f) / W) * 1.1f * fp.radius();
                const float s = (((H - 1 - y) + 0.5f) / H * 2.0f - 1.0f) * 1.2f * fp.radius();
                worst = std::max(worst, double(std::abs(img.at(x, y, 0) - fp.fractionBefore(r, s))));
                ASSERT_NEAR(img.at(x, y, 1), 0.3f / fp.radius() * 1.0f, 1e-6f) << "isotropic ray scale: spacing sqrt(0.3 * 0.3) / R";
            }
        EXPECT_LE(worst, bound);
        EXPECT_LT(bound, 0.01);
    }
}

} // namespace
} // namespace splatfx
