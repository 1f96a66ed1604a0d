#include "volume_kinds.hpp"

#include <cmath>

namespace splatfx::detail {

AdvanceResult TetraKind::advanceTo(double timeSec, const AdvanceContext&) {
    mTime = timeSec;
    return {};
}

void TetraKind::setTransfer(TransferFunction transfer, PreIntegrationTable table) {
    mTransfer = std::move(transfer);
    mTable = std::move(table);
    ++mTableVersion;
}

EmitResult LodVolumeKind::emit(const EmitContext& context) {
    return emitVolume(context, [&](LodFrame& out) { return bool(mVolume.update(context.splats.camera(), context.refine, &mTransfer, out)); });
}

EmitResult GroundFogKind::emit(const EmitContext& context) {
    mTerrain.clear();
    auto refine = [&](LodFrame& out) {
        const bool ok = bool(mVolume.update(context.splats.camera(), context.refine, out, context.keepTerrain ? &mTerrain : nullptr));
        if (!ok) mTerrain.clear();
        return ok;
    };
    if (!mVolume.lit()) return emitVolume(context, refine);
    if (!context.volumes) return {};
    FrameVolume& fv = context.volumes->emplace_back();
    fv.table = &mVolume.litTable();
    fv.tableVersion = mVolume.litTableBuilds();
    if (!refine(fv.lod)) {
        context.volumes->pop_back();
        return {};
    }
    return {.tetrahedra = fv.lod.tets.size()};
}

Result<double> GroundFogKind::fogExtinction() const {
    // The fog's colour and extinction: sigma = rho s with one colour (makeGroundFogTransfer).
    const double rho = mTransfer.extinction(1.0);
    const glm::dvec3 colour = mTransfer.color(1.0);
    for (const TransferPoint& p : mTransfer.points())
        if (std::abs(double(p.extinctionPerWorld) - double(p.scalar) * rho) > 1e-6 * rho || glm::length(glm::dvec3(p.color) - colour) > 1e-6)
            return makeError("a lit ground fog needs a transfer function of makeGroundFogTransfer's form (one colour, extinction linear from 0)");
    return rho;
}

Result<const GroundFogCaster*> GroundFogKind::caster() {
    Result<double> rho = fogExtinction();
    if (!rho) return makeError(rho.error());
    if (*rho != mCasterExtinction) {
        Result<GroundFogCaster> c = GroundFogCaster::create(mVolume, float(*rho));
        if (!c) return makeError(c.error());
        mCaster = std::move(*c);
        mCasterExtinction = *rho;
    }
    return &mCaster;
}

Status GroundFogKind::follow(std::span<const Light> lights, const EffectLighting& lighting, std::span<const ShadowCaster* const> casters) {
    for (const Light& l : lights) {
        if (l.type != LightType::Directional) continue;
        Result<double> rho = fogExtinction();
        if (!rho) {
            mVolume.clearLighting();
            return makeError(rho.error());
        }
        const glm::dvec3 colour = mTransfer.color(1.0);
        GroundFogLighting L = mVolume.lighting();
        L.sun = l;
        L.gas = lighting.gas;
        L.gas.colorTable = nullptr;
        L.color = glm::vec3(colour);
        L.extinctionPerWorld = float(*rho);
        if (Status s = mVolume.setLighting(L, casters); !s) {
            mVolume.clearLighting();
            return s;
        }
        return {};
    }
    mVolume.clearLighting();
    return {};
}

EmitResult CloudKind::emit(const EmitContext& context) {
    if (!context.volumes) return {};
    FrameVolume& fv = context.volumes->emplace_back();
    fv.table = &mCloud.table();
    fv.tableVersion = mCloud.tableVersion();
    if (!mCloud.update(context.splats.camera(), context.refine, fv.lod)) {
        context.volumes->pop_back();
        return {};
    }
    return {.tetrahedra = fv.lod.tets.size()};
}

Status CloudKind::follow(std::span<const Light> lights, const EffectLighting& lighting, std::size_t& dropped,
                         std::span<const ShadowCaster* const> casters) {
    dropped = 0;
    const Light* sun = nullptr;
    for (const Light& l : lights)
        if (l.type == LightType::Directional) {
            sun = &l;
            break;
        }
    CloudLighting L = mCloud.lighting();
    L.lights.clear();
    const Aabb box = mCloud.volume().boundsWorld();
    for (const Light& l : lights) {
        if (&l == sun || !Scene::lightReaches(l, box)) continue; // one that cannot reach it costs nothing
        if (L.model != CloudLightModel::LowAlbedo || L.lights.size() == std::size_t(kMaxCloudLights)) {
            ++dropped;
            continue;
        }
        L.lights.push_back(l);
        if (sun) L.sun = *sun;
        // Lights of any colour are taken (an RGB source per vertex when they
        // differ); a light the cloud refuses all the same is left out and counted.
        if (!Cloud::validateLighting(L)) L.lights.pop_back(), ++dropped;
    }
    if (!sun && L.lights.empty() && mCloud.lighting().lights.empty())
        return mCloud.setLight(mCloud.lighting(), casters); // nothing to follow: keeps its own sun, shadowed by the casters
    if (sun) L.sun = *sun;
    L.gas = lighting.gas;
    L.gas.colorTable = nullptr;
    return mCloud.setLight(L, casters);
}

} // namespace splatfx::detail
