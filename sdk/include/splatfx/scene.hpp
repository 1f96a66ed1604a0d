// splatfx/scene.hpp: the effects a level declares, and only the ones the
// camera needs get work.
//
// A Scene holds effects of every kind in one list, behind one interface
// (EffectKind, effect_kind.hpp): splat effects (Effect: grid, solver,
// procedural gas, played-back sequence), LOD volumes (clouds) and ground fog
// layers (volume.hpp), and any kind a host adds. Every effect has one
// EffectId, one EffectOptions and one EffectStatus. Every frame the Scene
// decides which effects are needed now: enabled, within range of the camera,
// inside the view frustum by their conservative world bounds (motion and
// splat extent included), and alive (emitting, or with material left). Only
// those are advanced and emitted into the Frame: splats into its builder,
// tetrahedra into its volumes. A skipped effect comes back exactly as it
// would have been: stateless kinds are evaluated at the current time
// directly, solver effects catch up over the skipped interval in at most
// `maxCatchUpSteps` coarse steps (bounded cost; its error against full
// simulation is measured in docs/BENCHMARKS.md).
// It also holds lights (addLight) and lights the effects that opt in
// (EffectOptions::lighting) and whose kind exposes the density the light sees
// (EffectKind::lightingDensity: every Effect does; LOD volumes and ground fog
// do not, their light is part of their data; a Cloud, cloud.hpp, and a ground
// fog layer, GroundFog::setLighting, follow the scene's first directional light
// (a low-albedo Cloud its point and spot lights too) and are relit when it moves, both also
// shadowed by the other lit clouds, effects and layers (a cloud relit only under the casters
// that changed), the fog casting like a cloud (GroundFogCaster,
// its exact optical depth): their splat colours follow Ebert & Parent's low-albedo model with
// self-shadowing, the light also attenuated through every other lit,
// shadow-casting volume between them and it (a cloud's shadow on a plume, a
// plume's on another effect: every effect's field is updated before any is
// lit; only casters whose box can shadow the receiver's for that light are
// traced, shadowFallsOn), and prepare() puts their shadows on the scene, one per
// shadowing light, into Frame::shadows() (docs/lighting.md, "In a Scene"). And the scene's fog
// (setFog), handed to every Frame without the terms the view cannot see
// (FogCullDesc). Shadows are scheduled by light influence, not visibility: a
// lit caster out of view whose shadow can fall into the view
// (shadowReachesView) is advanced and put into the scene shadow, not drawn
// (EffectStatus::castsIntoView); a light that cannot reach an effect builds
// no table for it (lightReaches).
// It does not render, load files, or own GL resources. Its frustum test is
// per effect; a LOD volume's refinement culls its own nodes inside
// (LodRefineDesc::frustumCull).
//
//   splatfx::Scene scene;
//   auto id = scene.add(*splatfx::presets::fire(materials), {.name = "campfire", .rangeWorld = 80});
//   scene.prepare(timeSec, camera, materials, frame);   // per frame: decide, simulate, emit, sort
//
// prepare() is update() + emit() into a Frame + the sort; the two halves stay
// public for hosts that feed their own SplatBuilder (emit() then adds splats
// only: kinds drawn as tetrahedra need a Frame). gl::FrameRenderer
// (gl/frame_renderer.hpp) draws the Frame.
//
// Threading: one thread at a time.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "splatfx/budget.hpp"
#include "splatfx/camera.hpp"
#include "splatfx/effect.hpp"
#include "splatfx/effect_kind.hpp"
#include "splatfx/emitted_light.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/frame.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/splats.hpp"
#include "splatfx/volume.hpp"

namespace splatfx {

class Cloud; // cloud.hpp

// One id space for every effect a Scene holds, of any kind: ids are 0, 1, ...
// in the order of add().
using EffectId = std::uint32_t;

// How a lit effect shadows itself (docs/lighting.md, "In a Scene").
enum class SelfShadow {
    Off,    // every voxel sees the lights unattenuated
    Traced, // each splat traces to each light through the effect's field (the reference)
    Table,  // each light's shadow table of the effect (Ebert & Parent 1990), rebuilt only on change
};

// How an effect is lit by the scene's lights. Off by default: an unlit
// effect draws its colour tables' colours and costs nothing more.
// A lit effect's splats get colour = table colour * lightPoints(...) factor
// at each splat's centre (per splat, on the CPU; the GL pass is unchanged),
// also in a scene with no light (emission and ambient alone).
// Only kinds that expose the density the light sees are lit
// (EffectKind::lightingDensity: every Effect); the others stay unlit.
struct EffectLighting {
    bool enabled = false; // default false (unlit)
    // Albedo, phase lobes, emission, ambient, multipleScattering; its
    // colorTable is ignored (each layer's own table is the base colour).
    GasLightingDesc gas{};                     // default GasLightingDesc{} (albedo 0.5, isotropic)
    SelfShadow selfShadow = SelfShadow::Table; // default Table
    glm::ivec3 tableDims{32};                  // self-shadowing table entries per axis, each in [1, 1024]; default 32^3
    // Whether the effect's gas is in the frame's shadow on the scene
    // (FrameShadow, Scene::setSceneShadow) and shadows the other lit
    // effects' splats (and lit ground fog layers). For a lit Cloud and a lit
    // ground fog layer: the same, with their extinction. Default true.
    bool castsShadow = true;
};

// The shadow the lit effects cast on the scene: per shadowing light, one
// table over every needed, lit, shadow-casting effect that light reaches,
// put into Frame::shadows() (docs/lighting.md, "Every light casts"). Slot 0
// is `light`'s; the other slots go to the most influential of the other
// lights (the largest sum over its casters of the light's irradiance at the
// caster's box), at most maxLights in all. A light that reaches no caster
// builds nothing. Each light's table is rebuilt only when its casters'
// density or that light changes. When exactly one effect casts and its
// self-shadowing table for a light has these dims, that table is used (no
// second build). Tables that would not fit memoryBudgetBytes (or what
// Budgets::lightingBytes leaves) are not built, least influential first,
// and counted (SceneCounters::sceneShadowLightsOverBudget,
// FrameCounters::shadowLightsDropped); slot 0's is always tried.
struct SceneShadowDesc {
    bool enabled = true;                           // default true (when a light exists)
    std::size_t light = 0;                         // index into Scene::lights(): slot 0, splatfx_shadow(); default 0 (the first)
    int maxLights = kMaxShadowLights;              // lights with a table at once, [1, kMaxShadowLights]; default kMaxShadowLights (4)
    glm::ivec3 dims{64};                           // entries per axis of each table, each in [1, 1024]; default 64^3
    std::uint64_t memoryBudgetBytes = 64ull << 20; // every table together, ShadowTable::memoryBytes each; default 64 MiB
};

// Which of the scene's fog terms a frame draws (docs/fog.md, "Terms out of
// view"). Terms whose optical depth along every view ray is provably small
// (Fog::termDepthBound over the view frustum's box) are dropped, smallest
// first, while the dropped bounds sum to at most maxSkippedDepth; so no
// pixel's fog transmittance, hence no fogged colour channel in [0, 1], moves
// by more than 1 - exp(-maxSkippedDepth) <= maxSkippedDepth. With every term
// dropped (and no far cut-off within the view) the frame has no fog and the
// fog pass is skipped.
struct FogCullDesc {
    bool enabled = true; // default true
    // >= 0, optical depth (natural log units); default 1/512: under half an 8-bit level.
    double maxSkippedDepth = 1.0 / 512.0;
};

// How the Scene treats one effect. Every field applies to every kind; a
// field a kind has no use for (catch-up for a stateless kind, refine for a
// splat effect) is ignored by it.
struct EffectOptions {
    std::string name;                                          // for counters and messages; default empty
    float rangeWorld = std::numeric_limits<float>::infinity(); // skipped beyond this distance from its bounds; default no limit
    bool enabled = true;                                       // default true
    // Passed to the kind's advanceTo (AdvanceContext): solver effects
    // returning after dt unseen seconds catch up in
    // n = min(ceil(dt / catchUpStepSec), maxCatchUpSteps) steps of dt / n.
    double catchUpStepSec = 1.0 / 30.0; // default 1/30 s
    int maxCatchUpSteps = 8;            // default 8
    // Passed to the kind's alive (AliveHints): a solver effect whose emitters
    // are all off and whose total density is below this is dead: not
    // simulated, not drawn.
    double deadDensity = 1e-4; // default 1e-4
    // How splats are drawn (textured or traditional, opacity scale);
    // combined with the options given to prepare()/emit(). Default EmitOptions{}.
    EmitOptions draw{};
    EffectLighting lighting{}; // default unlit
    // An emissive effect as light for the host's surfaces: point lights
    // fitted to its splats each frame into Frame::emittedLights()
    // (emitted_light.hpp). Out of view it is still advanced (not drawn) while
    // its bounds grown by reachWorld touch the view. Default off.
    EmittedLightDesc emitsLight{};
    // LOD volumes and ground fog: the per-frame refinement (c, morphing,
    // per-node frustum culling, near clipping). Default LodRefineDesc{}.
    LodRefineDesc refine{};
    // Ground fog: prepare() keeps the terrain triangles its refinement stands
    // on (groundFogTerrain), so a host draws its terrain from the same LOD
    // mesh without refining it twice. Default false.
    bool keepTerrain = false;
};

// Why an effect was or was not needed at the last update, and what it cost.
struct EffectStatus {
    bool enabled = true;
    bool inRange = false;
    bool inView = false;                 // in range and inside the frustum
    bool alive = false;                  // with material present (only tested when in view, or out of view but casting into it)
    bool needed = false;                 // enabled && inRange && inView && alive
    // Not needed (out of view), but lit, shadow-casting, in range and alive,
    // and its shadow away from one of the lights can reach the view
    // of any light (Scene::shadowReachesView): advanced to the time, put into the scene
    // shadow and traced for the lit effects' splats, not emitted (docs/lighting.md,
    // "Scheduled by light influence").
    bool castsIntoView = false;
    // Not needed (out of view), but emitting light (EffectOptions::emitsLight)
    // whose reach touches the view: advanced and its lights fitted, not drawn.
    bool lightsIntoView = false;
    std::size_t emittedLights = 0;       // point lights it gave the last prepare()
    bool inSceneShadow = false;          // its density was in one of the frame's scene shadows at the last prepare()
    std::uint64_t framesNeeded = 0;      // updates where it was needed
    std::uint64_t framesCastOnly = 0;    // updates where it was advanced only to cast into the view (castsIntoView)
    std::uint64_t framesSkipped = 0;     // updates where it was neither (no work done)
    std::uint64_t catchUps = 0;          // returns of a stateful kind after being skipped (AdvanceResult::caughtUp)
    std::uint64_t splatsDrawn = 0;       // splats emitted at the last emit()
    std::uint64_t tetrahedraDrawn = 0;   // tetrahedra emitted at the last prepare() (emit() takes none)
    Aabb bounds;                         // world bounds used for the last decision
    bool lit = false;                    // lit at the last emit()
    std::uint64_t shadowTableBuilds = 0; // self-shadowing tables built (cumulative)
    std::uint64_t shadowTableReuses = 0; // ... and reused unchanged (cumulative)
    std::uint64_t shadowTableSkips = 0;  // self-shadowing tables not updated: the light cannot reach the effect (cumulative)
};

// Every count covers effects of every kind.
struct SceneCounters {
    std::size_t declared = 0;            // effects in the scene
    std::size_t needed = 0;              // needed at the last update (= advanced and emitted)
    std::size_t simulated = 0;           // effects advanced to the time at the last update (needed + castOnly)
    std::size_t castOnly = 0;            // of those, advanced only to cast into the view (EffectStatus::castsIntoView)
    std::size_t castersCulled = 0;       // lit casters out of view whose shadow cannot reach it: not advanced
    std::uint64_t splats = 0;            // splats emitted at the last emit()
    std::uint64_t tetrahedra = 0;        // tetrahedra emitted at the last prepare()
    std::size_t litEffects = 0;          // effects lit at the last emit()
    std::uint64_t shadowTableBuilds = 0; // self-shadowing and scene-shadow tables built at the last emit()
    std::uint64_t shadowTableReuses = 0; // ... reused unchanged at the last emit()
    std::uint64_t sceneShadowBuilds = 0; // scene-shadow table builds (cumulative)
    std::size_t sceneShadowCasters = 0;  // effects in a scene shadow at the last prepare()
    // Scene shadows at the last prepare(): lights with a table, and lights
    // that reach a caster but got none: past SceneShadowDesc::maxLights, or
    // over SceneShadowDesc::memoryBudgetBytes or Budgets::lightingBytes (the
    // least influential dropped first; never slot 0's light).
    std::size_t sceneShadowLights = 0;
    std::size_t sceneShadowLightsOverMax = 0;
    std::size_t sceneShadowLightsOverBudget = 0;
    // Self-shadowing tables not updated at the last emit() because their
    // light cannot reach the effect (a spot light's cone misses its bounds).
    std::uint64_t shadowTableSkips = 0;
    // The scene's fog at the last prepare() (FogCullDesc): terms drawn and
    // dropped, and whether the frame got no fog at all because none is in view.
    std::size_t fogTermsDrawn = 0;
    std::size_t fogTermsSkipped = 0;
    bool fogSkipped = false;
    // Emitted lights (EffectOptions::emitsLight) at the last prepare(): fitted,
    // and the dimmest dropped past kMaxEmittedLights (the frame keeps the brightest).
    std::size_t emittedLights = 0;
    std::size_t emittedLightsDropped = 0;
    // Frames whose dropped terms left a fog that failed validation (a dropped
    // term held the rest non-negative): the full fog was drawn (cumulative).
    std::uint64_t fogCullFallbacks = 0;
    // Volumes shadowing the lit effects at the last emit(): (caster, light)
    // pairs traced for a receiving effect's splats, and pairs skipped because
    // the caster's box cannot shadow the receiver's for that light (shadowFallsOn).
    std::size_t crossShadowPairs = 0;
    std::size_t crossShadowPairsSkipped = 0;
    // Lit clouds at the last emit(): scene lights (other than the sun) that
    // reach a cloud's box but do not light it: any for the Roettger model, or
    // past kMaxCloudLights (lights of any colour are taken: cloud.hpp). Summed over clouds.
    std::size_t cloudLightsDropped = 0;
};

class Scene {
public:
    // ---- Effects: one list, one id space -----------------------------------
    // An Effect (grid, solver, procedural gas, sequence), drawn as splats.
    EffectId add(Effect effect, EffectOptions options = {});
    // A LOD volume (clouds) with the transfer function its zero-opacity test
    // uses and the table it is drawn with, refined by options.refine.
    EffectId add(LodVolume volume, TransferFunction transfer, PreIntegrationTable table, EffectOptions options = {});
    // A ground fog layer with its transfer function and table, refined by
    // options.refine (a layer made with GroundFogDesc::lod). With
    // options.lighting.enabled it is lit (GroundFog::setLighting: the first
    // directional light, options.lighting.gas, the transfer's colour and
    // extinction) and drawn with its lit table, emitted after the other effects.
    EffectId add(GroundFog fog, TransferFunction transfer, PreIntegrationTable table, EffectOptions options = {});
    // A relightable cloud (cloud.hpp). With options.lighting.enabled it
    // follows the scene's first directional light (and, in the low-albedo
    // model, options.lighting.gas and the scene's other lights that reach it,
    // up to kMaxCloudLights of any colour; SceneCounters::cloudLightsDropped
    // counts the rest), and is shadowed by the frame's other lit,
    // shadow-casting volumes (Cloud::setLight's casters); relit only when
    // those change, under a changed caster only where its shadow falls.
    EffectId add(Cloud cloud, EffectOptions options = {});
    // Any other kind (effect_kind.hpp). Expects kind != nullptr.
    EffectId add(std::unique_ptr<EffectKind> kind, EffectOptions options = {});
    // Effects of every kind; ids are [0, size()).
    std::size_t size() const { return mEntries.size(); }

    // Every effect through the interface the Scene schedules by.
    EffectKind& kind(EffectId id) { return *mEntries.at(id).kind; }
    const EffectKind& kind(EffectId id) const { return *mEntries.at(id).kind; }
    // The effect as its concrete kind; nullptr when it is of another kind.
    Effect* findEffect(EffectId id);
    const Effect* findEffect(EffectId id) const;
    LodVolume* findLodVolume(EffectId id);
    const LodVolume* findLodVolume(EffectId id) const;
    const GroundFog* findGroundFog(EffectId id) const;
    Cloud* findCloud(EffectId id);
    const Cloud* findCloud(EffectId id) const;
    // Expects an Effect (asserts otherwise; use findEffect for any kind).
    Effect& effect(EffectId id);
    const Effect& effect(EffectId id) const;

    // Options take effect at the next update() / prepare().
    const EffectOptions& options(EffectId id) const { return mEntries.at(id).options; }
    EffectOptions& options(EffectId id) { return mEntries.at(id).options; }
    void setEnabled(EffectId id, bool enabled) { mEntries.at(id).options.enabled = enabled; }
    // Replaces the transfer function and table of a LOD volume or ground fog
    // layer (the GL pass re-uploads it). Expects one of those kinds (asserts otherwise).
    void setTransfer(EffectId id, TransferFunction transfer, PreIntegrationTable table);
    // The terrain the last prepare() refined for a ground fog layer with
    // options.keepTerrain (GroundFog::update's terrainTriangles). Empty
    // otherwise: for other kinds, and when the layer was not needed (disabled,
    // out of range or out of view: then no part of its terrain is in view
    // either) or its update failed.
    const std::vector<glm::vec3>& groundFogTerrain(EffectId id) const;

    const EffectStatus& status(EffectId id) const { return mEntries.at(id).status; }
    const SceneCounters& counters() const { return mCounters; }
    double time() const { return mTime; }

    // ---- Frames ------------------------------------------------------------
    // Decides what is needed for this camera at timeSec (non-decreasing
    // across calls) and brings exactly those effects to timeSec. Fails,
    // changing nothing, unless timeSec is in [0, kMaxTimeSec] (effect_kind.hpp).
    Status update(double timeSec, const Camera& camera);
    // Adds the splats of the effects the last update() found needed, each
    // drawn with its EffectOptions::draw combined with `options` (textured
    // only if both are; opacity scales multiply). Kinds drawn as tetrahedra
    // add nothing here (they need a Frame: prepare()).
    std::size_t emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options = {});
    // One frame: update(timeSec, camera), then frame.begin, every needed
    // effect emitted into it in id order (splats, tetrahedra), the lit
    // effects' shadow, frame.end (one back-to-front sort), the fog, and the
    // frame's counters. Fails as update(), changing neither the scene nor the frame.
    Status prepare(double timeSec, const Camera& camera, const Materials& materials, Frame& frame, const EmitOptions& options = {});

    // True when any part of the box may be inside the camera's frustum
    // (conservative: boxes near a frustum corner may pass).
    static bool inFrustum(const Aabb& box, const Camera& camera);
    // True when the light may reach some point of the box (conservative).
    // Directional and point lights reach everything (splatfx's lights have
    // no range); a spot light misses a box whose bounding sphere lies
    // outside its outer cone (where its irradiance is exactly 0).
    static bool lightReaches(const Light& light, const Aabb& box);
    // True when the shadow of a caster within `caster`, cast by `light`, may
    // fall inside the camera's frustum (conservative): the caster's box
    // extruded away from the light (along a directional light's travel, away
    // from a point or spot light's position, without end) is tested against
    // the frustum's planes, and a light that cannot reach the box casts no
    // shadow. Used to schedule casters by light influence (docs/lighting.md).
    static bool shadowReachesView(const Aabb& caster, const Light& light, const Camera& camera);
    // True when some ray from a point of `receiver` to the light may cross
    // `caster` (conservative only by a 1e-5 relative margin: the test is
    // exact for boxes): only such casters are traced for a lit effect's splats.
    static bool shadowFallsOn(const Aabb& caster, const Light& light, const Aabb& receiver);

    // ---- Lights (docs/lighting.md, "In a Scene") ---------------------------
    // Adds a light; fails on an invalid light (the message names the field).
    Result<std::size_t> addLight(const Light& light);
    // Replaces light i (expects i < lights().size()); fails as addLight.
    Status setLight(std::size_t i, const Light& light);
    std::span<const Light> lights() const { return mLights; }
    void clearLights() { mLights.clear(); }
    // Per-effect lighting (also settable through EffectOptions::lighting at add()).
    void setLighting(EffectId id, const EffectLighting& lighting) { mEntries.at(id).options.lighting = lighting; }
    void setSceneShadow(const SceneShadowDesc& desc) { mSceneShadowDesc = desc; }
    const SceneShadowDesc& sceneShadow() const { return mSceneShadowDesc; }
    // HDR lit colour (docs/lighting.md, "HDR lit colour"): on, a lit colour
    // brighter than 1 keeps its brightness as a per-splat scale (Splat,
    // splatColor) for a floating-point target (RGBA16F, RGBA32F); off, it is
    // scaled down to 1 keeping its hue, for 8-bit targets. Colours <= 1 are
    // the same either way. Default off.
    void setHdrLit(bool on) { mHdrLit = on; }
    bool hdrLit() const { return mHdrLit; }
    // Builds of light i's scene-shadow table since it was made (0 for a light
    // that never had one, or whose table is a caster's own self-shadowing table).
    std::uint64_t sceneShadowBuilds(std::size_t light) const;
    // The last lighting failure (a bad EffectLighting or SceneShadowDesc, a
    // sceneShadow.light past the lights, a sceneShadow.maxLights outside [1, kMaxShadowLights], the shadow tables over
    // Budgets::lightingBytes: the effect is drawn unlit, or no scene shadow);
    // empty when the last emit() had none. Hosts must show it: the render
    // tool fails the frame, the C API's prepare returns it.
    const std::string& lightingError() const { return mLightingError; }
    // The lights the emissive effects gave at the last prepare() (all of
    // them, brightest first; the Frame keeps the first kMaxEmittedLights).
    std::span<const EmittedLight> emittedLights() const { return mEmittedLights; }
    // The first EmittedLightMode::Grid effect's grid at the last prepare()
    // (dims 0: none); later grid effects' are dropped (emittedLightsDropped).
    const EmittedGrid& emittedGrid() const { return mEmittedGrid; }
    // What the scene may spend; only lightingBytes is read here (every light
    // x every table-lit effect's table, plus slot 0's scene shadow, checked
    // before any table is built; the other lights' scene shadows only use
    // what is left). Default Budgets{}; loadSceneFile sets the
    // file's budgets.
    void setBudgets(const Budgets& budgets) { mBudgets = budgets; }
    const Budgets& budgets() const { return mBudgets; }

    // ---- Fog (docs/fog.md) -------------------------------------------------
    // The scene's fog, handed to every Frame prepare() fills (Frame::setFog).
    // A Fog is a pure function of time: it costs nothing while out of view.
    void setFog(Fog fog) { mFog = std::make_shared<const Fog>(std::move(fog)), mFogView.reset(), mFogKeep.clear(); }
    void clearFog() { mFog.reset(), mFogView.reset(), mFogKeep.clear(); }
    const Fog* fog() const { return mFog.get(); }
    // Which terms each frame draws. Fails on a maxSkippedDepth that is
    // negative or not finite (the message names it), keeping the previous desc.
    Status setFogCulling(const FogCullDesc& desc);
    const FogCullDesc& fogCulling() const { return mFogCull; }

private:
    // What a lit effect keeps between frames (scene_lighting.cpp).
    struct LitState {
        Grid densityGrid;                       // the density the light sees (EffectKind::lightingDensity; scratch)
        DensityField field;                     // what the light sees; its fingerprint says when it changed
        ShadowTables tables;                    // self-shadowing, one per light
        glm::ivec3 tableDims{0};                // what `tables` was made with
        std::vector<glm::vec3> points, factors; // scratch: splat centres and their light factors
        std::vector<bool> reaches;              // scratch: which lights reach the effect (Scene::lightReaches)
        bool fieldReady = false;                // `field` is this emit's (updateEffectCasters)
        // A ground fog layer that casts this emit: its GroundFogCaster (the
        // kind's; its extinction stands for the layer), else null.
        const ShadowCaster* fogCaster = nullptr;
    };
    struct Entry {
        std::unique_ptr<EffectKind> kind; // never null; on the heap, so what a Frame points at stays put
        EffectOptions options;
        EffectStatus status;
        std::unique_ptr<LitState> lit; // made when first lit
    };
    EffectId push(std::unique_ptr<EffectKind> kind, EffectOptions options);
    // Emits every needed effect in id order; `volumes` null: splats only.
    std::size_t emitInto(SplatBuilder& builder, std::vector<FrameVolume>* volumes, const Materials& materials, const EmitOptions& options);
    // Lights and emits the needed ground fog layers with lighting enabled,
    // shadowed by this emit's casters (scene_ground_fog.cpp); their tetrahedra.
    std::uint64_t emitLitGroundFogs(SplatBuilder& builder, std::vector<FrameVolume>* volumes, const Materials& materials, const EmitOptions& options);
    // Lights the splats [first, end) the entry just emitted (its field from updateEffectCasters).
    void lightEmitted(Entry& e, SplatBuilder& builder, const Materials& materials, std::size_t first);
    // Refreshes e.lit->field from the kind's lighting density; false when the
    // kind has none or it is bad (then mLightingError says why).
    bool updateLitField(Entry& e, const Materials& materials, const EmitOptions& draw);
    // Before any effect is lit: the field of every effect lit or casting this
    // emit, and the shadow-casting ones appended to mVolumeCasters, so each
    // lit effect is shadowed by all the others (scene_lighting.cpp).
    void updateEffectCasters(const Materials& materials, const EmitOptions& options);
    // Before any volume is lit: every lit, casting ground fog layer needed or
    // casting into the view joins mVolumeCasters (scene_ground_fog.cpp).
    void updateFogCasters();
    // mCastersPerLight: per light, the casters other than e's own field whose
    // box can shadow e's (shadowFallsOn).
    void scheduleCasters(const Entry& e);
    void shadeScene(Frame& frame); // fills frame.shadows()
    // Which lights get a scene-shadow table this frame, slot order (scene_lighting.cpp).
    std::vector<std::size_t> chooseShadowLights(const std::vector<std::vector<const ShadowCaster*>>& casters);
    std::uint64_t requiredLightingBytes() const;
    // Fits e's emitted lights (EffectOptions::emitsLight) into mEmittedLights.
    void fitLights(Entry& e, const Camera& camera, const Materials& materials, const EmitOptions& draw);
    // The shadow tables' bytes against mBudgets.lightingBytes; the error when over.
    Status checkLightingBudget() const;
    // The fog this camera's frame draws: mFog without the terms it cannot see (scene_fog.cpp).
    std::shared_ptr<const Fog> fogForView(const Camera& camera, double timeSec);

    std::vector<Entry> mEntries;
    SceneCounters mCounters;
    double mTime = 0.0;
    bool mUpdated = false;
    std::vector<Light> mLights;
    std::vector<EmittedLight> mEmittedLights;
    EmittedGrid mEmittedGrid;
    std::size_t mEmittedGridsDropped = 0;
    // This emit's shadow-casting lit volumes (clouds' and effects' fields,
    // ground fog layers' GroundFogCasters): each lit volume's light is
    // attenuated through the others'.
    std::vector<const ShadowCaster*> mVolumeCasters;
    std::vector<std::vector<const ShadowCaster*>> mCastersPerLight; // scratch (scheduleCasters)
    std::vector<const ShadowCaster*> mFogCasterScratch;             // scratch: a layer's or a cloud's casters, itself left out (emitLitGroundFogs, emitInto)
    SplatBuilder mLightScratch{SplatBuilderDesc{.frustumCull = false}}; // an emitter's whole splats, fitted, never drawn
    SceneShadowDesc mSceneShadowDesc;
    bool mHdrLit = false;
    // One scene-shadow table per light (index into mLights), kept while the
    // light exists so a light moving does not rebuild another's.
    struct LightShadow {
        ShadowTable table;
        ShadowTableDesc desc; // what `table` was made with
    };
    std::vector<LightShadow> mLightShadows;
    // What each Frame::shadows() slot holds: a light's table or a lit
    // effect's own, and the builds it had when copied.
    struct ShadowSlot {
        const ShadowTable* source = nullptr;
        int light = -1;
        std::uint64_t builds = 0;
        std::uint64_t version = 0; // bumped whenever the slot's contents change
    };
    std::array<ShadowSlot, kMaxShadowLights> mShadowSlots{};
    std::uint64_t mShadowVersions = 0; // the last version handed out (versions are unique across slots)
    std::string mLightingError;
    Budgets mBudgets;
    bool mTablesFit = true; // checkLightingBudget() at the last emit
    std::shared_ptr<const Fog> mFog; // default none
    FogCullDesc mFogCull;
    std::shared_ptr<const Fog> mFogView; // mFog with the terms of mFogKeep (rebuilt when the kept set changes)
    std::vector<bool> mFogKeep;
};

} // namespace splatfx
