#include "splatfx/scene.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>

#include "volume_kinds.hpp"

namespace splatfx {

EffectId Scene::add(Effect effect, EffectOptions options) { return push(std::make_unique<Effect>(std::move(effect)), std::move(options)); }

EffectId Scene::add(LodVolume volume, TransferFunction transfer, PreIntegrationTable table, EffectOptions options) {
    return push(std::make_unique<detail::LodVolumeKind>(std::move(volume), std::move(transfer), std::move(table)), std::move(options));
}

EffectId Scene::add(GroundFog fog, TransferFunction transfer, PreIntegrationTable table, EffectOptions options) {
    return push(std::make_unique<detail::GroundFogKind>(std::move(fog), std::move(transfer), std::move(table)), std::move(options));
}

EffectId Scene::add(Cloud cloud, EffectOptions options) { return push(std::make_unique<detail::CloudKind>(std::move(cloud)), std::move(options)); }

EffectId Scene::add(std::unique_ptr<EffectKind> kind, EffectOptions options) {
    assert(kind && "Scene::add: kind must not be null");
    return push(std::move(kind), std::move(options));
}

EffectId Scene::push(std::unique_ptr<EffectKind> kind, EffectOptions options) {
    mEntries.push_back(Entry{std::move(kind), std::move(options), {}, nullptr});
    mCounters.declared = mEntries.size();
    return EffectId(mEntries.size() - 1);
}

Effect* Scene::findEffect(EffectId id) { return dynamic_cast<Effect*>(mEntries.at(id).kind.get()); }
const Effect* Scene::findEffect(EffectId id) const { return dynamic_cast<const Effect*>(mEntries.at(id).kind.get()); }

LodVolume* Scene::findLodVolume(EffectId id) {
    auto* k = dynamic_cast<detail::LodVolumeKind*>(mEntries.at(id).kind.get());
    return k ? &k->volume() : nullptr;
}

const LodVolume* Scene::findLodVolume(EffectId id) const {
    const auto* k = dynamic_cast<const detail::LodVolumeKind*>(mEntries.at(id).kind.get());
    return k ? &k->volume() : nullptr;
}

Cloud* Scene::findCloud(EffectId id) {
    auto* k = dynamic_cast<detail::CloudKind*>(mEntries.at(id).kind.get());
    return k ? &k->cloud() : nullptr;
}

const Cloud* Scene::findCloud(EffectId id) const {
    const auto* k = dynamic_cast<const detail::CloudKind*>(mEntries.at(id).kind.get());
    return k ? &k->cloud() : nullptr;
}

const GroundFog* Scene::findGroundFog(EffectId id) const {
    const auto* k = dynamic_cast<const detail::GroundFogKind*>(mEntries.at(id).kind.get());
    return k ? &k->volume() : nullptr;
}

Effect& Scene::effect(EffectId id) {
    Effect* e = findEffect(id);
    assert(e && "Scene::effect: this entry is not an Effect; use Scene::kind or Scene::findEffect");
    return *e;
}

const Effect& Scene::effect(EffectId id) const {
    const Effect* e = findEffect(id);
    assert(e && "Scene::effect: this entry is not an Effect; use Scene::kind or Scene::findEffect");
    return *e;
}

void Scene::setTransfer(EffectId id, TransferFunction transfer, PreIntegrationTable table) {
    auto* k = dynamic_cast<detail::TetraKind*>(mEntries.at(id).kind.get());
    assert(k && "Scene::setTransfer: this entry is neither a LOD volume nor ground fog");
    if (k) k->setTransfer(std::move(transfer), std::move(table));
}

const std::vector<glm::vec3>& Scene::groundFogTerrain(EffectId id) const {
    static const std::vector<glm::vec3> kNone;
    const Entry& e = mEntries.at(id);
    const auto* k = dynamic_cast<const detail::GroundFogKind*>(e.kind.get());
    // A layer not needed was not emitted: what it kept is an older frame's.
    return k && e.status.needed ? k->terrain() : kNone;
}

bool Scene::inFrustum(const Aabb& box, const Camera& camera) {
    if (box.empty()) return false;
    // Gribb & Hartmann planes; a box is outside if all 8 corners are behind one plane.
    const glm::mat4 vp = camera.proj * camera.view;
    for (int i = 0; i < 3; ++i)
        for (int sign = -1; sign <= 1; sign += 2) {
            const glm::vec4 plane =
                glm::vec4(vp[0][3], vp[1][3], vp[2][3], vp[3][3]) + float(sign) * glm::vec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
            // The corner farthest along the plane normal decides.
            const glm::vec3 p(plane.x >= 0 ? box.hi.x : box.lo.x, plane.y >= 0 ? box.hi.y : box.lo.y, plane.z >= 0 ? box.hi.z : box.lo.z);
            if (glm::dot(glm::vec3(plane), p) + plane.w < 0.0f) return false;
        }
    return true;
}

namespace {

// Times the dynamics hold exactly (kMaxTimeSec); NaN fails every comparison.
Status checkTime(const char* function, double timeSec) {
    if (timeSec >= 0.0 && timeSec <= kMaxTimeSec) return {};
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "%s: timeSec is %g; expected a finite number of seconds in [0, %g] (kMaxTimeSec, about 72.8 hours: later times lose the "
                  "dynamics' precision; restart the scene clock before then)",
                  function, timeSec, kMaxTimeSec);
    return makeError(buf);
}

} // namespace

Status Scene::update(double timeSec, const Camera& camera) {
    if (Status s = checkTime("Scene::update", timeSec); !s) return s;
    const double previous = mUpdated ? std::min(mTime, timeSec) : timeSec;
    mTime = timeSec;
    mUpdated = true;
    mCounters.needed = mCounters.simulated = mCounters.castOnly = mCounters.castersCulled = 0;
    const glm::vec3 eye = camera.eye();
    // Every light may shadow the scene (SceneShadowDesc) and the lit effects in
    // view (effects shadow one another, with or without a scene shadow):
    // casters out of view are scheduled by where their shadow falls away from any of them.
    const bool shadowing = !mLights.empty();
    for (Entry& e : mEntries) {
        EffectStatus& s = e.status;
        const bool wasAdvanced = s.needed || s.castsIntoView || s.lightsIntoView;
        s.enabled = e.options.enabled;
        s.needed = s.castsIntoView = s.lightsIntoView = false;
        if (!s.enabled) {
            ++s.framesSkipped;
            continue;
        }
        // Bounds over the interval since the last update: motion between frames is covered.
        s.bounds = e.kind->bounds(std::max(0.0, previous), timeSec);
        const glm::vec3 nearest = glm::clamp(eye, s.bounds.lo, s.bounds.hi);
        s.inRange = !s.bounds.empty() && glm::length(eye - nearest) <= e.options.rangeWorld;
        // Cheapest tests first: a hidden effect costs one bounds query and a frustum test.
        s.inView = s.inRange && inFrustum(s.bounds, camera);
        // Out of view, a lit caster still matters where its shadow reaches the
        // view (light influence, not visibility): it is advanced, not drawn.
        const bool caster = shadowing && s.inRange && !s.inView && e.options.lighting.enabled && e.options.lighting.castsShadow;
        bool casts = false;
        for (std::size_t i = 0; caster && !casts && i < mLights.size(); ++i) casts = shadowReachesView(s.bounds, mLights[i], camera);
        if (caster && !casts) ++mCounters.castersCulled;
        // Out of view, an emitter still lights what is in view within its reach.
        const EmittedLightDesc& emits = e.options.emitsLight;
        const bool lights = emits.enabled && s.inRange && !s.inView && !casts &&
                            inFrustum(Aabb{s.bounds.lo - glm::vec3(emits.reachWorld), s.bounds.hi + glm::vec3(emits.reachWorld)}, camera);
        s.alive = (s.inView || casts || lights) && e.kind->alive(timeSec, AliveHints{.deadDensity = e.options.deadDensity});
        if (!s.alive) {
            ++s.framesSkipped;
            continue;
        }
        // Resumed: advanced before, skipped since; the kind decides what catching up costs.
        const AdvanceContext context{.catchUpStepSec = e.options.catchUpStepSec,
                                     .maxCatchUpSteps = e.options.maxCatchUpSteps,
                                     .resumed = !wasAdvanced && s.framesNeeded + s.framesCastOnly > 0};
        if (e.kind->advanceTo(timeSec, context).caughtUp) ++s.catchUps;
        ++mCounters.simulated;
        if (s.inView) {
            s.needed = true;
            ++s.framesNeeded;
            ++mCounters.needed;
        } else {
            // Advanced for its shadow or its light only (counted as cast-only work).
            s.castsIntoView = casts;
            s.lightsIntoView = lights;
            ++s.framesCastOnly;
            ++mCounters.castOnly;
        }
    }
    return {};
}

std::size_t Scene::emitInto(SplatBuilder& builder, std::vector<FrameVolume>* volumes, const Materials& materials, const EmitOptions& options) {
    std::size_t splats = 0, tetrahedra = 0;
    // Per-emit lighting counters (scene_lighting.cpp).
    mLightingError.clear();
    mCounters.litEffects = 0;
    mCounters.cloudLightsDropped = 0;
    mCounters.shadowTableBuilds = mCounters.shadowTableReuses = mCounters.shadowTableSkips = 0;
    mTablesFit = true;
    mEmittedLights.clear();
    mEmittedGrid = {};
    mEmittedGridsDropped = 0;
    if (Status s = checkLightingBudget(); !s) {
        mLightingError = s.error();
        mTablesFit = false;
    }
    // Lit clouds' extinction first: it depends on their density only, joins
    // the scene's shadow casters (shadeScene reads e.lit->field; copied only
    // when the density changed) and shadows the effects lit below and the
    // other lit volumes (mVolumeCasters).
    mVolumeCasters.clear();
    std::vector<char> cloudLit(mEntries.size(), 0);
    for (Entry& e : mEntries) {
        auto* cloud = dynamic_cast<detail::CloudKind*>(e.kind.get());
        if (!cloud || !(e.status.needed || e.status.castsIntoView) || !e.options.lighting.enabled) continue;
        if (!e.lit) e.lit = std::make_unique<LitState>();
        const DensityField& f = cloud->cloud().densityField();
        if (e.lit->field.empty() != f.empty() || e.lit->field.fingerprint() != f.fingerprint()) e.lit->field = f;
        if (e.options.lighting.castsShadow && !e.lit->field.empty()) mVolumeCasters.push_back(&e.lit->field);
    }
    updateFogCasters();                      // the casting ground fog layers: exact, their extinction only
    updateEffectCasters(materials, options); // every effect's field before any is lit: they shadow one another
    // Then each lit cloud in view takes the scene's lights and the shadows of
    // every other caster of this emit (not its own field: its self-shadowing
    // is its own sweep) before it refines; relit only when a light or a
    // caster changed, and then only under the changed casters (Cloud::setLight).
    for (std::size_t i = 0; i < mEntries.size(); ++i) {
        Entry& e = mEntries[i];
        auto* cloud = dynamic_cast<detail::CloudKind*>(e.kind.get());
        if (!cloud || !e.status.needed || !e.options.lighting.enabled) continue;
        mFogCasterScratch.assign(mVolumeCasters.begin(), mVolumeCasters.end());
        std::erase(mFogCasterScratch, static_cast<const ShadowCaster*>(&e.lit->field));
        std::size_t dropped = 0;
        if (Status s = cloud->follow(mLights, e.options.lighting, dropped, mFogCasterScratch); !s) {
            mLightingError = "effect '" + e.options.name + "': lighting: " + s.error();
            continue;
        }
        mCounters.cloudLightsDropped += dropped; // lights reaching the cloud that cannot light it (CloudKind::follow)
        cloudLit[i] = 1;
    }
    for (std::size_t i = 0; i < mEntries.size(); ++i) {
        Entry& e = mEntries[i];
        const EmitOptions draw{.textured = e.options.draw.textured && options.textured,
                               .opacityScale = e.options.draw.opacityScale * options.opacityScale};
        const std::size_t first = builder.splats().size();
        auto* cloud = dynamic_cast<detail::CloudKind*>(e.kind.get());
        // Lit ground fog is emitted after every caster's field is current (emitLitGroundFogs).
        const bool litFog = e.options.lighting.enabled && dynamic_cast<detail::GroundFogKind*>(e.kind.get());
        EmitResult r;
        if (e.status.needed && !litFog)
            r = e.kind->emit(EmitContext{.splats = builder,
                                         .volumes = volumes,
                                         .materials = materials,
                                         .draw = draw,
                                         .refine = e.options.refine,
                                         .keepTerrain = e.options.keepTerrain});
        e.status.splatsDrawn = r.splats;
        e.status.tetrahedraDrawn = r.tetrahedra;
        splats += r.splats;
        tetrahedra += r.tetrahedra;
        // Colour the splats just emitted; unlit effects skip this.
        e.status.lit = cloudLit[i] != 0;
        mCounters.litEffects += cloudLit[i] != 0 ? 1 : 0;
        // Tables over the budget are never built: those effects stay unlit (the error says why).
        const bool tableLit = e.options.lighting.selfShadow == SelfShadow::Table;
        if (!cloud && !litFog && e.status.needed && e.options.lighting.enabled && (mTablesFit || !tableLit))
            lightEmitted(e, builder, materials, first);
        e.status.emittedLights = 0;
        if (e.options.emitsLight.enabled && (e.status.needed || e.status.lightsIntoView)) fitLights(e, builder.camera(), materials, draw);
    }
    tetrahedra += emitLitGroundFogs(builder, volumes, materials, options);
    mCounters.splats = splats;
    mCounters.tetrahedra = tetrahedra;
    return splats;
}

void Scene::fitLights(Entry& e, const Camera& camera, const Materials& materials, const EmitOptions& draw) {
    // Every splat, in view or not (no frustum culling), so the light does not
    // change as the effect crosses the view's edge; drawn nowhere.
    mLightScratch.begin(camera);
    e.kind->emit(EmitContext{.splats = mLightScratch, .volumes = nullptr, .materials = materials, .draw = draw});
    if (e.options.emitsLight.mode == EmittedLightMode::Grid) {
        if (mEmittedGrid.dims.x > 0) {
            ++mEmittedGridsDropped;
            return;
        }
        Result<EmittedGrid> grid = fitEmittedGrid(mLightScratch.splats(), materials, e.options.emitsLight);
        if (!grid) {
            mLightingError = "effect '" + e.options.name + "': " + grid.error();
            return;
        }
        mEmittedGrid = std::move(*grid);
        return;
    }
    Result<std::vector<EmittedLight>> lights = fitEmittedLights(mLightScratch.splats(), materials, e.options.emitsLight);
    if (!lights) {
        mLightingError = "effect '" + e.options.name + "': " + lights.error();
        return;
    }
    e.status.emittedLights = lights->size();
    mEmittedLights.insert(mEmittedLights.end(), lights->begin(), lights->end());
}

std::size_t Scene::emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) {
    return emitInto(builder, nullptr, materials, options);
}

Status Scene::prepare(double timeSec, const Camera& camera, const Materials& materials, Frame& frame, const EmitOptions& options) {
    if (Status s = checkTime("Scene::prepare", timeSec); !s) return s;
    if (Status s = update(timeSec, camera); !s) return s;
    frame.begin(timeSec, camera);
    emitInto(frame.builder(), &frame.volumes(), materials, options);
    shadeScene(frame); // the lit effects' shadows on the scene, into frame.shadows()
    // The emitters' lights, brightest first; the frame keeps what the GLSL holds.
    std::stable_sort(mEmittedLights.begin(), mEmittedLights.end(), [](const EmittedLight& a, const EmittedLight& b) {
        return a.intensity.x + a.intensity.y + a.intensity.z > b.intensity.x + b.intensity.y + b.intensity.z;
    });
    const std::size_t kept = std::min<std::size_t>(mEmittedLights.size(), kMaxEmittedLights);
    frame.emittedLights().assign(mEmittedLights.begin(), mEmittedLights.begin() + std::ptrdiff_t(kept));
    mCounters.emittedLights = mEmittedLights.size();
    mCounters.emittedLightsDropped = mEmittedLights.size() - kept + mEmittedGridsDropped;
    frame.emittedGrid() = mEmittedGrid;
    frame.end();
    frame.setFog(fogForView(camera, timeSec)); // only the terms this view can see
    FrameCounters& c = frame.counters();
    c.litEffects = mCounters.litEffects;
    c.shadowTableBuilds = mCounters.shadowTableBuilds;
    c.shadowTableReuses = mCounters.shadowTableReuses;
    c.shadowLights = mCounters.sceneShadowLights;
    c.shadowLightsDropped = mCounters.sceneShadowLightsOverMax + mCounters.sceneShadowLightsOverBudget;
    c.declared = mCounters.declared;
    c.needed = mCounters.needed;
    c.simulated = mCounters.simulated;
    c.drawn = 0;
    for (const Entry& e : mEntries) c.drawn += e.status.splatsDrawn > 0 || e.status.tetrahedraDrawn > 0 ? 1 : 0;
    return {};
}

} // namespace splatfx
