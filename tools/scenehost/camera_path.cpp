#include "camera_path.hpp"

#include <algorithm>
#include <cassert>

namespace scenehost {

splatfx::CameraKey sampleKey(const splatfx::CameraPath& path, double t) {
    assert(!path.keys.empty() && "CameraPath needs at least one key");
    const auto& k = path.keys;
    if (t <= k.front().timeSec) return k.front();
    if (t >= k.back().timeSec) return k.back();
    const auto next = std::upper_bound(k.begin(), k.end(), t, [](double v, const splatfx::CameraKey& key) { return v < key.timeSec; });
    const splatfx::CameraKey& b = *next;
    const splatfx::CameraKey& a = *(next - 1);
    float u = float((t - a.timeSec) / (b.timeSec - a.timeSec));
    if (path.smooth) u = u * u * (3.0f - 2.0f * u);
    splatfx::CameraKey out;
    out.timeSec = t;
    out.position = glm::mix(a.position, b.position, u);
    out.target = glm::mix(a.target, b.target, u);
    out.fovYRad = glm::mix(a.fovYRad, b.fovYRad, u);
    return out;
}

splatfx::Camera evaluate(const splatfx::CameraPath& path, double t, glm::ivec2 viewport, const splatfx::DepthConvention& depth) {
    const splatfx::CameraKey k = sampleKey(path, t);
    glm::vec3 up(0, 1, 0);
    // Looking straight up or down: any up that is not parallel will do.
    if (glm::length(glm::cross(glm::normalize(k.target - k.position), up)) < 1e-4f) up = {0, 0, -1};
    return splatfx::Camera::lookAt(k.position, k.target, up, k.fovYRad, viewport, path.nearPlane, path.farPlane, depth);
}

} // namespace scenehost
