// splatfx/camera.hpp: the host's camera, as splatfx sees it.
//
// The host passes its own view and projection matrices (right-handed view
// space looking down -z) and the depth convention its projection and depth
// buffer follow (depth_convention.hpp: OpenGL's clip z in [-w, w] by default;
// [0, w], reversed, infinite far); splatfx only derives what it needs from
// them (eye, near plane, perspective or not, window depth -> distance).
//
//   auto cam = splatfx::Camera::lookAt({0, 5, 20}, {0, 5, 0}, {0, 1, 0},
//                                      glm::radians(45.0f), {640, 480});
//
// Threading: a plain value.
#pragma once

#include <glm/glm.hpp>

#include "splatfx/depth_convention.hpp"

namespace splatfx {

struct Camera {
    glm::mat4 view{1.0f};
    glm::mat4 proj{1.0f};
    glm::ivec2 viewport{1, 1}; // pixels
    DepthConvention depth{};   // how proj and the host's depth buffer map distance to depth; default OpenGL's

    // From host matrices; near plane and projection kind are read off proj
    // under `depth` (conventionOfProjection derives it from proj and the clip range).
    static Camera fromMatrices(const glm::mat4& view, const glm::mat4& proj, glm::ivec2 viewport, const DepthConvention& depth = {});
    // Perspective camera; fovY in radians; near/far in world units (far
    // unused with depth.infiniteFar); proj as perspectiveProjection builds it.
    static Camera lookAt(glm::vec3 eye, glm::vec3 target, glm::vec3 up, float fovY, glm::ivec2 viewport, float nearPlane = 0.05f,
                         float farPlane = 1000.0f, const DepthConvention& depth = {});

    glm::vec3 eye() const;
    glm::vec3 forward() const; // unit view direction in world space
    glm::vec3 up() const;      // unit camera up in world space
    glm::vec3 right() const;   // unit camera right in world space
    bool perspective() const { return proj[3][3] == 0.0f; }
    // Distance of the near plane along forward(); 0 for an orthographic proj
    // whose near plane is behind the eye.
    float nearPlane() const;
};

} // namespace splatfx
