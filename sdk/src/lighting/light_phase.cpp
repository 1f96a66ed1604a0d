// Lights and Henyey-Greenstein phase functions (Ebert & Parent 1990, "Illumination of gaseous phenomena").
#include <algorithm>
#include <cmath>

#include "splatfx/lighting.hpp"

#include "grid/number_text.hpp"

namespace splatfx {
namespace {

constexpr double kPi = 3.14159265358979323846;

using grid_detail::str; // numbers in messages as the grid module shows them

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

Status checkColor(const glm::vec3& c, const std::string& field) {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(c[a]) || c[a] < 0.0f) return makeError(field + "." + "rgb"[a] + " must be a finite number >= 0, got " + str(c[a]));
    return {};
}

} // namespace

Light Light::directional(glm::vec3 direction, glm::vec3 color, float intensity) {
    Light l;
    l.type = LightType::Directional;
    l.direction = direction;
    l.color = color;
    l.intensity = intensity;
    return l;
}

Light Light::point(glm::vec3 position, glm::vec3 color, float intensity) {
    Light l;
    l.type = LightType::Point;
    l.position = position;
    l.color = color;
    l.intensity = intensity;
    return l;
}

Light Light::spot(glm::vec3 position, glm::vec3 direction, float innerConeRad, float outerConeRad, glm::vec3 color, float intensity) {
    Light l;
    l.type = LightType::Spot;
    l.position = position;
    l.direction = direction;
    l.innerConeRad = innerConeRad;
    l.outerConeRad = outerConeRad;
    l.color = color;
    l.intensity = intensity;
    return l;
}

Status validateLight(const Light& light, const std::string& name) {
    if (light.type != LightType::Directional && light.type != LightType::Point && light.type != LightType::Spot)
        return makeError(name + ".type is not a LightType");
    if (Status s = checkColor(light.color, name + ".color"); !s) return s;
    if (!std::isfinite(light.intensity) || light.intensity < 0.0f)
        return makeError(name + ".intensity must be a finite number >= 0, got " + str(light.intensity));
    if (light.type != LightType::Point) {
        if (!finite3(light.direction)) return makeError(name + ".direction must be finite");
        // A direction is normalized by the SDK; below this its square underflows.
        if (glm::dot(light.direction, light.direction) < 1e-30f) return makeError(name + ".direction must not be zero");
    }
    if (light.type != LightType::Directional) {
        if (!finite3(light.position)) return makeError(name + ".position must be finite");
        if (!std::isfinite(light.radiusWorld) || light.radiusWorld < 0.0f)
            return makeError(name + ".radiusWorld must be a finite number >= 0, got " + str(light.radiusWorld));
    }
    if (light.type == LightType::Spot) {
        if (!std::isfinite(light.outerConeRad) || light.outerConeRad <= 0.0f || light.outerConeRad >= float(kPi))
            return makeError(name + ".outerConeRad must be in (0, pi), got " + str(light.outerConeRad));
        if (!std::isfinite(light.innerConeRad) || light.innerConeRad < 0.0f || light.innerConeRad > light.outerConeRad)
            return makeError(name + ".innerConeRad must be in [0, outerConeRad = " + str(light.outerConeRad) + "], got " + str(light.innerConeRad));
    }
    return {};
}

Result<PhaseFunction> PhaseFunction::create(std::span<const HgLobe> lobes) {
    if (lobes.empty()) return makeError("lobes must hold at least one Henyey-Greenstein lobe");
    if (lobes.size() > std::size_t(kMaxLobes))
        return makeError("lobes holds " + std::to_string(lobes.size()) + " lobes; at most " + std::to_string(kMaxLobes) + " are supported");
    double sum = 0.0;
    for (std::size_t i = 0; i < lobes.size(); ++i) {
        const std::string at = "lobes[" + std::to_string(i) + "]";
        // |g| = 1 is a delta function, not a density; beyond 1 - 1e-6 the
        // peak (about 1 / (2 pi (1 - g)^2)) no longer fits a float.
        if (!std::isfinite(lobes[i].g) || !(std::abs(lobes[i].g) < 1.0f)) return makeError(at + ".g must be in (-1, 1), got " + str(lobes[i].g));
        if (std::abs(lobes[i].g) > 1.0f - 1e-6f)
            return makeError(at + ".g must be within 1e-6 of +-1 at most (its peak would overflow), got " + str(lobes[i].g));
        if (!std::isfinite(lobes[i].weight) || lobes[i].weight < 0.0f)
            return makeError(at + ".weight must be a finite number >= 0, got " + str(lobes[i].weight));
        sum += lobes[i].weight;
    }
    if (!(sum > 0.0) || !std::isfinite(sum)) return makeError("lobes: at least one weight must be positive (and the sum finite)");
    PhaseFunction p;
    p.mCount = int(lobes.size());
    for (std::size_t i = 0; i < lobes.size(); ++i) p.mLobes[i] = {lobes[i].g, float(double(lobes[i].weight) / sum)};
    return p;
}

namespace {

// One lobe from 1 - mu and 1 + mu (each in [0, 2]).
// 1 + g^2 - 2 g mu is written so that no two large terms cancel when |g|
// is near 1: for g >= 0 as (1 - g)^2 + 2 g (1 - mu), for g < 0 as
// (1 + g)^2 - 2 g (1 + mu); both terms are then >= 0.
double hg(double g, double oneMinusMu, double onePlusMu) {
    const double den = g >= 0.0 ? (1.0 - g) * (1.0 - g) + 2.0 * g * oneMinusMu : (1.0 + g) * (1.0 + g) - 2.0 * g * onePlusMu;
    return (1.0 - g) * (1.0 + g) / (4.0 * kPi * den * std::sqrt(den));
}

} // namespace

float PhaseFunction::henyeyGreenstein(float g, float cosTheta) {
    const double mu = std::isfinite(cosTheta) ? std::clamp(double(cosTheta), -1.0, 1.0) : 0.0;
    return float(hg(g, 1.0 - mu, 1.0 + mu));
}

float PhaseFunction::operator()(float cosTheta) const {
    const double mu = std::isfinite(cosTheta) ? std::clamp(double(cosTheta), -1.0, 1.0) : 0.0;
    double p = 0.0;
    for (int i = 0; i < mCount; ++i) p += double(mLobes[std::size_t(i)].weight) * hg(mLobes[std::size_t(i)].g, 1.0 - mu, 1.0 + mu);
    return float(p);
}

float PhaseFunction::operator()(glm::vec3 a, glm::vec3 b) const {
    const glm::dvec3 da(a), db(b);
    // For unit a, b: |a - b|^2 = 2 (1 - cos), |a + b|^2 = 2 (1 + cos), each
    // accurate to the vectors' own precision even at tiny angles.
    double omc = 0.5 * glm::dot(da - db, da - db), opc = 0.5 * glm::dot(da + db, da + db);
    if (!std::isfinite(omc) || !std::isfinite(opc)) omc = opc = 1.0;
    omc = std::clamp(omc, 0.0, 2.0);
    opc = std::clamp(opc, 0.0, 2.0);
    double p = 0.0;
    for (int i = 0; i < mCount; ++i) p += double(mLobes[std::size_t(i)].weight) * hg(mLobes[std::size_t(i)].g, omc, opc);
    return float(p);
}

} // namespace splatfx
