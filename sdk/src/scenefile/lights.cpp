// Scene files: lighting (issue 16; docs/scene-format.md, "lights"). The
// top-level "lights" list and "sceneShadow" object, and each effect's
// "lighting" object (read from effects.cpp with the keys every kind takes).
#include <algorithm>
#include <cmath>

#include "scenefile/reader.hpp"

namespace splatfx::scenefile {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// A count per axis: n (meaning [n, n, n]) or [x, y, z], each in [lo, hi].
void readAxisCounts(Context& c, ObjectReader& o, const std::string& key, glm::ivec3& out, int lo, int hi) {
    const Json* v = o.get(key);
    if (!v) return;
    if (v->is_number()) {
        if (auto n = readInt(c.d, o.at(key), *v, lo, hi)) out = glm::ivec3(int(*n));
    } else if (auto d = readIvec3(c.d, o.at(key), *v, lo, hi)) {
        out = *d;
    }
}

std::optional<Light> readLight(Context& c, const std::string& path, const Json& v, std::optional<LightMotion>& motion) {
    return readObject<Light>(c, path, v, [&](Context& cc, ObjectReader& o, Light& l) {
        if (o.has("directionEnd") || o.has("moveSec")) {
            LightMotion m;
            o.vec3("directionEnd", m.to, -kMaxCoord, kMaxCoord);
            o.number("moveSec", m.seconds, 1e-3, 1e6);
            if (!o.has("directionEnd")) cc.d.error(path, "\"moveSec\" needs \"directionEnd\" (where the light's direction goes)");
            else if (!(glm::length(m.to) > 0.0f)) cc.d.error(o.at("directionEnd"), "must not be zero");
            motion = m;
        }
        if (const Json* t = o.get("type")) {
            if (auto s = readChoice(cc.d, o.at("type"), *t, {"directional", "point", "spot"}))
                l.type = *s == "point" ? LightType::Point : *s == "spot" ? LightType::Spot : LightType::Directional;
        } else {
            cc.d.error(path, "missing \"type\" (one of directional, point, spot)");
        }
        o.color3("color", l.color);
        o.number("intensity", l.intensity, 0.0, 1e9);
        o.vec3("direction", l.direction, -kMaxCoord, kMaxCoord);
        o.vec3("position", l.position, -kMaxCoord, kMaxCoord);
        float innerDeg = float(l.innerConeRad / kDegToRad), outerDeg = float(l.outerConeRad / kDegToRad);
        o.number("innerConeDeg", innerDeg, 0.0, 179.9);
        o.number("outerConeDeg", outerDeg, 0.01, 179.9);
        l.innerConeRad = float(innerDeg * kDegToRad);
        l.outerConeRad = float(outerDeg * kDegToRad);
        o.number("radius", l.radiusWorld, 0.0, kMaxCoord);
        // What the ranges above cannot say (a zero direction, inner beyond
        // outer): the SDK's own check, its message naming the field.
        if (Status s = validateLight(l, "light"); !s) {
            std::string what = s.error();
            const std::string prefix = "light.";
            if (what.rfind(prefix, 0) == 0) {
                const std::size_t space = what.find(' ');
                const std::string field = what.substr(prefix.size(), space - prefix.size());
                const std::string key = field == "innerConeRad"   ? "innerConeDeg"
                                        : field == "outerConeRad" ? "outerConeDeg"
                                        : field == "radiusWorld"  ? "radius"
                                                                  : field;
                cc.d.error(o.at(key), what.substr(space + 1));
            } else {
                cc.d.error(path, what);
            }
        }
    });
}

} // namespace

void readLights(Context& c, const std::string& path, const Json& v, SceneFile& out) {
    constexpr std::size_t kMaxLights = 64; // every light costs every lit voxel a term (and a table)
    if (!v.is_array() || v.size() > kMaxLights) {
        c.d.error(path, "expected an array of at most " + std::to_string(kMaxLights) + " lights, got " + typeName(v) + " " + brief(v));
        return;
    }
    for (std::size_t i = 0; i < v.size() && !c.d.full(); ++i) {
        std::optional<LightMotion> motion;
        if (auto l = readLight(c, index(path, i), v[i], motion)) {
            auto r = out.scene.addLight(*l);
            if (!r) {
                c.d.error(index(path, i), r.error());
            } else if (motion) {
                motion->light = *r;
                motion->from = l->direction;
                out.lightMotions.push_back(*motion);
            }
        }
    }
}

void readSceneShadow(Context& c, const std::string& path, const Json& v, SceneFile& out) {
    auto d = readObject<SceneShadowDesc>(c, path, v, [&](Context& cc, ObjectReader& o, SceneShadowDesc& s) {
        o.boolean("enabled", s.enabled);
        int light = int(s.light);
        const bool lightGiven = o.has("light");
        o.integer("light", light, 0, 63);
        s.light = std::size_t(light);
        // A shadow cast by a light the scene does not have would silently be
        // no shadow at all (lights are read first; their own errors come first).
        const std::size_t lights = out.scene.lights().size();
        if ((s.enabled || lightGiven) && s.light >= lights && cc.d.ok())
            cc.d.error(o.at("light"),
                       lights == 0 ? "the scene has no \"lights\"; the scene shadow is cast by one of them (add one, or set \"enabled\": false)"
                                   : "expected the index of one of the scene's " + std::to_string(lights) + " light(s), 0 to " +
                                         std::to_string(lights - 1) + ", got " + std::to_string(s.light));
        o.integer("maxLights", s.maxLights, 1, kMaxShadowLights);
        int budgetMiB = int(s.memoryBudgetBytes >> 20);
        o.integer("memoryMiB", budgetMiB, 1, 65536);
        s.memoryBudgetBytes = std::uint64_t(budgetMiB) << 20;
        readAxisCounts(cc, o, "dims", s.dims, 1, 1024);
        const std::uint64_t bytes = ShadowTable::memoryBytes(s.dims);
        if (bytes > s.memoryBudgetBytes)
            cc.d.error(o.at("dims"), std::to_string(s.dims.x) + "x" + std::to_string(s.dims.y) + "x" + std::to_string(s.dims.z) + " needs " +
                                         std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB to build, over the " + std::to_string(budgetMiB) +
                                         " MiB budget (memoryMiB)");
    });
    if (d) out.scene.setSceneShadow(*d);
}

void checkLightingBudget(Context& c, const SceneFile& out) {
    const Scene& scene = out.scene;
    const std::size_t lights = scene.lights().size();
    if (lights == 0) return;
    std::uint64_t total = 0, largest = 0;
    std::size_t tableLit = 0;
    std::string largestAt;
    for (std::size_t i = 0; i < out.effects.size(); ++i) {
        const EffectLighting& L = scene.options(out.effects[i].id).lighting;
        if (!L.enabled || L.selfShadow != SelfShadow::Table) continue;
        const std::uint64_t bytes = ShadowTable::memoryBytes(L.tableDims) * lights; // one table per light
        ++tableLit;
        total += bytes;
        if (bytes > largest) largest = bytes, largestAt = "effects[" + std::to_string(i) + "].lighting.tableDims " + dimsText(L.tableDims);
    }
    const SceneShadowDesc& sd = scene.sceneShadow();
    if (sd.enabled) total += ShadowTable::memoryBytes(sd.dims);
    std::string what = std::to_string(lights) + " light(s) x " + std::to_string(tableLit) + " table-lit effect(s)";
    if (!largestAt.empty()) what += " (the largest " + largestAt + ")";
    if (sd.enabled) what += " and sceneShadow.dims " + dimsText(sd.dims);
    if (Status s = checkBudget("the shadow tables of " + what, total, "bytes", c.budgets.lightingBytes, "lightingBytes"); !s)
        c.d.error("lights", s.error());
}

void readEffectLighting(Context& c, const std::string& path, const Json& v, EffectLighting& out) {
    auto l = readObject<EffectLighting>(c, path, v, [&](Context& cc, ObjectReader& o, EffectLighting& e) {
        e.enabled = true; // giving the block asks for lighting
        o.boolean("enabled", e.enabled);
        o.number("albedo", e.gas.albedo, 0.0, 1.0);
        o.number("emission", e.gas.emission, 0.0, 1e6);
        o.number("multipleScattering", e.gas.multipleScattering, 0.0, 1e6);
        if (const Json* a = o.get("ambient"))
            if (auto col = readVec3(cc.d, o.at("ambient"), *a, 0.0, 1e6)) e.gas.ambient = *col;
        if (const Json* p = o.get("phase")) {
            const std::string pp = o.at("phase");
            if (!p->is_array() || p->empty() || p->size() > std::size_t(PhaseFunction::kMaxLobes)) {
                cc.d.error(pp, "expected an array of 1 to " + std::to_string(PhaseFunction::kMaxLobes) +
                                   " lobes {\"g\": ..., \"weight\": ...}, got " + typeName(*p) + " " + brief(*p));
            } else {
                std::vector<HgLobe> lobes;
                for (std::size_t i = 0; i < p->size(); ++i)
                    if (auto lobe = readObject<HgLobe>(cc, index(pp, i), (*p)[i], [](Context&, ObjectReader& lo, HgLobe& h) {
                            lo.number("g", h.g, -0.999999, 0.999999);
                            lo.number("weight", h.weight, 0.0, 1e6);
                        }))
                        lobes.push_back(*lobe);
                if (lobes.size() == p->size()) {
                    if (auto f = PhaseFunction::create(lobes)) e.gas.phase = *f;
                    else cc.d.error(pp, f.error());
                }
            }
        }
        if (const Json* s = o.get("selfShadow"))
            if (auto ch = readChoice(cc.d, o.at("selfShadow"), *s, {"off", "traced", "table"}))
                e.selfShadow = *ch == "off" ? SelfShadow::Off : *ch == "traced" ? SelfShadow::Traced : SelfShadow::Table;
        readAxisCounts(cc, o, "tableDims", e.tableDims, 1, 256);
        // A lit effect's tables are built with ShadowTableDesc's default budget
        // (the Scene gives them no other): a table over it would leave the
        // effect unlit at every frame, so it is refused here.
        if (e.selfShadow == SelfShadow::Table && o.has("tableDims"))
            if (const std::uint64_t bytes = ShadowTable::memoryBytes(e.tableDims), budget = ShadowTableDesc{}.memoryBudgetBytes; bytes > budget)
                cc.d.error(o.at("tableDims"), dimsText(e.tableDims) + " needs " + std::to_string(bytes) +
                                                  " bytes a table (17 an entry), over the budget of " + std::to_string(budget) +
                                                  " bytes of each shadow table (ShadowTableDesc::memoryBudgetBytes); 158x158x158 fits");
        o.boolean("castsShadow", e.castsShadow);
    });
    if (l) out = *l;
}

} // namespace splatfx::scenefile

namespace splatfx {

Light LightMotion::at(const Light& base, double timeSec) const {
    Light l = base;
    const double w = std::clamp(timeSec / double(seconds), 0.0, 1.0);
    const glm::dvec3 a = glm::normalize(glm::dvec3(from)), b = glm::normalize(glm::dvec3(to));
    // Spherical interpolation: constant angular speed; opposite ends (no
    // unique great circle) fall back to the straight line, normalised.
    const double cosAngle = std::clamp(glm::dot(a, b), -1.0, 1.0), angle = std::acos(cosAngle), s = std::sin(angle);
    glm::dvec3 d = s > 1e-6 ? (std::sin((1.0 - w) * angle) * a + std::sin(w * angle) * b) / s : glm::mix(a, b, w);
    if (!(glm::length(d) > 1e-9)) d = w < 0.5 ? a : b;
    l.direction = glm::vec3(glm::normalize(d));
    return l;
}

} // namespace splatfx
