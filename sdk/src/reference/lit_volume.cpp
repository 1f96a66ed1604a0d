// The lit volume reference (see reference.hpp, LitVolumeDesc): lighting.hpp's
// low-albedo model at any point of the continuous field, in double, with the
// transmittance to each light integrated through that field.
#include <algorithm>
#include <cmath>
#include <vector>

#include "reference_common.hpp"
#include "splatfx/reference.hpp"

namespace splatfx {
namespace {

constexpr double kPi = 3.14159265358979323846;
// 6-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree 11.
constexpr double kGx[6] = {-0.93246951420315202781, -0.66120938646626451366, -0.23861918608319690863,
                           0.23861918608319690863,  0.66120938646626451366,  0.93246951420315202781};
constexpr double kGw[6] = {0.17132449237917034504, 0.36076157304813860757, 0.46791393457269104739,
                           0.46791393457269104739, 0.36076157304813860757, 0.17132449237917034504};
constexpr int kMaxPanels = 1 << 12;

double smoothstep(double a, double b, double x) {
    if (!(b > a)) return x >= b ? 1.0 : 0.0;
    const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// A medium's optical depth along from + t dir, t in [0, L]: clipped to its
// box, cut at its breaks, each piece by 6-point Gauss-Legendre on panels
// doubled until two results agree to `tolerance` (absolute, in optical
// depth). A trilinear medium's piece is a cubic: exact at once.
double mediumSegmentDepth(const ContinuousMedium& m, glm::dvec3 from, glm::dvec3 dir, double L, double tolerance) {
    double t0 = 0.0, t1 = L;
    for (int a = 0; a < 3; ++a) {
        if (dir[a] == 0.0) {
            if (from[a] < m.boxMin[a] || from[a] > m.boxMax[a]) return 0.0;
            continue;
        }
        double u = (m.boxMin[a] - from[a]) / dir[a], v = (m.boxMax[a] - from[a]) / dir[a];
        if (u > v) std::swap(u, v);
        t0 = std::max(t0, u);
        t1 = std::min(t1, v);
    }
    if (!(t1 > t0)) return 0.0;
    std::vector<double> cuts{t0, t1};
    if (m.breaks) m.breaks(from, dir, t0, t1, cuts);
    std::sort(cuts.begin(), cuts.end());
    double tau = 0.0;
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
        const double a = std::max(cuts[c], t0), b = std::min(cuts[c + 1], t1);
        if (!(b > a)) continue;
        auto gauss = [&](int panels) {
            const double h = (b - a) / panels;
            double sum = 0.0;
            for (int p = 0; p < panels; ++p) {
                const double mid = a + (p + 0.5) * h;
                for (int g = 0; g < 6; ++g) {
                    // The sampler is called only inside the box (ContinuousMedium::sample).
                    const glm::dvec3 x = glm::clamp(from + (mid + 0.5 * h * kGx[g]) * dir, m.boxMin, m.boxMax);
                    sum += kGw[g] * m.sample(x).extinction;
                }
            }
            return sum * 0.5 * h;
        };
        double coarse = gauss(1), fine = coarse;
        for (int n = 2; n <= kMaxPanels; n *= 2) {
            fine = gauss(n);
            if (std::abs(fine - coarse) <= tolerance) break;
            coarse = fine;
        }
        tau += fine;
    }
    return tau;
}

} // namespace

double VolumeField::segmentOpticalDepth(glm::dvec3 from, glm::dvec3 to, double tolerance) const {
    const glm::dvec3 d = to - from;
    const double L = glm::length(d);
    if (!(L > 0.0) || !std::isfinite(L)) return 0.0;
    const glm::dvec3 dir = d / L;
    const Footprint& fp = mMaterials->footprint();
    const double R = mSupportRadius;
    double tau = 0.0;
    for (const VoxelKernel& k : mKernels) {
        const glm::dvec3 toC = k.center - from;
        const double along = glm::dot(toC, dir);
        if (glm::dot(toC, toC) - along * along > k.boundRadius * k.boundRadius) continue;
        // The segment's chord through the kernel's (ellipsoidal) support, in kernel space y + t b.
        const glm::dvec3 y = k.inverse * (from - k.center), b = k.inverse * dir;
        const double A = glm::dot(b, b), B = glm::dot(y, b), C = glm::dot(y, y) - R * R;
        const double disc = B * B - A * C;
        if (!(disc > 0.0)) continue;
        const double sq = std::sqrt(disc);
        const double t0 = std::max((-B - sq) / A, 0.0), t1 = std::min((-B + sq) / A, L);
        if (!(t1 > t0)) continue;
        auto gauss = [&](int panels) {
            const double h = (t1 - t0) / panels;
            double sum = 0.0;
            for (int p = 0; p < panels; ++p) {
                const double m = t0 + (p + 0.5) * h;
                for (int g = 0; g < 6; ++g) sum += kGw[g] * fp.kernel(glm::length(y + (m + 0.5 * h * kGx[g]) * b));
            }
            return sum * 0.5 * h;
        };
        // Relative to the kernel's depth through its centre along this direction, so a chord that
        // only grazes the support is not refined to no purpose.
        const double scaleDepth = mCentreFootprint / std::sqrt(A);
        double coarse = gauss(1), fine = coarse;
        for (int n = 2; n <= kMaxPanels; n *= 2) {
            fine = gauss(n);
            if (std::abs(fine - coarse) <= tolerance * scaleDepth) break;
            coarse = fine;
        }
        tau += k.scale * fine;
    }
    for (const ContinuousMedium& m : mMedia) tau += mediumSegmentDepth(m, from, dir, L, tolerance);
    return tau;
}

double VolumeField::opticalDepthToLight(glm::dvec3 world, const Light& light, double tolerance) const {
    if (light.type != LightType::Directional) return segmentOpticalDepth(world, glm::dvec3(light.position), tolerance);
    const glm::dvec3 dir(light.direction);
    const double len = glm::length(dir);
    if (!(len > 0.0) || (mKernels.empty() && mMedia.empty())) return 0.0;
    // Towards the light until past every kernel's bounding sphere and every medium's box.
    double reach = 0.0;
    for (const VoxelKernel& k : mKernels) reach = std::max(reach, glm::length(k.center - world) + k.boundRadius);
    for (const ContinuousMedium& m : mMedia)
        reach = std::max(reach, glm::length(glm::max(glm::abs(world - m.boxMin), glm::abs(world - m.boxMax))) + m.featureSize);
    return segmentOpticalDepth(world, world - dir / len * reach, tolerance);
}

double litPhase(const LitVolumeDesc& desc, double cosTheta, double oneMinusCos, double onePlusCos) {
    if (desc.phase) return desc.phase(cosTheta);
    double p = 0.0;
    for (int i = 0; i < desc.gas.phase.lobeCount(); ++i) {
        const HgLobe l = desc.gas.phase.lobe(i);
        const double g = l.g;
        // 1 + g^2 - 2 g mu without cancellation at |g| -> 1 (as PhaseFunction).
        const double den = g >= 0.0 ? (1.0 - g) * (1.0 - g) + 2.0 * g * oneMinusCos : (1.0 + g) * (1.0 + g) - 2.0 * g * onePlusCos;
        p += double(l.weight) * (1.0 - g * g) / (4.0 * kPi * den * std::sqrt(den));
    }
    return p;
}

glm::dvec3 litFactor(const VolumeField& field, glm::dvec3 x, glm::dvec3 eye, const LitVolumeDesc& desc) {
    const GasLightingDesc& gas = desc.gas;
    const glm::dvec3 toEyeV = eye - x;
    const double eyeDist = glm::length(toEyeV);
    const glm::dvec3 toEye = eyeDist > 0.0 ? toEyeV / eyeDist : glm::dvec3(0.0);
    glm::dvec3 scattered(gas.ambient);
    for (const Light& l : desc.lights) {
        double E = 1.0;
        glm::dvec3 travel(0.0);
        bool isotropic = !(eyeDist > 0.0);
        if (l.type == LightType::Directional) {
            travel = glm::normalize(glm::dvec3(l.direction));
        } else {
            const glm::dvec3 fromLight = x - glm::dvec3(l.position);
            const double d = glm::length(fromLight);
            const double dEff = std::max({d, double(l.radiusWorld), 1e-12});
            E = 1.0 / (dEff * dEff);
            if (d > 0.0) travel = fromLight / d;
            // Inside the light's own extent it reaches x from every side.
            isotropic = isotropic || !(d > 0.0) || d < double(l.radiusWorld);
            if (l.type == LightType::Spot) {
                const glm::dvec3 axis = glm::normalize(glm::dvec3(l.direction));
                E *= smoothstep(std::cos(double(l.outerConeRad)), std::cos(double(l.innerConeRad)), d > 0.0 ? glm::dot(travel, axis) : 1.0);
            }
        }
        if (!(E > 0.0)) continue;
        double p = 1.0 / (4.0 * kPi);
        if (!isotropic) {
            const glm::dvec3 a = travel - toEye, b = travel + toEye;
            const double omc = 0.5 * glm::dot(a, a), opc = 0.5 * glm::dot(b, b);
            p = litPhase(desc, 1.0 - omc, omc, opc);
        }
        const double T = std::exp(-field.opticalDepthToLight(x, l, desc.shadowTolerance));
        scattered += glm::dvec3(l.color) * double(l.intensity) * E * (4.0 * kPi * p * T + double(gas.multipleScattering));
    }
    return glm::dvec3(gas.emission) + double(gas.albedo) * scattered;
}

float VolumeFieldShadows::transmittance(std::size_t light, glm::vec3 world) const {
    if (light >= mLights.size()) return 1.0f;
    return float(std::exp(-mField->opticalDepthToLight(glm::dvec3(world), mLights[light], mTolerance)));
}

} // namespace splatfx
