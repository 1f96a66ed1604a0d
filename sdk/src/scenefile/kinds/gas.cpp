// Effect kind "gas": a turbulent procedural gas (Ebert & Parent 1990;
// presets::gas, procedural_gas.hpp). The "gas" object names its type and
// takes only that type's parameters, so a misspelt or misplaced key is an error.
#include "scenefile/kinds.hpp"
#include "splatfx/presets.hpp"

namespace splatfx::scenefile {
namespace {

void readTurbulence(Context& c, ObjectReader& g, GasTurbulenceDesc& t) {
    const Json* v = g.get("turbulence");
    if (!v) return;
    ObjectReader o(c.d, g.at("turbulence"), *v);
    if (!o.valid()) return;
    o.seed("seed", t.seed);
    o.integer("octaves", t.octaves, 1, 12);
    o.number("frequency", t.frequency, 1e-4, 1e4);
    o.finish();
}

void readGas(Context& c, ObjectReader& g, ProceduralGasDesc& d) {
    std::string type = "steam";
    if (const Json* t = g.get("type"))
        if (auto s = readChoice(c.d, g.at("type"), *t, {"steam", "fog", "cloud"})) type = *s;
    readTurbulence(c, g, d.turbulence);
    g.number("threshold", d.threshold, 0.0, 0.999);
    g.number("cellLength", d.cellLength, 0.0, 1e4);
    constexpr double kBig = 1e4;
    if (type == "steam") {
        GasSteamDesc& s = d.steam;
        d.kind = GasKind::Steam;
        g.vec3("source", s.source, -kMaxCoord, kMaxCoord);
        g.number("sourceRadius", s.sourceRadius, 1e-4, kBig);
        g.number("spread", s.spread, 0.0, kBig);
        g.number("height", s.height, 1e-4, kBig);
        g.number("riseSpeed", s.riseSpeed, -kBig, kBig);
        g.number("swirlPeriodSec", s.swirlPeriodSec, 1e-3, kBig);
        g.number("swirlRadius", s.swirlRadius, 0.0, kBig);
        g.number("opaque", s.opaque, 0.0, kBig);
        g.number("power", s.power, 1e-3, 100.0);
    } else if (type == "fog") {
        GasFogDesc& f = d.fog;
        d.kind = GasKind::Fog;
        g.number("swirlPeriodSec", f.swirlPeriodSec, 1e-3, kBig);
        g.number("ellipse1", f.ellipse1, 0.0, kBig);
        g.number("ellipse2", f.ellipse2, 0.0, kBig);
        g.number("driftPerSec", f.driftPerSec, -kBig, kBig);
        g.number("fullDensitySec", f.fullDensitySec, 1e-3, kBig);
        g.number("opaque", f.opaque, 0.0, kBig);
        g.number("power", f.power, 1e-3, 100.0);
        g.number("frontStart", f.frontStart, -kMaxCoord, kMaxCoord);
        g.number("frontSpeed", f.frontSpeed, -kBig, kBig);
        g.number("frontTurbulence", f.frontTurbulence, 0.0, kBig);
        g.number("thickenDistance", f.thickenDistance, 1e-4, kBig);
    } else {
        GasCloudDesc& k = d.cloud;
        d.kind = GasKind::Cloud;
        g.vec3("center", k.center, -kMaxCoord, kMaxCoord);
        g.vec3("radii", k.radii, 1e-4, kBig);
        g.vec3("windPerSec", k.windPerSec, -kBig, kBig);
        g.number("frequency", k.frequency, 1e-4, kBig);
        g.number("power", k.power, 1e-3, 100.0);
        g.number("opaque", k.opaque, 0.0, kBig);
    }
    g.finish();
}

} // namespace

std::optional<Effect> readGasKind(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    presets::GasDesc d;
    readDims(c, o, d.dims, c.budgets.effectCells, "effectCells", "gas effects");
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    const std::optional<TextureSpec> tex = readPresetTextureSet(c, o, e.seed, d.textureCount);
    o.number("opacity", d.opacity, 1e-6, 1.0);
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    if (const Json* g = o.get("gas")) {
        ObjectReader go(c.d, o.at("gas"), *g);
        if (go.valid()) readGas(c, go, d.gas);
    }
    if (!c.d.ok()) return std::nullopt;
    d.textureSet = presetSet(c, e.path, tex);
    if (!c.d.ok()) return std::nullopt;
    d.position = applyPoint(pl.parent, d.position);
    d.motion = pl.motion;
    d.seed = e.seed;
    Result<Effect> r = presets::gas(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

} // namespace splatfx::scenefile
