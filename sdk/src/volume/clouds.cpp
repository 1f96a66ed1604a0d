// Clouds, Roettger & Ertl 2002 sec. 5: 3D Perlin density, an isotropic light
// field from ambient plus attenuated diffuse sun light, and the non-physical
// transfer functions of sec. 5.2.
#include "splatfx/volume.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "texture/noise.hpp"
#include "volume/cloud_sweep.hpp"

namespace splatfx {

namespace detail {

void sweepSunTransmittance(glm::ivec3 n, const std::vector<float>& ext, double scale, glm::dvec3 sun, std::vector<float>& trans) {
    const std::size_t count = std::size_t(n.x) * std::size_t(n.y) * std::size_t(n.z);
    auto at = [&](int x, int y, int z) { return std::size_t(x) + std::size_t(n.x) * (std::size_t(y) + std::size_t(n.y) * std::size_t(z)); };
    trans.assign(count, 1.0f);
    const int axis =
        (std::fabs(sun.x) >= std::fabs(sun.y) && std::fabs(sun.x) >= std::fabs(sun.z)) ? 0 : (std::fabs(sun.y) >= std::fabs(sun.z) ? 1 : 2);
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const glm::dvec3 stepToSun = sun / std::fabs(sun[axis]); // one plane toward the sun
    const double stepLen = glm::length(stepToSun);
    const int towardSun = sun[axis] > 0.0 ? 1 : -1;
    const int planes = n[axis];
    auto sample = [&](const std::vector<float>& f, int plane, double pu, double pv) { // inside the plane
        const int iu = std::min(int(pu), n[u] - 2), iv = std::min(int(pv), n[v] - 2);
        const double fu = pu - iu, fv = pv - iv;
        auto g = [&](int a, int b) {
            glm::ivec3 p;
            p[axis] = plane;
            p[u] = a;
            p[v] = b;
            return double(f[at(p.x, p.y, p.z)]);
        };
        return (1 - fu) * (1 - fv) * g(iu, iv) + fu * (1 - fv) * g(iu + 1, iv) + (1 - fu) * fv * g(iu, iv + 1) + fu * fv * g(iu + 1, iv + 1);
    };
    for (int k = 1; k < planes; ++k) {
        const int plane = towardSun > 0 ? planes - 1 - k : k;
        const int prev = plane + towardSun;
        for (int b = 0; b < n[v]; ++b)
            for (int a = 0; a < n[u]; ++a) {
                glm::ivec3 p;
                p[axis] = plane;
                p[u] = a;
                p[v] = b;
                const double qu = a + stepToSun[u], qv = b + stepToSun[v];
                if (qu < 0.0 || qv < 0.0 || qu > double(n[u] - 1) || qv > double(n[v] - 1)) {
                    // The step leaves the grid: a sideways step is at most one
                    // cell, so the point lies on a face toward the sun and its
                    // ray leaves at once (no material on the way).
                    trans[at(p.x, p.y, p.z)] = 1.0f;
                    continue;
                }
                const double tPrev = sample(trans, prev, qu, qv);
                const double rho = 0.5 * (double(ext[at(p.x, p.y, p.z)]) + sample(ext, prev, qu, qv));
                trans[at(p.x, p.y, p.z)] = float(tPrev * std::exp(-scale * rho * stepLen));
            }
    }
}

} // namespace detail

Result<ScalarVolume> makeCloudVolume(const CloudDesc& desc) {
    const glm::ivec3 n = desc.dims;
    if (n.x < 2 || n.y < 2 || n.z < 2 || n.x > 4097 || n.y > 4097 || n.z > 4097)
        return makeError("CloudDesc.dims must be in [2, 4097] along every axis");
    if (!std::isfinite(desc.featureCells) || !(desc.featureCells > 0.0f)) return makeError("CloudDesc.featureCells must be finite and > 0");
    if (desc.octaves < 1 || desc.octaves > 12) return makeError("CloudDesc.octaves must be in [1, 12]");
    if (!std::isfinite(desc.coverage) || desc.coverage <= 0.0f || desc.coverage > 1.0f) return makeError("CloudDesc.coverage must be in (0, 1]");
    if (!std::isfinite(desc.sharpness) || !(desc.sharpness > 0.0f)) return makeError("CloudDesc.sharpness must be finite and > 0");
    const glm::dvec3 sun(desc.sunDirection);
    if (!std::isfinite(sun.x) || !std::isfinite(sun.y) || !std::isfinite(sun.z) || glm::length(sun) == 0.0)
        return makeError("CloudDesc.sunDirection must be finite and non-zero");
    if (!std::isfinite(desc.ambient) || !std::isfinite(desc.diffuse) || desc.ambient < 0.0f || desc.diffuse < 0.0f ||
        desc.ambient + desc.diffuse > 1.0f + 1e-6f)
        return makeError("CloudDesc.ambient and CloudDesc.diffuse must be >= 0 with ambient + diffuse <= 1");
    if (!std::isfinite(desc.lightExtinctionPerCell) || desc.lightExtinctionPerCell < 0.0f)
        return makeError("CloudDesc.lightExtinctionPerCell must be finite and >= 0");

    const std::size_t count = std::size_t(n.x) * std::size_t(n.y) * std::size_t(n.z);
    auto at = [&](int x, int y, int z) { return std::size_t(x) + std::size_t(n.x) * (std::size_t(y) + std::size_t(n.y) * std::size_t(z)); };
    std::vector<float> density(count, 0.0f);
    const detail::Noise4 noise(desc.seed);
    // fBm normalised by the sum of the octave gains; the 4th noise coordinate is
    // a fixed slice so this is 3D Perlin noise.
    double gainSum = 0.0;
    for (int o = 0; o < desc.octaves; ++o) gainSum += std::ldexp(1.0, -o);
    const double cut = 1.0 - double(desc.coverage);
    for (int z = 0; z < n.z; ++z) {
        // Cumulus profile: zero on the bottom and top layers, full in the middle.
        const double hgt = double(z) / double(n.z - 1);
        const double profile = std::min(1.0, 4.0 * hgt * (1.0 - hgt) * 1.5);
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                double v = 0.0;
                for (int o = 0; o < desc.octaves; ++o) {
                    const double f = std::ldexp(1.0, o) / double(desc.featureCells);
                    v += std::ldexp(1.0, -o) * noise(x * f, y * f, z * f, 0.37 + 7.1 * o);
                }
                const double n01 = 0.5 + v / gainSum; // about [0, 1]
                const double d = std::min(1.0, std::max(0.0, (n01 * profile - cut) * double(desc.sharpness) / double(desc.coverage)));
                density[at(x, y, z)] = float(d);
            }
    }

    // Light: the sun's transmittance by a plane sweep through the density.
    std::vector<float> light(count, 1.0f), trans;
    detail::sweepSunTransmittance(n, density, double(desc.lightExtinctionPerCell), sun, trans);
    float fMax = 0.0f;
    for (std::size_t i = 0; i < count; ++i) {
        light[i] = std::min(1.0f, desc.ambient + desc.diffuse * trans[i]);
        fMax = std::max(fMax, density[i]);
    }

    ScalarVolume out;
    out.dims = n;
    if (desc.model == CloudModel::DensityTableLightLength) {
        out.scalar = std::move(density);
        out.lengthScale = std::move(light);
    } else {
        // Sec. 5.1: the table indexes gamma; l' = l f / f_max (eq. 9).
        out.scalar = std::move(light);
        out.lengthScale.resize(count);
        for (std::size_t i = 0; i < count; ++i) out.lengthScale[i] = fMax > 0.0f ? density[i] / fMax : 0.0f;
    }
    return out;
}

Result<TransferFunction> makeCloudTransfer(const CloudTransferDesc& desc, CloudModel model) {
    if (!std::isfinite(desc.threshold) || desc.threshold < 0.0f || desc.threshold >= 1.0f)
        return makeError("CloudTransferDesc.threshold must be in [0, 1)");
    if (!std::isfinite(desc.maxExtinctionPerWorld) || desc.maxExtinctionPerWorld < 0.0f)
        return makeError("CloudTransferDesc.maxExtinctionPerWorld must be finite and >= 0");
    auto mixc = [](glm::vec3 a, glm::vec3 b, float t) { return a + (b - a) * t; };
    if (model == CloudModel::LightTableDensityLength) {
        // kappa ramps with the light, rho = Id: the density enters through the length (eq. 9).
        return TransferFunction::create({{0.0f, desc.dark, desc.maxExtinctionPerWorld}, {1.0f, desc.bright, desc.maxExtinctionPerWorld}});
    }
    // Inverse colour ramp in density; rho linear in density, zero below the threshold (a step there).
    const float t = desc.threshold;
    std::vector<TransferPoint> pts;
    pts.push_back({0.0f, desc.bright, 0.0f});
    if (t > 0.0f) pts.push_back({t, mixc(desc.bright, desc.dark, t), 0.0f});
    pts.push_back({t, mixc(desc.bright, desc.dark, t), desc.maxExtinctionPerWorld * t});
    pts.push_back({1.0f, desc.dark, desc.maxExtinctionPerWorld});
    return TransferFunction::create(std::move(pts));
}

} // namespace splatfx
