// A ground fog layer as a shadow caster (volume.hpp, GroundFogCaster): the
// layer's exact optical depth along a segment, the closed-form integral its
// own self-shadowing uses (ground_fog_light.cpp, fogScalarIntegral), turned
// into the log2 units every ShadowCaster speaks.
#include <bit>
#include <cmath>
#include <numbers>
#include <vector>

#include "splatfx/volume.hpp"
#include "volume/ground_fog_light.hpp"

namespace splatfx {
namespace {

// FNV-1a over 64-bit words: the caster's fingerprint (equal layers and
// extinctions hash equal; any height, thickness or extinction change differs).
struct Hash {
    std::uint64_t h = 0xcbf29ce484222325ull;
    void add(std::uint64_t v) { h = (h ^ v) * 0x100000001b3ull; }
    void add(double v) { add(std::bit_cast<std::uint64_t>(v)); }
};

constexpr double kLog2E = std::numbers::log2e; // natural-log depth to log2 units

// Scratch for the stretch boundaries, one per thread (const members may run concurrently).
std::vector<double>& scratch() {
    thread_local std::vector<double> ts;
    return ts;
}

} // namespace

Result<GroundFogCaster> GroundFogCaster::create(const GroundFog& fog, float extinctionPerWorld) {
    if (!std::isfinite(extinctionPerWorld) || extinctionPerWorld < 0.0f)
        return makeError("GroundFogCaster: extinctionPerWorld must be finite and >= 0, got " + std::to_string(extinctionPerWorld));
    GroundFogCaster c;
    const detail::FogFieldView f = fog.fieldView();
    if (!(extinctionPerWorld > 0.0f) || fog.prismCount() == 0 || !(f.density > 0.0)) return c; // casts nothing: empty
    c.mFog = &fog;
    c.mExtinction = extinctionPerWorld;
    // The continuous field's support: the grid's x and z, the lowest terrain to the highest top.
    c.mBounds.lo = glm::vec3(glm::dvec3(f.origin.x, f.yLo, f.origin.y));
    c.mBounds.hi = glm::vec3(glm::dvec3(f.origin.x + f.spacing * (f.nx - 1), f.yHi, f.origin.y + f.spacing * (f.nz - 1)));
    Hash h;
    h.add(std::uint64_t(f.nx)), h.add(std::uint64_t(f.nz));
    h.add(f.origin.x), h.add(f.origin.y), h.add(f.spacing), h.add(f.density), h.add(f.depth), h.add(double(extinctionPerWorld));
    for (int j = 0; j < f.nz; ++j)
        for (int i = 0; i < f.nx; ++i) h.add(f.h(i, j)), h.add(f.th(i, j));
    c.mFingerprint = h.h;
    return c;
}

float GroundFogCaster::at(glm::vec3 world) const {
    if (!mFog) return 0.0f;
    return float(double(mExtinction) * detail::fogScalarAt(mFog->fieldView(), glm::dvec3(world)) * kLog2E);
}

float GroundFogCaster::opticalDepth(glm::vec3 fromWorld, glm::vec3 toWorld) const {
    if (!mFog) return 0.0f;
    const glm::dvec3 a(fromWorld), d = glm::dvec3(toWorld) - a;
    const double len = glm::length(d);
    if (!(len > 0.0) || !std::isfinite(len) || !std::isfinite(a.x + a.y + a.z)) return 0.0f;
    return float(double(mExtinction) * detail::fogScalarIntegral(mFog->fieldView(), a, d / len, scratch(), len) * kLog2E);
}

float GroundFogCaster::opticalDepthToLight(glm::vec3 world, const Light& light) const {
    if (!mFog) return 0.0f;
    if (light.type != LightType::Directional) return opticalDepth(world, light.position);
    const glm::dvec3 toLight = -glm::dvec3(light.direction), p(world);
    const double n = glm::length(toLight);
    if (!(n > 0.0) || !std::isfinite(n) || !std::isfinite(p.x + p.y + p.z)) return 0.0f;
    // Without end towards the sun: the integral clips the ray to the layer's box.
    return float(double(mExtinction) * detail::fogScalarIntegral(mFog->fieldView(), p, toLight / n, scratch()) * kLog2E);
}

} // namespace splatfx
