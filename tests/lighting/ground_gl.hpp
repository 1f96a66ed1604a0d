// A host's ground under the gas, for the shadow GL tests: a quad at y = 0 seen
// straight down (so each pixel centre is a known world point), drawn by a
// shadowGlsl() shader inside FrameRenderer's opaque hook.
#pragma once

#include <functional>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/gl/framebuffer.hpp"

namespace splatfx::test {

// The ground quad [-uHalf, uHalf]^2 at y = 0 (docs/integration.md, "Shadows of the gas").
inline const char* kGroundVertex = R"(#version 450 core
uniform mat4 uViewProj;
uniform float uHalf;          // the ground quad: [-uHalf, uHalf]^2 at y = 0
out vec3 vWorldPos;
void main() {
    vec2 c = vec2((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0) * uHalf;
    vWorldPos = vec3(c.x, 0.0, c.y);
    gl_Position = uViewProj * vec4(vWorldPos, 1.0);
}
)";

// Orthographic, straight down from y = 10 over [-half.x, half.x] x [-half.y, half.y].
inline Camera topDown(glm::ivec2 size, glm::vec2 half) {
    const glm::mat4 view = glm::lookAt(glm::vec3(0, 10, 0), glm::vec3(0), glm::vec3(0, 0, -1));
    const glm::mat4 proj = glm::ortho(-half.x, half.x, -half.y, half.y, 0.1f, 100.0f);
    return Camera::fromMatrices(view, proj, size);
}

// The ground point (y = 0) under pixel (x, y)'s centre of a top-down camera.
inline glm::vec3 groundPoint(const Camera& cam, int x, int y) {
    const glm::vec4 ndc((x + 0.5f) / cam.viewport.x * 2.0f - 1.0f, 1.0f - (y + 0.5f) / cam.viewport.y * 2.0f, 0.0f, 1.0f);
    const glm::vec4 w = glm::inverse(cam.proj * cam.view) * ndc;
    return {w.x / w.w, 0.0f, w.z / w.w};
}

struct GroundDrawn {
    Image image;               // the F32 target after the frame
    gl::ShadowBinding binding; // what the ground shader was given
};

// Renders `frame` with the ground drawn by `prog` (kGroundVertex + shadowGlsl() + a body) as the
// opaque pass, cleared to black, into a fresh F32 target of the camera's size; `uniforms` sets
// the body's own uniforms.
inline GroundDrawn drawGround(gl::FrameRenderer& fr, const Frame& frame, GLuint prog, const Camera& cam, float half,
                              const std::function<void(GLuint)>& uniforms = {}) {
    auto fb = gl::Framebuffer::create({.width = cam.viewport.x, .height = cam.viewport.y, .color = gl::Precision::F32});
    EXPECT_TRUE(fb) << fb.error();
    const glm::mat4 vp = cam.proj * cam.view;
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    GroundDrawn out;
    fr.render(frame, {.framebuffer = fb->handle(), .drawOpaque = [&] {
                          glClearColor(0, 0, 0, 1);
                          glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                          glDisable(GL_BLEND);
                          glDisable(GL_DEPTH_TEST);
                          glUseProgram(prog);
                          out.binding = fr.shadowBinding();
                          gl::setShadowUniforms(prog, out.binding);
                          glUniformMatrix4fv(glGetUniformLocation(prog, "uViewProj"), 1, GL_FALSE, glm::value_ptr(vp));
                          glUniform1f(glGetUniformLocation(prog, "uHalf"), half);
                          if (uniforms) uniforms(prog);
                          glBindVertexArray(vao);
                          glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
                          glBindVertexArray(0);
                          glUseProgram(0);
                      }});
    glDeleteVertexArrays(1, &vao);
    out.image = fb->read();
    return out;
}

} // namespace splatfx::test
