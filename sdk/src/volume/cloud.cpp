// A LOD cloud relit when its sun or density changes (cloud.hpp).
#include "splatfx/cloud.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "splatfx/scene.hpp"
#include "volume/cloud_sweep.hpp"
#include "volume/same_phase.hpp"

namespace splatfx {
namespace {

using detail::samePhase;

Status checkLighting(const CloudLighting& L) {
    if (Status s = validateLight(L.sun, "CloudLighting.sun"); !s) return s;
    if (L.sun.type != LightType::Directional) return makeError("CloudLighting.sun must be a directional light");
    if (!std::isfinite(L.ambient) || !std::isfinite(L.diffuse) || L.ambient < 0.0f || L.diffuse < 0.0f || L.ambient + L.diffuse > 1.0f + 1e-6f)
        return makeError("CloudLighting.ambient and CloudLighting.diffuse must be >= 0 with ambient + diffuse <= 1");
    const GasLightingDesc& g = L.gas;
    if (!std::isfinite(g.albedo) || g.albedo < 0.0f || g.albedo > 1.0f) return makeError("CloudLighting.gas.albedo must be in [0, 1]");
    if (!std::isfinite(g.multipleScattering) || g.multipleScattering < 0.0f)
        return makeError("CloudLighting.gas.multipleScattering must be finite and >= 0");
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(g.ambient[a]) || g.ambient[a] < 0.0f)
            return makeError(std::string("CloudLighting.gas.ambient.") + "rgb"[a] + " must be a finite number >= 0");
    if (L.lights.empty()) return {};
    // Roettger's gamma = ambient + diffuse T is a bounded sun term scaling the
    // segment length (sec. 5.2), not an irradiance: a point light's 1/d^2 has no place in it.
    if (L.model == CloudLightModel::Roettger)
        return makeError("CloudLighting.lights must be empty with CloudLightModel::Roettger (its light is the sun's alone; use LowAlbedo)");
    if (L.lights.size() > std::size_t(kMaxCloudLights))
        return makeError("CloudLighting.lights holds " + std::to_string(L.lights.size()) + " lights; at most kMaxCloudLights = " +
                         std::to_string(kMaxCloudLights));
    for (std::size_t i = 0; i < L.lights.size(); ++i)
        if (Status s = validateLight(L.lights[i], "CloudLighting.lights[" + std::to_string(i) + "]"); !s) return s;
    return {};
}

bool sameLight(const Light& a, const Light& b) {
    return a.type == b.type && a.color == b.color && a.intensity == b.intensity && a.direction == b.direction && a.position == b.position &&
           a.innerConeRad == b.innerConeRad && a.outerConeRad == b.outerConeRad && a.radiusWorld == b.radiusWorld;
}

// What a light's transmittance depends on (not its colour or intensity).
bool sameGeometry(const Light& a, const Light& b) {
    Light x = a;
    x.color = b.color;
    x.intensity = b.intensity;
    return sameLight(x, b);
}

bool sameLights(const CloudLighting& a, const CloudLighting& b) {
    if (a.lights.size() != b.lights.size() || !sameLight(a.sun, b.sun)) return false;
    for (std::size_t i = 0; i < a.lights.size(); ++i)
        if (!sameLight(a.lights[i], b.lights[i])) return false;
    return true;
}

// What the sun's transmittance and the LOD fields depend on.
bool sameField(const CloudLighting& a, const CloudLighting& b) {
    if (a.model != b.model || a.sun.direction != b.sun.direction) return false;
    return a.model != CloudLightModel::Roettger || (a.ambient == b.ambient && a.diffuse == b.diffuse);
}

// What the LowAlbedo transfer function depends on (Roettger's is fixed).
bool sameColour(const CloudLighting& a, const CloudLighting& b) {
    if (a.model != b.model) return false;
    if (a.model == CloudLightModel::Roettger) return true;
    return a.sun.color == b.sun.color && a.sun.intensity == b.sun.intensity && a.gas.albedo == b.gas.albedo && a.gas.ambient == b.gas.ambient &&
           a.gas.multipleScattering == b.gas.multipleScattering && samePhase(a.gas.phase, b.gas.phase);
}

// HG lobes are convex in cos theta, so their sum peaks at cos theta = +-1.
float phaseMax(const PhaseFunction& p) { return std::max(p(1.0f), p(-1.0f)); }

bool multiLight(const CloudLighting& L) { return L.model == CloudLightModel::LowAlbedo && !L.lights.empty(); }

// Whether every lit light's colour (the sun's included; one of zero colour or
// intensity lights nothing) is a multiple of the first lit one's: cross
// product zero up to float rounding of the products, 1e-6 relative. Then one
// scalar per vertex draws them (the one-scalar path); otherwise each vertex
// carries an RGB source (LodFrame::rgb).
bool sharedColour(const CloudLighting& L) {
    glm::dvec3 ref(0.0);
    bool first = true;
    for (std::size_t i = 0; i <= L.lights.size(); ++i) {
        const Light& l = i == 0 ? L.sun : L.lights[i - 1];
        const glm::dvec3 c = glm::dvec3(l.color) * double(l.intensity);
        if (!(glm::dot(c, c) > 0.0)) continue;
        if (first) {
            ref = glm::dvec3(l.color);
            first = false;
            continue;
        }
        if (glm::length(glm::cross(c, ref)) > 1e-6 * glm::length(c) * glm::length(ref)) return false;
    }
    return true;
}

// Transmittance towards each light between grid points: trilinear in the
// per-point arrays (exact at grid points), clamped onto the grid.
class GridShadows final : public ShadowProvider {
public:
    GridShadows(glm::ivec3 dims, glm::vec3 origin, float spacing, std::vector<const std::vector<float>*> trans)
        : mDims(dims), mOrigin(origin), mInv(1.0f / spacing), mTrans(std::move(trans)) {}
    float transmittance(std::size_t light, glm::vec3 world) const override {
        const std::vector<float>& t = *mTrans[light];
        const glm::vec3 g = glm::clamp((world - mOrigin) * mInv, glm::vec3(0.0f), glm::vec3(mDims - 1));
        const glm::ivec3 i0 = glm::min(glm::ivec3(g), glm::max(mDims - 2, glm::ivec3(0)));
        const glm::vec3 f = g - glm::vec3(i0);
        float v = 0.0f;
        for (int c = 0; c < 8; ++c) {
            const glm::ivec3 k = glm::min(i0 + glm::ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1), mDims - 1);
            const float w = ((c & 1) ? f.x : 1.0f - f.x) * ((c & 2) ? f.y : 1.0f - f.y) * ((c & 4) ? f.z : 1.0f - f.z);
            if (w != 0.0f) v += w * t[std::size_t(k.x) + std::size_t(mDims.x) * (std::size_t(k.y) + std::size_t(mDims.y) * std::size_t(k.z))];
        }
        return v;
    }

private:
    glm::ivec3 mDims;
    glm::vec3 mOrigin;
    float mInv;
    std::vector<const std::vector<float>*> mTrans;
};

// A caster's box grown as Scene::shadowFallsOn grows it (a relative 1e-5):
// a point whose ray meets it lies in a grid that test lets through, so
// gating the casters by that test drops none the points would trace.
struct PaddedBox {
    glm::dvec3 lo, hi;
};

PaddedBox padded(glm::vec3 lo, glm::vec3 hi) {
    glm::dvec3 c0(lo), c1(hi);
    const double pad = 1e-5 * (1.0 + std::max({glm::length(c1 - c0), glm::length(c0), glm::length(c1)}));
    return {c0 - pad, c1 + pad};
}

// Whether the ray from p toward the light (without end toward a directional
// one, to its position for a point or spot) meets the box (slab test).
bool rayMeetsBox(glm::dvec3 p, const Light& light, const PaddedBox& b) {
    const bool directional = light.type == LightType::Directional;
    const glm::dvec3 d = directional ? -glm::normalize(glm::dvec3(light.direction)) : glm::dvec3(light.position) - p;
    double t0 = 0.0, t1 = directional ? std::numeric_limits<double>::infinity() : 1.0;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
            if (p[a] < b.lo[a] || p[a] > b.hi[a]) return false;
            continue;
        }
        double ta = (b.lo[a] - p[a]) / d[a], tb = (b.hi[a] - p[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
    }
    return true;
}

// A conservative bound, in world x and y, of the points in the plane z = c
// whose ray toward the light meets the box: false when none can. A
// directional light (u toward it): p = b - t u, t >= 0, so in the plane t
// spans the box's z extent's [t0, t1] and x, y the box's shifted by -t u. A
// point or spot light at q: p = q + s (b - q), s >= 1, so each coordinate
// stays on the far side of the box from q (or anywhere with q across it).
bool sliceBound(const PaddedBox& b, const Light& light, double c, glm::dvec2& lo, glm::dvec2& hi) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    lo = glm::dvec2(-inf), hi = glm::dvec2(inf);
    if (light.type == LightType::Directional) {
        const glm::dvec3 u = -glm::normalize(glm::dvec3(light.direction));
        const double ta = u.z != 0.0 ? (b.lo.z - c) / u.z : 0.0, tb = u.z != 0.0 ? (b.hi.z - c) / u.z : 0.0;
        if (u.z != 0.0 && std::isfinite(ta) && std::isfinite(tb)) {
            const double t0 = std::max(0.0, std::min(ta, tb)), t1 = std::max(ta, tb);
            if (t1 < 0.0) return false;
            for (int a = 0; a < 2; ++a) {
                lo[a] = b.lo[a] - std::max(t0 * u[a], t1 * u[a]);
                hi[a] = b.hi[a] - std::min(t0 * u[a], t1 * u[a]);
            }
            return true;
        }
        if (u.z == 0.0 && (c < b.lo.z || c > b.hi.z)) return false;
        for (int a = 0; a < 2; ++a) {
            if (u[a] >= 0.0) hi[a] = b.hi[a];
            if (u[a] <= 0.0) lo[a] = b.lo[a];
        }
        return true;
    }
    const glm::dvec3 q(light.position);
    if ((q.z > b.hi.z && c > b.hi.z) || (q.z < b.lo.z && c < b.lo.z)) return false;
    for (int a = 0; a < 2; ++a) {
        if (q[a] > b.hi[a]) hi[a] = b.hi[a];
        if (q[a] < b.lo[a]) lo[a] = b.lo[a];
    }
    return true;
}

// Marks the 26 neighbours of every marked point too (separable: x, y, z).
void dilate(glm::ivec3 dims, std::vector<std::uint8_t>& mask) {
    const std::size_t stride[3] = {1, std::size_t(dims.x), std::size_t(dims.x) * std::size_t(dims.y)};
    std::vector<std::uint8_t> src;
    for (int a = 0; a < 3; ++a) {
        src = mask;
        for (int z = 0, i = 0; z < dims.z; ++z)
            for (int y = 0; y < dims.y; ++y)
                for (int x = 0; x < dims.x; ++x, ++i) {
                    if (src[std::size_t(i)]) continue;
                    const int c = a == 0 ? x : a == 1 ? y : z, n = dims[a];
                    if ((c > 0 && src[std::size_t(i) - stride[a]]) || (c + 1 < n && src[std::size_t(i) + stride[a]])) mask[std::size_t(i)] = 1;
                }
    }
}

} // namespace

Status Cloud::validateLighting(const CloudLighting& lighting) { return checkLighting(lighting); }

Result<Cloud> Cloud::create(const CloudCreateDesc& desc) {
    if (Status s = checkLighting(desc.lighting); !s) return makeError(s.error());
    CloudDesc cd = desc.cloud;
    cd.model = CloudModel::DensityTableLightLength; // scalar = density
    auto field = makeCloudVolume(cd);
    if (!field) return makeError(field.error());
    // The transfer desc is checked by makeCloudTransfer in rebuildTable.
    if (auto t = makeCloudTransfer(desc.transfer); !t) return makeError(t.error());
    Cloud c;
    c.mDesc = desc;
    c.mLighting = desc.lighting;
    c.mDims = field->dims;
    c.mDensity = std::move(field->scalar);
    if (desc.yUp) {
        // Generator (x, y, z) with z up to world (x, z, y): y up.
        const glm::ivec3 g = c.mDims;
        std::vector<float> up(c.mDensity.size());
        for (int z = 0; z < g.z; ++z)
            for (int y = 0; y < g.y; ++y)
                for (int x = 0; x < g.x; ++x)
                    up[std::size_t(x) + std::size_t(g.x) * (std::size_t(z) + std::size_t(g.z) * std::size_t(y))] =
                        c.mDensity[std::size_t(x) + std::size_t(g.x) * (std::size_t(y) + std::size_t(g.y) * std::size_t(z))];
        c.mDensity = std::move(up);
        c.mDims = {g.x, g.z, g.y};
    }
    // The field first: a point or spot light is traced through it.
    if (Status s = c.rebuildField(); !s) return makeError(s.error());
    if (Status s = c.relight(); !s) return makeError(s.error());
    if (Status s = c.rebuildTable(); !s) return makeError(s.error());
    return c;
}

Status Cloud::relight(bool own, const std::span<const ShadowCaster* const>* casters) {
    const std::size_t count = mDensity.size();
    const CloudTransferDesc& td = mDesc.transfer;
    if (own) {
        const glm::dvec3 towardSun = -glm::normalize(glm::dvec3(mLighting.sun.direction));
        if (mLighting.model == CloudLightModel::Roettger) {
            detail::sweepSunTransmittance(mDims, mDensity, double(mDesc.cloud.lightExtinctionPerCell), towardSun, mSunOwn);
            mRgb = false;
        } else {
            // The extinction drawn (sigma = maxExtinction f above the threshold) is
            // the one the sun is attenuated by: one cell is spacingWorld long.
            std::vector<float> sigma(count);
            for (std::size_t i = 0; i < count; ++i) sigma[i] = mDensity[i] >= td.threshold ? mDensity[i] : 0.0f;
            detail::sweepSunTransmittance(mDims, sigma, double(td.maxExtinctionPerWorld) * double(mDesc.volume.spacingWorld), towardSun, mSunOwn);
            if (!multiLight(mLighting)) {
                mLightT.clear();
                mLightScale = 0.0f;
                mRgb = false;
            } else {
                mRgb = !sharedColour(mLighting); // before traceLights: it picks the colour the weights are shares of
                if (Status s = traceLights(); !s) return makeError("Cloud: lights: " + s.error());
            }
        }
    }
    std::vector<std::uint8_t> changed;
    bool any = own;
    if (casters) {
        changed.assign(count, 0);
        any = receive(*casters, changed) || any;
    }
    if (!any) return {}; // no point's light changed: nothing to rebuild
    const std::vector<std::uint8_t>* only = own ? nullptr : &changed;
    compose(only);
    if (Status s = buildField(only); !s) return s;
    if (own) ++mRelights;
    else ++mRestrictedRelights;
    return {};
}

bool Cloud::receive(std::span<const ShadowCaster* const> casters, std::vector<std::uint8_t>& changed) {
    const std::size_t count = mDensity.size();
    std::vector<CasterRecord> now(casters.size());
    for (std::size_t i = 0; i < casters.size(); ++i) {
        const ShadowCaster& c = *casters[i];
        if (c.empty()) continue; // casts nothing: the default record
        now[i] = {c.fingerprint(), c.boundsMin(), c.boundsMax(), false};
    }
    // The boxes whose shadow may have changed: a changed caster's old and new one.
    std::vector<const CasterRecord*> moved;
    for (std::size_t i = 0; i < std::max(now.size(), mCasters.size()); ++i) {
        const CasterRecord* was = i < mCasters.size() ? &mCasters[i] : nullptr;
        const CasterRecord* is = i < now.size() ? &now[i] : nullptr;
        if (was && is && *was == *is) continue;
        if (was && !was->empty) moved.push_back(was);
        if (is && !is->empty) moved.push_back(is);
    }
    const float h = mDesc.volume.spacingWorld;
    const Aabb grid{mDesc.volume.originWorld, mDesc.volume.originWorld + glm::vec3(mDims - 1) * h};
    const std::size_t slots = 1 + mLighting.lights.size();
    mRecv.resize(slots);
    bool any = false;
    std::vector<std::size_t> active;
    std::vector<PaddedBox> activeBox, dirty;
    for (std::size_t slot = 0; slot < slots; ++slot) {
        const Light& light = slot == 0 ? mLighting.sun : mLighting.lights[slot - 1];
        Received& r = mRecv[slot];
        if (slot > 0 && (slot - 1 >= mLightT.size() || mLightT[slot - 1].own.empty())) {
            r = {}; // lights nothing: nothing to shadow
            continue;
        }
        // The casters that can shadow the grid for this light; the others are never traced.
        active.clear(), activeBox.clear(), dirty.clear();
        for (std::size_t i = 0; i < now.size(); ++i)
            if (!now[i].empty && Scene::shadowFallsOn(Aabb{now[i].lo, now[i].hi}, light, grid)) {
                active.push_back(i);
                activeBox.push_back(padded(now[i].lo, now[i].hi));
            }
        const bool full = !r.valid || !sameGeometry(r.tracedFor, light) || r.depth.size() != count;
        if (!full)
            for (const CasterRecord* m : moved)
                if (Scene::shadowFallsOn(Aabb{m->lo, m->hi}, light, grid)) dirty.push_back(padded(m->lo, m->hi));
        if (!full && dirty.empty()) continue; // no changed caster can shadow the grid for this light: costs nothing
        if (full) {
            // A new light (or the first casters): every point, each marked
            // changed only where its depth differs (none with no caster).
            if (!r.valid || r.depth.size() != count) r.depth.assign(count, 0.0f);
            r.tracedFor = light;
            r.valid = true;
        }
        const glm::vec3 origin = mDesc.volume.originWorld;
        // World to grid index along axis a, rounded outward with a point to
        // spare (the bound is only a pre-filter: each point's own test decides).
        auto index = [&](int a, double w, bool upper) {
            const double v = (w - double(origin[a])) / double(h);
            if (!(v == v)) return upper ? mDims[a] - 1 : 0; // NaN: the whole axis
            const double r = std::clamp(upper ? std::ceil(v) + 1.0 : std::floor(v) - 1.0, 0.0, double(mDims[a] - 1));
            return int(r);
        };
        for (int z = 0; z < mDims.z; ++z) {
            glm::ivec2 i0(0), i1(mDims.x - 1, mDims.y - 1);
            if (!full) {
                // Only the rows the changed boxes' shadows can reach in this plane.
                i0 = glm::ivec2(mDims.x, mDims.y), i1 = glm::ivec2(-1);
                const double c = double(gridPoint({0, 0, z}).z);
                for (const PaddedBox& b : dirty) {
                    glm::dvec2 lo, hi;
                    if (!sliceBound(b, light, c, lo, hi)) continue;
                    for (int a = 0; a < 2; ++a) i0[a] = std::min(i0[a], index(a, lo[a], false)), i1[a] = std::max(i1[a], index(a, hi[a], true));
                }
            }
            for (int y = i0.y; y <= i1.y; ++y)
                for (int x = i0.x; x <= i1.x; ++x) {
                    const std::size_t i = std::size_t(x) + std::size_t(mDims.x) * (std::size_t(y) + std::size_t(mDims.y) * std::size_t(z));
                    const glm::vec3 p = gridPoint({x, y, z});
                    const glm::dvec3 pd(p);
                    if (!full && std::none_of(dirty.begin(), dirty.end(), [&](const PaddedBox& b) { return rayMeetsBox(pd, light, b); })) continue;
                    // Every caster the ray meets, in the casters' order: the same sum a full relight makes.
                    float depth = 0.0f;
                    for (std::size_t k = 0; k < active.size(); ++k)
                        if (rayMeetsBox(pd, light, activeBox[k])) {
                            depth += casters[active[k]]->opticalDepthToLight(p, light);
                            ++mReceiveTraces;
                        }
                    if (!full || !active.empty()) ++mReceivePoints;
                    float& d = r.depth[i];
                    if (d == depth) continue;
                    d = depth;
                    changed[i] = 1;
                    any = true;
                }
        }
    }
    mCasters = std::move(now);
    return any;
}

void Cloud::compose(const std::vector<std::uint8_t>* changed) {
    const std::size_t count = mDensity.size();
    for (std::size_t slot = 0; slot <= mLightT.size(); ++slot) {
        const std::vector<float>& own = slot == 0 ? mSunOwn : mLightT[slot - 1].own;
        std::vector<float>& trans = slot == 0 ? mTrans : mLightT[slot - 1].trans;
        if (own.empty()) {
            trans.clear();
            continue;
        }
        trans.resize(count);
        const Received* r = slot < mRecv.size() && mRecv[slot].valid ? &mRecv[slot] : nullptr;
        for (std::size_t i = 0; i < count; ++i) {
            if (changed && !(*changed)[i]) continue;
            const float d = r ? r->depth[i] : 0.0f;
            trans[i] = d > 0.0f ? own[i] * std::exp2(-d) : own[i];
        }
    }
}

Status Cloud::buildField(const std::vector<std::uint8_t>* changed) {
    const std::size_t count = mDensity.size();
    const CloudTransferDesc& td = mDesc.transfer;
    ScalarVolume field;
    field.dims = mDims;
    field.lengthScale.resize(count);
    if (mLighting.model == CloudLightModel::Roettger) {
        field.scalar = mDensity;
        for (std::size_t i = 0; i < count; ++i) field.lengthScale[i] = std::min(1.0f, mLighting.ambient + mLighting.diffuse * mTrans[i]);
    } else {
        for (std::size_t i = 0; i < count; ++i) field.lengthScale[i] = mDensity[i] >= td.threshold ? mDensity[i] : 0.0f;
        if (!multiLight(mLighting)) {
            field.scalar = mTrans;
        } else {
            // u = sum_i w_i E_i (4 pi maxPhase T_i + m) / scale at every grid
            // point, by the lighting code's own evaluation (lightPoints with
            // an isotropic phase: 4 pi phase = 1, each light's colour
            // w_i 4 pi maxPhase and multipleScattering m / (4 pi maxPhase)).
            // w_i: the light's share of the common colour, or with lights of
            // different colours its largest channel (unitLights).
            // After a caster moved, only the points whose transmittance
            // changed and their neighbours (GridShadows interpolates between
            // grid points, and a grid point's float position may sit a
            // rounding off its node) are evaluated again.
            mPhaseMax = phaseMax(mLighting.gas.phase);
            std::vector<std::size_t> index;
            std::vector<glm::vec3> points, source;
            std::vector<std::uint8_t> near;
            if (changed) {
                near = *changed;
                dilate(mDims, near);
            }
            if (mSource.size() != count) mSource.assign(count, 0.0f), near.clear();
            for (int z = 0, i = 0; z < mDims.z; ++z)
                for (int y = 0; y < mDims.y; ++y)
                    for (int x = 0; x < mDims.x; ++x, ++i)
                        if (near.empty() || near[std::size_t(i)]) {
                            index.push_back(std::size_t(i));
                            points.push_back(gridPoint({x, y, z}));
                        }
            const float fourPiMax = 4.0f * std::numbers::pi_v<float> * mPhaseMax;
            std::vector<const std::vector<float>*> trans;
            const std::vector<Light> lights = unitLights(fourPiMax, &trans);
            const GridShadows shadows(mDims, mDesc.volume.originWorld, mDesc.volume.spacingWorld, std::move(trans));
            const GasLightingDesc iso{.albedo = 1.0f, .multipleScattering = mLighting.gas.multipleScattering / fourPiMax};
            if (!points.empty())
                if (Status s = lightPoints(points, mDesc.volume.spacingWorld, gridPoint({0, 0, 0}), lights, &shadows, iso, source); !s)
                    return makeError("Cloud: lights: " + s.error());
            for (std::size_t k = 0; k < index.size(); ++k) mSource[index[k]] = source[k].x;
            float scale = 0.0f;
            for (float v : mSource) scale = std::max(scale, v);
            mLightScale = scale;
            field.scalar.resize(count);
            const float inv = scale > 0.0f ? 1.0f / scale : 0.0f;
            for (std::size_t i = 0; i < count; ++i) field.scalar[i] = std::clamp(mSource[i] * inv, 0.0f, 1.0f);
        }
    }
    auto vol = LodVolume::create(field, mDesc.volume);
    if (!vol) return makeError(vol.error());
    mVolume = std::move(*vol);
    return {};
}

Status Cloud::rebuildTable() {
    Result<TransferFunction> tf = makeError("");
    if (mLighting.model == CloudLightModel::Roettger) {
        tf = makeCloudTransfer(mDesc.transfer);
        mPhaseMax = 1.0f;
    } else {
        // kappa(s) = A + B s with s = T phase / max phase: at s = 0 only the
        // ambient and multiple-scattering terms, at s = 1 the full sun in the
        // phase function's peak.
        const GasLightingDesc& g = mLighting.gas;
        const glm::vec3 sun = mLighting.sun.color * mLighting.sun.intensity;
        mPhaseMax = phaseMax(g.phase);
        const glm::vec3 base = mDesc.transfer.bright * g.albedo;
        glm::vec3 a = base * (g.ambient + sun * g.multipleScattering);
        glm::vec3 b = base * sun * (4.0f * std::numbers::pi_v<float> * mPhaseMax);
        if (multiLight(mLighting)) {
            // With more lights every light's term is in s (their irradiance
            // varies over the cloud): kappa(s) = base (ambient + colour scale s).
            a = base * g.ambient;
            b = base * mLightColour * mLightScale;
        }
        const float rho = mDesc.transfer.maxExtinctionPerWorld;
        tf = TransferFunction::create({{0.0f, a, rho}, {1.0f, a + b, rho}});
    }
    if (!tf) return makeError(tf.error());
    PreIntegrationDesc pd = mDesc.table;
    // LowAlbedo: with rho constant the entry is A alpha(l) + B (s_f alpha(l) + (s_b - s_f) g(l)),
    // affine in each scalar, so two samples per scalar axis interpolate it exactly.
    if (mLighting.model == CloudLightModel::LowAlbedo) pd.scalarResolution = 2;
    pd.maxLengthWorld = std::sqrt(3.0f) * float(1 << mVolume.rootLevel()) * mVolume.spacingWorld();
    auto table = PreIntegrationTable::create(*tf, pd);
    if (!table) return makeError("CloudCreateDesc.table: " + table.error());
    mTransfer = std::move(*tf);
    mTable = std::move(*table);
    ++mTableBuilds;
    return {};
}

Status Cloud::rebuildField() {
    const float h = mDesc.volume.spacingWorld, maxExt = mDesc.transfer.maxExtinctionPerWorld, t = mDesc.transfer.threshold;
    Grid g;
    g.dims = mDims;
    g.spacing = glm::vec3(h);
    // Grid::localPosition centres x and z; undo it so cell c sits at origin + c h.
    const glm::vec3 half = glm::vec3(mDims - 1) * 0.5f;
    g.transform = glm::mat4(1.0f);
    g.transform[3] = glm::vec4(mDesc.volume.originWorld + glm::vec3(half.x, 0.0f, half.z) * h, 1.0f);
    for (int z = 0, i = 0; z < mDims.z; ++z)
        for (int y = 0; y < mDims.y; ++y)
            for (int x = 0; x < mDims.x; ++x, ++i) {
                const float f = mDensity[std::size_t(i)];
                if (!(f >= t) || f <= 0.0f) continue;
                Voxel v;
                v.cell = {x, y, z};
                v.opacity = float(-std::expm1(-double(maxExt) * double(f) * double(h)));
                if (v.opacity > 0.0f) g.voxels.push_back(v);
            }
    if (g.voxels.empty()) {
        mField = DensityField();
        return {};
    }
    auto field = DensityField::fromGrid(g);
    if (!field) return makeError("Cloud: density field: " + field.error());
    mField = std::move(*field);
    return {};
}

bool Cloud::sameCasters(std::span<const ShadowCaster* const> casters) const {
    if (casters.size() != mCasters.size()) return false;
    for (std::size_t i = 0; i < casters.size(); ++i) {
        const ShadowCaster& c = *casters[i];
        const CasterRecord r = c.empty() ? CasterRecord{} : CasterRecord{c.fingerprint(), c.boundsMin(), c.boundsMax(), false};
        if (!(r == mCasters[i])) return false;
    }
    return true;
}

void Cloud::forgetCasters() {
    mRecv.clear();
    mCasters.clear();
}

const std::vector<float>& Cloud::receivedDepth(std::size_t slot) const {
    static const std::vector<float> none;
    return slot < mRecv.size() && mRecv[slot].valid ? mRecv[slot].depth : none;
}

Status Cloud::setLight(const CloudLighting& lighting, std::span<const ShadowCaster* const> casters) {
    if (Status s = checkLighting(lighting); !s) return s;
    for (std::size_t i = 0; i < casters.size(); ++i) {
        if (!casters[i]) return makeError("Cloud::setLight: casters[" + std::to_string(i) + "] is null");
        if (casters[i] == &mField)
            return makeError("Cloud::setLight: casters[" + std::to_string(i) +
                             "] is this cloud's own densityField() (its self-shadowing is its own; pass the other volumes)");
    }
    const bool castersSame = sameCasters(casters);
    // Only the casters changed: the points under their old and new boxes.
    auto relightCasters = [&]() -> Status {
        if (castersSame) return {};
        const float scale = mLightScale;
        Status s = relight(false, &casters);
        if (s && multiLight(mLighting) && mLightScale != scale) s = rebuildTable(); // the scale of s moved
        if (!s) {
            // Not known to happen (the sizes and lights built before): traced again from scratch next time.
            forgetCasters();
            static_cast<void>(relight());
            if (multiLight(mLighting)) static_cast<void>(rebuildTable());
        }
        return s;
    };
    if (multiLight(lighting) || multiLight(mLighting)) {
        // The scale of s is the largest source over the grid: any change of a
        // light moves it, so the field and the table go together.
        if (lighting.model == mLighting.model && sameLights(lighting, mLighting) && lighting.gas.albedo == mLighting.gas.albedo &&
            lighting.gas.ambient == mLighting.gas.ambient && lighting.gas.multipleScattering == mLighting.gas.multipleScattering &&
            samePhase(lighting.gas.phase, mLighting.gas.phase)) {
            mLighting = lighting;
            return relightCasters();
        }
        const CloudLighting old = mLighting;
        const std::vector<LightState> oldT = mLightT;
        mLighting = lighting;
        Status s = relight(true, &casters);
        if (s) s = rebuildTable();
        if (!s) {
            mLighting = old;
            mLightT = oldT;
            forgetCasters();
            // Back to the previous field and table: built before from the same
            // sizes under the same budget, so they build again.
            static_cast<void>(relight());
            static_cast<void>(rebuildTable());
        }
        return s;
    }
    const bool field = !sameField(lighting, mLighting), colour = !sameColour(lighting, mLighting);
    if (!field && !colour) {
        mLighting = lighting; // e.g. a new Roettger gas desc: nothing it draws depends on it
        return relightCasters();
    }
    const CloudLighting old = mLighting;
    mLighting = lighting;
    if (field) {
        if (Status s = relight(true, &casters); !s) return mLighting = old, forgetCasters(), s;
    } else if (Status s = relightCasters(); !s) {
        return mLighting = old, s;
    }
    if (colour)
        if (Status s = rebuildTable(); !s) return mLighting = old, s;
    return {};
}

Status Cloud::setDensity(std::vector<float> density) {
    if (density.size() != mDensity.size())
        return makeError("Cloud::setDensity: " + std::to_string(density.size()) + " values; the cloud has " + std::to_string(mDensity.size()));
    for (std::size_t i = 0; i < density.size(); ++i)
        if (!std::isfinite(density[i]) || density[i] < 0.0f || density[i] > 1.0f)
            return makeError("Cloud::setDensity: density[" + std::to_string(i) + "] must be finite and in [0, 1]");
    if (density == mDensity) return {};
    std::swap(mDensity, density);
    // Every light's transmittance is traced again through the new field.
    for (LightState& l : mLightT) l.valid = false;
    Status s = rebuildField();
    if (s) s = relight();
    if (s && multiLight(mLighting)) s = rebuildTable(); // the scale of s moved
    if (!s) {
        // Back to the previous density's fields: built before, so they build again.
        std::swap(mDensity, density);
        for (LightState& l : mLightT) l.valid = false;
        static_cast<void>(rebuildField());
        static_cast<void>(relight());
        if (multiLight(mLighting)) static_cast<void>(rebuildTable());
    }
    return s;
}

Status Cloud::update(const Camera& camera, const LodRefineDesc& refine, LodFrame& out) {
    if (Status s = mVolume.update(camera, refine, &mTransfer, out); !s) return s;
    if (mLighting.model != CloudLightModel::LowAlbedo) return {};
    // Lights of different colours: an RGB source per vertex, whatever the phase.
    if (multiLight(mLighting) && mRgb) return applyLightPhases(camera, out);
    const PhaseFunction& phase = mLighting.gas.phase;
    if (phase.lobeCount() == 1 && phase.lobe(0).g == 0.0f) return {}; // isotropic: s = T (with more lights, R = 1)
    if (multiLight(mLighting)) return applyLightPhases(camera, out);
    const glm::vec3 travel = glm::normalize(mLighting.sun.direction);
    const glm::vec3 eye = camera.eye(), back = -camera.forward();
    const bool persp = camera.perspective();
    const float inv = 1.0f / mPhaseMax;
    for (Tetrahedron& t : out.tets)
        for (int k = 0; k < 4; ++k) {
            const glm::vec3 d = eye - t.position[std::size_t(k)];
            const float len = glm::length(d);
            const glm::vec3 toEye = persp && len > 0.0f ? d / len : back;
            t.scalar[std::size_t(k)] = std::clamp(t.scalar[std::size_t(k)] * phase(travel, toEye) * inv, 0.0f, 1.0f);
        }
    return {};
}

glm::vec3 Cloud::gridPoint(glm::ivec3 p) const { return mDesc.volume.originWorld + glm::vec3(p) * mDesc.volume.spacingWorld; }

std::vector<Light> Cloud::unitLights(float scale, std::vector<const std::vector<float>*>* trans, bool coloured) const {
    // Each lit light with colour w_i scale (w_i its share of the common
    // colour mLightColour; with lights of different colours, mLightColour is
    // white and w_i the light's largest channel), paired with its
    // transmittance. `coloured`: each light's own colour x intensity x scale instead.
    std::vector<Light> out;
    const double ref2 = glm::dot(glm::dvec3(mLightColour), glm::dvec3(mLightColour));
    for (std::size_t i = 0; i <= mLighting.lights.size(); ++i) {
        const Light& l = i == 0 ? mLighting.sun : mLighting.lights[i - 1];
        const glm::dvec3 c = glm::dvec3(l.color) * double(l.intensity);
        if (!(glm::dot(c, c) > 0.0) || !(ref2 > 0.0)) continue;
        Light u = l;
        u.color = glm::vec3(1.0f);
        if (coloured) {
            u.color = l.color;
            u.intensity = l.intensity * scale;
        } else if (mRgb) {
            u.intensity = float(std::max({c.x, c.y, c.z}) * double(scale));
        } else {
            u.intensity = float(glm::dot(c, glm::dvec3(mLightColour)) / ref2 * double(scale));
        }
        out.push_back(u);
        if (trans) trans->push_back(i == 0 ? &mTrans : &mLightT[i - 1].trans);
    }
    return out;
}

Status Cloud::traceLights() {
    mLightColour = glm::vec3(0.0f);
    for (std::size_t i = 0; i <= mLighting.lights.size() && !mRgb; ++i) {
        const Light& l = i == 0 ? mLighting.sun : mLighting.lights[i - 1];
        if (glm::dot(l.color * l.intensity, l.color * l.intensity) > 0.0f) {
            mLightColour = l.color * l.intensity; // the first lit light's: this path has the others multiples of it (sharedColour)
            break;
        }
    }
    if (mRgb) mLightColour = glm::vec3(1.0f); // the weights are the lights' largest channels (unitLights)
    mLightT.resize(mLighting.lights.size());
    const std::size_t count = mDensity.size();
    const float h = mDesc.volume.spacingWorld;
    const glm::vec3 lo = mDesc.volume.originWorld, hi = lo + glm::vec3(mDims - 1) * h;
    std::vector<glm::vec3> points(count), reach;
    for (int z = 0, i = 0; z < mDims.z; ++z)
        for (int y = 0; y < mDims.y; ++y)
            for (int x = 0; x < mDims.x; ++x, ++i) points[std::size_t(i)] = gridPoint({x, y, z});
    for (std::size_t k = 0; k < mLighting.lights.size(); ++k) {
        const Light& l = mLighting.lights[k];
        LightState& st = mLightT[k];
        if (!(glm::dot(l.color * l.intensity, l.color * l.intensity) > 0.0f)) {
            st = {}; // lights nothing: costs nothing
            continue;
        }
        if (st.valid && sameGeometry(st.tracedFor, l)) continue;
        st.tracedFor = l;
        st.valid = true;
        if (l.type == LightType::Directional) {
            // Parallel rays: swept as the sun.
            std::vector<float> sigma(count);
            for (std::size_t i = 0; i < count; ++i) sigma[i] = mDensity[i] >= mDesc.transfer.threshold ? mDensity[i] : 0.0f;
            detail::sweepSunTransmittance(mDims, sigma, double(mDesc.transfer.maxExtinctionPerWorld) * double(h),
                                          -glm::normalize(glm::dvec3(l.direction)), st.own);
            continue;
        }
        // Converging rays: which points the light reaches at all (the spot's
        // cone, by the lighting code's own evaluation), then each traced to
        // the light through the trilinear field inside the grid's box.
        Light unit = l;
        unit.color = glm::vec3(1.0f);
        unit.intensity = 1.0f;
        const Light one[] = {unit};
        if (Status s = lightPoints(points, h, points[0], one, nullptr, GasLightingDesc{.albedo = 1.0f}, reach); !s) return s;
        st.own.assign(count, 0.0f);
        for (std::size_t i = 0; i < count; ++i) {
            if (!(reach[i].x > 0.0f)) continue;
            const glm::vec3 p = points[i], d = l.position - p;
            // Where the segment to the light leaves the box (it starts inside).
            float t = 1.0f;
            for (int a = 0; a < 3; ++a) {
                if (d[a] > 0.0f) t = std::min(t, (hi[a] - p[a]) / d[a]);
                else if (d[a] < 0.0f) t = std::min(t, (lo[a] - p[a]) / d[a]);
            }
            t = std::max(t, 0.0f);
            st.own[i] = mField.empty() || t == 0.0f ? 1.0f : std::exp2(-mField.opticalDepth(p, p + t * d));
            ++mLightTraces;
        }
    }
    return {};
}

Status Cloud::applyLightPhases(const Camera& camera, LodFrame& out) {
    // s = u R per vertex: R = sum_i w_i E_i (4 pi phase_i T_i + m) / sum_i
    // w_i E_i (4 pi maxPhase T_i + m), both by lightPoints at the vertex.
    // Lights of different colours: s_c = u R_c per channel, R_c = sum_i c_i,c
    // E_i (4 pi phase_i T_i + m) / the same denominator (w_i = max_c c_i,c,
    // so R_c <= 1), written to out.rgb; the scalar keeps max_c s_c.
    mVertexScratch.resize(out.tets.size() * 4);
    for (std::size_t t = 0; t < out.tets.size(); ++t)
        for (std::size_t k = 0; k < 4; ++k) mVertexScratch[4 * t + k] = out.tets[t].position[k];
    // An orthographic camera looks along one direction: the eye is taken
    // 10^4 box diagonals behind the cloud (directions within 10^-4 rad).
    const Aabb box = mVolume.boundsWorld();
    const glm::vec3 eye = camera.perspective() ? camera.eye() : 0.5f * (box.lo + box.hi) - camera.forward() * (1e4f * glm::length(box.hi - box.lo));
    std::vector<const std::vector<float>*> trans;
    const float fourPiMax = 4.0f * std::numbers::pi_v<float> * mPhaseMax;
    const std::vector<Light> bound = unitLights(fourPiMax, &trans), seen = unitLights(1.0f, nullptr, mRgb);
    const GridShadows shadows(mDims, mDesc.volume.originWorld, mDesc.volume.spacingWorld, std::move(trans));
    GasLightingDesc viewed{.phase = mLighting.gas.phase, .albedo = 1.0f, .multipleScattering = mLighting.gas.multipleScattering};
    const GasLightingDesc iso{.albedo = 1.0f, .multipleScattering = mLighting.gas.multipleScattering / fourPiMax};
    if (Status s = lightPoints(mVertexScratch, mDesc.volume.spacingWorld, eye, seen, &shadows, viewed, mSeenScratch); !s) return s;
    if (Status s = lightPoints(mVertexScratch, mDesc.volume.spacingWorld, eye, bound, &shadows, iso, mBoundScratch); !s) return s;
    if (mRgb) {
        out.rgb.resize(out.tets.size());
        for (std::size_t t = 0; t < out.tets.size(); ++t)
            for (std::size_t k = 0; k < 4; ++k) {
                const glm::vec3 n = mSeenScratch[4 * t + k];
                const float d = mBoundScratch[4 * t + k].x;
                float& s = out.tets[t].scalar[k];
                glm::vec3& c = out.rgb[t][k];
                c = d > 0.0f ? glm::clamp(s * n / d, 0.0f, 1.0f) : glm::vec3(0.0f);
                s = std::max({c.x, c.y, c.z});
            }
        return {};
    }
    for (std::size_t t = 0; t < out.tets.size(); ++t)
        for (std::size_t k = 0; k < 4; ++k) {
            const float n = mSeenScratch[4 * t + k].x, d = mBoundScratch[4 * t + k].x;
            float& s = out.tets[t].scalar[k];
            s = d > 0.0f ? std::clamp(s * n / d, 0.0f, 1.0f) : 0.0f;
        }
    return {};
}

glm::dvec3 Cloud::sourceAt(double T, glm::vec3 toEye) const {
    if (mLighting.model == CloudLightModel::Roettger) return glm::dvec3(std::min(1.0, double(mLighting.ambient) + double(mLighting.diffuse) * T));
    const GasLightingDesc& g = mLighting.gas;
    const glm::dvec3 sun = glm::dvec3(mLighting.sun.color) * double(mLighting.sun.intensity);
    const double p = double(g.phase(glm::normalize(mLighting.sun.direction), toEye));
    return glm::dvec3(mDesc.transfer.bright) * double(g.albedo) *
           (glm::dvec3(g.ambient) + sun * (4.0 * std::numbers::pi * p * T + double(g.multipleScattering)));
}

} // namespace splatfx
