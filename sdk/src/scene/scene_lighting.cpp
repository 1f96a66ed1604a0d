// Scene lighting (docs/lighting.md, "In a Scene"): lit effects'
// splats get their colour from the low-albedo model (lightPoints at each
// splat's centre, self-shadowed by tracing or by shadow tables rebuilt only
// when the effect's density or a light changed), and one shadow table over
// every lit, shadow-casting effect goes into the Frame for the host's
// surfaces (FrameShadow).
#include <algorithm>
#include <cmath>
#include <limits>

#include "splat/color_table_entry.hpp"
#include "splatfx/scene.hpp"
#include "volume_kinds.hpp"

namespace splatfx {
namespace {

// Lit linear colour into the splat's RGBA8: a colour brighter than 1 in any
// channel is scaled down by its largest channel, keeping its hue (a clamp per
// channel would turn a bright orange flame yellow-white). Without HDR the
// lights' intensities set the brightness up to the table colour's
// saturation; with HDR (Scene::setHdrLit) that channel goes into the splat's
// colorCoord as -m (splats.hpp, Splat), so the GL pass draws m x chroma.
// Colours <= 1 are packed the same either way (8-bit hosts are unchanged).
std::uint32_t packLit(glm::vec3 c, float* scale) {
    // NaN is no light; a product that overflowed float is the brightest colour float holds.
    for (int a = 0; a < 3; ++a) c[a] = std::isnan(c[a]) ? 0.0f : std::clamp(c[a], 0.0f, std::numeric_limits<float>::max());
    const float m = std::max({c.r, c.g, c.b});
    *scale = 1.0f;
    if (m > 1.0f) c /= m, *scale = m;
    return std::uint32_t(c.r * 255.0f + 0.5f) | std::uint32_t(c.g * 255.0f + 0.5f) << 8 | std::uint32_t(c.b * 255.0f + 0.5f) << 16 | 0xff000000u;
}

// An effect's own shadow (self-shadowing: traced, table or none) times the
// transmittance through the other volumes between it and the light (the lit
// clouds, the casting ground fog layers and the other lit effects): a
// product, since optical depths along one ray add. Each other volume is
// traced through its own model (a trilinear DensityField, or a layer's
// closed form, GroundFogCaster: each exact up to float rounding); a ray that
// misses a caster's box costs one clip.
class VolumeShadows final : public ShadowProvider {
public:
    // others[i]: the volumes that can shadow the receiver for light i (Scene::scheduleCasters).
    VolumeShadows(const ShadowProvider* own, std::span<const Light> lights, std::span<const std::vector<const ShadowCaster*>> others)
        : mOwn(own), mLights(lights), mOthers(others) {}
    float transmittance(std::size_t light, glm::vec3 world) const override {
        float t = mOwn ? mOwn->transmittance(light, world) : 1.0f;
        if (light >= mLights.size() || light >= mOthers.size()) return t;
        float depth = 0.0f;
        for (const ShadowCaster* f : mOthers[light]) depth += f->opticalDepthToLight(world, mLights[light]);
        return depth > 0.0f ? t * std::exp2(-depth) : t;
    }

private:
    const ShadowProvider* mOwn;
    std::span<const Light> mLights;
    std::span<const std::vector<const ShadowCaster*>> mOthers;
};

} // namespace

Result<std::size_t> Scene::addLight(const Light& light) {
    if (Status s = validateLight(light, "lights[" + std::to_string(mLights.size()) + "]"); !s) return makeError(s.error());
    mLights.push_back(light);
    return mLights.size() - 1;
}

Status Scene::setLight(std::size_t i, const Light& light) {
    if (i >= mLights.size())
        return makeError("setLight: index " + std::to_string(i) + " is not a light (" + std::to_string(mLights.size()) + " lights)");
    if (Status s = validateLight(light, "lights[" + std::to_string(i) + "]"); !s) return s;
    mLights[i] = light;
    return {};
}

namespace {

// An effect that builds self-shadow tables: lit with SelfShadow::Table and of a
// kind lit through splats. Clouds (their relight) and the tetrahedra kinds (a
// ground fog's closed form; LOD volumes are unlit) build none, whatever their
// options say.
bool buildsShadowTables(const EffectKind& kind, const EffectOptions& options) {
    if (!options.enabled || !options.lighting.enabled || options.lighting.selfShadow != SelfShadow::Table) return false;
    return !dynamic_cast<const detail::CloudKind*>(&kind) && !dynamic_cast<const detail::TetraKind*>(&kind);
}

} // namespace

std::uint64_t Scene::requiredLightingBytes() const {
    std::uint64_t total = 0;
    for (const Entry& e : mEntries)
        if (buildsShadowTables(*e.kind, e.options))
            total += ShadowTable::memoryBytes(e.options.lighting.tableDims) * mLights.size(); // one table per light
    if (mSceneShadowDesc.enabled) total += ShadowTable::memoryBytes(mSceneShadowDesc.dims); // slot 0's
    return total;
}

Status Scene::checkLightingBudget() const {
    if (mLights.empty()) return {};
    std::size_t tableLit = 0;
    for (const Entry& e : mEntries) tableLit += buildsShadowTables(*e.kind, e.options) ? 1 : 0;
    return checkBudget("lighting: the shadow tables of " + std::to_string(mLights.size()) + " light(s) x " + std::to_string(tableLit) +
                           " table-lit effect(s)" + (mSceneShadowDesc.enabled ? " and the scene shadow" : ""),
                       requiredLightingBytes(), "bytes", mBudgets.lightingBytes, "lightingBytes");
}

std::uint64_t Scene::sceneShadowBuilds(std::size_t light) const {
    return light < mLightShadows.size() ? mLightShadows[light].table.builds() : 0;
}

bool Scene::updateLitField(Entry& e, const Materials& materials, const EmitOptions& draw) {
    if (!e.lit) e.lit = std::make_unique<LitState>();
    LitState& lit = *e.lit;
    // The density the light sees, as the kind draws it; kinds the lights
    // cannot see stay unlit.
    if (!e.kind->lightingDensity(materials, draw, lit.densityGrid)) return false;
    auto field = DensityField::fromGrid(lit.densityGrid);
    if (!field) {
        mLightingError = "effect '" + e.options.name + "': lighting.density: " + field.error();
        return false;
    }
    lit.field = std::move(*field);
    return true;
}

// Volumes shadow one another (scene.hpp): an effect's light passes through
// the lit clouds and the other lit effects, so every field must be this
// emit's before the first effect is lit. Effects out of view that cast into
// it (castsIntoView) only need their field.
void Scene::updateEffectCasters(const Materials& materials, const EmitOptions& options) {
    mCounters.crossShadowPairs = mCounters.crossShadowPairsSkipped = 0;
    for (Entry& e : mEntries) {
        if (e.lit) e.lit->fieldReady = false;
        if (dynamic_cast<const detail::CloudKind*>(e.kind.get())) continue;     // clouds: their own relight (emitInto)
        if (dynamic_cast<const detail::GroundFogKind*>(e.kind.get())) continue; // ground fog: its caster (updateFogCasters)
        const EmitOptions draw{.textured = e.options.draw.textured && options.textured,
                               .opacityScale = e.options.draw.opacityScale * options.opacityScale};
        const bool tableLit = e.options.lighting.selfShadow == SelfShadow::Table;
        // As emitInto decides who is lit: tables over the budget are never built, those effects stay unlit.
        const bool lit = e.status.needed && e.options.lighting.enabled && (mTablesFit || !tableLit);
        if (!lit && !e.status.castsIntoView) continue;
        if (!updateLitField(e, materials, draw)) {
            e.status.castsIntoView = false;
            continue;
        }
        e.lit->fieldReady = true;
        if (e.options.lighting.castsShadow && !e.lit->field.empty()) mVolumeCasters.push_back(&e.lit->field);
    }
}

void Scene::scheduleCasters(const Entry& e) {
    mCastersPerLight.resize(mLights.size());
    const DensityField& own = e.lit->field;
    const Aabb box{own.boundsMin(), own.boundsMax()};
    for (std::size_t i = 0; i < mLights.size(); ++i) {
        mCastersPerLight[i].clear();
        for (const ShadowCaster* f : mVolumeCasters) {
            if (f == &own) continue; // its own shadow is its self-shadowing
            if (shadowFallsOn(Aabb{f->boundsMin(), f->boundsMax()}, mLights[i], box)) {
                mCastersPerLight[i].push_back(f);
                ++mCounters.crossShadowPairs;
            } else {
                ++mCounters.crossShadowPairsSkipped;
            }
        }
    }
}

void Scene::lightEmitted(Entry& e, SplatBuilder& builder, const Materials& materials, std::size_t first) {
    const EffectLighting& L = e.options.lighting;
    const std::string at = "effect '" + e.options.name + "': lighting.";
    if (!e.lit || !e.lit->fieldReady) return;
    LitState& lit = *e.lit;
    const Grid& dg = lit.densityGrid;

    const ShadowProvider* shadows = nullptr;
    ShadowTracer tracer(lit.field, mLights);
    if (L.selfShadow == SelfShadow::Traced) {
        shadows = &tracer;
    } else if (L.selfShadow == SelfShadow::Table) {
        if (lit.tableDims != L.tableDims) {
            lit.tables = ShadowTables(ShadowTableDesc{.dims = L.tableDims});
            lit.tableDims = L.tableDims;
        }
        std::uint64_t b0 = 0, r0 = 0, b1 = 0, r1 = 0;
        for (const ShadowTable& t : lit.tables.tables()) b0 += t.builds(), r0 += t.reuses();
        // A light that cannot reach the effect lights none of its splats
        // (irradiance 0): its table is not worth building.
        const Aabb box{lit.field.boundsMin(), lit.field.boundsMax()};
        lit.reaches.assign(mLights.size(), true);
        std::uint64_t skips = 0;
        for (std::size_t i = 0; i < mLights.size(); ++i)
            if (!lightReaches(mLights[i], box)) lit.reaches[i] = false, ++skips;
        e.status.shadowTableSkips += skips;
        mCounters.shadowTableSkips += skips;
        if (Status s = lit.tables.update(lit.field, mLights, lit.reaches); !s) {
            mLightingError = at + "tableDims: " + s.error();
            return;
        }
        for (const ShadowTable& t : lit.tables.tables()) b1 += t.builds(), r1 += t.reuses();
        e.status.shadowTableBuilds += b1 - b0;
        e.status.shadowTableReuses += r1 - r0;
        mCounters.shadowTableBuilds += b1 - b0;
        mCounters.shadowTableReuses += r1 - r0;
        shadows = &lit.tables;
    }

    // Per splat: the factor at its centre, times its table colour.
    std::vector<Splat>& splats = builder.splats();
    const std::size_t n = splats.size() - first;
    lit.points.resize(n);
    for (std::size_t i = 0; i < n; ++i) lit.points[i] = splats[first + i].center;
    const glm::mat3 shape =
        glm::mat3(dg.transform) * glm::mat3(glm::vec3(dg.spacing.x, 0, 0), glm::vec3(0, dg.spacing.y, 0), glm::vec3(0, 0, dg.spacing.z));
    const float det = std::abs(glm::determinant(shape));
    const float voxelSize = std::isfinite(det) ? std::cbrt(det) : 0.0f;
    scheduleCasters(e);
    const VolumeShadows withVolumes(shadows, mLights, mCastersPerLight);
    bool anyCaster = false;
    for (const auto& c : mCastersPerLight) anyCaster = anyCaster || !c.empty();
    if (anyCaster) shadows = &withVolumes;
    if (Status s = lightPoints(lit.points, voxelSize, builder.camera().eye(), mLights, shadows, L.gas, lit.factors); !s) {
        mLightingError = at + "gas: " + s.error();
        return;
    }
    for (std::size_t i = 0; i < n; ++i) {
        Splat& sp = splats[first + i];
        const std::uint32_t row = std::uint32_t(std::lround(sp.colorRow));
        const ColorTable* table = row < materials.colorTableCount() ? &materials.colorTable(row) : nullptr;
        // The top byte is the depth cut's along-ray scale (splats.hpp, rayScaleCode): kept.
        float scale = 1.0f;
        sp.color = (packLit(glm::vec3(detail::colorTableEntry(table, sp.colorCoord)) * lit.factors[i], &scale) & 0x00ffffffu) |
                   (sp.color & 0xff000000u);
        if (mHdrLit && scale > 1.0f) sp.colorCoord = -scale;
    }
    e.status.lit = true;
    ++mCounters.litEffects;
}

namespace {

// How much light i can put into a shadow: its irradiance at each caster's
// box, summed (a point or spot light's at the box's nearest point, but no
// closer than the box's bounding radius, so a light inside stays finite),
// times its brightest colour channel. Spot cones that miss were removed
// before (Scene::lightReaches).
double influence(const Light& light, std::span<const ShadowCaster* const> casters) {
    const double power = double(light.intensity) * double(std::max({light.color.r, light.color.g, light.color.b}));
    if (light.type == LightType::Directional) return power * double(casters.size());
    double sum = 0.0;
    for (const ShadowCaster* f : casters) {
        const glm::dvec3 lo(f->boundsMin()), hi(f->boundsMax()), p(light.position);
        const glm::dvec3 q = glm::clamp(p, lo, hi);
        const double r = 0.5 * glm::length(hi - lo);
        const double d2 = std::max({glm::dot(p - q, p - q), r * r, double(light.radiusWorld) * double(light.radiusWorld)});
        sum += d2 > 0.0 ? power / d2 : 0.0;
    }
    return sum;
}

} // namespace

std::vector<std::size_t> Scene::chooseShadowLights(const std::vector<std::vector<const ShadowCaster*>>& casters) {
    const SceneShadowDesc& d = mSceneShadowDesc;
    std::vector<std::size_t> candidates; // lights that reach a caster, except slot 0's
    std::vector<double> weight(mLights.size(), 0.0);
    for (std::size_t i = 0; i < mLights.size(); ++i) {
        if (casters[i].empty()) continue;
        weight[i] = influence(mLights[i], casters[i]);
        if (i != d.light) candidates.push_back(i);
    }
    // Most influential first; ties (and NaN-free equal weights) by light order, so the choice is deterministic.
    std::stable_sort(candidates.begin(), candidates.end(), [&](std::size_t a, std::size_t b) { return weight[a] > weight[b]; });
    std::vector<std::size_t> chosen;
    const bool first = d.light < mLights.size() && !casters[d.light].empty();
    if (first) chosen.push_back(d.light);
    // Slot 0 is kept for d.light even when it casts nothing this frame: splatfx_shadow() reads it.
    const std::size_t room = std::size_t(std::clamp(d.maxLights, 1, kMaxShadowLights)) - 1;
    const std::size_t wanted = std::min(room, candidates.size());
    mCounters.sceneShadowLightsOverMax = candidates.size() - wanted;
    // Memory: each table costs memoryBytes(dims); all of them within the
    // desc's budget and within what Budgets::lightingBytes leaves once the
    // required tables (checkLightingBudget: slot 0's included) are counted.
    const std::uint64_t each = ShadowTable::memoryBytes(d.dims);
    const std::uint64_t required = requiredLightingBytes();
    const std::uint64_t leftOver = mBudgets.lightingBytes > required ? mBudgets.lightingBytes - required : 0;
    const std::uint64_t ownBudget = d.memoryBudgetBytes > each ? d.memoryBudgetBytes - each : 0; // slot 0's is counted in both
    const std::uint64_t fit = each > 0 ? std::min(leftOver, ownBudget) / each : 0;
    const std::size_t kept = std::size_t(std::min<std::uint64_t>(wanted, fit));
    mCounters.sceneShadowLightsOverBudget = wanted - kept;
    // The kept ones take the slots after slot 0 in light order, so a change of ranking moves no table between slots.
    std::vector<std::size_t> rest(candidates.begin(), candidates.begin() + std::ptrdiff_t(kept));
    std::sort(rest.begin(), rest.end());
    chosen.insert(chosen.end(), rest.begin(), rest.end());
    return chosen;
}

void Scene::shadeScene(Frame& frame) {
    const SceneShadowDesc& d = mSceneShadowDesc;
    // A shadow cast by a light the scene does not have would silently be no shadow.
    if (d.enabled && !mLights.empty() && d.light >= mLights.size() && mLightingError.empty())
        mLightingError = "sceneShadow.light: expected the index of one of the scene's " + std::to_string(mLights.size()) +
                         " light(s), 0 to " + std::to_string(mLights.size() - 1) + ", got " + std::to_string(d.light);
    if (d.enabled && (d.maxLights < 1 || d.maxLights > kMaxShadowLights) && mLightingError.empty())
        mLightingError = "sceneShadow.maxLights: expected 1 to " + std::to_string(kMaxShadowLights) + ", got " + std::to_string(d.maxLights);
    const bool on = d.enabled && d.light < mLights.size() && d.maxLights >= 1 && d.maxLights <= kMaxShadowLights && mTablesFit;
    // Casters per light: the drawn lit effects, and those out of view whose
    // shadow reaches it (castsIntoView); the casting ground fog layers
    // (updateFogCasters); each only where the light reaches it.
    std::vector<std::vector<const ShadowCaster*>> casters(mLights.size());
    std::vector<std::vector<Entry*>> casterEntries(mLights.size());
    for (Entry& e : mEntries) {
        e.status.inSceneShadow = false;
        if (!on || !e.lit) continue;
        const ShadowCaster* c = e.lit->fogCaster;
        if (!c && (e.status.lit || e.status.castsIntoView) && e.options.lighting.castsShadow && !e.lit->field.empty()) c = &e.lit->field;
        if (!c) continue;
        const Aabb box{c->boundsMin(), c->boundsMax()};
        for (std::size_t i = 0; i < mLights.size(); ++i)
            if (lightReaches(mLights[i], box)) {
                casters[i].push_back(c);
                casterEntries[i].push_back(&e);
            }
    }
    mCounters.sceneShadowLightsOverMax = mCounters.sceneShadowLightsOverBudget = 0;
    const std::vector<std::size_t> chosen = on ? chooseShadowLights(casters) : std::vector<std::size_t>{};
    // What the kept tables cover.
    std::size_t casting = 0;
    for (std::size_t li : chosen)
        for (Entry* e : casterEntries[li])
            if (!e->status.inSceneShadow) e->status.inSceneShadow = true, ++casting;
    mCounters.sceneShadowCasters = casting;
    if (mLightShadows.size() > mLights.size()) mLightShadows.resize(mLights.size());
    while (mLightShadows.size() < mLights.size()) mLightShadows.emplace_back();
    // The slots refer to what they copied by address and build count; a table replaced or freed
    // at the same address must not pass for the one copied.
    auto forgetSlotsOf = [&](std::size_t li) {
        for (ShadowSlot& slot : mShadowSlots)
            if (slot.light == int(li)) slot.source = nullptr, slot.version = 0;
    };
    // A light without a table this frame frees it (the budget counts only the kept ones); it is
    // rebuilt when the light gets a slot again.
    for (std::size_t li = 0; li < mLightShadows.size(); ++li)
        if (std::find(chosen.begin(), chosen.end(), li) == chosen.end() && mLightShadows[li].table.builds() > 0) {
            mLightShadows[li] = LightShadow{ShadowTable{}, {}};
            forgetSlotsOf(li);
        }

    std::array<const ShadowTable*, kMaxShadowLights> sources{};
    std::array<int, kMaxShadowLights> lights;
    lights.fill(-1);
    // chosen[0] is d.light's when it casts; otherwise slot 0 stays empty and the rest start at slot 1.
    const std::size_t firstSlot = !chosen.empty() && chosen[0] == d.light && !casters[d.light].empty() ? 0 : 1;
    for (std::size_t c = 0; c < chosen.size(); ++c) {
        const std::size_t k = c + firstSlot;
        const std::size_t li = chosen[c];
        // One casting effect whose self-shadowing table for this light has the
        // scene shadow's dims: that table is the scene shadow (the paper's one
        // table serves both), so nothing more is built. Only a drawn effect's
        // self-shadowing tables are current.
        const Entry* only = casterEntries[li].size() == 1 && casterEntries[li][0]->status.lit && !casterEntries[li][0]->lit->fogCaster
                                ? casterEntries[li][0]
                                : nullptr;
        if (only && only->options.lighting.selfShadow == SelfShadow::Table && only->options.lighting.tableDims == d.dims &&
            li < only->lit->tables.tables().size()) {
            sources[k] = &only->lit->tables.tables()[li];
            lights[k] = int(li);
            continue;
        }
        LightShadow& ls = mLightShadows[li];
        const ShadowTableDesc td{.dims = d.dims, .memoryBudgetBytes = d.memoryBudgetBytes};
        if (td.dims != ls.desc.dims || td.memoryBudgetBytes != ls.desc.memoryBudgetBytes) {
            ls.table = ShadowTable(td);
            ls.desc = td;
            forgetSlotsOf(li); // a new table at the same address: its build count starts again
        }
        const std::uint64_t builds = ls.table.builds(), reuses = ls.table.reuses();
        if (Status s = ls.table.update(casters[li], mLights[li]); !s) {
            if (mLightingError.empty()) mLightingError = "sceneShadow (light " + std::to_string(li) + "): " + s.error();
            continue;
        }
        if (ls.table.builds() != builds) {
            ++mCounters.shadowTableBuilds;
            ++mCounters.sceneShadowBuilds;
        }
        mCounters.shadowTableReuses += ls.table.reuses() - reuses;
        sources[k] = &ls.table;
        lights[k] = int(li);
    }
    std::size_t withTable = 0;
    for (std::size_t k = 0; k < std::size_t(kMaxShadowLights); ++k) {
        ShadowSlot& slot = mShadowSlots[k];
        const ShadowTable* src = sources[k];
        withTable += src ? 1 : 0;
        const std::uint64_t builds = src ? src->builds() : 0;
        if (src != slot.source || lights[k] != slot.light || builds != slot.builds || slot.version == 0) {
            slot.source = src;
            slot.light = lights[k];
            slot.builds = builds;
            slot.version = ++mShadowVersions;
        }
        FrameShadow& out = frame.shadows()[k];
        if (out.version == slot.version) continue; // unchanged: nothing to copy
        out.valid = src != nullptr;
        out.version = slot.version;
        out.light = src ? lights[k] : (k == 0 ? int(d.light) : -1);
        if (src) {
            out.depth = src->data();
            out.dims = src->dims();
            out.worldToTable = src->worldToTable();
            out.lightInTable = src->lightInTable();
        } else {
            out.depth.clear();
            out.dims = glm::ivec3(0);
        }
    }
    mCounters.sceneShadowLights = withTable;
}

} // namespace splatfx
