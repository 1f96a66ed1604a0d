// Effect kind "fireToSmoke" (presets::fireToSmoke: fire below, smoke above).
#include "scenefile/kinds.hpp"
#include "splatfx/presets.hpp"

namespace splatfx::scenefile {

std::optional<Effect> readFireToSmoke(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    presets::FireToSmokeDesc d;
    readDims(c, o, d.dims, c.budgets.effectCells, "effectCells", "grid effects");
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    o.number("split", d.split, 1e-3, 0.999);
    o.number("blend", d.blend, 0.0, 0.999);
    std::optional<TextureSpec> fireTex, smokeTex;
    if (const Json* t = o.get("fireTextureSet")) fireTex = readTextureSpec(c, o.at("fireTextureSet"), *t, 8, e.seed, true);
    if (const Json* t = o.get("smokeTextureSet")) smokeTex = readTextureSpec(c, o.at("smokeTextureSet"), *t, 8, e.seed, true);
    o.number("propagationStepsPerSec", d.propagationStepsPerSec, 1e-3, 1e3);
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    if (!c.d.ok()) return std::nullopt;
    d.fireTextureSet = presetSet(c, e.path, fireTex);
    d.smokeTextureSet = presetSet(c, e.path, smokeTex);
    if (!c.d.ok()) return std::nullopt;
    d.position = applyPoint(pl.parent, d.position);
    d.motion = pl.motion;
    d.seed = e.seed;
    Result<Effect> r = presets::fireToSmoke(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

} // namespace splatfx::scenefile
