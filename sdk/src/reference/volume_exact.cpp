// Volume-exact reference: emission-absorption integration of the field
// untextured splatting reconstructs (see reference.hpp).
#include <algorithm>
#include <cmath>
#include <mutex>
#include <vector>

#include "reference_common.hpp"
#include "splatfx/reference.hpp"

namespace splatfx {
namespace {

// 4-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree 7.
constexpr double kGx[4] = {-0.86113631159405257522, -0.33998104358485626480, 0.33998104358485626480, 0.86113631159405257522};
constexpr double kGw[4] = {0.34785484513745385737, 0.65214515486254614263, 0.65214515486254614263, 0.34785484513745385737};

// A kernel whose support the ray crosses, in kernel space: point(t) = y + t b.
struct Crossing {
    double t0, t1;
    glm::dvec3 y, b;
    double scale;
    glm::dvec3 color;
    const ContinuousMedium* medium = nullptr; // set: a medium's box (origin and dir in y, b), not a kernel
};

struct RayResult {
    glm::dvec3 color{0.0}; // premultiplied emission
    double transmittance = 1.0;
};

// Lit: the field, the eye, the lighting and the ray in world space, so each
// Gauss point's source can be lit where it is.
struct LitRay {
    const VolumeField* field = nullptr;
    const LitVolumeDesc* desc = nullptr;
    glm::dvec3 eye{0.0}, origin{0.0}, dir{0.0};
};

RayResult integrate(const std::vector<Crossing>& cs, const std::vector<double>& breaks, const Footprint& fp, double h, double cutoff,
                    std::uint64_t& evals, const LitRay& lit) {
    RayResult r;
    std::vector<const Crossing*> active;
    for (size_t i = 0; i + 1 < breaks.size(); ++i) {
        const double a = breaks[i], b = breaks[i + 1];
        if (!(b > a)) continue;
        active.clear();
        const double mid = 0.5 * (a + b);
        for (const Crossing& c : cs)
            if (c.t0 <= mid && mid <= c.t1) active.push_back(&c);
        if (active.empty()) continue;
        // Within a piece no support boundary is crossed, so the field is smooth.
        const int steps = std::max(1, int(std::ceil((b - a) / h - 1e-9)));
        const double ds = (b - a) / steps;
        for (int s = 0; s < steps; ++s) {
            const double m = a + (s + 0.5) * ds;
            double tau = 0.0;
            glm::dvec3 tauColor(0.0);
            for (int g = 0; g < 4; ++g) {
                const double t = m + 0.5 * ds * kGx[g];
                double e = 0.0;
                glm::dvec3 ec(0.0);
                for (const Crossing* c : active) {
                    if (c->medium) {
                        const ContinuousMedium::Sample ms = c->medium->sample(c->y + t * c->b);
                        e += ms.extinction;
                        ec += ms.extinction * ms.color;
                        continue;
                    }
                    const double k = c->scale * fp.kernel(glm::length(c->y + t * c->b));
                    e += k;
                    ec += k * c->color;
                }
                evals += active.size();
                if (lit.desc && e > 0.0) ec *= litFactor(*lit.field, lit.origin + t * lit.dir, lit.eye, *lit.desc);
                tau += kGw[g] * e;
                tauColor += kGw[g] * ec;
            }
            tau *= 0.5 * ds;
            tauColor *= 0.5 * ds;
            if (tau > 0.0) {
                // Exact when the colour is constant over the step, whatever sigma does.
                const double absorbed = -std::expm1(-tau);
                r.color += r.transmittance * absorbed * (tauColor / tau);
                r.transmittance *= 1.0 - absorbed;
            }
            if (r.transmittance < cutoff) return r;
        }
    }
    return r;
}

} // namespace

Result<Image> renderVolumeExact(const VolumeField& field, const Camera& camera, const VolumeExactDesc& desc, VolumeExactStats* statsOut) {
    if (Status s = reference::checkHost(desc.host, camera, "renderVolumeExact"); !s) return makeError(s.error());
    if (!(desc.tolerance > 0.0)) return makeError("renderVolumeExact: desc.tolerance must be positive");
    if (desc.lighting) {
        // The SDK's own checks of the lights and the gas desc (no points: nothing is lit).
        std::vector<glm::vec3> none;
        if (Status s = lightPoints({}, 0.0f, camera.eye(), desc.lighting->lights, nullptr, desc.lighting->gas, none); !s)
            return makeError("renderVolumeExact: desc.lighting: " + s.error());
    }
    const int W = camera.viewport.x, H = camera.viewport.y;
    const Footprint& fp = field.materials().footprint();
    const double R = fp.radius();
    const auto& kernels = field.kernels();

    double h0 = desc.initialStep;
    if (!(h0 > 0.0)) {
        double smallest = 1e300;
        for (const auto& k : kernels) smallest = std::min(smallest, R * std::cbrt(1.0 / std::abs(glm::determinant(k.inverse))));
        for (const ContinuousMedium& m : field.media()) smallest = std::min(smallest, m.featureSize);
        h0 = smallest < 1e300 ? 0.25 * smallest : 1.0;
    }

    Image out;
    out.width = W;
    out.height = H;
    out.channels = 4;
    out.pixels.assign(size_t(W) * H * 4, 0.0f);
    const reference::RayMapper mapper(camera);
    VolumeExactStats stats;
    std::mutex statsMutex;

    reference::parallelRows(H, desc.threads, [&](int y) {
        VolumeExactStats local;
        std::vector<Crossing> cs;
        std::vector<double> breaks;
        for (int x = 0; x < W; ++x) {
            const reference::PixelRay ray = mapper.ray(x, y, reference::hostDepth(desc.host, x, y));
            cs.clear();
            breaks.clear();
            for (const auto& k : kernels) {
                const glm::dvec3 toC = k.center - ray.origin;
                const double along = glm::dot(toC, ray.dir);
                if (glm::dot(toC, toC) - along * along > k.boundRadius * k.boundRadius) continue;
                // Where |y + t b| = R: the ray's chord through the (ellipsoidal) support.
                const glm::dvec3 yy = k.inverse * (ray.origin - k.center), b = k.inverse * ray.dir;
                const double A = glm::dot(b, b), B = glm::dot(yy, b), C = glm::dot(yy, yy) - R * R;
                const double disc = B * B - A * C;
                if (!(disc > 0.0)) continue;
                const double sq = std::sqrt(disc);
                const double t0 = std::max((-B - sq) / A, 0.0), t1 = std::min((-B + sq) / A, ray.tLimit);
                if (!(t1 > t0)) continue;
                cs.push_back({t0, t1, yy, b, k.scale, k.color, nullptr});
                breaks.push_back(t0);
                breaks.push_back(t1);
            }
            for (const ContinuousMedium& m : field.media()) {
                // The ray's stretch inside the medium's box (slabs), cut at its kinks.
                double t0 = 0.0, t1 = ray.tLimit;
                for (int a = 0; a < 3; ++a) {
                    if (ray.dir[a] == 0.0) {
                        if (ray.origin[a] < m.boxMin[a] || ray.origin[a] > m.boxMax[a]) t1 = -1.0;
                        continue;
                    }
                    const double ta = (m.boxMin[a] - ray.origin[a]) / ray.dir[a], tb = (m.boxMax[a] - ray.origin[a]) / ray.dir[a];
                    t0 = std::max(t0, std::min(ta, tb));
                    t1 = std::min(t1, std::max(ta, tb));
                }
                if (!(t1 > t0)) continue;
                cs.push_back({t0, t1, ray.origin, ray.dir, 0.0, glm::dvec3(0.0), &m});
                breaks.push_back(t0);
                breaks.push_back(t1);
                if (m.breaks) m.breaks(ray.origin, ray.dir, t0, t1, breaks);
            }
            const LitRay lit{&field, desc.lighting, glm::dvec3(camera.eye()), ray.origin, ray.dir};
            std::sort(breaks.begin(), breaks.end());
            breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
            // Stop once what is left behind cannot change the pixel by tolerance / 1000.
            const double cutoff = desc.tolerance * 1e-3;
            RayResult res;
            if (desc.fixedStep > 0.0) {
                res = integrate(cs, breaks, fp, desc.fixedStep, cutoff, local.kernelEvaluations, lit);
            } else {
                double h = h0;
                RayResult prev = integrate(cs, breaks, fp, h, cutoff, local.kernelEvaluations, lit);
                res = prev;
                double err = 0.0;
                int level = 0;
                for (level = 1; level <= desc.maxHalvings; ++level) {
                    h *= 0.5;
                    res = integrate(cs, breaks, fp, h, cutoff, local.kernelEvaluations, lit);
                    err = std::abs(res.transmittance - prev.transmittance);
                    for (int c = 0; c < 3; ++c) err = std::max(err, std::abs(res.color[c] - prev.color[c]));
                    if (level >= desc.minHalvings && err < desc.tolerance) break;
                    prev = res;
                }
                if (level > desc.maxHalvings) {
                    ++local.unconverged;
                    level = desc.maxHalvings;
                }
                local.maxErrorEstimate = std::max(local.maxErrorEstimate, err);
                local.maxHalvingsUsed = std::max(local.maxHalvingsUsed, level);
            }
            const glm::dvec4 bg = reference::background(desc.host, x, y);
            const double T = res.transmittance;
            out.at(x, y, 0) = float(res.color.r + T * bg.r);
            out.at(x, y, 1) = float(res.color.g + T * bg.g);
            out.at(x, y, 2) = float(res.color.b + T * bg.b);
            out.at(x, y, 3) = float((1.0 - T) + T * bg.a);
        }
        std::lock_guard<std::mutex> lock(statsMutex);
        stats.maxErrorEstimate = std::max(stats.maxErrorEstimate, local.maxErrorEstimate);
        stats.maxHalvingsUsed = std::max(stats.maxHalvingsUsed, local.maxHalvingsUsed);
        stats.unconverged += local.unconverged;
        stats.kernelEvaluations += local.kernelEvaluations;
    });
    if (statsOut) *statsOut = stats;
    return out;
}

} // namespace splatfx
