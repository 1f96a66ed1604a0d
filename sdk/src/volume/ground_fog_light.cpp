// A ground fog layer lit by the sun with the low-albedo model, self-shadowed
// through its own continuous field and shadowed by the scene's casters
// (volume.hpp, GroundFog::setLighting).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "splatfx/volume.hpp"
#include "volume/ground_fog_light.hpp"
#include "volume/same_phase.hpp"

namespace splatfx {
namespace detail {
namespace {

// Integral over [0, L] of (a + b t) / (c + e t): the paper's scalar g2 /
// (g1 + g2) along a straight stretch, where the top's distance g2 and the
// thickness g1 + g2 are both linear. 0 <= g2 <= thickness, so the ratio is in
// [0, 1] even where the thickness reaches 0 at an end.
double ratioIntegral(double a, double b, double c, double e, double L) {
    const double cEnd = c + e * L;
    if (!(c > 0.0) && !(cEnd > 0.0)) return 0.0; // no thickness along it
    if (!(c > 0.0)) return L * std::clamp(b / e, 0.0, 1.0); // starts at zero thickness: a = 0, the ratio is b / e throughout
    const double x = e * L / c;
    double r;
    if (std::abs(x) < 1e-3) {
        // log1p's series to x^3: truncation below 1e-12 relative.
        const double q = (a * e - b * c) * L / (c * c);
        r = L * (a / c - q / 2.0 + q * x / 3.0 - q * x * x / 4.0);
    } else if (!(cEnd > 0.0)) {
        r = L * std::clamp(b / e, 0.0, 1.0); // ends at zero thickness: a e = b c, the ratio is b / e throughout
    } else {
        r = b * L / e + (a * e - b * c) / (e * e) * std::log1p(x);
    }
    return std::clamp(r, 0.0, L);
}

} // namespace

namespace {

// Walks p + t u, t in [lo, hi] (inside the grid's domain), over the layer's
// triangulation: visit(t0, t1, h0, h1, th0, th1) for each piece over one
// triangle, with the terrain h and thickness th at its ends (both linear on
// it). Returns false as soon as visit does (the walk stops).
template <class Visit>
bool walkTriangles(const FogFieldView& f, glm::dvec3 p, glm::dvec3 u, double lo, double hi, std::vector<double>& ts, Visit&& visit) {
    const double s = f.spacing;
    const double ax = (p.x - f.origin.x) / s, bx = u.x / s, az = (p.z - f.origin.y) / s, bz = u.z / s;
    ts.clear();
    ts.push_back(lo), ts.push_back(hi);
    auto lines = [&](double a, double b, int count) {
        if (b == 0.0) return;
        const double g0 = a + b * lo, g1 = a + b * hi;
        const int first = std::max(0, int(std::ceil(std::min(g0, g1)))), last = std::min(count - 1, int(std::floor(std::max(g0, g1))));
        for (int i = first; i <= last; ++i) {
            const double t = (double(i) - a) / b;
            if (t > lo && t < hi) ts.push_back(t);
        }
    };
    lines(ax, bx, f.nx);
    lines(az, bz, f.nz);
    std::sort(ts.begin(), ts.end());
    for (std::size_t c = 0; c + 1 < ts.size(); ++c) {
        const double ta = ts[c], tb = ts[c + 1];
        if (!(tb > ta)) continue;
        const double tm = 0.5 * (ta + tb);
        const int i = std::clamp(int(std::floor(ax + bx * tm)), 0, f.nx - 2), j = std::clamp(int(std::floor(az + bz * tm)), 0, f.nz - 2);
        // GroundFog's triangulation: diagonal (i, j)-(i+1, j+1) when i + j is even, else (i+1, j)-(i, j+1).
        const bool even = ((i + j) & 1) == 0;
        auto diag = [&](double t) {
            const double uu = ax + bx * t - i, vv = az + bz * t - j;
            return even ? uu - vv : uu + vv - 1.0;
        };
        double sub[3] = {ta, tb, tb};
        int ns = 2;
        const double da = diag(ta), db = diag(tb);
        if ((da < 0.0) != (db < 0.0) && da != db) {
            const double t = ta + (tb - ta) * da / (da - db);
            if (t > ta && t < tb) sub[1] = t, sub[2] = tb, ns = 3;
        }
        for (int k = 0; k + 1 < ns; ++k) {
            const double t0 = sub[k], t1 = sub[k + 1];
            if (!(t1 > t0)) continue;
            const double side = diag(0.5 * (t0 + t1));
            glm::ivec2 v0, v1, v2;
            if (even) {
                if (side >= 0.0) v0 = {0, 0}, v1 = {1, 0}, v2 = {1, 1};
                else v0 = {0, 0}, v1 = {1, 1}, v2 = {0, 1};
            } else {
                if (side <= 0.0) v0 = {0, 0}, v1 = {1, 0}, v2 = {0, 1};
                else v0 = {1, 0}, v1 = {1, 1}, v2 = {0, 1};
            }
            // Terrain and thickness are linear over the triangle.
            auto linear = [&](auto&& value, double t) {
                const double uu = ax + bx * t - i, vv = az + bz * t - j;
                const double f0 = value(i + v0.x, j + v0.y), f1 = value(i + v1.x, j + v1.y), f2 = value(i + v2.x, j + v2.y);
                const double e1x = v1.x - v0.x, e1z = v1.y - v0.y, e2x = v2.x - v0.x, e2z = v2.y - v0.y;
                const double det = e1x * e2z - e2x * e1z;
                const double pu = uu - v0.x, pv = vv - v0.y;
                const double l1 = (pu * e2z - e2x * pv) / det, l2 = (e1x * pv - pu * e1z) / det;
                return f0 + l1 * (f1 - f0) + l2 * (f2 - f0);
            };
            auto hAt = [&](int x, int z) { return f.h(x, z); };
            auto thAt = [&](int x, int z) { return f.th(x, z); };
            if (!visit(t0, t1, linear(hAt, t0), linear(hAt, t1), linear(thAt, t0), linear(thAt, t1))) return false;
        }
    }
    return true;
}

// Clips [0, tMax] of p + t u to the grid's domain in x and z and to [yLo, yHi]
// in y; false when nothing is left.
bool clipToLayer(const FogFieldView& f, glm::dvec3 p, glm::dvec3 u, double yLo, double yHi, double tMax, double& lo, double& hi) {
    const double s = f.spacing;
    lo = 0.0, hi = std::min(tMax, 1e30);
    auto slab = [&](double a, double b, double lower, double upper) {
        if (b == 0.0) {
            if (a < lower || a > upper) hi = lo - 1.0;
            return;
        }
        double t0 = (lower - a) / b, t1 = (upper - a) / b;
        if (t0 > t1) std::swap(t0, t1);
        lo = std::max(lo, t0), hi = std::min(hi, t1);
    };
    slab((p.x - f.origin.x) / s, u.x / s, 0.0, double(f.nx - 1));
    slab((p.z - f.origin.y) / s, u.z / s, 0.0, double(f.nz - 1));
    slab(p.y, u.y, yLo, yHi);
    return hi > lo;
}

} // namespace

double fogScalarIntegral(const FogFieldView& f, glm::dvec3 p, glm::dvec3 u, std::vector<double>& ts, double tMax) {
    double lo = 0.0, hi = 0.0;
    if (f.nx < 2 || f.nz < 2 || !(tMax > 0.0) || !clipToLayer(f, p, u, f.yLo, f.yHi, tMax, lo, hi)) return 0.0;
    double total = 0.0;
    walkTriangles(f, p, u, lo, hi, ts, [&](double t0, double t1, double h0, double h1, double th0, double th1) {
        const double y0 = p.y + u.y * t0, y1 = p.y + u.y * t1;
        // g1 = y - terrain, g2 = top - y: linear in t; the layer is where both are >= 0.
        const double g1a = y0 - h0, g1b = y1 - h1, g2a = h0 + th0 - y0, g2b = h1 + th1 - y1;
        double l0 = t0, l1 = t1;
        for (const auto& g : {std::make_pair(g1a, g1b), std::make_pair(g2a, g2b)}) {
            const double fa = g.first, fb = g.second;
            if (fa < 0.0 && fb < 0.0) l1 = l0 - 1.0;
            else if (fa < 0.0) l0 = std::max(l0, t0 + (t1 - t0) * fa / (fa - fb));
            else if (fb < 0.0) l1 = std::min(l1, t0 + (t1 - t0) * fa / (fa - fb));
        }
        if (!(l1 > l0)) return true;
        const double L = l1 - l0;
        auto at = [&](double fa, double fb, double t) { return fa + (fb - fa) * (t - t0) / (t1 - t0); };
        const double g2l0 = std::max(at(g2a, g2b, l0), 0.0), g2l1 = std::max(at(g2a, g2b, l1), 0.0);
        if (f.depth > 0.0) {
            total += f.density / f.depth * 0.5 * (g2l0 + g2l1) * L; // affine scalar: the trapezoid is exact
        } else {
            const double c0 = std::max(at(th0, th1, l0), 0.0), c1 = std::max(at(th0, th1, l1), 0.0);
            total += f.density * ratioIntegral(g2l0, (g2l1 - g2l0) / L, c0, (c1 - c0) / L, L);
        }
        return true;
    });
    return total;
}

bool terrainBlocks(const FogFieldView& f, glm::dvec3 p, glm::dvec3 u, std::vector<double>& ts) {
    // The ground goes on past the grid: a light below the horizon is behind it.
    if (u.y < 0.0) return true;
    if (f.nx < 2 || f.nz < 2) return false;
    // Only the terrain can block, so the walk ends where the ray rises above the
    // highest terrain point or leaves the grid.
    double lo = 0.0, hi = 0.0;
    if (!clipToLayer(f, p, u, -1e30, std::min(f.hMax, 1e30), 1e30, lo, hi)) return false;
    // Below the terrain by more than the rounding of the terrain's linear
    // interpolation (double, of floats of at most this size) is blocked; a ray
    // along the surface (a vertex's own slope, a sun on the horizon over flat
    // ground) is not.
    const double eps = 1e-9 * (1.0 + std::abs(f.yHi) + std::abs(f.yLo) + f.spacing);
    return !walkTriangles(f, p, u, lo, hi, ts, [&](double t0, double t1, double h0, double h1, double, double) {
        return !(p.y + u.y * t0 - h0 < -eps || p.y + u.y * t1 - h1 < -eps);
    });
}

double fogScalarAt(const FogFieldView& f, glm::dvec3 p) {
    if (f.nx < 2 || f.nz < 2 || !(p.y >= f.yLo && p.y <= f.yHi)) return 0.0;
    const double gx = (p.x - f.origin.x) / f.spacing, gz = (p.z - f.origin.y) / f.spacing;
    if (!(gx >= 0.0 && gx <= double(f.nx - 1) && gz >= 0.0 && gz <= double(f.nz - 1))) return 0.0;
    const int i = std::min(int(gx), f.nx - 2), j = std::min(int(gz), f.nz - 2);
    const double uu = gx - i, vv = gz - j;
    // The triangle of GroundFog's triangulation holding the point (as fogScalarIntegral), terrain and thickness linear on it.
    auto linear = [&](auto&& value) {
        const double v00 = value(i, j), v10 = value(i + 1, j), v01 = value(i, j + 1), v11 = value(i + 1, j + 1);
        if (((i + j) & 1) == 0) return uu >= vv ? v00 + uu * (v10 - v00) + vv * (v11 - v10) : v00 + vv * (v01 - v00) + uu * (v11 - v01);
        return uu + vv <= 1.0 ? v00 + uu * (v10 - v00) + vv * (v01 - v00) : v11 + (1.0 - uu) * (v01 - v11) + (1.0 - vv) * (v10 - v11);
    };
    const double h = linear([&](int x, int z) { return f.h(x, z); }), th = linear([&](int x, int z) { return f.th(x, z); });
    const double above = p.y - h, below = h + th - p.y; // g1, g2: the layer is where both are >= 0
    if (!(above >= 0.0 && below >= 0.0 && th > 0.0)) return 0.0;
    return f.depth > 0.0 ? f.density * below / f.depth : f.density * std::min(below / th, 1.0);
}

float FogLitView::scalarAt(glm::vec3 world, bool top) const {
    const FogFieldView& f = *field;
    const double gx = std::clamp((double(world.x) - f.origin.x) / f.spacing, 0.0, double(f.nx - 1));
    const double gz = std::clamp((double(world.z) - f.origin.y) / f.spacing, 0.0, double(f.nz - 1));
    auto value = [&](int i, int j) { return double(sunT[2 * f.at(i, j) + (top ? 1 : 0)]); };
    double T;
    const double ri = std::round(gx), rj = std::round(gz);
    // A grid point (float positions, rounded): its own value, bit for bit.
    if (std::abs(gx - ri) < 1e-4 && std::abs(gz - rj) < 1e-4) {
        T = value(int(ri), int(rj));
    } else { // between points: linear over the triangle of the triangulation
        const int i = std::clamp(int(std::floor(gx)), 0, f.nx - 2), j = std::clamp(int(std::floor(gz)), 0, f.nz - 2);
        const double uu = gx - i, vv = gz - j;
        const double t00 = value(i, j), t10 = value(i + 1, j), t01 = value(i, j + 1), t11 = value(i + 1, j + 1);
        if (((i + j) & 1) == 0) T = uu >= vv ? t00 + uu * (t10 - t00) + vv * (t11 - t10) : t00 + vv * (t01 - t00) + uu * (t11 - t01);
        else T = uu + vv <= 1.0 ? t00 + uu * (t10 - t00) + vv * (t01 - t00) : t11 + (1.0 - uu) * (t01 - t11) + (1.0 - vv) * (t10 - t11);
    }
    float s = float(T);
    if (!isotropic) {
        const glm::vec3 d = eye - world;
        const float len = glm::length(d);
        const glm::vec3 toEye = perspective && len > 0.0f ? d / len : back;
        s *= (*phase)(travel, toEye) * invPhaseMax;
    }
    return std::clamp(s, 0.0f, 1.0f);
}

} // namespace detail

namespace {

using detail::samePhase;

Status checkFogLighting(const GroundFogLighting& L) {
    if (Status s = validateLight(L.sun, "GroundFogLighting.sun"); !s) return s;
    if (L.sun.type != LightType::Directional) return makeError("GroundFogLighting.sun must be a directional light");
    const GasLightingDesc& g = L.gas;
    if (!std::isfinite(g.albedo) || g.albedo < 0.0f || g.albedo > 1.0f) return makeError("GroundFogLighting.gas.albedo must be in [0, 1]");
    if (!std::isfinite(g.multipleScattering) || g.multipleScattering < 0.0f)
        return makeError("GroundFogLighting.gas.multipleScattering must be finite and >= 0");
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(g.ambient[a]) || g.ambient[a] < 0.0f)
            return makeError(std::string("GroundFogLighting.gas.ambient.") + "rgb"[a] + " must be a finite number >= 0");
        if (!std::isfinite(L.color[a]) || L.color[a] < 0.0f)
            return makeError(std::string("GroundFogLighting.color.") + "rgb"[a] + " must be a finite number >= 0");
    }
    if (!std::isfinite(L.extinctionPerWorld) || L.extinctionPerWorld < 0.0f)
        return makeError("GroundFogLighting.extinctionPerWorld must be finite and >= 0");
    if (L.lengthResolution < 2 || L.lengthResolution > 1024) return makeError("GroundFogLighting.lengthResolution must be in [2, 1024]");
    return {};
}

// What the lit transfer function and table depend on.
bool sameColour(const GroundFogLighting& a, const GroundFogLighting& b) {
    return a.sun.color == b.sun.color && a.sun.intensity == b.sun.intensity && a.gas.albedo == b.gas.albedo && a.gas.ambient == b.gas.ambient &&
           a.gas.multipleScattering == b.gas.multipleScattering && samePhase(a.gas.phase, b.gas.phase) && a.color == b.color &&
           a.extinctionPerWorld == b.extinctionPerWorld && a.lengthResolution == b.lengthResolution;
}

} // namespace

detail::FogFieldView GroundFog::fieldView() const {
    detail::FogFieldView f;
    f.nx = mDesc.dims.x, f.nz = mDesc.dims.y;
    f.origin = {double(mDesc.originWorld.x), double(mDesc.originWorld.z)};
    f.spacing = double(mDesc.spacingWorld);
    f.density = double(mDesc.density), f.depth = double(mDesc.densityDepthWorld);
    f.yLo = double(mBounds.lo.y), f.yHi = double(mBounds.hi.y);
    if (mDesc.lod) {
        f.stride = mN, f.height = mHeight.data(), f.thickness = mThickness.data();
    } else {
        f.stride = mDesc.dims.x, f.height = mDesc.terrainHeight.data(), f.top = mDesc.fogTop.data();
    }
    return f;
}

double GroundFog::opticalDepthToSun(glm::dvec3 p, glm::dvec3 towardSun) const {
    const double len = glm::length(towardSun);
    if (!(len > 0.0) || !std::isfinite(len) || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return 0.0;
    std::vector<double> scratch;
    return double(mLighting.extinctionPerWorld) * detail::fogScalarIntegral(fieldView(), p, towardSun / len, scratch);
}

Status GroundFog::relightFog(std::span<const ShadowCaster* const> casters) {
    detail::FogFieldView f = fieldView();
    f.hMax = -1e30;
    for (int j = 0; j < f.nz; ++j)
        for (int i = 0; i < f.nx; ++i) f.hMax = std::max(f.hMax, f.h(i, j));
    const int points = mDesc.lod ? mN * mN : mDesc.dims.x * mDesc.dims.y;
    std::vector<float> trans(2 * std::size_t(points), 1.0f);
    const glm::dvec3 toSun = -glm::normalize(glm::dvec3(mLighting.sun.direction));
    const double ext = double(mLighting.extinctionPerWorld);
    std::vector<double> scratch;
    for (int j = 0; j < f.nz; ++j)
        for (int i = 0; i < f.nx; ++i) {
            // The same float positions update() emits (Emitter::bottom, LodGrid::worldX).
            const float x = mDesc.originWorld.x + float(i) * mDesc.spacingWorld, z = mDesc.originWorld.z + float(j) * mDesc.spacingWorld;
            const float hb = float(f.h(i, j)), ht = hb + float(f.th(i, j));
            for (int k = 0; k < 2; ++k) {
                const glm::vec3 p(x, k ? ht : hb, z);
                // A hill between the point and the sun: no direct light (ambient and multiple scattering
                // remain). Asked at the exact grid point (double): the float position is off the grid line
                // by its rounding, which on a steep slope would put the point below its own terrain.
                const glm::dvec3 exact(f.origin.x + double(i) * f.spacing, k ? double(ht) : double(hb), f.origin.y + double(j) * f.spacing);
                if (detail::terrainBlocks(f, exact, toSun, scratch)) {
                    trans[2 * f.at(i, j) + std::size_t(k)] = 0.0f;
                    continue;
                }
                double depth = ext > 0.0 ? ext * detail::fogScalarIntegral(f, glm::dvec3(p), toSun, scratch) : 0.0;
                double log2Depth = 0.0;
                for (const ShadowCaster* c : casters) log2Depth += double(c->opticalDepthToLight(p, mLighting.sun));
                trans[2 * f.at(i, j) + std::size_t(k)] = float(std::exp(-depth) * std::exp2(-log2Depth));
            }
        }
    mSunT = std::move(trans);
    mCasterPrints.clear();
    for (const ShadowCaster* c : casters) mCasterPrints.push_back(c->empty() ? 0 : c->fingerprint());
    ++mRelights;
    return {};
}

Status GroundFog::rebuildLitTable() {
    const GasLightingDesc& g = mLighting.gas;
    const glm::vec3 sun = mLighting.sun.color * mLighting.sun.intensity;
    const float phaseMax = std::max(g.phase(1.0f), g.phase(-1.0f)); // HG lobes peak at cos theta = +-1
    const glm::vec3 base = mLighting.color * g.albedo;
    const glm::vec3 a = base * (g.ambient + sun * g.multipleScattering);
    const glm::vec3 b = base * sun * (4.0f * std::numbers::pi_v<float> * phaseMax);
    const float rho = mLighting.extinctionPerWorld;
    auto tf = TransferFunction::create({{0.0f, a, rho}, {1.0f, a + b, rho}});
    if (!tf) return makeError("GroundFogLighting: " + tf.error());
    // With rho constant an entry is affine in each scalar: 2 samples are exact.
    // The longest segment: the layer's box diagonal (longer ones are split).
    const glm::vec3 ext = mBounds.hi - mBounds.lo;
    PreIntegrationDesc pd{.scalarResolution = 2, .lengthResolution = mLighting.lengthResolution, .maxLengthWorld = std::max(glm::length(ext), 1e-6f)};
    auto table = PreIntegrationTable::create(*tf, pd);
    if (!table) return makeError("GroundFogLighting: table: " + table.error());
    mLitTransfer = std::move(*tf);
    mLitTable = std::move(*table);
    mPhaseMax = phaseMax;
    ++mLitTableBuilds;
    return {};
}

Status GroundFog::setLighting(const GroundFogLighting& lighting, std::span<const DensityField* const> casters) {
    // Null stays null: the overload below names it, after the lighting's own checks.
    const std::vector<const ShadowCaster*> all(casters.begin(), casters.end());
    return setLighting(lighting, std::span<const ShadowCaster* const>(all));
}

Status GroundFog::setLighting(const GroundFogLighting& lighting, std::span<const ShadowCaster* const> casters) {
    if (Status s = checkFogLighting(lighting); !s) return s;
    for (std::size_t i = 0; i < casters.size(); ++i)
        if (!casters[i]) return makeError("GroundFog::setLighting: casters[" + std::to_string(i) + "] is null");
    bool sameCasters = mLit && casters.size() == mCasterPrints.size();
    for (std::size_t i = 0; sameCasters && i < casters.size(); ++i) sameCasters = (casters[i]->empty() ? 0 : casters[i]->fingerprint()) == mCasterPrints[i];
    const bool relight = !mLit || !sameCasters || lighting.sun.direction != mLighting.sun.direction ||
                         lighting.extinctionPerWorld != mLighting.extinctionPerWorld;
    const bool colour = !mLit || !sameColour(lighting, mLighting);
    const GroundFogLighting old = mLighting;
    mLighting = lighting;
    if (colour)
        if (Status s = rebuildLitTable(); !s) return mLighting = old, s;
    if (relight)
        if (Status s = relightFog(casters); !s) return mLighting = old, s;
    mLit = true;
    return {};
}

glm::dvec3 GroundFog::sourceAt(double T, glm::vec3 toEye) const {
    const GasLightingDesc& g = mLighting.gas;
    const glm::dvec3 sun = glm::dvec3(mLighting.sun.color) * double(mLighting.sun.intensity);
    const double p = double(g.phase(glm::normalize(mLighting.sun.direction), toEye));
    return glm::dvec3(mLighting.color) * double(g.albedo) * (glm::dvec3(g.ambient) + sun * (4.0 * std::numbers::pi * p * T + double(g.multipleScattering)));
}

} // namespace splatfx
