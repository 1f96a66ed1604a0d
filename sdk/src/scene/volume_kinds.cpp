#include "volume_kinds.hpp"

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
    return emitVolume(context, [&](LodFrame& out) {
        const bool ok = bool(mVolume.update(context.splats.camera(), context.refine, out, context.keepTerrain ? &mTerrain : nullptr));
        if (!ok) mTerrain.clear();
        return ok;
    });
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

Status CloudKind::follow(std::span<const Light> lights, const EffectLighting& lighting) {
    for (const Light& l : lights)
        if (l.type == LightType::Directional) {
            CloudLighting L = mCloud.lighting();
            L.sun = l;
            L.gas = lighting.gas;
            L.gas.colorTable = nullptr;
            return mCloud.setLight(L);
        }
    return {};
}

} // namespace splatfx::detail
