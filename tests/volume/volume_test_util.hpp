// Helpers shared by the volume tests: fields, and geometry on emitted tetrahedra.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/volume.hpp"

namespace voltest {

inline splatfx::ScalarVolume randomField(glm::ivec3 dims, std::uint32_t seed, bool withLength = false) {
    splatfx::ScalarVolume v;
    v.dims = dims;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const std::size_t n = std::size_t(dims.x) * std::size_t(dims.y) * std::size_t(dims.z);
    v.scalar.resize(n);
    for (float& s : v.scalar) s = u(rng);
    if (withLength) {
        v.lengthScale.resize(n);
        for (float& s : v.lengthScale) s = u(rng);
    }
    return v;
}

inline splatfx::ScalarVolume constantField(glm::ivec3 dims, float value) {
    splatfx::ScalarVolume v;
    v.dims = dims;
    v.scalar.assign(std::size_t(dims.x) * std::size_t(dims.y) * std::size_t(dims.z), value);
    return v;
}

inline double tetVolume(const splatfx::Tetrahedron& t) {
    const glm::dvec3 p0(t.position[0]);
    return glm::dot(glm::dvec3(t.position[1]) - p0, glm::cross(glm::dvec3(t.position[2]) - p0, glm::dvec3(t.position[3]) - p0)) / 6.0;
}

// Barycentric coordinates of p in t (double).
inline glm::dvec4 barycentric(const splatfx::Tetrahedron& t, glm::dvec3 p) {
    const glm::dvec3 p0(t.position[0]);
    const glm::dmat3 m(glm::dvec3(t.position[1]) - p0, glm::dvec3(t.position[2]) - p0, glm::dvec3(t.position[3]) - p0);
    const glm::dvec3 l = glm::inverse(m) * (p - p0);
    return {1.0 - l.x - l.y - l.z, l.x, l.y, l.z};
}

// Parameter interval where origin + t dir is inside t (empty: lo >= hi).
inline glm::dvec2 rayInterval(const splatfx::Tetrahedron& t, glm::dvec3 o, glm::dvec3 d) {
    double lo = -1e300, hi = 1e300;
    static constexpr int kFaces[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};
    for (const auto& f : kFaces) {
        const glm::dvec3 a(t.position[std::size_t(f[0])]), b(t.position[std::size_t(f[1])]), c(t.position[std::size_t(f[2])]),
            q(t.position[std::size_t(f[3])]);
        glm::dvec3 n = glm::cross(b - a, c - a);
        if (glm::dot(n, q - a) < 0.0) n = -n; // inward
        const double num = glm::dot(n, o - a), den = glm::dot(n, d);
        if (den == 0.0) {
            if (num < 0.0) return {1.0, 0.0};
            continue;
        }
        const double tc = -num / den;
        if (den > 0.0) lo = std::max(lo, tc);
        else hi = std::min(hi, tc);
    }
    return {lo, hi};
}

} // namespace voltest
