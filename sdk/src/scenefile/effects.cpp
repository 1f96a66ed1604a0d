// Scene files: the effects list. The keys every kind takes are read here;
// the rest by the kind's reader, found in the table in kinds.cpp.
#include "scenefile/kinds.hpp"
#include "scenefile/reader.hpp"

#include <algorithm>

#include "splatfx/presets.hpp"

namespace splatfx::scenefile {

void readEffects(Context& c, const std::string& path, const Json& v, const std::vector<RawGeometry>& geo,
                 const std::map<std::string, std::size_t>& geoByName, SceneFile& out) {
    if (!v.is_array() || v.size() > kMaxEffects) {
        c.d.error(path, "expected an array of at most " + std::to_string(kMaxEffects) + " effects, got " + typeName(v) + " " + brief(v));
        return;
    }
    const std::vector<std::string> kinds = effectKindNames();
    std::string kindList; // "fire, smoke, ..."
    for (std::size_t k = 0; k < kinds.size(); ++k) kindList += (k ? ", " : "") + kinds[k];
    std::uint64_t totalCells = 0;
    std::map<std::string, std::size_t> names;
    for (std::size_t i = 0; i < v.size() && !c.d.full(); ++i) {
        EffectCommon e;
        e.path = index(path, i);
        ObjectReader o(c.d, e.path, v[i]);
        if (!o.valid()) continue;
        if (const Json* k = o.get("kind")) {
            if (k->is_string() && *k == "vdb" && !findEffectKind("vdb"))
                c.d.error(o.at("kind"), "kind \"vdb\" needs splatfx built with OpenVDB (libopenvdb-dev and libboost-iostreams-dev, "
                                        "tools/setup-deps.sh); this build was configured without it (SPLATFX_VDB)");
            else if (auto s = readChoice(c.d, o.at("kind"), *k, kinds)) e.kind = *s;
        } else {
            c.d.error(e.path, "missing \"kind\" (one of " + kindList + ")");
        }
        if (e.kind.empty()) continue; // kind-specific keys cannot be checked without it
        e.name = e.kind + std::to_string(i);
        o.string("name", e.name);
        if (names.count(e.name)) c.d.error(o.at("name"), "duplicate effect name '" + e.name + "'");
        names[e.name] = i;
        std::uint32_t localSeed = std::uint32_t(i);
        o.seed("seed", localSeed);
        // Every effect's seed derives from the scene seed (so --seed changes them all).
        e.seed = c.sceneSeed * 1000003u + localSeed;
        o.boolean("enabled", e.options.enabled);
        o.number("rangeWorld", e.options.rangeWorld, 0.0, 1e9);
        o.boolean("traditional", e.traditional);
        // Per-splat variation hiding the lattice (splats.hpp): the presets' default, keys override it.
        SplatVariation variation = e.kind == "ghosts" ? presets::GhostsDesc{}.variation : SplatVariation::recommended(0);
        variation.seed = hash32(e.seed ^ 0x51a7u);
        if (const Json* va = o.get("variation")) {
            ObjectReader vo(c.d, o.at("variation"), *va);
            vo.number("jitter", variation.jitter, 0.0, SplatVariation::kMaxJitter);
            float rotationDeg = variation.rotationRad * 57.2957795f;
            vo.number("rotationDeg", rotationDeg, 0.0, 180.0);
            variation.rotationRad = std::min(rotationDeg * 0.0174532925f, 3.14159265f);
            vo.boolean("mirror", variation.mirror);
            vo.number("scaleLog2", variation.scaleLog2, 0.0, 1.0);
            vo.finish();
        }
        if (const Json* t = o.get("toggles")) {
            ObjectReader to(c.d, o.at("toggles"), *t);
            to.boolean("object", e.toggles.object);
            to.boolean("global", e.toggles.global);
            to.boolean("local", e.toggles.local);
            to.finish();
        }
        if (const Json* l = o.get("lighting")) readEffectLighting(c, o.at("lighting"), *l, e.options.lighting); // issue 16
        if (const Json* em = o.get("emitsLight")) { // the effect as light for the host (emitted_light.hpp)
            ObjectReader eo(c.d, o.at("emitsLight"), *em);
            EmittedLightDesc& d = e.options.emitsLight;
            d.enabled = true; // giving the block asks for it
            eo.boolean("enabled", d.enabled);
            eo.integer("lights", d.lights, 1, kMaxEmittedLights);
            eo.number("scale", d.scale, 0.0, 1e6);
            eo.boolean("occlusion", d.occlusion);
            eo.number("reachWorld", d.reachWorld, 1e-6, 1e30);
            std::string mode = "lights";
            eo.string("mode", mode);
            if (mode == "grid") d.mode = EmittedLightMode::Grid;
            else if (mode != "lights") c.d.error(eo.at("mode"), "mode must be \"lights\" or \"grid\", got \"" + mode + "\"");
            eo.ivec3("gridDims", d.gridDims, 2, kMaxEmittedGridNodes);
            if (d.gridDims.x * d.gridDims.y * d.gridDims.z > kMaxEmittedGridNodes)
                c.d.error(eo.at("gridDims"), "gridDims may hold at most " + std::to_string(kMaxEmittedGridNodes) + " nodes");
            eo.number("gridMargin", d.gridMargin, 0.0, 1e6);
            eo.finish();
        }
        o.string("attachTo", e.attachTo);
        if (const Json* m = o.get("motion")) {
            if (!e.attachTo.empty()) c.d.error(o.at("motion"), "an effect either has its own \"motion\" or is attached to geometry; not both");
            e.motion = readMotion(c, o.at("motion"), *m);
        }
        Placement pl;
        if (!e.attachTo.empty()) {
            if (auto a = resolveAnchor(c, geo, geoByName, e.attachTo, o.at("attachTo"))) pl.motion = a->motion, pl.parent = a->transform;
        } else if (e.motion) {
            pl.motion = *e.motion; // kinds that stay put (solver effects, ghosts) refuse it themselves
        }
        const std::size_t before = c.d.count();
        std::optional<Effect> effect = findEffectKind(e.kind)->read(c, o, e, pl);
        o.finish();
        if (!effect || c.d.count() != before) continue;
        // The default layer budget is what every GL 4.5 guarantees (GL_MAX_ARRAY_TEXTURE_LAYERS
        // >= 2048); checked as effects are read, so a level of too many distinct sets stops at
        // the effect that crosses it.
        if (Status s = checkBudget("the scene, with this effect,", c.materials.layerCount(), "layers", c.budgets.textureLayers, "textureLayers");
            !s) {
            c.d.error(e.path,
                      s.error() +
                          " in its distinct texture sets; share texture sets between effects (equal parameters and seeds) or use fewer textures");
            return;
        }
        totalCells += effect->costCells(); // EffectKind: cells or voxels one advance evaluates
        if (Status s = checkBudget("the scene, with this effect,", totalCells, "cells", c.budgets.effectCells, "effectCells"); !s) {
            c.d.error(e.path, s.error());
            return;
        }
        effect->setToggles(e.toggles);
        if (Status st = effect->setSplatVariation(variation); !st) { // ranges were checked above: a bug if it fails
            c.d.error(o.at("variation"), st.error());
            continue;
        }
        e.options.name = e.name;
        e.options.draw.textured = !e.traditional; // the Scene owns how each effect is drawn
        SceneEffectInfo info;
        info.name = e.name;
        info.kind = e.kind;
        info.attachedTo = e.attachTo;
        info.traditional = e.traditional;
        info.id = out.scene.add(std::move(*effect), e.options);
        out.effects.push_back(info);
    }
}

} // namespace splatfx::scenefile
