// Scheduling by light influence (docs/lighting.md, "Scheduled by light
// influence"): whether a light can reach a box, and whether a caster's shadow
// can fall inside the view. Both are conservative: a wrong "no" would make a
// shadow pop, a wrong "yes" only costs the caster's advance.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

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

// Narrows [lo, hi] to the x with a + b x <= c.
void keepWhere(double a, double b, double c, double& lo, double& hi) {
    if (b > 0.0) hi = std::min(hi, (c - a) / b);
    else if (b < 0.0) lo = std::max(lo, (c - a) / b);
    else if (a > c) hi = -1.0, lo = 1.0; // never
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

bool Scene::shadowFallsOn(const Aabb& caster, const Light& light, const Aabb& receiver) {
    if (!lightReaches(light, caster) || !lightReaches(light, receiver)) return false;
    // The caster, grown by a relative 1e-5 so float rounding in the boxes
    // cannot turn a grazing ray into a miss.
    const glm::dvec3 r0(receiver.lo), r1(receiver.hi);
    glm::dvec3 c0(caster.lo), c1(caster.hi);
    const double pad = 1e-5 * (1.0 + std::max({glm::length(c1 - c0), glm::length(c0), glm::length(c1)}));
    c0 -= pad, c1 += pad;
    // Is there a receiver point p and a ray parameter x with p + (ray to the
    // light at x) inside the caster? Per axis both bounds are linear in x, so
    // the feasible x form one interval. Directional (towards the light u):
    // p = c - x u, x >= 0. Point or spot at q: p = q + x (c - q), x >= 1
    // (x = 1 / the fraction of the way from p to q where c lies).
    double lo = 0.0, hi = std::numeric_limits<double>::infinity();
    if (light.type == LightType::Directional) {
        const glm::dvec3 u = -glm::normalize(glm::dvec3(light.direction));
        for (int a = 0; a < 3; ++a) {
            keepWhere(c0[a], -u[a], r1[a], lo, hi);   // c0 - x u <= r1
            keepWhere(-c1[a], u[a], -r0[a], lo, hi);  // c1 - x u >= r0
        }
    } else {
        const glm::dvec3 q(light.position);
        if (glm::all(glm::greaterThanEqual(q, c0)) && glm::all(glm::lessThanEqual(q, c1))) return true; // the light is in the caster's box
        lo = 1.0;
        for (int a = 0; a < 3; ++a) {
            keepWhere(q[a], c0[a] - q[a], r1[a], lo, hi);    // q + x (c0 - q) <= r1
            keepWhere(-q[a], q[a] - c1[a], -r0[a], lo, hi);  // q + x (c1 - q) >= r0
        }
    }
    return lo <= hi;
}

} // namespace splatfx
