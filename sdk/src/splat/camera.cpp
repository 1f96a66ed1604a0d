#include "splatfx/camera.hpp"

#include <glm/gtc/matrix_transform.hpp>

namespace splatfx {

Camera Camera::fromMatrices(const glm::mat4& view, const glm::mat4& proj, glm::ivec2 viewport, const DepthConvention& depth) {
    return Camera{view, proj, viewport, depth};
}

Camera Camera::lookAt(glm::vec3 eye, glm::vec3 target, glm::vec3 up, float fovY, glm::ivec2 viewport, float nearPlane, float farPlane,
                      const DepthConvention& depth) {
    const float aspect = float(viewport.x) / float(glm::max(viewport.y, 1));
    return Camera{glm::lookAt(eye, target, up), perspectiveProjection(fovY, aspect, nearPlane, farPlane, depth), viewport, depth};
}

glm::vec3 Camera::eye() const { return glm::vec3(glm::inverse(view)[3]); }
// Rows of the view matrix's rotation are the camera axes in world space.
glm::vec3 Camera::right() const { return glm::normalize(glm::vec3(view[0][0], view[1][0], view[2][0])); }
glm::vec3 Camera::up() const { return glm::normalize(glm::vec3(view[0][1], view[1][1], view[2][1])); }
glm::vec3 Camera::forward() const { return -glm::normalize(glm::vec3(view[0][2], view[1][2], view[2][2])); }

float Camera::nearPlane() const {
    // The view depth at the convention's near ndc z (c): perspective
    // ndc = (P22 z + P32) / (P23 z) at z = -depth; orthographic ndc = P22 z + P32.
    // (OpenGL's default, c = -1, P23 = -1: P32 / (P22 - 1) and (P32 + 1) / P22.)
    const float c = float(depth.nearNdc());
    if (perspective()) return proj[3][2] / (proj[2][2] - proj[2][3] * c);
    return (proj[3][2] - c) / proj[2][2];
}

} // namespace splatfx
