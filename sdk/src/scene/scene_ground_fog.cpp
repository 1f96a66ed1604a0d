// Lit ground fog in a Scene (docs/lighting.md, "Ground fog"): each layer with
// lighting enabled takes the scene's sun and is shadowed by every lit,
// shadow-casting cloud, effect and other layer of this emit (smoke darkening
// the fog under it), relit only when the sun or a caster's field changed.
// Emitted after the other effects, so every caster's field is this frame's.
// And it casts (lighting.castsShadow, as a cloud): its GroundFogCaster joins
// the volumes that shadow the lit effects and the scene shadow's casters.
#include <algorithm>

#include "splatfx/scene.hpp"
#include "volume_kinds.hpp"

namespace splatfx {

void Scene::updateFogCasters() {
    for (Entry& e : mEntries) {
        auto* fog = dynamic_cast<detail::GroundFogKind*>(e.kind.get());
        if (!fog) continue;
        if (e.lit) e.lit->fogCaster = nullptr;
        // As a cloud: lit and casting (the default), drawn or casting into the
        // view (Scene::update schedules it by where its shadow can fall).
        const EffectLighting& L = e.options.lighting;
        if (mLights.empty() || !L.enabled || !L.castsShadow || !(e.status.needed || e.status.castsIntoView)) continue;
        Result<const GroundFogCaster*> c = fog->caster();
        if (!c) {
            // The same refusal the layer's own lighting gives (emitLitGroundFogs), said once.
            if (mLightingError.empty()) mLightingError = "effect '" + e.options.name + "': lighting: " + c.error();
            e.status.castsIntoView = false;
            continue;
        }
        if ((*c)->empty()) continue; // no fog, or no extinction: casts nothing
        if (!e.lit) e.lit = std::make_unique<LitState>();
        e.lit->fogCaster = *c;
        mVolumeCasters.push_back(*c);
    }
}

std::uint64_t Scene::emitLitGroundFogs(SplatBuilder& builder, std::vector<FrameVolume>* volumes, const Materials& materials, const EmitOptions& options) {
    std::uint64_t tetrahedra = 0;
    for (Entry& e : mEntries) {
        auto* fog = dynamic_cast<detail::GroundFogKind*>(e.kind.get());
        if (!fog || !e.options.lighting.enabled || !e.status.needed) continue;
        // mVolumeCasters: the lit clouds' fields, the casting layers and every lit or casting
        // effect's (updateEffectCasters); not this layer's own (its self-shadowing is its relight's).
        mFogCasterScratch.assign(mVolumeCasters.begin(), mVolumeCasters.end());
        if (e.lit && e.lit->fogCaster) std::erase(mFogCasterScratch, e.lit->fogCaster);
        if (Status s = fog->follow(mLights, e.options.lighting, mFogCasterScratch); !s) mLightingError = "effect '" + e.options.name + "': lighting: " + s.error();
        const EmitOptions draw{.textured = e.options.draw.textured && options.textured, .opacityScale = e.options.draw.opacityScale * options.opacityScale};
        const EmitResult r = e.kind->emit(EmitContext{.splats = builder,
                                                      .volumes = volumes,
                                                      .materials = materials,
                                                      .draw = draw,
                                                      .refine = e.options.refine,
                                                      .keepTerrain = e.options.keepTerrain});
        e.status.tetrahedraDrawn = r.tetrahedra;
        tetrahedra += r.tetrahedra;
        e.status.lit = fog->volume().lit();
        mCounters.litEffects += e.status.lit ? 1 : 0;
    }
    return tetrahedra;
}

} // namespace splatfx
