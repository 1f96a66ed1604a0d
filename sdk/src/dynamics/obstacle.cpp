// Obstacles for the gas solver: validation and the inside test each cell
// centre goes through when FluidSolver voxelizes them (solver.cpp).
#include "splatfx/obstacle.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace splatfx {
namespace {

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Signed solid angle of triangle (a, b, c) seen from the origin (Van Oosterom
// and Strackee 1983): tan(omega / 2) = a . (b x c) / (|a||b||c| + (a.b)|c| +
// (a.c)|b| + (b.c)|a|). A zero-area triangle has a zero triple product and
// adds nothing.
double solidAngle(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = glm::dot(a, glm::cross(b, c));
    const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
    return 2.0 * std::atan2(num, den);
}

} // namespace

Status validateObstacle(const ObstacleDesc& d) {
    if (!finite3(d.size) || !(d.size.x > 0.0f && d.size.y > 0.0f && d.size.z > 0.0f))
        return makeError("ObstacleDesc.size must be positive and finite on every axis");
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(d.transform[c][r])) return makeError("ObstacleDesc.transform has a non-finite entry");
    if (std::abs(glm::determinant(glm::mat3(d.transform))) < 1e-12f) return makeError("ObstacleDesc.transform is singular");
    if (d.shape != ObstacleShape::Mesh) {
        if (!d.triangles.empty()) return makeError("ObstacleDesc.triangles is only read for ObstacleShape::Mesh; leave it empty");
        return {};
    }
    if (d.triangles.empty() || d.triangles.size() % 3 != 0)
        return makeError("ObstacleDesc.triangles must hold three vertices per triangle (a non-zero multiple of 3), got " +
                         std::to_string(d.triangles.size()));
    bool anyArea = false;
    for (std::size_t i = 0; i < d.triangles.size(); ++i)
        if (!finite3(d.triangles[i])) return makeError("ObstacleDesc.triangles[" + std::to_string(i) + "] is not finite");
    for (std::size_t i = 0; i < d.triangles.size(); i += 3) {
        const glm::dvec3 a(d.triangles[i]), b(d.triangles[i + 1]), c(d.triangles[i + 2]);
        anyArea = anyArea || glm::length(glm::cross(b - a, c - a)) > 0.0;
    }
    if (!anyArea) return makeError("ObstacleDesc.triangles: every triangle has zero area, so the mesh encloses nothing");
    return {};
}

bool obstacleContains(const ObstacleDesc& d, glm::vec3 p) {
    const glm::vec3 h = 0.5f * d.size;
    switch (d.shape) {
    case ObstacleShape::Box: return std::abs(p.x) <= h.x && std::abs(p.y) <= h.y && std::abs(p.z) <= h.z;
    case ObstacleShape::Plane: return p.y <= 0.0f && std::abs(p.x) <= h.x && std::abs(p.z) <= h.z;
    case ObstacleShape::Sphere: return glm::dot(p, p) <= h.x * h.x;
    case ObstacleShape::Cylinder: return p.y >= 0.0f && p.y <= d.size.y && p.x * p.x + p.z * p.z <= h.x * h.x;
    case ObstacleShape::Mesh: {
        double omega = 0.0;
        for (std::size_t i = 0; i + 2 < d.triangles.size(); i += 3)
            omega += solidAngle(glm::dvec3(d.triangles[i] - p), glm::dvec3(d.triangles[i + 1] - p), glm::dvec3(d.triangles[i + 2] - p));
        // Winding number omega / 4 pi: 1 inside a closed mesh (either
        // orientation counts), 0 outside.
        return std::abs(omega) > 2.0 * 3.14159265358979323846;
    }
    }
    return false;
}

Aabb obstacleBounds(const ObstacleDesc& d) {
    const glm::vec3 h = 0.5f * d.size;
    Aabb b;
    switch (d.shape) {
    case ObstacleShape::Box: b = {-h, h}; break;
    case ObstacleShape::Plane: b = {{-h.x, -std::numeric_limits<float>::infinity(), -h.z}, {h.x, 0.0f, h.z}}; break;
    case ObstacleShape::Sphere: b = {glm::vec3(-h.x), glm::vec3(h.x)}; break;
    case ObstacleShape::Cylinder: b = {{-h.x, 0.0f, -h.x}, {h.x, d.size.y, h.x}}; break;
    case ObstacleShape::Mesh:
        for (glm::vec3 v : d.triangles) b.extend(v);
        break;
    }
    return b;
}

} // namespace splatfx
