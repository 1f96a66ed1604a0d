// The fog include for the host's own shaders: docs/integration.md's snippet,
// read from the doc itself, compiled, fed by gl::setFogUniforms and drawn;
// the pixel is checked against the double-precision Fog::apply.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/gl/fog_uniforms.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/program.hpp"

namespace splatfx {
namespace {

// The two ```glsl blocks between the snippet markers of docs/integration.md.
std::vector<std::string> snippetShaders() {
    std::ifstream in(test::sourcePath("docs/integration.md"));
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string doc = ss.str();
    const std::size_t a = doc.find("<!-- fog-snippet-begin"), b = doc.find("<!-- fog-snippet-end");
    std::vector<std::string> out;
    if (a == std::string::npos || b == std::string::npos) return out;
    std::size_t p = a;
    while ((p = doc.find("```glsl\n", p)) != std::string::npos && p < b) {
        const std::size_t start = p + 8, end = doc.find("```", start);
        out.push_back(doc.substr(start, end - start));
        p = end + 3;
    }
    return out;
}

class FogIncludeGL : public test::GLTest {};

TEST_F(FogIncludeGL, TheIntegrationSnippetCompilesAndFogsLikeTheCpu) {
    std::vector<std::string> sh = snippetShaders();
    ASSERT_EQ(sh.size(), 2u) << "docs/integration.md must hold the vertex and fragment snippet between the markers";
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.08));
    d.terms.push_back(FogTerm::cosine(0.05, 0.9, {0.0, 1.0, 0.15}, 0.5));
    d.terms.push_back(FogTerm::point(0.3, {0.5, 0.2, -2.0}, 1.0, 2.0));
    d.colour = {0.3, 0.4, 0.6};
    d.wind = FogWind::constant({0.4, 0.0, 0.1});
    const Fog fog = *Fog::create(d);
    auto glsl = fogGlsl(fog);
    ASSERT_TRUE(glsl);
    std::string& frag = sh[1];
    const std::size_t marker = frag.find("// SPLATFX_FOG");
    ASSERT_NE(marker, std::string::npos);
    frag.replace(marker, frag.find('\n', marker) - marker, glsl->source);
    auto prog = gl::linkProgram({sh[0].c_str()}, {frag.c_str()}, "integration snippet");
    ASSERT_TRUE(prog) << prog.error();

    // A triangle covering the view in the plane z = -4, camera at (0.3, 0.5, 2) looking down -z.
    const glm::dvec3 eye{0.3, 0.5, 2.0};
    const Camera cam = Camera::lookAt(glm::vec3(eye), glm::vec3(eye) + glm::vec3(0, 0, -1), {0, 1, 0}, 0.8f, {8, 8}, 0.1f, 50.0f);
    const float tri[9] = {-50.0f, -50.0f, -4.0f, 50.0f, -50.0f, -4.0f, 0.0f, 50.0f, -4.0f};
    GLuint vao = 0, vbo = 0;
    glCreateVertexArrays(1, &vao);
    glCreateBuffers(1, &vbo);
    glNamedBufferStorage(vbo, sizeof tri, tri, 0);
    glVertexArrayVertexBuffer(vao, 0, vbo, 0, 12);
    glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
    glEnableVertexArrayAttrib(vao, 0);
    auto fb = gl::Framebuffer::create({.width = 8, .height = 8, .color = gl::Precision::F32});
    ASSERT_TRUE(fb);
    fb->clear({0, 0, 0, 0});
    const double t = 1.5;
    ASSERT_TRUE(gl::setFogUniforms(*prog, fog, t, eye));
    const glm::mat4 vp = cam.proj * cam.view;
    glProgramUniformMatrix4fv(*prog, glGetUniformLocation(*prog, "uViewProj"), 1, GL_FALSE, &vp[0][0]);
    glProgramUniform3f(*prog, glGetUniformLocation(*prog, "uEye"), float(eye.x), float(eye.y), float(eye.z));
    const glm::dvec3 albedo{0.9, 0.5, 0.1};
    glProgramUniform3f(*prog, glGetUniformLocation(*prog, "uAlbedo"), float(albedo.x), float(albedo.y), float(albedo.z));
    glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
    glViewport(0, 0, 8, 8);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(*prog);
    glBindVertexArray(vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    const Image img = fb->read();

    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    double worst = 0.0, fMin = 1.0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            // The pixel centre's ray meets z = -4 at:
            const glm::dvec4 h = inv * glm::dvec4((x + 0.5) / 8 * 2 - 1, (7 - y + 0.5) / 8 * 2 - 1, -1.0, 1.0);
            const glm::dvec3 dir = glm::normalize(glm::dvec3(h) / h.w - eye);
            const glm::dvec3 p = eye + dir * ((-4.0 - eye.z) / dir.z);
            const glm::dvec3 want = fog.apply(eye, p, t, albedo);
            fMin = std::min(fMin, fog.transmittance(eye, p, t));
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(img.at(x, y, c)) - want[c]));
        }
    // |d colour| <= |d tau| (colours <= 1): per term amplitude * L * (argument
    // rounding + device trig error, < 2^-20) over L < 7, about 3e-6, plus the
    // interpolated position's rounding times the density; 2e-5 covers both.
    EXPECT_LE(worst, 2e-5);
    EXPECT_LT(fMin, 0.6) << "the fog must be visible";
    glDeleteBuffers(1, &vbo);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(*prog);
}

TEST_F(FogIncludeGL, SetFogUniformsRejectsAProgramWithoutTheInclude) {
    auto prog = gl::linkProgram({"#version 450 core\nvoid main() { gl_Position = vec4(0.0); }\n"},
                                {"#version 450 core\nout vec4 o;\nvoid main() { o = vec4(1.0); }\n"}, "plain");
    ASSERT_TRUE(prog) << prog.error();
    const Status s = gl::setFogUniforms(*prog, *Fog::create(paperFig6Fog()), 0.0, glm::dvec3(0.0));
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("splatfx_fog_params"), std::string::npos) << s.error();
    glDeleteProgram(*prog);
}

} // namespace
} // namespace splatfx
