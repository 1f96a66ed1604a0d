// Low-albedo lighting of a gas per voxel (Ebert & Parent 1990, "Illumination of
// gaseous phenomena", after Kajiya & Von Herzen 1984): emission, single
// scattering of each (shadowed) light through a Henyey-Greenstein phase
// function, and an albedo-based ambient term for higher orders.
#include <algorithm>
#include <cmath>

#include "splatfx/lighting.hpp"

namespace splatfx {
namespace {

constexpr float kFourPi = 12.566370614359172f;

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

float smoothstep(float a, float b, float x) {
    if (!(b > a)) return x >= b ? 1.0f : 0.0f;
    const float t = std::clamp((x - a) / (b - a), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

Status checkNonNegative(float v, const char* field) {
    if (!std::isfinite(v) || v < 0.0f) return makeError(std::string("GasLightingDesc.") + field + " must be a finite number >= 0");
    return {};
}

// What one light contributes, prepared once per call.
struct PreparedLight {
    LightType type;
    glm::vec3 color;  // colour times intensity
    glm::vec3 travel; // unit direction the light travels (directional; spot axis)
    glm::vec3 position;
    float cosOuter, cosInner;
    float minDist2; // irradiance is capped at intensity / minDist2
    float minDist;
};

Status checkInputs(glm::vec3 eyeWorld, std::span<const Light> lights, const GasLightingDesc& desc) {
    if (!finite3(eyeWorld)) return makeError("eyeWorld must be finite");
    if (!std::isfinite(desc.albedo) || desc.albedo < 0.0f || desc.albedo > 1.0f) return makeError("GasLightingDesc.albedo must be in [0, 1]");
    if (Status s = checkNonNegative(desc.emission, "emission"); !s) return s;
    if (Status s = checkNonNegative(desc.multipleScattering, "multipleScattering"); !s) return s;
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(desc.ambient[a]) || desc.ambient[a] < 0.0f)
            return makeError(std::string("GasLightingDesc.ambient.") + "rgb"[a] + " must be a finite number >= 0");
    for (std::size_t i = 0; i < lights.size(); ++i)
        if (Status s = validateLight(lights[i], "lights[" + std::to_string(i) + "]"); !s) return s;
    return {};
}

// (10^-12 world units)^2: the closest a point light is taken to be.
constexpr float kMinDist2 = 1e-24f;

// The model for `count` points: point(v) gives the world position (and
// false for data that is not finite), base(v) the base colour.
template <class PointFn, class BaseFn>
void lightImpl(std::size_t count, PointFn point, BaseFn base, float voxelSize, glm::vec3 eyeWorld, std::span<const Light> lights,
               const ShadowProvider* shadows, const GasLightingDesc& desc, std::vector<glm::vec3>& out) {
    // Up to this many lights are prepared on the stack; more are prepared per voxel (still no allocation).
    constexpr std::size_t kStackLights = 16;
    PreparedLight stackLights[kStackLights];
    auto prepare = [&](const Light& l) {
        PreparedLight p{};
        p.type = l.type;
        p.color = l.color * l.intensity;
        p.travel = l.type == LightType::Point ? glm::vec3(0.0f) : glm::normalize(l.direction);
        p.position = l.position;
        p.cosOuter = std::cos(l.outerConeRad);
        p.cosInner = std::cos(l.innerConeRad);
        // A light inside a voxel's material lights it from all sides: the
        // irradiance of its nearest surface, half a voxel away.
        p.minDist = std::max(l.radiusWorld, 0.5f * voxelSize);
        p.minDist2 = p.minDist * p.minDist;
        return p;
    };
    for (std::size_t i = 0; i < std::min(lights.size(), kStackLights); ++i) stackLights[i] = prepare(lights[i]);

    const float isotropic = 1.0f / kFourPi;
    out.resize(count);
    for (std::size_t v = 0; v < count; ++v) {
        glm::vec3 x;
        if (!point(v, x) || !finite3(x)) {
            out[v] = glm::vec3(0.0f);
            continue;
        }
        const glm::vec3 toEyeV = eyeWorld - x;
        const float eyeDist = glm::length(toEyeV);
        const glm::vec3 toEye = eyeDist > 0.0f ? toEyeV / eyeDist : glm::vec3(0.0f);
        glm::vec3 scattered = desc.ambient;
        for (std::size_t i = 0; i < lights.size(); ++i) {
            const PreparedLight l = i < kStackLights ? stackLights[i] : prepare(lights[i]);
            float irradiance = 1.0f, phase;
            if (l.type == LightType::Directional) {
                phase = eyeDist > 0.0f ? desc.phase(l.travel, toEye) : isotropic;
            } else {
                const glm::vec3 fromLight = x - l.position;
                const float d2 = glm::dot(fromLight, fromLight);
                // kMinDist2: a light exactly on a zero-size point with
                // radiusWorld 0 gets a huge but finite irradiance, not inf.
                irradiance = 1.0f / std::max({d2, l.minDist2, kMinDist2});
                const float d = std::sqrt(d2);
                const glm::vec3 travel = d > 0.0f ? fromLight / d : l.travel;
                // Within minDist the light is among the voxel's material and
                // reaches it from every side: the phase function's mean, 1 / 4 pi.
                phase = (d >= l.minDist && eyeDist > 0.0f) ? desc.phase(travel, toEye) : isotropic;
                if (l.type == LightType::Spot) irradiance *= smoothstep(l.cosOuter, l.cosInner, glm::dot(travel, l.travel));
            }
            if (irradiance <= 0.0f) continue;
            float T = shadows ? shadows->transmittance(i, x) : 1.0f;
            T = std::isfinite(T) ? std::clamp(T, 0.0f, 1.0f) : 0.0f;
            scattered += l.color * (irradiance * (kFourPi * phase * T + desc.multipleScattering));
        }
        out[v] = base(v) * (desc.emission + desc.albedo * scattered);
    }
}

} // namespace

Status lightVoxels(const Grid& grid, glm::vec3 eyeWorld, std::span<const Light> lights, const ShadowProvider* shadows, const GasLightingDesc& desc,
                   std::vector<glm::vec3>& out) {
    if (Status s = checkInputs(eyeWorld, lights, desc); !s) return s;
    const glm::mat3 shape =
        glm::mat3(grid.transform) * glm::mat3(glm::vec3(grid.spacing.x, 0, 0), glm::vec3(0, grid.spacing.y, 0), glm::vec3(0, 0, grid.spacing.z));
    const float det = std::abs(glm::determinant(shape));
    const float voxelSize = std::isfinite(det) ? std::cbrt(det) : 0.0f;
    const bool hasTable = desc.colorTable && desc.colorTable->entries.size() >= 2;
    auto point = [&](std::size_t v, glm::vec3& x) {
        const Voxel& vox = grid.voxels[v];
        x = grid.worldPosition(vox.cell);
        return std::isfinite(vox.opacity) && std::isfinite(vox.colorCoord);
    };
    auto base = [&](std::size_t v) {
        return hasTable ? glm::clamp(glm::vec3(desc.colorTable->sample(grid.voxels[v].colorCoord)), 0.0f, 1.0f) : glm::vec3(1.0f);
    };
    lightImpl(grid.voxels.size(), point, base, voxelSize, eyeWorld, lights, shadows, desc, out);
    return {};
}

Status lightPoints(std::span<const glm::vec3> worldPoints, float voxelSizeWorld, glm::vec3 eyeWorld, std::span<const Light> lights,
                   const ShadowProvider* shadows, const GasLightingDesc& desc, std::vector<glm::vec3>& out) {
    if (Status s = checkInputs(eyeWorld, lights, desc); !s) return s;
    if (!std::isfinite(voxelSizeWorld) || voxelSizeWorld < 0.0f) return makeError("voxelSizeWorld must be a finite number >= 0");
    auto point = [&](std::size_t v, glm::vec3& x) {
        x = worldPoints[v];
        return true;
    };
    auto base = [](std::size_t) { return glm::vec3(1.0f); };
    lightImpl(worldPoints.size(), point, base, voxelSizeWorld, eyeWorld, lights, shadows, desc, out);
    return {};
}

} // namespace splatfx
