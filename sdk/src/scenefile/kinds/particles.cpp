// Effect kind "particles" (King et al. 1999, sec. 6): splats at the positions
// of a closed-form particle emitter (Effect::fromParticles, particles.hpp),
// drawn with a texture set and a colour table over the particles' lives.
#include "scenefile/kinds.hpp"

namespace splatfx::scenefile {

std::optional<Effect> readParticlesKind(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    ParticleEmitterDesc d;
    const double L = kMaxCoord;
    o.vec3("position", d.position, -L, L);
    o.vec3("halfExtent", d.halfExtent, 0.0, L, true);
    o.number("rate", d.ratePerSec, 0.0, 1e6);
    o.number("startSec", d.startSec, -kMaxSeconds, kMaxSeconds); // before 0: the emitter is warmed up at t = 0
    double stop = kMaxSeconds;
    o.number("stopSec", stop, 0.0, kMaxSeconds);
    d.stopSec = o.has("stopSec") ? stop : d.stopSec;
    o.vec3("velocity", d.velocity, -1e4, 1e4);
    o.vec3("velocitySpread", d.velocitySpread, 0.0, 1e4, true);
    o.number("lifetimeSec", d.lifetimeSec, 0.0, 3600.0);
    o.number("lifetimeJitter", d.lifetimeJitter, 0.0, 1.0);
    o.vec3("acceleration", d.acceleration, -1e4, 1e4);
    o.number("drag", d.dragPerSec, 0.0, 1e3);
    o.vec3("wind", d.wind, -1e4, 1e4);
    o.number("size", d.sizeWorld, 1e-5, 1e3);
    d.sizeEndWorld = d.sizeWorld;
    o.number("sizeEnd", d.sizeEndWorld, 1e-5, 1e3);
    o.number("opacity", d.opacity, 0.0, 1.0);
    o.number("fadeIn", d.fadeIn, 0.0, 1.0);
    o.number("fadeOut", d.fadeOut, 0.0, 1.0);
    o.number("colorFrom", d.colorFrom, 0.0, 1.0);
    o.number("colorTo", d.colorTo, 0.0, 1.0);
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    o.number("stretchPerSpeed", d.stretchPerSpeed, 0.0, 100.0);
    o.number("maxStretch", d.maxStretch, 0.0, 100.0);
    int maxParticles = int(d.maxParticles);
    o.integer("maxParticles", maxParticles, 1, int(kMaxParticles));
    d.maxParticles = std::uint32_t(maxParticles);
    std::optional<TextureSpec> tex;
    if (const Json* t = o.get("textureSet")) tex = readTextureSpec(c, o.at("textureSet"), *t, 8, e.seed, false);
    else {
        tex.emplace();
        tex->seed = e.seed;
    }
    std::optional<ColorTable> table = ColorTable::fire();
    if (const Json* t = o.get("colorTable")) table = readColorTable(c, o.at("colorTable"), *t);
    bool crossfade = true;
    o.boolean("crossfade", crossfade);
    if (!c.d.ok() || !tex || !table) return std::nullopt;
    // The particle budget, named in the file's terms before anything is built.
    const double alive = std::ceil(double(d.ratePerSec) * double(d.lifetimeSec));
    if (alive > double(d.maxParticles)) {
        c.d.error(o.at("rate"), "rate * lifetimeSec = " + std::to_string(std::uint64_t(alive)) + " particles alive at once exceeds maxParticles (" +
                                    std::to_string(d.maxParticles) + "); lower \"rate\" or \"lifetimeSec\", or raise \"maxParticles\" (at most " +
                                    std::to_string(kMaxParticles) + ")");
        return std::nullopt;
    }
    d.position = applyPoint(pl.parent, d.position);
    d.seed = e.seed;
    Result<TextureSet> set = buildTextureSet(*tex);
    if (!set) return c.d.error(join(e.path, "textureSet"), set.error()), std::nullopt;
    if (set->count() == 0) return c.d.error(join(e.path, "textureSet"), "the texture set is empty"), std::nullopt;
    EffectDesc desc;
    desc.name = e.name;
    desc.motion = pl.motion;
    desc.footprintRadius = c.materials.footprint().radius();
    desc.textures.seed = e.seed;
    const std::uint32_t setId = c.materials.addTextureSet(*set);
    const std::uint32_t tableId = c.materials.addColorTable(*table);
    desc.layers = {{.style = {.textureSet = setId, .colorTable = tableId, .textured = true, .crossfade = crossfade}}};
    Result<Effect> r = Effect::fromParticles(d, std::move(desc));
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

} // namespace splatfx::scenefile
