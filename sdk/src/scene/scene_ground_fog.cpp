// Lit ground fog in a Scene (docs/lighting.md, "Ground fog"): each layer with
// lighting enabled takes the scene's sun and is shadowed by every lit,
// shadow-casting cloud and effect of this emit (smoke darkening the fog under
// it), relit only when the sun or a caster's field changed. Emitted after
// the other effects, so every caster's field is this frame's.
#include "splatfx/scene.hpp"
#include "volume_kinds.hpp"

namespace splatfx {

std::uint64_t Scene::emitLitGroundFogs(SplatBuilder& builder, std::vector<FrameVolume>* volumes, const Materials& materials, const EmitOptions& options) {
    std::uint64_t tetrahedra = 0;
    for (Entry& e : mEntries) {
        auto* fog = dynamic_cast<detail::GroundFogKind*>(e.kind.get());
        if (!fog || !e.options.lighting.enabled || !e.status.needed) continue;
        // mVolumeCasters: the lit clouds' fields and every lit or casting effect's (updateEffectCasters).
        if (Status s = fog->follow(mLights, e.options.lighting, mVolumeCasters); !s) mLightingError = "effect '" + e.options.name + "': lighting: " + s.error();
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
