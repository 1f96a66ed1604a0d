// (issue 14 + 17) Tetrahedra and fog in one medium (reference.hpp,
// renderTetraExact / integrateRayWithFog): the physical emission-absorption
// integral of the cloud's transfer function and the fog together, in double.
#include <algorithm>
#include <cmath>
#include <mutex>
#include <vector>

#include "reference_common.hpp"
#include "splatfx/reference.hpp"

namespace splatfx {
namespace {

// 4-point Gauss-Legendre on [-1, 1].
constexpr double kGx[4] = {-0.86113631159405257522, -0.33998104358485626480, 0.33998104358485626480, 0.86113631159405257522};
constexpr double kGw[4] = {0.34785484513745385737, 0.65214515486254614263, 0.65214515486254614263, 0.34785484513745385737};

// The state carried along a ray: emitted colour (premultiplied), the cloud's
// own transmittance and the fog's (from the eye), kept apart because a frame
// drawn without the host fog pass counts fog only in front of cloud matter.
struct RayState {
    glm::dvec3 color{0.0};
    double cloudT = 1.0;
    double fogT = 1.0;
};

struct Piece {
    double t0, t1;
    std::size_t tet;
};

// The pieces of the ray inside each tetrahedron, in ray order.
std::vector<Piece> piecesAlong(const std::vector<Tetrahedron>& tets, glm::dvec3 o, glm::dvec3 d, double tNear, double tFar) {
    std::vector<Piece> pieces;
    static constexpr int kFaces[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};
    for (std::size_t i = 0; i < tets.size(); ++i) {
        const Tetrahedron& t = tets[i];
        double lo = tNear, hi = tFar;
        for (const auto& f : kFaces) {
            const glm::dvec3 a(t.position[std::size_t(f[0])]), b(t.position[std::size_t(f[1])]), c(t.position[std::size_t(f[2])]),
                q(t.position[std::size_t(f[3])]);
            glm::dvec3 n = glm::cross(b - a, c - a);
            if (glm::dot(n, q - a) < 0.0) n = -n; // inward
            const double num = glm::dot(n, o - a), den = glm::dot(n, d);
            if (den == 0.0) {
                if (num < 0.0) hi = lo - 1.0;
                continue;
            }
            const double tc = -num / den;
            if (den > 0.0) lo = std::max(lo, tc);
            else hi = std::min(hi, tc);
        }
        if (hi > lo) pieces.push_back({lo, hi, i});
    }
    std::sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) { return a.t0 < b.t0; });
    return pieces;
}

struct Integrator {
    const TransferFunction& transfer;
    const Fog* fog;
    double timeSec;
    double tolerance;
    int maxHalvings;
    glm::dvec3 o, d; // unit d, t in world units from o (the eye)
    double farT;     // the fog's far cut-off along the ray (infinity: none)
    double errorEstimate = 0.0;
    bool converged = true;

    glm::dvec3 fogColour() const { return fog ? fog->desc().colour : glm::dvec3(0.0); }

    // Crossing the far cut-off: what fog transmittance is left turns into fog
    // colour at once (the GL passes give f = 0 beyond it).
    void wall(RayState& s) const {
        s.color += s.cloudT * s.fogT * fogColour();
        s.fogT = 0.0;
    }

    // Fog only on [a, b] (exact up to the numerical quadrature's tolerance).
    void fogOnly(RayState& s, double a, double b) {
        if (!fog || !(b > a) || s.fogT == 0.0) return;
        const FogQuadrature q = integrateFogNumerically(*fog, o + a * d, o + b * d, timeSec, tolerance * 1e-2);
        if (!q.converged) converged = false;
        errorEstimate += q.errorEstimate;
        const double absorbed = -std::expm1(-q.value);
        s.color += s.cloudT * s.fogT * absorbed * fogColour();
        s.fogT *= 1.0 - absorbed;
    }

    // Cloud and fog together on [a, b] of one tetrahedron, `steps` equal
    // steps: each step's optical depths by Gauss-Legendre, its emission
    // (1 - e^-(tc + tf)) times the extinction-weighted colour (exact for a
    // colour constant over the step; second order in the step otherwise).
    RayState combined(RayState s, double a, double b, int steps, double sa, double sb, double ma, double mb) const {
        if (!(b > a)) return s; // an empty piece (the ray grazes a face): nothing to integrate, and u would be 0/0
        const double h = (b - a) / steps;
        const glm::dvec3 fc = fogColour();
        for (int k = 0; k < steps; ++k) {
            const double m = a + (k + 0.5) * h;
            double tc = 0.0, tf = 0.0;
            glm::dvec3 ec(0.0);
            for (int g = 0; g < 4; ++g) {
                const double t = m + 0.5 * h * kGx[g];
                const double u = (t - a) / (b - a);
                const double sc = sa + (sb - sa) * u, ls = std::max(0.0, ma + (mb - ma) * u);
                const double sigma = transfer.extinction(sc) * ls;
                tc += kGw[g] * sigma;
                ec += kGw[g] * sigma * transfer.color(sc);
                if (fog) tf += kGw[g] * std::max(0.0, fog->density(o + t * d, timeSec));
            }
            tc *= 0.5 * h;
            tf *= 0.5 * h;
            ec *= 0.5 * h;
            const double tau = tc + tf;
            if (tau > 0.0) {
                const double absorbed = -std::expm1(-tau);
                s.color += s.cloudT * s.fogT * absorbed * (ec + tf * fc) / tau;
            }
            s.cloudT *= std::exp(-tc);
            s.fogT *= std::exp(-tf);
        }
        return s;
    }

    // One tetrahedron piece, halving the step until two results agree.
    void piece(RayState& s, double a, double b, double sa, double sb, double ma, double mb) {
        int steps = 2;
        RayState prev = combined(s, a, b, steps, sa, sb, ma, mb), cur = prev;
        double err = 0.0;
        int level = 1;
        for (; level <= maxHalvings; ++level) {
            steps *= 2;
            cur = combined(s, a, b, steps, sa, sb, ma, mb);
            err = std::max({std::abs(cur.cloudT - prev.cloudT), std::abs(cur.fogT - prev.fogT), std::abs(cur.color.r - prev.color.r),
                            std::abs(cur.color.g - prev.color.g), std::abs(cur.color.b - prev.color.b)});
            if (err < tolerance) break;
            prev = cur;
        }
        if (level > maxHalvings) converged = false;
        errorEstimate += err;
        s = cur;
    }

    // Cut [a, b] at the far cut-off, integrating the fog-only or combined part on each side.
    template <typename F>
    void split(RayState& s, double a, double b, F&& run) {
        if (a < farT && b > farT) {
            run(s, a, farT);
            wall(s);
            run(s, farT, b);
        } else {
            if (a >= farT && s.fogT > 0.0) wall(s);
            run(s, a, b);
        }
    }
};

} // namespace

glm::dvec4 integrateRayWithFog(const std::vector<Tetrahedron>& tets, const TransferFunction& transfer, glm::dvec3 eye, glm::dvec3 dir, double tNear,
                               double tFar, const RayFogDesc& desc, RayFogStats* statsOut) {
    RayFogStats stats;
    const double speed = glm::length(dir);
    if (!(speed > 0.0) || !std::isfinite(speed) || std::isnan(tNear) || std::isnan(tFar) || !std::isfinite(eye.x) || !std::isfinite(eye.y) ||
        !std::isfinite(eye.z)) {
        if (statsOut) *statsOut = stats;
        return glm::dvec4(0.0);
    }
    const glm::dvec3 d = dir / speed;
    tNear *= speed; // from here on t is world distance from the eye
    tFar = std::min(tFar * speed, 1e30);
    const Fog* fog = desc.fog && !desc.fog->empty() ? desc.fog : nullptr;
    Integrator in{transfer,
                  fog,
                  desc.timeSec,
                  desc.tolerance,
                  desc.maxHalvings,
                  eye,
                  d,
                  fog && fog->desc().farDistanceWorld > 0.0 ? fog->desc().farDistanceWorld : INFINITY};
    RayState s;
    in.fogOnly(s, 0.0, tNear); // the fog between the eye and the near plane
    double reached = tNear;
    for (const Piece& p : piecesAlong(tets, eye, d, tNear, tFar)) {
        const double t0 = std::max(p.t0, reached); // shared faces: each stretch of the ray once
        if (!(p.t1 > t0)) continue;
        in.split(s, reached, t0, [&](RayState& st, double a, double b) { in.fogOnly(st, a, b); });
        const Tetrahedron& t = tets[p.tet];
        const glm::dvec3 p0(t.position[0]);
        const glm::dmat3 inv =
            glm::inverse(glm::dmat3(glm::dvec3(t.position[1]) - p0, glm::dvec3(t.position[2]) - p0, glm::dvec3(t.position[3]) - p0));
        auto at = [&](double tt, const std::array<float, 4>& v) {
            const glm::dvec3 l = inv * (eye + d * tt - p0);
            return (1.0 - l.x - l.y - l.z) * v[0] + l.x * v[1] + l.y * v[2] + l.z * v[3];
        };
        // Cut further where the scalar crosses a control point (a kink of the transfer function).
        const double sa = at(t0, t.scalar), sb = at(p.t1, t.scalar), ma = at(t0, t.lengthScale), mb = at(p.t1, t.lengthScale);
        std::vector<double> cuts{0.0, 1.0};
        if (sa != sb)
            for (const TransferPoint& q : transfer.points()) {
                const double u = (double(q.scalar) - sa) / (sb - sa);
                if (u > 0.0 && u < 1.0) cuts.push_back(u);
            }
        std::sort(cuts.begin(), cuts.end());
        for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
            const double ua = cuts[k], ub = cuts[k + 1];
            if (!(ub > ua)) continue;
            const double a = t0 + (p.t1 - t0) * ua, b = t0 + (p.t1 - t0) * ub;
            in.split(s, a, b, [&](RayState& st, double x0, double x1) {
                const double u0 = (x0 - t0) / (p.t1 - t0), u1 = (x1 - t0) / (p.t1 - t0);
                in.piece(st, x0, x1, sa + (sb - sa) * u0, sa + (sb - sa) * u1, ma + (mb - ma) * u0, ma + (mb - ma) * u1);
            });
        }
        reached = p.t1;
        if (s.cloudT < 1e-18) break;
    }
    // The fog behind the last piece to the ray's end (the host point), so that
    // s.fogT is the fog's transmittance there.
    in.split(s, reached, tFar, [&](RayState& st, double a, double b) { in.fogOnly(st, a, b); });
    stats.errorEstimate = in.errorEstimate;
    stats.converged = in.converged;
    stats.cloudTransmittance = s.cloudT;
    stats.fogTransmittance = s.fogT;
    if (statsOut) *statsOut = stats;
    if (desc.fogHost) return glm::dvec4(s.color, 1.0 - s.cloudT * s.fogT);
    // Without the host fog pass the GL frame counts fog only in front of cloud
    // matter (f c + (1 - f) alpha C_fog per layer): the physical colour less the
    // fog that reaches the background through the whole cloud, alpha the cloud's.
    return glm::dvec4(s.color - s.cloudT * (1.0 - s.fogT) * in.fogColour(), 1.0 - s.cloudT);
}

Result<Image> renderTetraExact(const std::vector<Tetrahedron>& tets, const TransferFunction& transfer, const Camera& camera,
                               const TetraExactDesc& desc, TetraExactStats* statsOut) {
    if (Status s = reference::checkHost(desc.host, camera, "renderTetraExact"); !s) return makeError(s.error());
    if (!(desc.tolerance > 0.0)) return makeError("renderTetraExact: desc.tolerance must be positive");
    if (desc.maxHalvings < 1 || desc.maxHalvings > 20) return makeError("renderTetraExact: desc.maxHalvings must be in [1, 20]");
    if (!camera.perspective())
        return makeError("renderTetraExact: needs a perspective camera (the fog is integrated from the eye along each pixel ray)");
    const int W = camera.viewport.x, H = camera.viewport.y;
    Image out;
    out.width = W;
    out.height = H;
    out.channels = 4;
    out.pixels.assign(std::size_t(W) * H * 4, 0.0f);
    const reference::RayMapper mapper(camera);
    const glm::dvec3 eye(camera.eye());
    TetraExactStats stats;
    std::mutex statsMutex;
    reference::parallelRows(H, desc.threads, [&](int y) {
        TetraExactStats local;
        for (int x = 0; x < W; ++x) {
            const double hd = reference::hostDepth(desc.host, x, y);
            const reference::PixelRay ray = mapper.ray(x, y, std::isnan(hd) || hd < 0.0 ? 2.0 : hd); // bad depth: none
            const double tNear = glm::length(ray.origin - eye);                                      // the ray passes through the eye
            RayFogStats rs;
            const glm::dvec4 c = integrateRayWithFog(
                tets, transfer, eye, ray.dir, tNear, tNear + ray.tLimit,
                {.fog = desc.fog, .timeSec = desc.fogTimeSec, .fogHost = desc.fogHost, .tolerance = desc.tolerance, .maxHalvings = desc.maxHalvings},
                &rs);
            local.maxErrorEstimate = std::max(local.maxErrorEstimate, rs.errorEstimate);
            local.unconverged += rs.converged ? 0 : 1;
            const double T = 1.0 - c.a;
            const glm::dvec4 px = c;
            const glm::dvec4 bg = reference::background(desc.host, x, y);
            for (int ch = 0; ch < 3; ++ch) out.at(x, y, ch) = float(px[ch] + T * bg[ch]);
            out.at(x, y, 3) = float(px.a + T * bg.a);
        }
        std::lock_guard<std::mutex> lock(statsMutex);
        stats.maxErrorEstimate = std::max(stats.maxErrorEstimate, local.maxErrorEstimate);
        stats.unconverged += local.unconverged;
    });
    if (statsOut) *statsOut = stats;
    return out;
}

} // namespace splatfx
