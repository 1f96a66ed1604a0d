// The ground fog's continuous field, integrated along pixel rays
// (reference.hpp, integrateGroundFogRay / renderGroundFogExact): the layer of
// Roettger & Ertl 2002, sec. 6 between the terrain and the fog top, never
// through the tetrahedra GroundFog emits, so their split, the LOD and the
// sort-free mode each show their own error against it.
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

struct State {
    glm::dvec3 color{0.0};
    double T = 1.0;
};

// Along one triangle's stretch of the ray, g1 = y - terrain and g2 = top - y
// are linear in t (both surfaces are planes over the triangle), so the scalar
// is linear (affine model) or a ratio of linear functions (the paper's).
struct Piece {
    double t0, t1;           // the stretch inside the layer
    double g1a, g1b;         // y - terrain at t0, t1
    double g2a, g2b;         // top - y at t0, t1
    double density, depth;   // GroundFogDesc::density, densityDepthWorld
    double g1(double t) const { return g1a + (g1b - g1a) * (t - t0) / (t1 - t0); }
    double g2(double t) const { return g2a + (g2b - g2a) * (t - t0) / (t1 - t0); }
    double scalar(double t) const {
        const double a = std::max(g1(t), 0.0), b = std::max(g2(t), 0.0);
        if (depth > 0.0) return std::min(density * b / depth, 1.0);
        return a + b > 0.0 ? density * b / (a + b) : 0.0;
    }
};

struct Integrator {
    const TransferFunction& transfer;
    double tolerance;
    int maxHalvings;
    double errorEstimate = 0.0;
    bool converged = true;
    std::uint64_t pieces = 0;

    // `steps` equal steps on [a, b]: optical depth by Gauss-Legendre, emission
    // (1 - e^-tau) times the extinction-weighted colour (exact for a constant
    // colour, second order in the step otherwise).
    State run(State s, const Piece& p, double a, double b, int steps) const {
        const double h = (b - a) / steps;
        for (int k = 0; k < steps; ++k) {
            const double m = a + (k + 0.5) * h;
            double tau = 0.0;
            glm::dvec3 ec(0.0);
            for (int g = 0; g < 4; ++g) {
                const double sc = p.scalar(m + 0.5 * h * kGx[g]);
                const double sigma = transfer.extinction(sc);
                tau += kGw[g] * sigma;
                ec += kGw[g] * sigma * transfer.color(sc);
            }
            tau *= 0.5 * h;
            ec *= 0.5 * h;
            if (tau > 0.0) {
                const double absorbed = -std::expm1(-tau);
                s.color += s.T * absorbed * ec / tau;
                s.T *= 1.0 - absorbed;
            }
        }
        return s;
    }

    // Halve the step until two results agree to the tolerance.
    void integrate(State& s, const Piece& p, double a, double b) {
        if (!(b > a)) return;
        ++pieces;
        int steps = 1;
        State prev = run(s, p, a, b, steps), cur = prev;
        double err = 0.0;
        int level = 1;
        for (; level <= maxHalvings; ++level) {
            steps *= 2;
            cur = run(s, p, a, b, steps);
            err = std::max({std::abs(cur.T - prev.T), std::abs(cur.color.r - prev.color.r), std::abs(cur.color.g - prev.color.g),
                            std::abs(cur.color.b - prev.color.b)});
            if (err < tolerance) break;
            prev = cur;
        }
        if (level > maxHalvings) converged = false;
        errorEstimate += err;
        s = cur;
    }

    // One layer stretch, cut where the scalar crosses a control point of the
    // transfer function (its kinks) and where the affine scalar reaches 1.
    void layer(State& s, const Piece& p) {
        std::vector<double> cuts{p.t0, p.t1};
        auto root = [&](double fa, double fb) { // the zero of a linear function on (t0, t1)
            if ((fa < 0.0) == (fb < 0.0) || fa == fb) return;
            const double u = fa / (fa - fb);
            if (u > 0.0 && u < 1.0) cuts.push_back(p.t0 + (p.t1 - p.t0) * u);
        };
        std::vector<double> levels;
        for (const TransferPoint& q : transfer.points()) levels.push_back(double(q.scalar));
        if (p.depth > 0.0) levels.push_back(1.0);
        for (double q : levels) {
            // affine: density g2 - q D = 0; the paper's: density g2 - q (g1 + g2) = 0.
            if (p.depth > 0.0) root(p.density * p.g2a - q * p.depth, p.density * p.g2b - q * p.depth);
            else root(p.density * p.g2a - q * (p.g1a + p.g2a), p.density * p.g2b - q * (p.g1b + p.g2b));
        }
        std::sort(cuts.begin(), cuts.end());
        for (std::size_t k = 0; k + 1 < cuts.size(); ++k) integrate(s, p, cuts[k], cuts[k + 1]);
    }
};

} // namespace

glm::dvec4 integrateGroundFogRay(const GroundFogDesc& desc, const TransferFunction& transfer, glm::dvec3 origin, glm::dvec3 dir, double tNear,
                                 double tFar, double tolerance, int maxHalvings, GroundFogRayStats* statsOut) {
    GroundFogRayStats stats;
    if (statsOut) *statsOut = stats;
    const double speed = glm::length(dir);
    const std::size_t n = std::size_t(std::max(desc.dims.x, 0)) * std::size_t(std::max(desc.dims.y, 0));
    if (!(speed > 0.0) || !std::isfinite(speed) || std::isnan(tNear) || std::isnan(tFar) || !std::isfinite(origin.x) || !std::isfinite(origin.y) ||
        !std::isfinite(origin.z) || desc.dims.x < 2 || desc.dims.y < 2 || desc.terrainHeight.size() != n || desc.fogTop.size() != n ||
        !(desc.spacingWorld > 0.0f) || !(tolerance > 0.0))
        return glm::dvec4(0.0);
    const glm::dvec3 d = dir / speed;
    // t is world distance from `origin` from here on.
    double lo = std::max(tNear * speed, -1e30), hi = std::min(tFar * speed, 1e30);

    // Grid coordinates along the ray: gx = ax + bx t, gz = az + bz t.
    const double s = desc.spacingWorld;
    const double ax = (origin.x - double(desc.originWorld.x)) / s, bx = d.x / s;
    const double az = (origin.z - double(desc.originWorld.z)) / s, bz = d.z / s;
    const int nx = desc.dims.x, nz = desc.dims.y;
    auto bottomAt = [&](int i, int j) { return double(desc.terrainHeight[std::size_t(i) + std::size_t(nx) * std::size_t(j)]); };
    // The builder's thickness, in double: the top never below the terrain.
    auto thickAt = [&](int i, int j) {
        const std::size_t k = std::size_t(i) + std::size_t(nx) * std::size_t(j);
        return std::max(double(desc.fogTop[k]) - double(desc.terrainHeight[k]), 0.0);
    };
    double yLo = INFINITY, yHi = -INFINITY;
    for (std::size_t k = 0; k < n; ++k) {
        yLo = std::min(yLo, double(desc.terrainHeight[k]));
        yHi = std::max(yHi, std::max(double(desc.fogTop[k]), double(desc.terrainHeight[k])));
    }
    // Clip to the layer's box (slabs in grid x, grid z and world y).
    auto slab = [&](double a, double b, double lower, double upper) {
        if (b == 0.0) {
            if (a < lower || a > upper) hi = lo - 1.0;
            return;
        }
        double t0 = (lower - a) / b, t1 = (upper - a) / b;
        if (t0 > t1) std::swap(t0, t1);
        lo = std::max(lo, t0), hi = std::min(hi, t1);
    };
    slab(ax, bx, 0.0, double(nx - 1));
    slab(az, bz, 0.0, double(nz - 1));
    slab(origin.y, d.y, yLo, yHi);
    if (!(hi > lo)) return glm::dvec4(0.0);

    // Every crossing of a grid line inside [lo, hi]: between two, the ray is in one cell.
    std::vector<double> ts{lo, hi};
    auto lines = [&](double a, double b, int count) {
        if (b == 0.0) return;
        const double g0 = a + b * lo, g1 = a + b * hi;
        const int first = std::max(0, int(std::ceil(std::min(g0, g1)))), last = std::min(count - 1, int(std::floor(std::max(g0, g1))));
        for (int i = first; i <= last; ++i) {
            const double t = (double(i) - a) / b;
            if (t > lo && t < hi) ts.push_back(t);
        }
    };
    lines(ax, bx, nx);
    lines(az, bz, nz);
    std::sort(ts.begin(), ts.end());

    Integrator in{transfer, tolerance, maxHalvings};
    State st;
    for (std::size_t c = 0; c + 1 < ts.size() && st.T >= 1e-18; ++c) {
        const double ta = ts[c], tb = ts[c + 1];
        if (!(tb > ta)) continue;
        const double tm = 0.5 * (ta + tb);
        const int i = std::clamp(int(std::floor(ax + bx * tm)), 0, nx - 2), j = std::clamp(int(std::floor(az + bz * tm)), 0, nz - 2);
        // The builder's triangulation: cell (i, j) split along (i, j)-(i+1, j+1)
        // when i + j is even, else along (i+1, j)-(i, j+1). In cell coordinates
        // (u, v) the diagonal is u - v = 0 or u + v - 1 = 0.
        const bool even = ((i + j) & 1) == 0;
        auto diag = [&](double t) {
            const double u = ax + bx * t - i, v = az + bz * t - j;
            return even ? u - v : u + v - 1.0;
        };
        std::vector<double> sub{ta, tb};
        const double da = diag(ta), db = diag(tb);
        if ((da < 0.0) != (db < 0.0) && da != db) {
            const double t = ta + (tb - ta) * da / (da - db);
            if (t > ta && t < tb) sub.insert(sub.begin() + 1, t);
        }
        for (std::size_t k = 0; k + 1 < sub.size(); ++k) {
            const double t0 = sub[k], t1 = sub[k + 1];
            if (!(t1 > t0)) continue;
            const double side = diag(0.5 * (t0 + t1));
            // The triangle's corners (cell offsets) on the side of the diagonal the stretch is on.
            glm::ivec2 v0, v1, v2;
            if (even) {
                if (side >= 0.0) v0 = {0, 0}, v1 = {1, 0}, v2 = {1, 1}; // u >= v: below the diagonal
                else v0 = {0, 0}, v1 = {1, 1}, v2 = {0, 1};
            } else {
                if (side <= 0.0) v0 = {0, 0}, v1 = {1, 0}, v2 = {0, 1};
                else v0 = {1, 0}, v1 = {1, 1}, v2 = {0, 1};
            }
            // A linear function over the triangle from its corner values, at ray parameter t.
            auto linear = [&](auto&& value, double t) {
                const double u = ax + bx * t - i, v = az + bz * t - j;
                const double f0 = value(i + v0.x, j + v0.y), f1 = value(i + v1.x, j + v1.y), f2 = value(i + v2.x, j + v2.y);
                // Barycentric in the unit right triangle (v1 - v0 and v2 - v0 are orthogonal or not: solve 2x2).
                const double e1x = v1.x - v0.x, e1z = v1.y - v0.y, e2x = v2.x - v0.x, e2z = v2.y - v0.y;
                const double det = e1x * e2z - e2x * e1z;
                const double pu = u - v0.x, pv = v - v0.y;
                const double l1 = (pu * e2z - e2x * pv) / det, l2 = (e1x * pv - pu * e1z) / det;
                return f0 + l1 * (f1 - f0) + l2 * (f2 - f0);
            };
            auto g1 = [&](double t) { return origin.y + d.y * t - linear(bottomAt, t); };
            auto g2 = [&](double t) { return linear(bottomAt, t) + linear(thickAt, t) - (origin.y + d.y * t); };
            // Inside the layer: g1 >= 0 and g2 >= 0, each linear, so one interval.
            double l0 = t0, l1 = t1;
            for (const auto& g : {std::make_pair(g1(t0), g1(t1)), std::make_pair(g2(t0), g2(t1))}) {
                const double fa = g.first, fb = g.second;
                if (fa < 0.0 && fb < 0.0) l1 = l0 - 1.0;
                else if (fa < 0.0) l0 = std::max(l0, t0 + (t1 - t0) * fa / (fa - fb));
                else if (fb < 0.0) l1 = std::min(l1, t0 + (t1 - t0) * fa / (fa - fb));
            }
            if (!(l1 > l0)) continue;
            Piece p{l0, l1, g1(l0), g1(l1), g2(l0), g2(l1), double(desc.density), double(desc.densityDepthWorld)};
            in.layer(st, p);
        }
    }
    stats.errorEstimate = in.errorEstimate;
    stats.converged = in.converged;
    stats.pieces = in.pieces;
    stats.transmittance = st.T;
    if (statsOut) *statsOut = stats;
    return glm::dvec4(st.color, 1.0 - st.T);
}

Result<Image> renderGroundFogExact(const GroundFogDesc& fogDesc, const TransferFunction& transfer, const Camera& camera,
                                   const GroundFogExactDesc& desc, GroundFogExactStats* statsOut) {
    if (Status s = reference::checkHost(desc.host, camera, "renderGroundFogExact"); !s) return makeError(s.error());
    if (!(desc.tolerance > 0.0) || !std::isfinite(desc.tolerance)) return makeError("renderGroundFogExact: desc.tolerance must be positive");
    if (desc.maxHalvings < 1 || desc.maxHalvings > 20) return makeError("renderGroundFogExact: desc.maxHalvings must be in [1, 20]");
    { // The layer's own checks (the LOD's tables are not needed here).
        GroundFogDesc plain;
        plain.dims = fogDesc.dims, plain.originWorld = fogDesc.originWorld, plain.spacingWorld = fogDesc.spacingWorld;
        plain.density = fogDesc.density, plain.densityDepthWorld = fogDesc.densityDepthWorld;
        plain.terrainHeight = fogDesc.terrainHeight, plain.fogTop = fogDesc.fogTop;
        if (auto f = GroundFog::create(plain); !f) return makeError("renderGroundFogExact: " + f.error());
    }
    const int W = camera.viewport.x, H = camera.viewport.y;
    Image out;
    out.width = W;
    out.height = H;
    out.channels = 4;
    out.pixels.assign(std::size_t(W) * H * 4, 0.0f);
    const reference::RayMapper mapper(camera);
    GroundFogExactStats stats;
    std::mutex statsMutex;
    reference::parallelRows(H, desc.threads, [&](int y) {
        GroundFogExactStats local;
        for (int x = 0; x < W; ++x) {
            const double hd = reference::hostDepth(desc.host, x, y);
            const reference::PixelRay ray = mapper.ray(x, y, std::isnan(hd) || hd < 0.0 ? 2.0 : hd); // bad depth: none
            GroundFogRayStats rs;
            const glm::dvec4 c = integrateGroundFogRay(fogDesc, transfer, ray.origin, ray.dir, 0.0, ray.tLimit, desc.tolerance, desc.maxHalvings, &rs);
            local.maxErrorEstimate = std::max(local.maxErrorEstimate, rs.errorEstimate);
            local.unconverged += rs.converged ? 0 : 1;
            local.pieces += rs.pieces;
            const double T = 1.0 - c.a;
            const glm::dvec4 bg = reference::background(desc.host, x, y);
            for (int ch = 0; ch < 3; ++ch) out.at(x, y, ch) = float(c[ch] + T * bg[ch]);
            out.at(x, y, 3) = float(c.a + T * bg.a);
        }
        std::lock_guard<std::mutex> lock(statsMutex);
        stats.maxErrorEstimate = std::max(stats.maxErrorEstimate, local.maxErrorEstimate);
        stats.unconverged += local.unconverged;
        stats.pieces += local.pieces;
    });
    if (statsOut) *statsOut = stats;
    return out;
}

} // namespace splatfx
