// Private: the reader fire and steam share (kinds/fire.cpp, kinds/steam.cpp).
#pragma once

#include "scenefile/kinds.hpp"
#include "splatfx/presets.hpp"

namespace splatfx::scenefile {

// Fire and steam share their fields: a lattice, textures, opacity and the
// two rates; `extra` reads what only one of them has.
template <class Desc, class Extra>
std::optional<Effect> readLatticePreset(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl, Extra extra,
                                        Result<Effect> (*make)(Materials&, const Desc&)) {
    Desc d;
    readDims(c, o, d.dims, c.budgets.effectCells, "effectCells", "grid effects");
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    const std::optional<TextureSpec> tex = readPresetTextureSet(c, o, e.seed, d.textureCount);
    o.number("opacity", d.opacity, 1e-6, 1.0);
    o.number("propagationStepsPerSec", d.propagationStepsPerSec, 1e-3, 1e3);
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    extra(d);
    if (!c.d.ok()) return std::nullopt;
    d.textureSet = presetSet(c, e.path, tex);
    if (!c.d.ok()) return std::nullopt;
    d.position = applyPoint(pl.parent, d.position);
    d.motion = pl.motion;
    d.seed = e.seed;
    Result<Effect> r = make(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

} // namespace splatfx::scenefile
