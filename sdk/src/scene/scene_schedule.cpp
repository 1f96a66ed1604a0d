// Scheduling by light influence (docs/lighting.md, "Scheduled by light
// influence"): whether a light can reach a box, and whether a caster's shadow
// can fall inside the view. Both are conservative: a wrong "no" would make a
// shadow pop, a wrong "yes" only costs the caster's advance.
#include <algorithm>
#include <array>
#include <cmath>

#include "splatfx/scene.hpp"

namespace splatfx {
namespace {

// The six frustum planes (Gribb & Hartmann), inside where dot(n, p) + w >= 0.
std::array<glm::vec4, 6> frustumPlanes(const Camera& camera) {
    const glm::mat4 vp = camera.proj * camera.view;
    std::array<glm::vec4, 6> planes;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 2; ++k) {
            const float sign = k == 0 ? -1.0f : 1.0f;
            planes[std::size_t(2 * i + k)] =
                glm::vec4(vp[0][3], vp[1][3], vp[2][3], vp[3][3]) + sign * glm::vec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
        }
    return planes;
}

// max over the box of dot(n, p).
float support(const Aabb& box, glm::vec3 n) {
    const glm::vec3 p(n.x >= 0 ? box.hi.x : box.lo.x, n.y >= 0 ? box.hi.y : box.lo.y, n.z >= 0 ? box.hi.z : box.lo.z);
    return glm::dot(n, p);
}

} // namespace

bool Scene::lightReaches(const Light& light, const Aabb& box) {
    if (box.empty()) return false;
    if (light.type != LightType::Spot) return true;
    // The box's bounding sphere against the outer cone: the sphere is outside
    // when the angle from the axis to its centre exceeds the outer half-angle
    // by more than the sphere's angular radius asin(r / |v|).
    const glm::vec3 c = 0.5f * (box.lo + box.hi);
    const float r = 0.5f * glm::length(box.hi - box.lo);
    const glm::vec3 v = c - light.position;
    const float dist = glm::length(v);
    if (!(dist > r)) return true; // the light is inside the sphere (or a NaN): reached
    const float cosAngle = std::clamp(glm::dot(v, glm::normalize(light.direction)) / dist, -1.0f, 1.0f);
    const float reach = light.outerConeRad + std::asin(std::min(1.0f, r / dist));
    return reach >= 3.14159265f || std::acos(cosAngle) <= reach;
}

bool Scene::shadowReachesView(const Aabb& caster, const Light& light, const Camera& camera) {
    if (!lightReaches(light, caster)) return false;
    // The shadow volume is the box swept away from the light without end. It
    // lies behind a frustum plane (normal n) when the box does and the sweep
    // never moves towards n: for a directional light travelling along t,
    // dot(n, t) <= 0; for a point light at P, every corner q has
    // dot(n, q - P) <= 0, i.e. the box's support along n is at most dot(n, P).
    const bool directional = light.type == LightType::Directional;
    const glm::vec3 travel = directional ? glm::normalize(light.direction) : glm::vec3(0.0f);
    for (const glm::vec4& plane : frustumPlanes(camera)) {
        const glm::vec3 n(plane);
        const float s = support(caster, n);
        if (s + plane.w >= 0.0f) continue; // the box itself is not behind this plane
        const bool sweepStaysBehind = directional ? glm::dot(n, travel) <= 0.0f : s <= glm::dot(n, light.position);
        if (sweepStaysBehind) return false;
    }
    return true;
}

} // namespace splatfx
