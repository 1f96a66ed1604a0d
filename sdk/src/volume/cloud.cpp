// A LOD cloud relit when its sun or density changes (cloud.hpp).
#include "splatfx/cloud.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "volume/cloud_sweep.hpp"

namespace splatfx {
namespace {

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
    return {};
}

bool samePhase(const PhaseFunction& a, const PhaseFunction& b) {
    if (a.lobeCount() != b.lobeCount()) return false;
    for (int i = 0; i < a.lobeCount(); ++i)
        if (a.lobe(i).g != b.lobe(i).g || a.lobe(i).weight != b.lobe(i).weight) return false;
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

} // namespace

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
    if (Status s = c.relight(); !s) return makeError(s.error());
    if (Status s = c.rebuildTable(); !s) return makeError(s.error());
    if (Status s = c.rebuildField(); !s) return makeError(s.error());
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
        field.lengthScale.resize(count);
        for (std::size_t i = 0; i < count; ++i) field.lengthScale[i] = std::min(1.0f, mLighting.ambient + mLighting.diffuse * mTrans[i]);
    } else {
        // The extinction drawn (sigma = maxExtinction f above the threshold) is
        // the one the sun is attenuated by: one cell is spacingWorld long.
        field.lengthScale.resize(count);
        for (std::size_t i = 0; i < count; ++i) field.lengthScale[i] = mDensity[i] >= td.threshold ? mDensity[i] : 0.0f;
        detail::sweepSunTransmittance(mDims, field.lengthScale, double(td.maxExtinctionPerWorld) * double(mDesc.volume.spacingWorld), towardSun,
                                      mTrans);
        field.scalar = mTrans;
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
        const glm::vec3 a = base * (g.ambient + sun * g.multipleScattering);
        const glm::vec3 b = base * sun * (4.0f * std::numbers::pi_v<float> * mPhaseMax);
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
    if (Status s = relight(); !s) return std::swap(mDensity, density), s;
    return rebuildField();
}

Status Cloud::update(const Camera& camera, const LodRefineDesc& refine, LodFrame& out) {
    if (Status s = mVolume.update(camera, refine, &mTransfer, out); !s) return s;
    if (mLighting.model != CloudLightModel::LowAlbedo) return {};
    const PhaseFunction& phase = mLighting.gas.phase;
    if (phase.lobeCount() == 1 && phase.lobe(0).g == 0.0f) return {}; // isotropic: s = T
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

glm::dvec3 Cloud::sourceAt(double T, glm::vec3 toEye) const {
    if (mLighting.model == CloudLightModel::Roettger) return glm::dvec3(std::min(1.0, double(mLighting.ambient) + double(mLighting.diffuse) * T));
    const GasLightingDesc& g = mLighting.gas;
    const glm::dvec3 sun = glm::dvec3(mLighting.sun.color) * double(mLighting.sun.intensity);
    const double p = double(g.phase(glm::normalize(mLighting.sun.direction), toEye));
    return glm::dvec3(mDesc.transfer.bright) * double(g.albedo) *
           (glm::dvec3(g.ambient) + sun * (4.0 * std::numbers::pi * p * T + double(g.multipleScattering)));
}

} // namespace splatfx
