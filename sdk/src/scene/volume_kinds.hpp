// Private to the SDK: LOD volumes and ground fog as effect kinds, so the
// Scene holds, culls, schedules and emits them like every other kind.
#pragma once

#include <cstdint>
#include <vector>

#include <span>

#include "splatfx/cloud.hpp"
#include "splatfx/effect_kind.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/volume.hpp"

namespace splatfx::detail {

// A volume drawn as projected tetrahedra with one transfer function and its
// pre-integration table. Static: its material is in its data, so it is alive
// whenever it is in view and advancing it costs nothing. Scene keeps kinds on
// the heap, so the table's address the Frame points at stays put.
class TetraKind : public EffectKind {
public:
    bool alive(double, const AliveHints&) const override { return true; }
    AdvanceResult advanceTo(double timeSec, const AdvanceContext&) override;
    double time() const override { return mTime; }
    std::uint64_t costCells() const override { return 0; }

    const TransferFunction& transfer() const { return mTransfer; }
    // Replaces the transfer function and table (the GL pass re-uploads it: the version changes).
    void setTransfer(TransferFunction transfer, PreIntegrationTable table);

protected:
    TetraKind(TransferFunction transfer, PreIntegrationTable table) : mTransfer(std::move(transfer)), mTable(std::move(table)) {}
    // Appends one FrameVolume drawn with this kind's table and has `refine`
    // (Status(LodFrame&)) fill its tetrahedra; a failed refinement (a
    // non-finite camera, a bad refine field) draws nothing.
    template <class Refine>
    EmitResult emitVolume(const EmitContext& context, Refine&& refine) {
        if (!context.volumes) return {};
        FrameVolume& fv = context.volumes->emplace_back();
        fv.table = &mTable;
        fv.tableVersion = mTableVersion;
        if (!refine(fv.lod)) {
            context.volumes->pop_back();
            return {};
        }
        return {.tetrahedra = fv.lod.tets.size()};
    }

    TransferFunction mTransfer;

private:
    PreIntegrationTable mTable;
    std::uint64_t mTableVersion = 1;
    double mTime = 0.0;
};

// A TetraKind around one volume object bounded by its boundsWorld().
template <class Volume>
class VolumeKind : public TetraKind {
public:
    VolumeKind(Volume volume, TransferFunction transfer, PreIntegrationTable table)
        : TetraKind(std::move(transfer), std::move(table)), mVolume(std::move(volume)) {}
    Aabb bounds(double, double) const override { return mVolume.boundsWorld(); }
    Volume& volume() { return mVolume; }
    const Volume& volume() const { return mVolume; }

protected:
    Volume mVolume;
};

// A LOD volume (clouds): LodVolume::update refines it for the frame's camera
// (its own per-node frustum culling inside).
class LodVolumeKind final : public VolumeKind<LodVolume> {
public:
    using VolumeKind::VolumeKind;
    EmitResult emit(const EmitContext& context) override;
};

// A ground fog layer over its terrain; keeps the terrain triangles of the
// last emit when asked (EmitContext::keepTerrain).
class GroundFogKind final : public VolumeKind<GroundFog> {
public:
    using VolumeKind::VolumeKind;
    EmitResult emit(const EmitContext& context) override;
    // The terrain the last emit refined with keepTerrain; empty otherwise.
    const std::vector<glm::vec3>& terrain() const { return mTerrain; }
    // Lit (EffectOptions::lighting.enabled): the scene's first directional
    // light is the sun, lighting.gas the model, the transfer function's colour
    // and extinction at scalar 1 the fog's (it must be makeGroundFogTransfer's
    // form), shadowed by `casters`; relit only when those change. No
    // directional light: drawn unlit. On an error the layer is drawn unlit.
    Status follow(std::span<const Light> lights, const EffectLighting& lighting, std::span<const ShadowCaster* const> casters);
    // The layer as a shadow caster with the transfer function's extinction at
    // scalar 1 (it must be makeGroundFogTransfer's form, else the error);
    // remade only when that extinction changed (setTransfer). Independent of
    // the camera and of the sun.
    Result<const GroundFogCaster*> caster();

private:
    // The transfer's extinction at scalar 1, or the error when it is not makeGroundFogTransfer's form.
    Result<double> fogExtinction() const;
    std::vector<glm::vec3> mTerrain;
    GroundFogCaster mCaster;
    double mCasterExtinction = -1.0; // what mCaster was made with; < 0: not made
};

// A relightable cloud (cloud.hpp): static like the other volumes, drawn with
// the table the Cloud owns (its version bumps when a relight rebuilds it).
class CloudKind final : public EffectKind {
public:
    explicit CloudKind(Cloud cloud) : mCloud(std::move(cloud)) {}
    Aabb bounds(double, double) const override { return mCloud.volume().boundsWorld(); }
    bool alive(double, const AliveHints&) const override { return true; }
    AdvanceResult advanceTo(double timeSec, const AdvanceContext&) override {
        mTime = timeSec;
        return {};
    }
    double time() const override { return mTime; }
    std::uint64_t costCells() const override { return 0; }
    EmitResult emit(const EmitContext& context) override;
    // The scene's sun is its first directional light: the cloud takes it
    // (and, for the low-albedo model, the effect's gas desc) and relights
    // only when that changed. No directional light: the cloud keeps its own.
    // A low-albedo cloud also takes the scene's other lights that reach its
    // box (Scene::lightReaches), in scene order, up to kMaxCloudLights, each
    // only if its colour is a multiple of the lights taken before
    // (Cloud::validateLighting); `dropped` counts the reaching lights left
    // out (over the count, another colour, or any for the Roettger model).
    // `casters` shadow it (Cloud::setLight; not its own field).
    Status follow(std::span<const Light> lights, const EffectLighting& lighting, std::size_t& dropped, std::span<const ShadowCaster* const> casters);
    Cloud& cloud() { return mCloud; }
    const Cloud& cloud() const { return mCloud; }

private:
    Cloud mCloud;
    double mTime = 0.0;
};

} // namespace splatfx::detail
