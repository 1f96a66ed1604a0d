// Effect kind "ghosts" (Fig. 10: presets::ghosts).
#include "scenefile/kinds.hpp"
#include "splatfx/presets.hpp"

namespace splatfx::scenefile {

std::optional<Effect> readGhosts(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    presets::GhostsDesc d;
    o.number("headRadiusCells", d.headRadiusCells, 1.0, 64.0);
    o.integer("plumeCells", d.plumeCells, 0, 256);
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    const std::optional<TextureSpec> tex = readPresetTextureSet(c, o, e.seed, d.textureCount);
    o.number("opacity", d.opacity, 1e-6, 1.0);
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    o.number("propagationStepsPerSec", d.propagationStepsPerSec, 1e-3, 1e3);
    if (!e.attachTo.empty() || e.motion)
        c.d.error(e.path, "kind \"ghosts\" stays where it is put: it takes no \"motion\" or \"attachTo\" (place it with \"position\")");
    if (!c.d.ok()) return std::nullopt;
    d.textureSet = presetSet(c, e.path, tex);
    if (!c.d.ok()) return std::nullopt;
    d.position = applyPoint(pl.parent, d.position);
    d.seed = e.seed;
    Result<Effect> r = presets::ghosts(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

} // namespace splatfx::scenefile
