// The coarse-grid Eulerian solver of King et al. 1999, sec. 3.1 ("a simple
// Eulerian or fluid flow calculation ... across the grid"), built the
// unconditionally stable way (Stam 1999, "Stable Fluids"): implicit sources,
// forces relaxed implicitly, semi-Lagrangian transport, pressure projection.
//
// [SECTION] layout and sampling   [SECTION] create   [SECTION] substep stages
// [SECTION] obstacles             [SECTION] projection
// [SECTION] output
#include "splatfx/solver.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <deque>
#include <limits>
#include <string>

namespace splatfx {
namespace {

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string fieldError(const char* field, const std::string& what) { return std::string("FluidSolverDesc.") + field + " " + what; }

// The shortest interval an obstacle's velocity is differenced over, seconds:
// its rounding error is about (|x| + |v| t) 2^-24 / interval (0.1 % of a
// speed of 1 at 10 s and 10 units out), and a substep this short is rare.
constexpr double kMinWallIntervalSec = 1e-3;

} // namespace

// [SECTION] layout and sampling
//
// Cell (i, j, k) has its centre at (i, j, k) in cell coordinates. Face
// velocity component a lives on the faces normal to axis a: the face between
// cells i-1 and i along x is at x = i - 0.5 and has storage index i in
// 0..dims.x. So face storage along a is shifted by +0.5 in cell coordinates.

namespace {

glm::ivec3 faceDims(glm::ivec3 dims, int axis) {
    glm::ivec3 d = dims;
    d[axis] += 1;
    return d;
}

std::size_t lin(glm::ivec3 c, glm::ivec3 d) { return (std::size_t(c.z) * d.y + c.y) * d.x + c.x; }

// Trilinear interpolation of a field of size d at continuous index q,
// reading value(i) for integer corners (value handles out-of-range indices).
template <class Value>
float trilinear(glm::vec3 q, Value value) {
    const glm::vec3 f = glm::floor(q);
    const glm::ivec3 i0(f);
    const glm::vec3 t = q - f;
    float acc = 0.0f;
    for (int c = 0; c < 8; ++c) {
        const glm::ivec3 o((c & 1), (c >> 1) & 1, (c >> 2) & 1);
        const float w = (o.x ? t.x : 1.0f - t.x) * (o.y ? t.y : 1.0f - t.y) * (o.z ? t.z : 1.0f - t.z);
        if (w == 0.0f) continue; // also keeps out-of-range corners of exact samples from mattering
        acc += w * value(i0 + o);
    }
    return acc;
}

} // namespace

glm::vec3 FluidSolver::localPosition(glm::ivec3 cell) const {
    const glm::vec3 half = glm::vec3(glm::max(mDims - 1, glm::ivec3(0))) * 0.5f;
    return (glm::vec3(cell) - glm::vec3(half.x, 0.0f, half.z)) * mDesc.spacing;
}

// Scalars: closed sides clamp to the last cell (zero gradient, nothing crosses);
// open sides see one ghost layer holding the surroundings' value.
float FluidSolver::sampleScalar(const std::vector<float>& f, glm::vec3 p, float outside) const {
    const bool closedLo[3] = {mDesc.closedWalls, mDesc.closedFloor, mDesc.closedWalls};
    const bool closedHi[3] = {mDesc.closedWalls, mDesc.closedCeiling, mDesc.closedWalls};
    for (int a = 0; a < 3; ++a) p[a] = std::clamp(p[a], closedLo[a] ? 0.0f : -1.0f, closedHi[a] ? float(mDims[a] - 1) : float(mDims[a]));
    auto inside = [&](glm::ivec3 i) { return glm::all(glm::greaterThanEqual(i, glm::ivec3(0))) && glm::all(glm::lessThan(i, mDims)); };
    if (mStats.solidCells == 0)
        return trilinear(p, [&](glm::ivec3 i) { return inside(i) ? f[lin(i, mDims)] : outside; });
    // Solid corners hold no material: the weights of the fluid corners are
    // renormalized, so nothing is read through a wall. stopAtSolid leaves p
    // nearest a fluid cell, whose weight is at least 1/8.
    const glm::vec3 fl = glm::floor(p);
    const glm::ivec3 i0(fl);
    const glm::vec3 t = p - fl;
    float acc = 0.0f, wsum = 0.0f;
    for (int c = 0; c < 8; ++c) {
        const glm::ivec3 o((c & 1), (c >> 1) & 1, (c >> 2) & 1);
        const float w = (o.x ? t.x : 1.0f - t.x) * (o.y ? t.y : 1.0f - t.y) * (o.z ? t.z : 1.0f - t.z);
        if (w == 0.0f) continue;
        const glm::ivec3 i = i0 + o;
        if (!inside(i)) {
            acc += w * outside, wsum += w;
        } else if (mSolidOwner[lin(i, mDims)] < 0) {
            acc += w * f[lin(i, mDims)], wsum += w;
        }
    }
    return wsum > 0.0f ? acc / wsum : outside;
}

float FluidSolver::sampleFace(int axis, const std::vector<float>& f, glm::vec3 p) const {
    const glm::ivec3 fd = faceDims(mDims, axis);
    glm::vec3 q = p;
    q[axis] += 0.5f;
    q = glm::clamp(q, glm::vec3(0.0f), glm::vec3(fd - 1));
    return trilinear(q, [&](glm::ivec3 i) { return f[lin(glm::min(i, fd - 1), fd)]; });
}

glm::vec3 FluidSolver::velocityCells(glm::vec3 p) const {
    return glm::vec3(sampleFace(0, mU[0], p), sampleFace(1, mU[1], p), sampleFace(2, mU[2], p)) / mDesc.spacing;
}

glm::vec3 FluidSolver::backtrace(glm::vec3 p, float dt) const {
    // RK2 (midpoint); every stage is clamped to the sampled region, so a
    // velocity far above the CFL limit just reaches the boundary.
    const glm::vec3 lo(mDesc.closedWalls ? 0.0f : -1.0f, mDesc.closedFloor ? 0.0f : -1.0f, mDesc.closedWalls ? 0.0f : -1.0f);
    const glm::vec3 hi(mDesc.closedWalls ? mDims.x - 1.0f : float(mDims.x), mDesc.closedCeiling ? mDims.y - 1.0f : float(mDims.y),
                       mDesc.closedWalls ? mDims.z - 1.0f : float(mDims.z));
    auto clampIn = [&](glm::vec3 q) { return finite3(q) ? glm::clamp(q, lo, hi) : glm::clamp(p, lo, hi); };
    const glm::vec3 mid = clampIn(p - 0.5f * dt * velocityCells(p));
    return stopAtSolid(p, clampIn(p - dt * velocityCells(mid)));
}

glm::vec3 FluidSolver::stopAtSolid(glm::vec3 from, glm::vec3 to) const {
    if (mStats.solidCells == 0) return to;
    auto solidAt = [&](glm::vec3 q) {
        const glm::ivec3 c(glm::round(q));
        if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, mDims))) return false;
        return mSolidOwner[lin(c, mDims)] >= 0;
    };
    if (solidAt(from)) return to; // a wall face's own point: its velocity is re-imposed after advection
    // Half-cell steps: a one-cell wall cannot be stepped over.
    const float len = glm::length(to - from);
    const int n = std::max(1, int(std::ceil(2.0f * len)));
    glm::vec3 last = from;
    for (int s = 1; s <= n; ++s) {
        const glm::vec3 q = from + (to - from) * (float(s) / float(n));
        if (solidAt(q)) return last;
        last = q;
    }
    return to;
}

// [SECTION] create

Result<FluidSolver> FluidSolver::create(const FluidSolverDesc& d) {
    for (int a = 0; a < 3; ++a) {
        if (d.dims[a] < 1) return makeError(fieldError("dims", std::string(1, "xyz"[a]) + " must be at least 1, got " + std::to_string(d.dims[a])));
        if (!std::isfinite(d.spacing[a]) || d.spacing[a] <= 0.0f)
            return makeError(
                fieldError("spacing", std::string(1, "xyz"[a]) + " must be a positive finite number, got " + std::to_string(d.spacing[a])));
    }
    const std::uint64_t n = std::uint64_t(d.dims.x) * std::uint64_t(d.dims.y) * std::uint64_t(d.dims.z);
    if (n > kMaxVoxels) return makeError(fieldError("dims", "asks for " + std::to_string(n) + " cells; the limit is " + std::to_string(kMaxVoxels)));
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(d.transform[c][r])) return makeError(fieldError("transform", "has a non-finite entry"));
    if (std::abs(glm::determinant(glm::mat3(d.transform))) < 1e-12f) return makeError(fieldError("transform", "is singular"));
    struct Rate {
        const char* name;
        float v;
    };
    for (Rate r : {Rate{"buoyancy", d.buoyancy}, Rate{"weight", d.weight}, Rate{"ambientTemperature", d.ambientTemperature}})
        if (!std::isfinite(r.v)) return makeError(fieldError(r.name, "must be finite"));
    for (Rate r : {Rate{"windCoupling", d.windCoupling}, Rate{"velocityDamping", d.velocityDamping}, Rate{"densityDissipation", d.densityDissipation},
                   Rate{"temperatureDissipation", d.temperatureDissipation}})
        if (!std::isfinite(r.v) || r.v < 0.0f) return makeError(fieldError(r.name, "must be finite and >= 0, got " + std::to_string(r.v)));
    if (!finite3(d.windWorld)) return makeError(fieldError("windWorld", "must be finite"));
    if (d.pressureIterations < 0 || d.pressureIterations > 10000)
        return makeError(fieldError("pressureIterations", "must be in [0, 10000], got " + std::to_string(d.pressureIterations)));
    if (!(d.pressureTolerance >= 0.0f)) return makeError(fieldError("pressureTolerance", "must be >= 0"));
    if (d.substeps < 1 || d.substeps > 1000) return makeError(fieldError("substeps", "must be in [1, 1000], got " + std::to_string(d.substeps)));
    if (d.conserveMass && !(d.closedFloor && d.closedWalls && d.closedCeiling))
        return makeError(fieldError("conserveMass", "needs a closed domain (closedFloor, closedWalls and closedCeiling all "
                                                    "true); with open faces material leaves and the total is not conserved"));

    FluidSolver s;
    s.mDesc = d;
    s.mDims = d.dims;
    s.mDensity.assign(n, 0.0f);
    s.mTemp.assign(n, d.ambientTemperature);
    for (int a = 0; a < 3; ++a) {
        const glm::ivec3 fd = faceDims(d.dims, a);
        s.mU[a].assign(std::size_t(fd.x) * fd.y * fd.z, 0.0f);
    }
    // Buoyancy acts against world gravity; wind is given in world units.
    const glm::mat3 toLocal = glm::inverse(glm::mat3(d.transform));
    const glm::vec3 up = toLocal * glm::vec3(0, 1, 0);
    s.mUpLocal = glm::length(up) > 0.0f ? glm::normalize(up) : glm::vec3(0, 1, 0);
    s.mWindLocal = toLocal * d.windWorld;
    return s;
}

void FluidSolver::setUniformVelocity(glm::vec3 v) {
    for (int a = 0; a < 3; ++a) std::fill(mU[a].begin(), mU[a].end(), v[a]);
}

// [SECTION] substep stages

void FluidSolver::step(double dtSec) {
    assert(std::isfinite(dtSec) && dtSec >= 0.0 && "FluidSolver::step: dtSec must be finite and >= 0");
    ++mStats.steps;
    const double h = dtSec / mDesc.substeps;
    for (int i = 0; i < mDesc.substeps; ++i) {
        mTime += h;
        substep(float(h));
        ++mStats.substeps;
        mStats.cellsUpdated += mDensity.size();
    }
}

void FluidSolver::substep(float dt) {
    updateObstacles(dt);
    applyEmitters(dt);
    applyForces(dt);
    enforceObstacleFaces();
    project();
    advectScalars(dt);
    advectVelocity(dt);
    enforceObstacleFaces();
    dissipate(dt);
}

void FluidSolver::applyEmitters(float dt) {
    if (mEmitters.empty() || dt <= 0.0f) return;
    const glm::mat3 lin3(mDesc.transform);
    const float cellDiag = 0.5f * glm::length(glm::vec3(glm::length(lin3[0] * mDesc.spacing.x), glm::length(lin3[1] * mDesc.spacing.y),
                                                        glm::length(lin3[2] * mDesc.spacing.z)));
    const glm::mat3 toLocal = glm::inverse(lin3);
    for (const Emitter& e : mEmitters) {
        const EmitterDesc& ed = e.desc;
        assert(ed.radius > 0.0f && ed.rate >= 0.0f && ed.density >= 0.0f && ed.temperature >= 0.0f &&
               "EmitterDesc: radius must be > 0; rate, density and temperature >= 0");
        const glm::vec3 centre = e.worldCenter(mTime);
        const float radius = std::max(ed.radius, cellDiag);
        auto weightAt = [&](glm::vec3 world) {
            const float r2 = glm::dot(world - centre, world - centre) / (radius * radius);
            return r2 < 1.0f ? (1.0f - r2) * (1.0f - r2) : 0.0f;
        };
        for (int k = 0; k < mDims.z; ++k)
            for (int j = 0; j < mDims.y; ++j)
                for (int i = 0; i < mDims.x; ++i) {
                    const glm::ivec3 c{i, j, k};
                    if (solid(c)) continue; // no material inside an obstacle
                    const float w = weightAt(glm::vec3(mDesc.transform * glm::vec4(localPosition(c), 1.0f)));
                    if (w <= 0.0f) continue;
                    // Implicit relaxation towards the target: bounded by it for any
                    // dt, and never removes material already there.
                    const float a = dt * ed.rate * w;
                    const std::size_t idx = lin(c, mDims);
                    mDensity[idx] = std::max(mDensity[idx], (mDensity[idx] + a * ed.density) / (1.0f + a));
                    const float tt = mDesc.ambientTemperature + ed.temperature;
                    mTemp[idx] = std::max(mTemp[idx], (mTemp[idx] + a * tt) / (1.0f + a));
                }
        if (!ed.injectVelocity) continue;
        const glm::vec3 vLocal = toLocal * ed.velocity;
        for (int a = 0; a < 3; ++a) {
            const glm::ivec3 fd = faceDims(mDims, a);
            for (int k = 0; k < fd.z; ++k)
                for (int j = 0; j < fd.y; ++j)
                    for (int i = 0; i < fd.x; ++i) {
                        if (fixedFace(a, lin({i, j, k}, fd))) continue; // an obstacle sets it
                        glm::vec3 p(i, j, k);
                        p[a] -= 0.5f;
                        const glm::vec3 local = (p - glm::vec3(0.5f * (mDims.x - 1), 0.0f, 0.5f * (mDims.z - 1))) * mDesc.spacing;
                        const float w = weightAt(glm::vec3(mDesc.transform * glm::vec4(local, 1.0f)));
                        if (w <= 0.0f) continue;
                        const float r = dt * ed.rate * w;
                        float& u = mU[a][lin({i, j, k}, fd)];
                        u = (u + r * vLocal[a]) / (1.0f + r);
                    }
        }
    }
}

bool FluidSolver::closedFace(int a, glm::ivec3 f) const {
    const bool closedLo = a == 1 ? mDesc.closedFloor : mDesc.closedWalls;
    const bool closedHi = a == 1 ? mDesc.closedCeiling : mDesc.closedWalls;
    return (f[a] == 0 && closedLo) || (f[a] == mDims[a] && closedHi);
}

void FluidSolver::applyForces(float dt) {
    const float relax = dt * (mDesc.windCoupling + mDesc.velocityDamping);
    for (int a = 0; a < 3; ++a) {
        const glm::ivec3 fd = faceDims(mDims, a);
        for (int k = 0; k < fd.z; ++k)
            for (int j = 0; j < fd.y; ++j)
                for (int i = 0; i < fd.x; ++i) {
                    const glm::ivec3 f{i, j, k};
                    float& u = mU[a][lin(f, fd)];
                    if (closedFace(a, f)) {
                        u = 0.0f;
                        continue;
                    }
                    // Temperature and density on the face: mean of the cells beside it.
                    glm::ivec3 c0 = f, c1 = f;
                    c0[a] -= 1;
                    c0[a] = std::max(c0[a], 0);
                    c1[a] = std::min(c1[a], mDims[a] - 1);
                    const float t = 0.5f * (mTemp[lin(c0, mDims)] + mTemp[lin(c1, mDims)]) - mDesc.ambientTemperature;
                    const float d = 0.5f * (mDensity[lin(c0, mDims)] + mDensity[lin(c1, mDims)]);
                    const float lift = (mDesc.buoyancy * t - mDesc.weight * d) * mUpLocal[a];
                    // Buoyancy is bounded by the bounded temperature; wind and drag
                    // are relaxed implicitly, so the speed cannot run away with dt.
                    u = (u + dt * (lift + mDesc.windCoupling * mWindLocal[a])) / (1.0f + relax);
                }
    }
}

void FluidSolver::advectScalars(float dt) {
    if (dt <= 0.0f) return;
    const double before = mDesc.conserveMass ? totalDensity() : 0.0;
    for (int which = 0; which < 2; ++which) {
        std::vector<float>& f = which == 0 ? mDensity : mTemp;
        const float outside = which == 0 ? 0.0f : mDesc.ambientTemperature;
        mScratch.resize(f.size());
        for (int k = 0; k < mDims.z; ++k)
            for (int j = 0; j < mDims.y; ++j)
                for (int i = 0; i < mDims.x; ++i) {
                    const glm::ivec3 c{i, j, k};
                    mScratch[lin(c, mDims)] = solid(c) ? outside : sampleScalar(f, backtrace(glm::vec3(c), dt), outside);
                }
        f.swap(mScratch);
    }
    if (mDesc.conserveMass) {
        // Semi-Lagrangian transport gains or loses a little material each step;
        // in a closed domain the total must not change, so rescale (keeps
        // density non-negative, unlike adding the difference).
        const double after = totalDensity();
        if (after > 0.0) {
            const double s = before / after;
            for (float& v : mDensity) v = float(double(v) * s);
        }
    }
}

void FluidSolver::advectVelocity(float dt) {
    if (dt <= 0.0f) return;
    for (int a = 0; a < 3; ++a) {
        const glm::ivec3 fd = faceDims(mDims, a);
        mUScratch[a].resize(mU[a].size());
        for (int k = 0; k < fd.z; ++k)
            for (int j = 0; j < fd.y; ++j)
                for (int i = 0; i < fd.x; ++i) {
                    glm::vec3 p(i, j, k);
                    p[a] -= 0.5f;
                    mUScratch[a][lin({i, j, k}, fd)] = sampleFace(a, mU[a], backtrace(p, dt));
                }
    }
    for (int a = 0; a < 3; ++a) {
        mU[a].swap(mUScratch[a]);
        // Closed faces stay closed.
        const glm::ivec3 fd = faceDims(mDims, a);
        for (int k = 0; k < fd.z; ++k)
            for (int j = 0; j < fd.y; ++j)
                for (int i = 0; i < fd.x; ++i)
                    if (closedFace(a, {i, j, k})) mU[a][lin({i, j, k}, fd)] = 0.0f;
    }
}

void FluidSolver::dissipate(float dt) {
    if (dt <= 0.0f) return;
    const float kd = 1.0f / (1.0f + dt * mDesc.densityDissipation);
    const float kt = 1.0f / (1.0f + dt * mDesc.temperatureDissipation);
    if (kd != 1.0f)
        for (float& v : mDensity) v *= kd;
    if (kt != 1.0f)
        for (float& v : mTemp) v = mDesc.ambientTemperature + (v - mDesc.ambientTemperature) * kt;
}

// [SECTION] obstacles

Status FluidSolver::addObstacle(const Obstacle& o) {
    if (mObstacles.size() >= kMaxObstacles) return makeError("FluidSolver::addObstacle: at most " + std::to_string(kMaxObstacles) + " obstacles");
    if (Status st = validateObstacle(o.desc); !st) return st;
    mObstacles.push_back(o);
    updateObstacles(0.0f);
    return {};
}

void FluidSolver::clearObstacles() {
    mObstacles.clear();
    updateObstacles(0.0f);
}

void FluidSolver::updateObstacles(float dt) {
    const std::size_t n = mDensity.size();
    if (mObstacles.empty()) {
        mSolidOwner.clear(), mSolidVelocity.clear();
        for (int a = 0; a < 3; ++a) mFixed[a].clear(), mFixedVelocity[a].clear();
        mStats.solidCells = 0;
        return;
    }
    mSolidOwner.assign(n, -1);
    mSolidVelocity.assign(n, glm::vec3(0.0f));
    const glm::mat4& toWorld = mDesc.transform;
    const glm::mat3 velToLocal = glm::inverse(glm::mat3(toWorld));
    const glm::vec3 half(0.5f * float(mDims.x - 1), 0.0f, 0.5f * float(mDims.z - 1));
    std::uint64_t solidCount = 0;
    for (std::size_t oi = 0; oi < mObstacles.size(); ++oi) {
        const Obstacle& ob = mObstacles[oi];
        const glm::mat4 now = ob.objectToWorld(mTime);
        const glm::mat4 objectFromLocal = glm::inverse(now) * toWorld;
        // Where each material point of the object was at the substep's start:
        // its velocity is the displacement over the substep (rotation included).
        // Over a substep shorter than kMinWallIntervalSec the displacement is
        // below the float resolution of the object's positions (and of Motion's
        // float time), so displacement / dt is 0 or a multiple of ulp / dt: it is
        // taken over that interval instead.
        const double interval = std::max(double(dt), kMinWallIntervalSec);
        const glm::mat4 before = dt > 0.0f ? ob.objectToWorld(mTime - interval) * glm::inverse(now) : glm::mat4(1.0f);
        // Cells to test: the object's bounds in lattice coordinates.
        glm::ivec3 lo(0), hi = mDims - 1;
        const Aabb ob3 = obstacleBounds(ob.desc);
        if (std::isfinite(ob3.lo.y)) {
            Aabb lattice;
            const glm::mat4 latticeFromObject = glm::inverse(objectFromLocal);
            for (int c = 0; c < 8; ++c) lattice.extend(glm::vec3(latticeFromObject * glm::vec4(ob3.corner(c), 1.0f)) / mDesc.spacing + half);
            // Clamped in float before the conversion: an obstacle 10^10 units
            // across overflows int (it covered no cell); a bound made NaN by
            // overflowing corners keeps the whole axis.
            for (int a = 0; a < 3; ++a) {
                const float l = std::floor(lattice.lo[a]), h = std::ceil(lattice.hi[a]);
                if (l > 0.0f) lo[a] = l < float(mDims[a]) ? int(l) : mDims[a];
                if (h < float(mDims[a] - 1)) hi[a] = h > -1.0f ? int(h) : -1;
            }
        }
        for (int k = lo.z; k <= hi.z; ++k)
            for (int j = lo.y; j <= hi.y; ++j)
                for (int i = lo.x; i <= hi.x; ++i) {
                    const std::size_t idx = lin({i, j, k}, mDims);
                    if (mSolidOwner[idx] >= 0) continue; // the first obstacle listed owns shared cells
                    const glm::vec4 local(localPosition({i, j, k}), 1.0f);
                    if (!obstacleContains(ob.desc, glm::vec3(objectFromLocal * local))) continue;
                    mSolidOwner[idx] = std::int16_t(oi);
                    ++solidCount;
                    if (dt > 0.0f) {
                        const glm::vec3 x(toWorld * local);
                        const glm::vec3 x0(before * glm::vec4(x, 1.0f));
                        mSolidVelocity[idx] = velToLocal * ((x - x0) / float(interval));
                    }
                }
    }
    mStats.solidCells = solidCount;

    // Material an obstacle now covers goes to the nearest fluid cell
    // (breadth-first from every fluid cell at once, ties in index order), so a
    // moving obstacle pushes smoke instead of deleting it.
    bool covered = false;
    for (std::size_t i = 0; i < n && !covered; ++i) covered = mSolidOwner[i] >= 0 && mDensity[i] > 0.0f;
    if (covered) {
        std::vector<std::int64_t> nearest(n, -1);
        std::deque<std::size_t> queue;
        for (std::size_t i = 0; i < n; ++i)
            if (mSolidOwner[i] < 0) nearest[i] = std::int64_t(i), queue.push_back(i);
        while (!queue.empty()) {
            const std::size_t i = queue.front();
            queue.pop_front();
            const glm::ivec3 c(int(i % std::size_t(mDims.x)), int((i / std::size_t(mDims.x)) % std::size_t(mDims.y)),
                               int(i / (std::size_t(mDims.x) * std::size_t(mDims.y))));
            for (int a = 0; a < 3; ++a)
                for (int side = -1; side <= 1; side += 2) {
                    glm::ivec3 nb = c;
                    nb[a] += side;
                    if (nb[a] < 0 || nb[a] >= mDims[a]) continue;
                    const std::size_t j = lin(nb, mDims);
                    if (nearest[j] >= 0) continue;
                    nearest[j] = nearest[i];
                    queue.push_back(j);
                }
        }
        for (std::size_t i = 0; i < n; ++i) {
            if (mSolidOwner[i] < 0 || mDensity[i] <= 0.0f) continue;
            if (nearest[i] >= 0) mDensity[std::size_t(nearest[i])] += mDensity[i];
            mStats.displacedDensity += mDensity[i];
            mDensity[i] = 0.0f;
        }
    }
    for (std::size_t i = 0; i < n; ++i)
        if (mSolidOwner[i] >= 0) mTemp[i] = mDesc.ambientTemperature;

    // Faces: a face with a solid cell on either side moves with the
    // obstacle (the mean of the two when both are solid); with Slip::None a
    // fluid face with a solid cell beside it (across a tangential axis) does too.
    auto owner = [&](glm::ivec3 c) -> int {
        if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, mDims))) return -1;
        return mSolidOwner[lin(c, mDims)];
    };
    for (int a = 0; a < 3; ++a) {
        const glm::ivec3 fd = faceDims(mDims, a);
        mFixed[a].assign(mU[a].size(), 0);
        mFixedVelocity[a].assign(mU[a].size(), 0.0f);
        for (int k = 0; k < fd.z; ++k)
            for (int j = 0; j < fd.y; ++j)
                for (int i = 0; i < fd.x; ++i) {
                    const glm::ivec3 f{i, j, k};
                    glm::ivec3 c0 = f;
                    c0[a] -= 1;
                    const glm::ivec3 cells[2] = {c0, f};
                    float sum = 0.0f;
                    int count = 0;
                    for (glm::ivec3 c : cells)
                        if (owner(c) >= 0) sum += mSolidVelocity[lin(c, mDims)][a], ++count;
                    if (count == 0)
                        for (glm::ivec3 c : cells)
                            for (int b = 0; b < 3; ++b)
                                for (int side = -1; side <= 1 && b != a; side += 2) {
                                    if (c[a] < 0 || c[a] >= mDims[a]) continue; // only cells of the grid have sideways neighbours
                                    glm::ivec3 nb = c;
                                    nb[b] += side;
                                    const int o = owner(nb);
                                    if (o < 0 || mObstacles[std::size_t(o)].desc.slip != Slip::None) continue;
                                    sum += mSolidVelocity[lin(nb, mDims)][a], ++count;
                                }
                    if (count == 0) continue;
                    const std::size_t fi = lin(f, fd);
                    mFixed[a][fi] = 1;
                    mFixedVelocity[a][fi] = sum / float(count);
                }
    }
}

void FluidSolver::enforceObstacleFaces() {
    if (mObstacles.empty()) return;
    for (int a = 0; a < 3; ++a) {
        const glm::ivec3 fd = faceDims(mDims, a);
        for (int k = 0; k < fd.z; ++k)
            for (int j = 0; j < fd.y; ++j)
                for (int i = 0; i < fd.x; ++i) {
                    const std::size_t fi = lin({i, j, k}, fd);
                    if (!mFixed[a][fi]) continue;
                    mU[a][fi] = closedFace(a, {i, j, k}) ? 0.0f : mFixedVelocity[a][fi];
                }
    }
}

float FluidSolver::maxFluidDivergence() const {
    float m = 0.0f;
    for (int k = 0; k < mDims.z; ++k)
        for (int j = 0; j < mDims.y; ++j)
            for (int i = 0; i < mDims.x; ++i) {
                const glm::ivec3 cell{i, j, k};
                if (solid(cell)) continue;
                double div = 0.0;
                for (int a = 0; a < 3; ++a) {
                    const glm::ivec3 fd = faceDims(mDims, a);
                    glm::ivec3 hiF = cell;
                    hiF[a] += 1;
                    div += (double(mU[a][lin(hiF, fd)]) - double(mU[a][lin(cell, fd)])) / double(mDesc.spacing[a]);
                }
                m = std::max(m, float(std::abs(div)));
            }
    return m;
}

// [SECTION] projection
//
// Solve A phi = -div u with A = -Laplacian (closed faces: no term; open
// faces: phi = 0 outside), then u -= grad phi. A is symmetric positive
// (semi)definite, so conjugate gradient applies; for any iteration count the
// result is no larger in energy than u (CG reduces the A-norm error
// monotonically), which keeps the projection stable when it stops early.

void FluidSolver::project() {
    if (mDesc.pressureIterations == 0) return;
    const std::size_t n = mDensity.size();
    const glm::dvec3 h(mDesc.spacing);
    const glm::dvec3 c = 1.0 / (h * h);
    const bool closedLo[3] = {mDesc.closedWalls, mDesc.closedFloor, mDesc.closedWalls};
    const bool closedHi[3] = {mDesc.closedWalls, mDesc.closedCeiling, mDesc.closedWalls};
    const bool anyOpen = !(closedLo[0] && closedLo[1] && closedHi[0] && closedHi[1]);
    const bool withObstacles = !mObstacles.empty();
    // A face the projection may not change: a closed side, or one an obstacle sets.
    auto wall = [&](int a, glm::ivec3 f) { return closedFace(a, f) || fixedFace(a, lin(f, faceDims(mDims, a))); };

    mRhs.assign(n, 0.0);
    double mean = 0.0;
    for (int k = 0; k < mDims.z; ++k)
        for (int j = 0; j < mDims.y; ++j)
            for (int i = 0; i < mDims.x; ++i) {
                const glm::ivec3 cell{i, j, k};
                if (withObstacles && solid(cell)) continue; // not an unknown: phi stays 0 there
                double div = 0.0;
                for (int a = 0; a < 3; ++a) {
                    const glm::ivec3 fd = faceDims(mDims, a);
                    glm::ivec3 hiF = cell;
                    hiF[a] += 1;
                    div += (double(mU[a][lin(hiF, fd)]) - double(mU[a][lin(cell, fd)])) / h[a];
                }
                mRhs[lin(cell, mDims)] = -div;
                mean += -div;
            }
    if (!withObstacles) {
        if (!anyOpen) {
            // Closed domain: A is singular (constants); make the right side consistent.
            mean /= double(n);
            for (double& v : mRhs) v -= mean;
        }
    } else {
        // Obstacles can cut the fluid into regions; each region with no open
        // side has a singular block (constants), made consistent by removing
        // its mean. (Gas squeezed by an obstacle moving into a closed pocket
        // cannot leave: that pocket keeps the mean divergence.)
        mComponent.assign(n, -1);
        std::vector<std::size_t> stack;
        std::vector<double> sum;
        std::vector<std::size_t> size;
        std::vector<char> open;
        for (std::size_t seed = 0; seed < n; ++seed) {
            if (mComponent[seed] >= 0 || mSolidOwner[seed] >= 0) continue;
            const int id = int(sum.size());
            sum.push_back(0.0), size.push_back(0), open.push_back(0);
            mComponent[seed] = id;
            stack.assign(1, seed);
            while (!stack.empty()) {
                const std::size_t i = stack.back();
                stack.pop_back();
                sum[id] += mRhs[i], ++size[id];
                const glm::ivec3 cell(int(i % std::size_t(mDims.x)), int((i / std::size_t(mDims.x)) % std::size_t(mDims.y)),
                                      int(i / (std::size_t(mDims.x) * std::size_t(mDims.y))));
                for (int a = 0; a < 3; ++a)
                    for (int side = -1; side <= 1; side += 2) {
                        glm::ivec3 f = cell;
                        if (side > 0) f[a] += 1;
                        if (wall(a, f)) continue;
                        glm::ivec3 nb = cell;
                        nb[a] += side;
                        if (nb[a] < 0 || nb[a] >= mDims[a]) {
                            open[id] = 1;
                            continue;
                        }
                        const std::size_t j = lin(nb, mDims);
                        if (mComponent[j] >= 0 || mSolidOwner[j] >= 0) continue;
                        mComponent[j] = id;
                        stack.push_back(j);
                    }
            }
        }
        for (std::size_t i = 0; i < n; ++i)
            if (mComponent[i] >= 0 && !open[std::size_t(mComponent[i])]) mRhs[i] -= sum[std::size_t(mComponent[i])] / double(size[std::size_t(mComponent[i])]);
    }

    // With obstacles, which of each fluid cell's six faces are walls (bit 2a
    // for the low face on axis a, 2a + 1 for the high one), looked up once
    // per projection instead of once per CG iteration.
    if (withObstacles) {
        mWallBits.assign(n, 0);
        for (int k = 0; k < mDims.z; ++k)
            for (int j = 0; j < mDims.y; ++j)
                for (int i = 0; i < mDims.x; ++i) {
                    const glm::ivec3 cell{i, j, k};
                    std::uint8_t bits = 0;
                    for (int a = 0; a < 3; ++a) {
                        glm::ivec3 hiF = cell;
                        hiF[a] += 1;
                        const glm::ivec3 fd = faceDims(mDims, a);
                        if (fixedFace(a, lin(cell, fd))) bits |= std::uint8_t(1u << (2 * a));
                        if (fixedFace(a, lin(hiF, fd))) bits |= std::uint8_t(1u << (2 * a + 1));
                    }
                    mWallBits[lin(cell, mDims)] = bits;
                }
    }

    auto applyA = [&](const std::vector<double>& x, std::vector<double>& out) {
        for (int k = 0; k < mDims.z; ++k)
            for (int j = 0; j < mDims.y; ++j)
                for (int i = 0; i < mDims.x; ++i) {
                    const glm::ivec3 cell{i, j, k};
                    const std::size_t ci = lin(cell, mDims);
                    if (withObstacles && mSolidOwner[ci] >= 0) {
                        out[ci] = 0.0;
                        continue;
                    }
                    const double xc = x[ci];
                    const std::uint8_t walls = withObstacles ? mWallBits[ci] : std::uint8_t(0);
                    double acc = 0.0;
                    for (int a = 0; a < 3; ++a)
                        for (int side = -1; side <= 1; side += 2) {
                            if (walls & (1u << (2 * a + (side > 0 ? 1 : 0)))) continue; // a wall: no flux term
                            glm::ivec3 nb = cell;
                            nb[a] += side;
                            if (nb[a] < 0 || nb[a] >= mDims[a]) {
                                if (!(side < 0 ? closedLo[a] : closedHi[a])) acc += c[a] * xc; // phi = 0 outside
                                continue;
                            }
                            acc += c[a] * (xc - x[lin(nb, mDims)]);
                        }
                    out[ci] = acc;
                }
    };

    mP.assign(n, 0.0);
    mR = mRhs;
    mD = mR;
    mQ.assign(n, 0.0);
    auto dot = [](const std::vector<double>& a, const std::vector<double>& b) {
        double s = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
        return s;
    };
    double rr = dot(mR, mR);
    const double rr0 = rr;
    const double tol2 = double(mDesc.pressureTolerance) * double(mDesc.pressureTolerance) * rr0;
    int it = 0;
    if (rr0 > 0.0 && std::isfinite(rr0))
        for (; it < mDesc.pressureIterations && rr > tol2; ++it) {
            applyA(mD, mQ);
            const double dq = dot(mD, mQ);
            if (!(dq > 0.0)) break;
            const double alpha = rr / dq;
            for (std::size_t i = 0; i < n; ++i) {
                mP[i] += alpha * mD[i];
                mR[i] -= alpha * mQ[i];
            }
            const double rrNew = dot(mR, mR);
            const double beta = rrNew / rr;
            rr = rrNew;
            for (std::size_t i = 0; i < n; ++i) mD[i] = mR[i] + beta * mD[i];
        }
    mStats.lastPressureIterations = it;
    mStats.lastResidual = rr0 > 0.0 ? float(std::sqrt(rr / rr0)) : 0.0f;

    // u -= grad phi on every face that is not a wall.
    for (int a = 0; a < 3; ++a) {
        const glm::ivec3 fd = faceDims(mDims, a);
        for (int k = 0; k < fd.z; ++k)
            for (int j = 0; j < fd.y; ++j)
                for (int i = 0; i < fd.x; ++i) {
                    const glm::ivec3 f{i, j, k};
                    if (wall(a, f)) continue;
                    glm::ivec3 lo = f;
                    lo[a] -= 1;
                    const double pHi = f[a] < mDims[a] ? mP[lin(f, mDims)] : 0.0;
                    const double pLo = lo[a] >= 0 ? mP[lin(lo, mDims)] : 0.0;
                    float& u = mU[a][lin(f, fd)];
                    u = float(double(u) - (pHi - pLo) / h[a]);
                }
    }
}

// [SECTION] output

glm::vec3 FluidSolver::velocityAt(glm::ivec3 c) const {
    glm::vec3 v;
    for (int a = 0; a < 3; ++a) {
        const glm::ivec3 fd = faceDims(mDims, a);
        glm::ivec3 hi = c;
        hi[a] += 1;
        v[a] = 0.5f * (mU[a][lin(c, fd)] + mU[a][lin(hi, fd)]);
    }
    return v;
}

float FluidSolver::faceVelocity(int axis, glm::ivec3 f) const {
    assert(axis >= 0 && axis < 3 && glm::all(glm::greaterThanEqual(f, glm::ivec3(0))) &&
           glm::all(glm::lessThan(f, faceDims(mDims, axis))) && "FluidSolver::faceVelocity: axis or face out of range");
    return mU[axis][lin(f, faceDims(mDims, axis))];
}

std::vector<glm::vec3> FluidSolver::cellVelocities() const {
    std::vector<glm::vec3> out(mDensity.size());
    for (int k = 0; k < mDims.z; ++k)
        for (int j = 0; j < mDims.y; ++j)
            for (int i = 0; i < mDims.x; ++i) out[lin({i, j, k}, mDims)] = velocityAt({i, j, k});
    return out;
}

double FluidSolver::totalDensity() const {
    double s = 0.0;
    for (float v : mDensity) s += v;
    return s;
}

float FluidSolver::maxSpeed() const {
    float m = 0.0f;
    for (int a = 0; a < 3; ++a)
        for (float u : mU[a]) m = std::max(m, std::abs(u));
    return m;
}

void FluidSolver::toGrid(Grid& out, const SparseOutputDesc& d) const {
    assert(d.opacityPerDensity >= 0.0f && d.minOpacity >= 0.0f && d.temperatureRange > 0.0f && d.maxStretch >= 0.0f &&
           "SparseOutputDesc: opacityPerDensity, minOpacity, maxStretch must be >= 0 and temperatureRange > 0");
    out.voxels.clear();
    out.dims = mDims;
    out.spacing = mDesc.spacing;
    out.transform = mDesc.transform;
    const float ySpan = float(std::max(mDims.y - 1, 1));
    for (int k = 0; k < mDims.z; ++k)
        for (int j = 0; j < mDims.y; ++j)
            for (int i = 0; i < mDims.x; ++i) {
                const glm::ivec3 c{i, j, k};
                const std::size_t idx = lin(c, mDims);
                const float o = std::clamp(mDensity[idx] * d.opacityPerDensity, 0.0f, 1.0f);
                // Sparse: material that has faded (or never arrived) is no voxel.
                if (!(o >= d.minOpacity) || o <= 0.0f) continue;
                Voxel v;
                v.cell = c;
                v.opacity = o;
                switch (d.color) {
                case ColorSource::Temperature:
                    v.colorCoord = 1.0f - std::clamp((mTemp[idx] - mDesc.ambientTemperature) / d.temperatureRange, 0.0f, 1.0f);
                    break;
                case ColorSource::Height: v.colorCoord = float(j) / ySpan; break;
                case ColorSource::Density: v.colorCoord = o; break;
                }
                if (d.stretchPerSpeed > 0.0f) {
                    // Elongate the kernel along the flow (in lattice units).
                    glm::vec3 s = velocityAt(c) / mDesc.spacing * d.stretchPerSpeed;
                    const float len = glm::length(s);
                    if (len > d.maxStretch) s *= d.maxStretch / len;
                    if (std::isfinite(len)) v.stretch = s;
                }
                out.voxels.push_back(v);
            }
}

} // namespace splatfx
