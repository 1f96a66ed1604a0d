// splatfx/scene.hpp: many effects, and only the ones the camera needs get work.
//
// A Scene holds the effects a level declares and, every frame, decides which
// are needed now: enabled, within range of the camera, alive (emitting, or
// with material left), and inside the view frustum by conservative bounds
// that include their motion and the extent of their splats. Only those are
// simulated and drawn. It sees every effect through EffectKind
// (effect_kind.hpp: bounds, alive, advanceTo, emit), so new kinds are added
// with add(std::unique_ptr<EffectKind>) and no change here. An effect that
// was skipped comes back exactly as it would have been: stateless effects
// are evaluated at the current time directly, solver effects catch up over
// the skipped interval in at most `maxCatchUpSteps` coarse steps (bounded
// cost; its error against full simulation is measured in docs/BENCHMARKS.md).
// It also holds lights (addLight) and lights the effects that opt in
// (EffectOptions::lighting): their splat colours follow Ebert & Parent's
// low-albedo model with self-shadowing, and prepare() puts the gas's shadow
// on the scene into Frame::shadow() (docs/lighting.md, "In a Scene").
// It does not render, load files, or own GL resources.
//
//   splatfx::Scene scene;
//   auto id = scene.add(*splatfx::presets::fire(materials), {.name = "campfire", .rangeWorld = 80});
//   scene.prepare(timeSec, camera, materials, frame);   // per frame: decide, simulate, emit, sort
//   frameRenderer->render(frame, hostTarget);            // gl/frame_renderer.hpp
//
// prepare() is update() + emit() into a Frame + the sort; the two halves stay
// public for hosts that feed their own SplatBuilder. LOD volumes (clouds,
// volume.hpp) are a second list (addVolume): prepare() refines those in view
// into the Frame's volumes.
//
// Threading: one thread at a time.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/effect.hpp"
#include "splatfx/effect_kind.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/frame.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/splats.hpp"
#include "splatfx/volume.hpp"

namespace splatfx {

using EffectId = std::uint32_t;

// ---- lighting (issue 16; docs/lighting.md, "In a Scene")
enum class SelfShadow {
    Off,    // every voxel sees the lights unattenuated
    Traced, // each splat traces to each light through the effect's field (the reference)
    Table,  // each light's shadow table of the effect (Ebert & Parent 1990), rebuilt only on change
};

// How an effect is lit by the scene's lights. Off by default: an unlit
// effect draws its colour tables' colours and costs nothing more.
// A lit effect's splats get colour = table colour * lightPoints(...) factor
// at each splat's centre (per splat, on the CPU; the GL pass is unchanged).
// Only effects added as an Effect are lit (other kinds stay unlit).
struct EffectLighting {
    bool enabled = false; // default false (unlit)
    // Albedo, phase lobes, emission, ambient, multipleScattering; its
    // colorTable is ignored (each layer's own table is the base colour).
    GasLightingDesc gas{};                     // default GasLightingDesc{} (albedo 0.5, isotropic)
    SelfShadow selfShadow = SelfShadow::Table; // default Table
    glm::ivec3 tableDims{32};                  // self-shadowing table entries per axis, each in [1, 1024]; default 32^3
    // Whether the effect's gas is in the frame's shadow on the scene
    // (FrameShadow, Scene::setSceneShadow). Default true.
    bool castsShadow = true;
};

// The shadow the lit effects cast on the scene: one table for one light over
// every needed, lit, shadow-casting effect, put into Frame::shadow(). When
// exactly one effect casts and its self-shadowing table for that light has
// these dims, that table is used (no second build).
struct SceneShadowDesc {
    bool enabled = true;                           // default true (when a light exists)
    std::size_t light = 0;                         // index into Scene::lights(); default 0 (the first)
    glm::ivec3 dims{64};                           // entries per axis, each in [1, 1024]; default 64^3
    std::uint64_t memoryBudgetBytes = 64ull << 20; // as ShadowTableDesc; default 64 MiB
};

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
    // How the effect is drawn (textured or traditional, opacity scale);
    // combined with the options given to prepare()/emit(). Default EmitOptions{}.
    EmitOptions draw{};
    EffectLighting lighting{}; // lighting (issue 16); default unlit
};

// Why an effect was or was not needed at the last update, and what it cost.
struct EffectStatus {
    bool enabled = true;
    bool inRange = false;
    bool inView = false;             // in range and inside the frustum
    bool alive = false;              // in view and with material present (only tested when in view)
    bool needed = false;             // enabled && inRange && inView && alive
    std::uint64_t framesNeeded = 0;  // updates where it was needed
    std::uint64_t framesSkipped = 0; // updates where it was not (no work done)
    std::uint64_t catchUps = 0;      // returns of a stateful kind after being skipped (AdvanceResult::caughtUp)
    std::uint64_t splatsDrawn = 0;   // splats emitted at the last emit()
    Aabb bounds;                     // world bounds used for the last decision
    // ---- lighting (issue 16)
    bool lit = false;                    // lit at the last emit()
    std::uint64_t shadowTableBuilds = 0; // self-shadowing tables built (cumulative)
    std::uint64_t shadowTableReuses = 0; // ... and reused unchanged (cumulative)
};

struct SceneCounters {
    std::size_t declared = 0;  // effects in the scene
    std::size_t needed = 0;    // needed at the last update (= simulated and drawn)
    std::size_t simulated = 0; // effects that did dynamics work at the last update
    std::uint64_t splats = 0;  // splats emitted at the last emit()
    // ---- lighting (issue 16)
    std::size_t litEffects = 0;          // effects lit at the last emit()
    std::uint64_t shadowTableBuilds = 0; // self-shadowing and scene-shadow tables built at the last emit()
    std::uint64_t shadowTableReuses = 0; // ... reused unchanged at the last emit()
    std::uint64_t sceneShadowBuilds = 0; // scene-shadow table builds (cumulative)
};

// ---- [clouds, issue 17] LOD volumes, drawn as projected tetrahedra ----
using VolumeId = std::uint32_t;
struct VolumeOptions {
    std::string name;       // for messages; default empty
    bool enabled = true;    // default true
    LodRefineDesc refine{}; // per-frame refinement (c, morphing, culling); default LodRefineDesc{}
    // Ground fog only: prepare() keeps the frame's terrain triangles
    // (groundFogTerrain), so a host draws its terrain from the same LOD mesh
    // without refining it twice. Default false.
    bool keepTerrain = false;
};
// ---- end [clouds] ----

class Scene {
public:
    // An Effect (grid or solver); effect(id) returns it.
    EffectId add(Effect effect, EffectOptions options = {});
    // Any other kind (effect_kind.hpp). Expects kind != nullptr.
    EffectId add(std::unique_ptr<EffectKind> kind, EffectOptions options = {});
    std::size_t size() const { return mEntries.size(); }
    // Every entry through the interface the Scene schedules by.
    EffectKind& kind(EffectId id) { return *mEntries.at(id).kind; }
    const EffectKind& kind(EffectId id) const { return *mEntries.at(id).kind; }
    // The Effect of an entry added as an Effect; nullptr for other kinds.
    Effect* findEffect(EffectId id) { return mEntries.at(id).effect; }
    const Effect* findEffect(EffectId id) const { return mEntries.at(id).effect; }
    // Expects an entry added as an Effect (asserts otherwise; use findEffect
    // or kind for other kinds).
    Effect& effect(EffectId id);
    const Effect& effect(EffectId id) const;
    const EffectOptions& options(EffectId id) const { return mEntries.at(id).options; }
    void setEnabled(EffectId id, bool enabled) { mEntries.at(id).options.enabled = enabled; }

    // Decides what is needed for this camera at timeSec (non-decreasing
    // across calls) and brings exactly those effects to timeSec.
    void update(double timeSec, const Camera& camera);
    // Adds the splats of the effects the last update() found needed, each
    // drawn with its EffectOptions::draw combined with `options` (textured
    // only if both are; opacity scales multiply).
    std::size_t emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options = {});
    // One frame: update(timeSec, camera), then frame.begin, emit into it,
    // frame.end (one back-to-front sort), and the frame's counters.
    void prepare(double timeSec, const Camera& camera, const Materials& materials, Frame& frame, const EmitOptions& options = {});

    // ---- lighting (issue 16; docs/lighting.md, "In a Scene")
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
    // The last lighting failure (a bad EffectLighting or SceneShadowDesc: the
    // effect is drawn unlit, or no scene shadow); empty when the last emit() had none.
    const std::string& lightingError() const { return mLightingError; }
    // --- Fog (issue 14) ---------------------------------------------------
    // The scene's fog, handed to every Frame prepare() fills (Frame::setFog).
    // A Fog is a pure function of time: it costs nothing while out of view.
    void setFog(Fog fog) { mFog = std::make_shared<const Fog>(std::move(fog)); }
    void clearFog() { mFog.reset(); }
    const Fog* fog() const { return mFog.get(); }
    // --- end fog -----------------------------------------------------------

    const EffectStatus& status(EffectId id) const { return mEntries.at(id).status; }
    const SceneCounters& counters() const { return mCounters; }
    double time() const { return mTime; }

    // True when any part of the box may be inside the camera's frustum
    // (conservative: boxes near a frustum corner may pass).
    static bool inFrustum(const Aabb& box, const Camera& camera);

    // ---- [clouds, issue 17] LOD volumes ----
    // A volume with the transfer function its zero-opacity test uses and the
    // table it is drawn with. prepare() refines every enabled volume whose box
    // is in view (LodVolume::update) and adds its tetrahedra to the Frame.
    VolumeId addVolume(LodVolume volume, TransferFunction transfer, PreIntegrationTable table, VolumeOptions options = {});
    std::size_t volumeCount() const { return mVolumes.size(); }
    LodVolume& volume(VolumeId id) { return mVolumes.at(id)->volume; }
    VolumeOptions& volumeOptions(VolumeId id) { return mVolumes.at(id)->options; }
    // Replaces the transfer function and table (the GL pass re-uploads it).
    void setVolumeTransfer(VolumeId id, TransferFunction transfer, PreIntegrationTable table);
    // ---- end [clouds] ----
    // ---- (issue 17) Ground fog (prisms over a terrain, volume.hpp GroundFog) ----
    // prepare() emits every enabled layer (GroundFog::update: back to front,
    // near-clipped) as one more Frame volume, drawn by the same pass as the
    // clouds; options.refine is the LOD refinement (detailC, morph, clipNear) of a layer made with GroundFogDesc::lod.
    VolumeId addGroundFog(GroundFog fog, TransferFunction transfer, PreIntegrationTable table, VolumeOptions options = {});
    std::size_t groundFogCount() const { return mGroundFogs.size(); }
    VolumeOptions& groundFogOptions(VolumeId id) { return mGroundFogs.at(id)->options; }
    // The layer itself (e.g. for its LOD terrain: GroundFog::update's terrainTriangles).
    const GroundFog& groundFog(VolumeId id) const { return mGroundFogs.at(id)->fog; }
    // The terrain the last prepare() refined for a layer with options.keepTerrain
    // (GroundFog::update's terrainTriangles); empty otherwise, and when the layer is
    // disabled or its update failed.
    const std::vector<glm::vec3>& groundFogTerrain(VolumeId id) const { return mGroundFogs.at(id)->terrain; }
    // ---- end ----

private:
    // ---- lighting (issue 16): what a lit effect keeps between frames (scene_lighting.cpp).
    struct LitState {
        Grid densityGrid;                       // the layers' voxels, opacity as the splats draw it (scratch)
        DensityField field;                     // what the light sees; its fingerprint says when it changed
        ShadowTables tables;                    // self-shadowing, one per light
        glm::ivec3 tableDims{0};                // what `tables` was made with
        std::vector<glm::vec3> points, factors; // scratch: splat centres and their light factors
    };
    struct Entry {
        std::unique_ptr<EffectKind> kind; // never null
        Effect* effect = nullptr;         // kind as an Effect, if it was added as one
        EffectOptions options;
        EffectStatus status;
        std::unique_ptr<LitState> lit; // lighting (issue 16): made when first lit
    };
    EffectId push(Entry entry);
    // lighting (issue 16): lights the splats [first, end) the entry just emitted.
    void lightEmitted(Entry& e, SplatBuilder& builder, const Materials& materials, std::size_t first, const EmitOptions& draw);
    void shadeScene(Frame& frame); // fills frame.shadow()

    std::vector<Entry> mEntries;
    // [clouds] Boxed so the table addresses the Frame points at stay put.
    struct VolumeEntry {
        LodVolume volume;
        TransferFunction transfer;
        PreIntegrationTable table;
        std::uint64_t tableVersion = 1;
        VolumeOptions options;
    };
    std::vector<std::unique_ptr<VolumeEntry>> mVolumes;
    struct GroundFogEntry {
        GroundFog fog;
        TransferFunction transfer;
        PreIntegrationTable table;
        VolumeOptions options;
        std::vector<glm::vec3> terrain; // options.keepTerrain
    };
    std::vector<std::unique_ptr<GroundFogEntry>> mGroundFogs;
    void prepareVolumes(const Camera& camera, Frame& frame); // [clouds]
    SceneCounters mCounters;
    double mTime = 0.0;
    bool mUpdated = false;
    // ---- lighting (issue 16)
    std::vector<Light> mLights;
    SceneShadowDesc mSceneShadowDesc;
    ShadowTable mSceneShadow;
    ShadowTableDesc mSceneShadowTableDesc; // what mSceneShadow was made with
    std::uint64_t mSceneShadowVersion = 0; // bumped whenever the scene shadow's contents change
    std::uint64_t mSceneShadowLastBuilds = 0;
    const ShadowTable* mSceneShadowSource = nullptr; // mSceneShadow, or a lit effect's own table it shares
    std::string mLightingError;
    std::shared_ptr<const Fog> mFog; // issue 14; default none
};

} // namespace splatfx
