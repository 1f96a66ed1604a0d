#include <array>
#include <cmath>
#include <string>

#include "splatfx/reference.hpp"

namespace splatfx {
namespace {

// Sum over one cube face of radiance x cosine x solid angle, at n x n pixels.
Result<glm::dvec3> faceIntegral(const std::vector<Splat>& splats, const Materials& materials, glm::dvec3 point, glm::dvec3 normal, glm::dvec3 forward,
                                glm::dvec3 up, int n, const IrradianceExactDesc& desc) {
    const Camera camera = Camera::lookAt(glm::vec3(point), glm::vec3(point + forward), glm::vec3(up), float(M_PI / 2.0), {n, n}, float(desc.nearDistance), 1e6f);
    Result<Image> image = renderSplatExact(splats, camera, materials, {.threads = desc.threads, .packedColor = desc.packedColor, .depthCut = true});
    if (!image) return makeError(image.error());
    const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
    const glm::dvec3 top = glm::cross(right, forward);
    glm::dvec3 sum(0.0);
    const double pixel = 2.0 / n; // side of a pixel on the face at distance 1
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            // Output rows are top first.
            const double fx = -1.0 + (x + 0.5) * pixel, fy = 1.0 - (y + 0.5) * pixel;
            const glm::dvec3 ray = forward + fx * right + fy * top;
            const double len2 = glm::dot(ray, ray);
            const double cosine = glm::dot(normal, ray) / std::sqrt(len2);
            if (!(cosine > 0.0)) continue;
            // Solid angle of the pixel: its area / len^3 (midpoint rule).
            const double omega = pixel * pixel / (len2 * std::sqrt(len2));
            sum += glm::dvec3(image->at(x, y, 0), image->at(x, y, 1), image->at(x, y, 2)) * (cosine * omega);
        }
    return sum;
}

Result<glm::dvec3> sphereIntegral(const std::vector<Splat>& splats, const Materials& materials, glm::dvec3 point, glm::dvec3 normal, int n,
                                  const IrradianceExactDesc& desc) {
    static const std::array<std::pair<glm::dvec3, glm::dvec3>, 6> faces{{{{1, 0, 0}, {0, 1, 0}},
                                                                         {{-1, 0, 0}, {0, 1, 0}},
                                                                         {{0, 0, 1}, {0, 1, 0}},
                                                                         {{0, 0, -1}, {0, 1, 0}},
                                                                         {{0, 1, 0}, {0, 0, -1}},
                                                                         {{0, -1, 0}, {0, 0, 1}}}};
    glm::dvec3 sum(0.0);
    for (const auto& [forward, up] : faces) {
        if (glm::dot(forward, normal) <= -std::sqrt(2.0) / 2.0) continue; // the face lies wholly behind the surface
        Result<glm::dvec3> f = faceIntegral(splats, materials, point, normal, forward, up, n, desc);
        if (!f) return f;
        sum += *f;
    }
    return sum;
}

} // namespace

Result<IrradianceExact> emittedIrradianceExact(const std::vector<Splat>& splats, const Materials& materials, glm::dvec3 point, glm::dvec3 normal,
                                               const IrradianceExactDesc& desc) {
    if (desc.faceSize < 2 || desc.faceSize > 4096)
        return makeError("IrradianceExactDesc.faceSize must be in [2, 4096], got " + std::to_string(desc.faceSize));
    if (!(desc.nearDistance > 0.0) || !std::isfinite(desc.nearDistance)) return makeError("IrradianceExactDesc.nearDistance must be finite and > 0");
    const double len = glm::length(normal);
    if (!(len > 0.0) || !std::isfinite(len)) return makeError("emittedIrradianceExact: normal must be finite and non-zero");
    if (!std::isfinite(point.x + point.y + point.z)) return makeError("emittedIrradianceExact: point must be finite");
    normal /= len;
    Result<glm::dvec3> fine = sphereIntegral(splats, materials, point, normal, desc.faceSize, desc);
    if (!fine) return makeError(fine.error());
    Result<glm::dvec3> coarse = sphereIntegral(splats, materials, point, normal, std::max(desc.faceSize / 2, 1), desc);
    if (!coarse) return makeError(coarse.error());
    const glm::dvec3 d = glm::abs(*fine - *coarse);
    return IrradianceExact{.irradiance = *fine, .errorEstimate = std::max(d.x, std::max(d.y, d.z))};
}

} // namespace splatfx
