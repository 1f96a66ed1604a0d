// A LOD cloud relit when its sun or density changes (cloud.hpp).
#include "splatfx/cloud.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

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

Status Cloud::relight() {
    const std::size_t count = mDensity.size();
    const CloudTransferDesc& td = mDesc.transfer;
    const glm::dvec3 towardSun = -glm::normalize(glm::dvec3(mLighting.sun.direction));
    ScalarVolume field;
    field.dims = mDims;
    if (mLighting.model == CloudLightModel::Roettger) {
        detail::sweepSunTransmittance(mDims, mDensity, double(mDesc.cloud.lightExtinctionPerCell), towardSun, mTrans);
        field.scalar = mDensity;
        mRgb = false;
        field.lengthScale.resize(count);
        for (std::size_t i = 0; i < count; ++i) field.lengthScale[i] = std::min(1.0f, mLighting.ambient + mLighting.diffuse * mTrans[i]);
    } else {
        // The extinction drawn (sigma = maxExtinction f above the threshold) is
        // the one the sun is attenuated by: one cell is spacingWorld long.
        field.lengthScale.resize(count);
        for (std::size_t i = 0; i < count; ++i) field.lengthScale[i] = mDensity[i] >= td.threshold ? mDensity[i] : 0.0f;
        detail::sweepSunTransmittance(mDims, field.lengthScale, double(td.maxExtinctionPerWorld) * double(mDesc.volume.spacingWorld), towardSun,
                                      mTrans);
        if (!multiLight(mLighting)) {
            field.scalar = mTrans;
            mLightT.clear();
            mLightScale = 0.0f;
            mRgb = false;
        } else {
            // u = sum_i w_i E_i (4 pi maxPhase T_i + m) / scale at every grid
            // point, by the lighting code's own evaluation (lightPoints with
            // an isotropic phase: 4 pi phase = 1, each light's colour
            // w_i 4 pi maxPhase and multipleScattering m / (4 pi maxPhase)).
            // w_i: the light's share of the common colour, or with lights of
            // different colours its largest channel (unitLights).
            mRgb = !sharedColour(mLighting);
            if (Status s = traceLights(); !s) return makeError("Cloud: lights: " + s.error());
            mPhaseMax = phaseMax(mLighting.gas.phase);
            std::vector<glm::vec3> points(count), source;
            for (int z = 0, i = 0; z < mDims.z; ++z)
                for (int y = 0; y < mDims.y; ++y)
                    for (int x = 0; x < mDims.x; ++x, ++i) points[std::size_t(i)] = gridPoint({x, y, z});
            const float fourPiMax = 4.0f * std::numbers::pi_v<float> * mPhaseMax;
            std::vector<const std::vector<float>*> trans;
            const std::vector<Light> lights = unitLights(fourPiMax, &trans);
            const GridShadows shadows(mDims, mDesc.volume.originWorld, mDesc.volume.spacingWorld, std::move(trans));
            const GasLightingDesc iso{.albedo = 1.0f, .multipleScattering = mLighting.gas.multipleScattering / fourPiMax};
            if (Status s = lightPoints(points, mDesc.volume.spacingWorld, points[0], lights, &shadows, iso, source); !s)
                return makeError("Cloud: lights: " + s.error());
            float scale = 0.0f;
            for (const glm::vec3& v : source) scale = std::max(scale, v.x);
            mLightScale = scale;
            field.scalar.resize(count);
            const float inv = scale > 0.0f ? 1.0f / scale : 0.0f;
            for (std::size_t i = 0; i < count; ++i) field.scalar[i] = std::clamp(source[i].x * inv, 0.0f, 1.0f);
        }
    }
    auto vol = LodVolume::create(field, mDesc.volume);
    if (!vol) return makeError(vol.error());
    mVolume = std::move(*vol);
    ++mRelights;
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

Status Cloud::setLight(const CloudLighting& lighting) {
    if (Status s = checkLighting(lighting); !s) return s;
    if (multiLight(lighting) || multiLight(mLighting)) {
        // The scale of s is the largest source over the grid: any change of a
        // light moves it, so the field and the table go together.
        if (lighting.model == mLighting.model && sameLights(lighting, mLighting) && lighting.gas.albedo == mLighting.gas.albedo &&
            lighting.gas.ambient == mLighting.gas.ambient && lighting.gas.multipleScattering == mLighting.gas.multipleScattering &&
            samePhase(lighting.gas.phase, mLighting.gas.phase)) {
            mLighting = lighting;
            return {};
        }
        const CloudLighting old = mLighting;
        const std::vector<LightState> oldT = mLightT;
        mLighting = lighting;
        Status s = relight();
        if (s) s = rebuildTable();
        if (!s) {
            mLighting = old;
            mLightT = oldT;
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
        return {};
    }
    const CloudLighting old = mLighting;
    mLighting = lighting;
    if (field)
        if (Status s = relight(); !s) return mLighting = old, s;
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
                                          -glm::normalize(glm::dvec3(l.direction)), st.trans);
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
        st.trans.assign(count, 0.0f);
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
            st.trans[i] = mField.empty() || t == 0.0f ? 1.0f : std::exp2(-mField.opticalDepth(p, p + t * d));
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
