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

Status Scene::checkLightingBudget() const {
    if (mLights.empty()) return {};
    std::uint64_t total = 0;
    std::size_t tableLit = 0;
    for (const Entry& e : mEntries) {
        const EffectLighting& L = e.options.lighting;
        if (!e.options.enabled || !L.enabled || L.selfShadow != SelfShadow::Table) continue;
        total += ShadowTable::memoryBytes(L.tableDims) * mLights.size(); // one table per light
        ++tableLit;
    }
    if (mSceneShadowDesc.enabled) total += ShadowTable::memoryBytes(mSceneShadowDesc.dims);
    return checkBudget("lighting: the shadow tables of " + std::to_string(mLights.size()) + " light(s) x " + std::to_string(tableLit) +
                           " table-lit effect(s)" + (mSceneShadowDesc.enabled ? " and the scene shadow" : ""),
                       total, "bytes", mBudgets.lightingBytes, "lightingBytes");
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

void Scene::lightEmitted(Entry& e, SplatBuilder& builder, const Materials& materials, std::size_t first, const EmitOptions& draw) {
    const EffectLighting& L = e.options.lighting;
    const std::string at = "effect '" + e.options.name + "': lighting.";
    if (!updateLitField(e, materials, draw)) return;
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

void Scene::shadeScene(Frame& frame) {
    const SceneShadowDesc& d = mSceneShadowDesc;
    std::vector<const DensityField*> fields;
    const Entry* only = nullptr; // the one casting effect, when there is one
    // A shadow cast by a light the scene does not have would silently be no shadow.
    if (d.enabled && !mLights.empty() && d.light >= mLights.size() && mLightingError.empty())
        mLightingError = "sceneShadow.light: expected the index of one of the scene's " + std::to_string(mLights.size()) +
                         " light(s), 0 to " + std::to_string(mLights.size() - 1) + ", got " + std::to_string(d.light);
    // Casters: the drawn lit effects, and those out of view whose shadow
    // reaches it (castsIntoView); each only where the light reaches it.
    for (Entry& e : mEntries) e.status.inSceneShadow = false;
    if (d.enabled && d.light < mLights.size() && mTablesFit)
        for (Entry& e : mEntries)
            if ((e.status.lit || e.status.castsIntoView) && e.options.lighting.castsShadow && e.lit && !e.lit->field.empty() &&
                lightReaches(mLights[d.light], Aabb{e.lit->field.boundsMin(), e.lit->field.boundsMax()})) {
                fields.push_back(&e.lit->field);
                e.status.inSceneShadow = true;
                only = &e;
            }
    mCounters.sceneShadowCasters = fields.size();
    // Only a drawn effect's self-shadowing tables are current.
    if (fields.size() != 1 || !only->status.lit) only = nullptr;
    // One casting effect whose self-shadowing table for this light has the
    // scene shadow's dims: that table is the scene shadow (the paper's one
    // table serves both), so nothing more is built.
    const ShadowTable* shared = nullptr;
    if (only && only->options.lighting.selfShadow == SelfShadow::Table && only->options.lighting.tableDims == d.dims &&
        d.light < only->lit->tables.tables().size())
        shared = &only->lit->tables.tables()[d.light];
    const ShadowTable* src = nullptr;
    if (shared) {
        src = shared;
        if (shared != mSceneShadowSource || shared->builds() != mSceneShadowLastBuilds) {
            mSceneShadowSource = shared;
            mSceneShadowLastBuilds = shared->builds();
            ++mSceneShadowVersion;
        }
    } else if (!fields.empty()) {
        const ShadowTableDesc td{.dims = d.dims, .memoryBudgetBytes = d.memoryBudgetBytes};
        if (td.dims != mSceneShadowTableDesc.dims || td.memoryBudgetBytes != mSceneShadowTableDesc.memoryBudgetBytes) {
            mSceneShadow = ShadowTable(td);
            mSceneShadowTableDesc = td;
        }
        const std::uint64_t reuses = mSceneShadow.reuses();
        if (Status s = mSceneShadow.update(fields, mLights[d.light]); !s) {
            mLightingError = "sceneShadow: " + s.error();
        } else {
            src = &mSceneShadow;
            if (mSceneShadowSource != &mSceneShadow || mSceneShadow.builds() != mSceneShadowLastBuilds) {
                if (mSceneShadow.builds() != mSceneShadowLastBuilds) {
                    ++mCounters.shadowTableBuilds;
                    ++mCounters.sceneShadowBuilds;
                }
                mSceneShadowSource = &mSceneShadow;
                mSceneShadowLastBuilds = mSceneShadow.builds();
                ++mSceneShadowVersion;
            }
            mCounters.shadowTableReuses += mSceneShadow.reuses() - reuses;
        }
    }
    if (!src && mSceneShadowSource) {
        mSceneShadowSource = nullptr;
        ++mSceneShadowVersion;
    }
    FrameShadow& out = frame.shadow();
    if (out.version == mSceneShadowVersion && mSceneShadowVersion != 0) return; // unchanged: nothing to copy
    out.valid = src != nullptr;
    out.version = mSceneShadowVersion;
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

} // namespace splatfx
