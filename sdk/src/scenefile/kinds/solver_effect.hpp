// Private: the one reader of the solver effects (kinds/smoke.cpp,
// kinds/dust.cpp), parameterized by the preset's descriptor: an emitter in
// a simulated domain (presets::SmokeDesc, presets::DustDesc). The keys a
// descriptor lacks (dust has no "substeps", smoke no "settle") are not read,
// so the file gets "unknown key" for them. "obstacles" (obstacles.cpp) are
// placed in the world as they are, not by the effect's anchor.
#pragma once

#include "scenefile/kinds.hpp"
#include "splatfx/presets.hpp"

namespace splatfx::scenefile {

template <class Desc>
std::optional<Effect> readSolverEffect(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl,
                                       Result<Effect> (*make)(Materials&, const Desc&)) {
    if (e.motion)
        c.d.error(join(e.path, "motion"),
                  "solver effects (\"" + e.kind + "\") stay put; move their source with \"sourceMotion\" or \"attachTo\" so the material trails");
    std::optional<Motion> sourceMotion;
    if (const Json* m = o.get("sourceMotion")) {
        sourceMotion = readMotion(c, o.at("sourceMotion"), *m);
        if (!e.attachTo.empty()) c.d.error(o.at("sourceMotion"), "give either \"sourceMotion\" or \"attachTo\", not both");
    }
    Desc d;
    // The keys in the order the messages report them (the order the file format lists them).
    readDims(c, o, d.dims, c.budgets.solverCells, "solverCells", "solver effects simulate every cell every step");
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    o.vec3("sourceOffset", d.sourceOffset, -kMaxCoord, kMaxCoord);
    o.number("sourceRadius", d.sourceRadius, 1e-4, kMaxCoord);
    o.vec3("windWorld", d.windWorld, -1e3, 1e3);
    if constexpr (requires { d.settle; }) o.number("settle", d.settle, 0.0, 1e3);
    o.number("dissipation", d.dissipation, 0.0, 1e3);
    const std::optional<TextureSpec> tex = readPresetTextureSet(c, o, e.seed, d.textureCount);
    if constexpr (requires { d.texturesPerSec; }) o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    if constexpr (requires { d.substeps; }) o.integer("substeps", d.substeps, 1, 16);
    if (const Json* ob = o.get("obstacles"))
        if (auto obstacles = readObstacles(c, o.at("obstacles"), *ob)) d.obstacles = std::move(*obstacles);
    if (!c.d.ok()) return std::nullopt;
    d.textureSet = presetSet(c, e.path, tex);
    if (!c.d.ok()) return std::nullopt;
    d.sourceMotion = sourceMotion ? *sourceMotion : pl.motion;
    d.sourceOffset = applyPoint(pl.parent, d.sourceOffset);
    d.seed = e.seed;
    Result<Effect> r = make(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

} // namespace splatfx::scenefile
