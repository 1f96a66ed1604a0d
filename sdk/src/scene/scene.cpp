#include "splatfx/scene.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace splatfx {

EffectId Scene::add(Effect effect, EffectOptions options) {
    auto owned = std::make_unique<Effect>(std::move(effect));
    Effect* asEffect = owned.get();
    return push(Entry{std::move(owned), asEffect, std::move(options), {}, nullptr});
}

EffectId Scene::add(std::unique_ptr<EffectKind> kind, EffectOptions options) {
    assert(kind && "Scene::add: kind must not be null");
    // An Effect handed over as a kind is still one: effect(id) should find it.
    Effect* asEffect = dynamic_cast<Effect*>(kind.get());
    return push(Entry{std::move(kind), asEffect, std::move(options), {}, nullptr});
}

EffectId Scene::push(Entry entry) {
    mEntries.push_back(std::move(entry));
    mCounters.declared = mEntries.size();
    return EffectId(mEntries.size() - 1);
}

Effect& Scene::effect(EffectId id) {
    Effect* e = mEntries.at(id).effect;
    assert(e && "Scene::effect: this entry is not an Effect; use Scene::kind or Scene::findEffect");
    return *e;
}

const Effect& Scene::effect(EffectId id) const {
    const Effect* e = mEntries.at(id).effect;
    assert(e && "Scene::effect: this entry is not an Effect; use Scene::kind or Scene::findEffect");
    return *e;
}

bool Scene::inFrustum(const Aabb& box, const Camera& camera) {
    if (box.empty()) return false;
    // Gribb & Hartmann planes; a box is outside if all 8 corners are behind one plane.
    const glm::mat4 vp = camera.proj * camera.view;
    for (int i = 0; i < 3; ++i)
        for (int sign = -1; sign <= 1; sign += 2) {
            const glm::vec4 plane =
                glm::vec4(vp[0][3], vp[1][3], vp[2][3], vp[3][3]) + float(sign) * glm::vec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
            // The corner farthest along the plane normal decides.
            const glm::vec3 p(plane.x >= 0 ? box.hi.x : box.lo.x, plane.y >= 0 ? box.hi.y : box.lo.y, plane.z >= 0 ? box.hi.z : box.lo.z);
            if (glm::dot(glm::vec3(plane), p) + plane.w < 0.0f) return false;
        }
    return true;
}

void Scene::update(double timeSec, const Camera& camera) {
    const double previous = mUpdated ? std::min(mTime, timeSec) : timeSec;
    mTime = timeSec;
    mUpdated = true;
    mCounters.needed = mCounters.simulated = 0;
    const glm::vec3 eye = camera.eye();
    for (Entry& e : mEntries) {
        EffectStatus& s = e.status;
        const bool wasNeeded = s.needed;
        s.enabled = e.options.enabled;
        s.needed = false;
        if (!s.enabled) {
            ++s.framesSkipped;
            continue;
        }
        // Bounds over the interval since the last update: motion between frames is covered.
        s.bounds = e.kind->bounds(std::max(0.0, previous), timeSec);
        const glm::vec3 nearest = glm::clamp(eye, s.bounds.lo, s.bounds.hi);
        s.inRange = !s.bounds.empty() && glm::length(eye - nearest) <= e.options.rangeWorld;
        // Cheapest tests first: a hidden effect costs one bounds query and a frustum test.
        s.inView = s.inRange && inFrustum(s.bounds, camera);
        s.alive = s.inView && e.kind->alive(timeSec, AliveHints{.deadDensity = e.options.deadDensity});
        if (!s.alive) {
            ++s.framesSkipped;
            continue;
        }
        // Resumed: advanced before, skipped since; the kind decides what catching up costs.
        const AdvanceContext context{
            .catchUpStepSec = e.options.catchUpStepSec, .maxCatchUpSteps = e.options.maxCatchUpSteps, .resumed = !wasNeeded && s.framesNeeded > 0};
        if (e.kind->advanceTo(timeSec, context).caughtUp) ++s.catchUps;
        s.needed = true;
        ++s.framesNeeded;
        ++mCounters.needed;
        ++mCounters.simulated;
    }
}

std::size_t Scene::emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) {
    std::size_t total = 0;
    // ---- lighting (issue 16): per-emit counters (scene_lighting.cpp)
    mLightingError.clear();
    mCounters.litEffects = 0;
    mCounters.shadowTableBuilds = mCounters.shadowTableReuses = 0;
    for (Entry& e : mEntries) {
        const EmitOptions draw{.textured = e.options.draw.textured && options.textured,
                               .opacityScale = e.options.draw.opacityScale * options.opacityScale};
        const std::size_t first = builder.splats().size();
        e.status.splatsDrawn = e.status.needed ? e.kind->emit(builder, materials, draw) : 0;
        total += e.status.splatsDrawn;
        // ---- lighting (issue 16): colour the splats just emitted; unlit effects skip this.
        e.status.lit = false;
        if (e.status.needed && e.options.lighting.enabled && !mLights.empty()) lightEmitted(e, builder, materials, first, draw);
    }
    mCounters.splats = total;
    return total;
}

void Scene::prepare(double timeSec, const Camera& camera, const Materials& materials, Frame& frame, const EmitOptions& options) {
    update(timeSec, camera);
    frame.begin(timeSec, camera);
    emit(frame.builder(), materials, options);
    shadeScene(frame);             // lighting (issue 16): the shadow on the scene, into frame.shadow()
    prepareVolumes(camera, frame); // [clouds]
    frame.end();
    frame.setFog(mFog); // fog (issue 14)
    FrameCounters& c = frame.counters();
    // ---- lighting (issue 16)
    c.litEffects = mCounters.litEffects;
    c.shadowTableBuilds = mCounters.shadowTableBuilds;
    c.shadowTableReuses = mCounters.shadowTableReuses;
    c.declared = mCounters.declared;
    c.needed = mCounters.needed;
    c.simulated = mCounters.simulated;
    c.drawn = 0;
    for (const Entry& e : mEntries) c.drawn += e.status.splatsDrawn > 0 ? 1 : 0;
}

// ---- [clouds, issue 17] LOD volumes ----
VolumeId Scene::addVolume(LodVolume volume, TransferFunction transfer, PreIntegrationTable table, VolumeOptions options) {
    mVolumes.push_back(std::make_unique<VolumeEntry>(VolumeEntry{std::move(volume), std::move(transfer), std::move(table), 1, std::move(options)}));
    return VolumeId(mVolumes.size() - 1);
}

void Scene::setVolumeTransfer(VolumeId id, TransferFunction transfer, PreIntegrationTable table) {
    VolumeEntry& e = *mVolumes.at(id);
    e.transfer = std::move(transfer);
    e.table = std::move(table);
    ++e.tableVersion;
}

void Scene::prepareVolumes(const Camera& camera, Frame& frame) {
    for (auto& owned : mVolumes) {
        VolumeEntry& e = *owned;
        if (!e.options.enabled) continue;
        const glm::vec3 lo = e.volume.originWorld();
        const glm::vec3 hi = lo + glm::vec3(e.volume.pointDims() - 1) * e.volume.spacingWorld();
        if (!inFrustum(Aabb{lo, hi}, camera)) continue;
        FrameVolume& fv = frame.volumes().emplace_back();
        fv.table = &e.table;
        fv.tableVersion = e.tableVersion;
        // A failed update (non-finite camera, bad refine field) draws nothing for this volume.
        if (!e.volume.update(camera, e.options.refine, &e.transfer, fv.lod)) frame.volumes().pop_back();
    }
    for (auto& owned : mGroundFogs) { // ground fog layers
        GroundFogEntry& e = *owned;
        e.terrain.clear();
        if (!e.options.enabled) continue;
        FrameVolume& fv = frame.volumes().emplace_back();
        fv.table = &e.table;
        fv.tableVersion = 1;
        // refine: the LOD terrain's c, morphing
        if (!e.fog.update(camera, e.options.refine, fv.lod, e.options.keepTerrain ? &e.terrain : nullptr)) {
            frame.volumes().pop_back();
            e.terrain.clear();
        }
    }
}

//
VolumeId Scene::addGroundFog(GroundFog fog, TransferFunction transfer, PreIntegrationTable table, VolumeOptions options) {
    mGroundFogs.push_back(
        std::make_unique<GroundFogEntry>(GroundFogEntry{std::move(fog), std::move(transfer), std::move(table), std::move(options), {}}));
    return VolumeId(mGroundFogs.size() - 1);
}

} // namespace splatfx
