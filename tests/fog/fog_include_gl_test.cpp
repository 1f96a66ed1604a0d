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

// The two ```glsl blocks between the snippet markers of docs/integration.md
// (fog-snippet or fog-vertex-snippet).
std::vector<std::string> snippetShaders(const std::string& name = "fog-snippet") {
    std::ifstream in(test::sourcePath("docs/integration.md"));
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string doc = ss.str();
    const std::size_t a = doc.find("<!-- " + name + "-begin"), b = doc.find("<!-- " + name + "-end");
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

// Biri et al.'s buffer method (sec. 4.3), as docs/integration.md's per-vertex
// snippet: a ground plane of n x n quads seen from eye height, each vertex's
// transmittance from the include, interpolated. (1) The GL image is that model:
// the exact per-vertex f interpolated linearly over each world triangle (what
// perspective-correct interpolation is), computed here in double. (2) The
// model's error against the per-pixel fog is second order in the triangle
// size once the edges are shorter than the fog's narrowest feature (the
// point's width sqrt(c / d) = 2.2 units; n = 32 gives edges of 1.9 x 1.9):
// going from n = 32 to n = 128 (edges 4x shorter) divides it by about 16;
// first order would give 4, so >= 8 tells the orders apart.
TEST_F(FogIncludeGL, PerVertexBufferMethodIsSecondOrderInTheTriangleSize) {
    std::vector<std::string> sh = snippetShaders("fog-vertex-snippet");
    ASSERT_EQ(sh.size(), 2u) << "docs/integration.md must hold the per-vertex snippet between the markers";
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.02));
    d.terms.push_back(FogTerm::cosine(0.015, 0.3, {1.0, 0.0, 0.4}, 0.2));
    d.terms.push_back(FogTerm::point(0.4, {2.0, 0.5, -14.0}, 1.0, 0.2));
    d.colour = {0.7, 0.75, 0.8};
    const Fog fog = *Fog::create(d);
    auto glsl = fogGlsl(fog);
    ASSERT_TRUE(glsl);
    std::string& vert = sh[0];
    const std::size_t marker = vert.find("// SPLATFX_FOG");
    ASSERT_NE(marker, std::string::npos);
    vert.replace(marker, vert.find('\n', marker) - marker, glsl->source);
    auto prog = gl::linkProgram({vert.c_str()}, {sh[1].c_str()}, "per-vertex snippet");
    ASSERT_TRUE(prog) << prog.error();

    constexpr int W = 64, H = 48;
    const glm::dvec3 eye{0.0, 1.7, 0.0};
    const Camera cam = Camera::lookAt(glm::vec3(eye), {0.0f, 0.0f, -20.0f}, {0, 1, 0}, 0.9f, {W, H}, 0.1f, 100.0f);
    const double x0 = -30.0, x1 = 30.0, z0 = -2.0, z1 = -62.0; // the ground y = 0 under the view
    const glm::dvec3 albedo{0.3, 0.45, 0.2};
    const double t = 0.0;
    auto fb = gl::Framebuffer::create({.width = W, .height = H, .color = gl::Precision::F32});
    ASSERT_TRUE(fb);
    ASSERT_TRUE(gl::setFogUniforms(*prog, fog, t, eye));
    const glm::mat4 vp = cam.proj * cam.view;
    glProgramUniformMatrix4fv(*prog, glGetUniformLocation(*prog, "uViewProj"), 1, GL_FALSE, &vp[0][0]);
    glProgramUniform3f(*prog, glGetUniformLocation(*prog, "uEye"), float(eye.x), float(eye.y), float(eye.z));
    glProgramUniform3f(*prog, glGetUniformLocation(*prog, "uAlbedo"), float(albedo.x), float(albedo.y), float(albedo.z));
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));

    auto run = [&](int n, double& glVsModel, double& modelVsExact) {
        // Vertices (i, j) on the plane; quad (i, j) split along its (i, j)-(i+1, j+1) diagonal.
        auto vertex = [&](int i, int j) { return glm::dvec3(x0 + (x1 - x0) * i / n, 0.0, z0 + (z1 - z0) * j / n); };
        std::vector<float> tris;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                for (glm::ivec2 c : {glm::ivec2(0, 0), glm::ivec2(1, 0), glm::ivec2(1, 1), glm::ivec2(0, 0), glm::ivec2(1, 1), glm::ivec2(0, 1)}) {
                    const glm::dvec3 v = vertex(i + c.x, j + c.y);
                    tris.insert(tris.end(), {float(v.x), float(v.y), float(v.z)});
                }
        GLuint vao = 0, vbo = 0;
        glCreateVertexArrays(1, &vao);
        glCreateBuffers(1, &vbo);
        glNamedBufferStorage(vbo, GLsizeiptr(tris.size() * sizeof(float)), tris.data(), 0);
        glVertexArrayVertexBuffer(vao, 0, vbo, 0, 12);
        glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(vao, 0, 0);
        glEnableVertexArrayAttrib(vao, 0);
        fb->clear({0, 0, 0, 0});
        glBindFramebuffer(GL_FRAMEBUFFER, fb->handle());
        glViewport(0, 0, W, H);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_BLEND);
        glUseProgram(*prog);
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLES, 0, GLsizei(tris.size() / 3));
        glBindVertexArray(0);
        glUseProgram(0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        const Image img = fb->read();
        glDeleteBuffers(1, &vbo);
        glDeleteVertexArrays(1, &vao);
        glVsModel = modelVsExact = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const glm::dvec4 h = inv * glm::dvec4((x + 0.5) / W * 2 - 1, (H - 1 - y + 0.5) / H * 2 - 1, -1.0, 1.0);
                const glm::dvec3 dir = glm::normalize(glm::dvec3(h) / h.w - eye);
                if (dir.y >= 0.0) continue; // sky: no ground there
                const glm::dvec3 p = eye + dir * (-eye.y / dir.y);
                const double u = (p.x - x0) / (x1 - x0) * n, v = (p.z - z0) / (z1 - z0) * n;
                if (u <= 0.0 || u >= n || v <= 0.0 || v >= n) continue;
                const int i = int(u), j = int(v);
                const double fu = u - i, fv = v - j;
                auto f = [&](int a, int b) { return fog.transmittance(eye, vertex(i + a, j + b), t); };
                // Linear over the triangle the point lies in (below or above the diagonal).
                const double model = fu >= fv ? f(0, 0) + fu * (f(1, 0) - f(0, 0)) + fv * (f(1, 1) - f(1, 0))
                                              : f(0, 0) + fv * (f(0, 1) - f(0, 0)) + fu * (f(1, 1) - f(0, 1));
                const double exact = fog.transmittance(eye, p, t);
                for (int c = 0; c < 3; ++c) {
                    const double want = model * albedo[c] + (1.0 - model) * d.colour[c];
                    glVsModel = std::max(glVsModel, std::abs(double(img.at(x, y, c)) - want));
                }
                modelVsExact = std::max(modelVsExact, std::abs(model - exact));
            }
    };
    double glCoarse = 0, errCoarse = 0, glFine = 0, errFine = 0; // n = 32 and n = 128
    run(32, glCoarse, errCoarse);
    run(128, glFine, errFine);
    // (1) The vertex's f in float: as the per-fragment test, <= 2e-5 (|d colour| <= |d f|),
    // plus the float barycentrics (a few ulps of f): 3e-5.
    EXPECT_LE(glCoarse, 3e-5);
    EXPECT_LE(glFine, 3e-5);
    // (2) Second order.
    EXPECT_GT(errCoarse, 1e-3) << "the fog must vary enough across a coarse triangle to measure";
    EXPECT_GE(errCoarse / errFine, 8.0) << "n = 32: " << errCoarse << ", n = 128: " << errFine;
    std::printf("[ buffer method ] max |f_vertex - f_pixel|: n = 32 %.2e, n = 128 %.2e (ratio %.1f); GL vs model %.1e\n", errCoarse, errFine,
                errCoarse / errFine, std::max(glCoarse, glFine));
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
