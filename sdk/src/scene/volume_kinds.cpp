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

} // namespace splatfx::detail
