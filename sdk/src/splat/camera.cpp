#include "splatfx/camera.hpp"

#include <glm/gtc/matrix_transform.hpp>

namespace splatfx {

Camera Camera::fromMatrices(const glm::mat4& view, const glm::mat4& proj, glm::ivec2 viewport) { return Camera{view, proj, viewport}; }

Camera Camera::lookAt(glm::vec3 eye, glm::vec3 target, glm::vec3 up, float fovY, glm::ivec2 viewport, float nearPlane, float farPlane) {
    const float aspect = float(viewport.x) / float(glm::max(viewport.y, 1));
    return Camera{glm::lookAt(eye, target, up), glm::perspective(fovY, aspect, nearPlane, farPlane), viewport};
}

glm::vec3 Camera::eye() const { return glm::vec3(glm::inverse(view)[3]); }
// Rows of the view matrix's rotation are the camera axes in world space.
glm::vec3 Camera::right() const { return glm::normalize(glm::vec3(view[0][0], view[1][0], view[2][0])); }
glm::vec3 Camera::up() const { return glm::normalize(glm::vec3(view[0][1], view[1][1], view[2][1])); }
glm::vec3 Camera::forward() const { return -glm::normalize(glm::vec3(view[0][2], view[1][2], view[2][2])); }

float Camera::nearPlane() const {
    // Perspective: proj[2][2] = -(f + n) / (f - n), proj[3][2] = -2 f n / (f - n).
    if (perspective()) return proj[3][2] / (proj[2][2] - 1.0f);
    // Orthographic: proj[2][2] = -2 / (f - n), proj[3][2] = -(f + n) / (f - n).
    return (proj[3][2] + 1.0f) / proj[2][2];
}

} // namespace splatfx
