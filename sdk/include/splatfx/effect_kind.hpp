// splatfx/effect_kind.hpp: the one interface a Scene holds every effect by,
// and the extension point for new kinds.
//
// An effect kind is anything volumetric a Scene holds: it occupies a world
// box over time, can say whether it has material now, can be brought to a
// time t, emits what it draws into a frame (splats into the frame's
// SplatBuilder, or tetrahedra into the frame's volumes), and may expose the
// density the scene's lights see. Scene (scene.hpp) decides per frame which
// effects are needed (enabled, in range, in view by bounds(), alive()) and
// calls advanceTo() and emit() on exactly those; it knows nothing else about
// them. The SDK ships:
//   - Effect (effect.hpp): grid effects, solver effects, procedural gases and
//     played-back sequences (e.g. OpenVDB), drawn as splats and lit by the
//     scene's lights (lightingDensity);
//   - LOD volumes (volume.hpp, LodVolume: clouds) and ground fog layers
//     (volume.hpp, GroundFog), drawn as projected tetrahedra; they are added
//     with Scene::add(LodVolume, ...) and Scene::add(GroundFog, ...) and are
//     not lit by the scene's lights (their light is part of the volume data).
// It does not own materials, sort or render (the Frame and the renderer do).
//
// How to add a kind:
//   1. derive from EffectKind and implement the six pure functions below.
//      bounds() must be conservative (every primitive emit() can produce over
//      [t0, t1], splat extent included), or the Scene culls what is visible;
//   2. a stateless kind evaluates advanceTo(t) directly; a stateful one steps
//      from time() to t, and when AdvanceContext::resumed is set it catches up
//      in at most AdvanceContext::maxCatchUpSteps steps (bounded cost) and
//      reports it in AdvanceResult::caughtUp;
//   3. to be lit, override lightingDensity();
//   4. add it with Scene::add(std::make_unique<MyKind>(...), options). Scene,
//      Frame and the renderer need no change. (A scene-file kind also needs
//      its reader under sdk/src/scenefile; the loader budgets costCells().)
//
//   class Cube : public splatfx::EffectKind { ... };            // the six functions
//   auto id = scene.add(std::make_unique<Cube>(), {.name = "cube"});
//   scene.prepare(timeSec, camera, materials, frame);            // culled, advanced, emitted
//
// Threading: one thread at a time per object; kinds are independent.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "splatfx/frame.hpp"
#include "splatfx/grid.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/motion.hpp"
#include "splatfx/splats.hpp"
#include "splatfx/volume.hpp"

namespace splatfx {

// How splats are drawn; Scene combines the caller's with EffectOptions::draw.
struct EmitOptions {
    bool textured = true;      // false: traditional splats for every layer (Fig. 1a); default true
    float opacityScale = 1.0f; // multiplies each layer's style.opacityScale; default 1
};

// The latest time, in seconds, at which the effects' dynamics are held
// exactly: 2^18 s, about 72.8 hours. The local dynamics' phase is
// p = t * rate + start in double precision and its fraction is the splat's
// cross-fade weight, a float; the fraction keeps all of a float's 24 bits
// while p < 2^28, i.e. t < 2^18 s at rates up to 1024 a second (scene files
// take at most 1000). Below it the propagation step floor(t * stepsPerSec)
// is an exact integer, and the bob and spin phases (double) err by under
// 1e-6 rad at the rates scene files take. Beyond it the cross-fades coarsen,
// and past 2^63 steps the integer casts overflow: Scene::update and prepare
// refuse such times, and a host restarts its scene clock before them.
inline constexpr double kMaxTimeSec = 262144.0;

// What alive() may use besides the time; filled by the Scene from EffectOptions.
struct AliveHints {
    // A stateful kind with no source on and less total material than this is
    // dead: not advanced, not drawn.
    double deadDensity = 1e-4; // default 1e-4
};

// How advanceTo() may spend its work; filled by the Scene from EffectOptions.
struct AdvanceContext {
    // A stateful kind advancing by a gap dt takes
    // n = min(ceil(dt / catchUpStepSec), maxCatchUpSteps) steps of dt / n
    // (bounded cost after a long gap; the solver is unconditionally stable).
    double catchUpStepSec = 1.0 / 30.0; // default 1/30 s
    int maxCatchUpSteps = 8;            // default 8
    // True when the kind was skipped since it last advanced (the Scene did not
    // need it at its previous update) and has been advanced before.
    bool resumed = false; // default false
};

struct AdvanceResult {
    int steps = 0;         // steps (stateful) or evaluations (stateless) taken; 0 when already at t
    bool caughtUp = false; // a resumed stateful kind covered a skipped interval
};

// Where emit() puts what it draws, and how; filled by the Scene from
// EffectOptions and the caller's options.
struct EmitContext {
    SplatBuilder& splats; // splats go here (after splats.begin); splats.camera() is the frame's camera
    // Tetrahedra go here, one FrameVolume per kind and frame. Null when the
    // caller takes splats only (Scene::emit into a host's builder): kinds
    // drawn as tetrahedra then add nothing.
    std::vector<FrameVolume>* volumes = nullptr;
    const Materials& materials;
    EmitOptions draw{};     // splat kinds: textured, opacity scale
    LodRefineDesc refine{}; // kinds drawn as LOD tetrahedra: the per-frame refinement (c, morphing, culling, clipping)
    // Ground fog: keep the terrain triangles the refinement stands on
    // (Scene::groundFogTerrain), so a host draws its terrain from the same mesh.
    bool keepTerrain = false;
};

struct EmitResult {
    std::size_t splats = 0;     // splats added to EmitContext::splats
    std::size_t tetrahedra = 0; // tetrahedra added to EmitContext::volumes
};

class EffectKind {
public:
    virtual ~EffectKind() = default;

    // Conservative world box of every primitive emit() can produce at any
    // time in [t0, t1] (seconds; either order). Empty when the kind draws nothing.
    virtual Aabb bounds(double t0, double t1) const = 0;
    // Whether material is present at timeSec (so advancing and drawing can matter).
    // Called only for kinds in view; must be cheap and must not advance.
    virtual bool alive(double timeSec, const AliveHints& hints) const = 0;
    // Brings the kind to timeSec (>= time() for stateful kinds; stateless
    // kinds accept any t in [0, kMaxTimeSec]).
    virtual AdvanceResult advanceTo(double timeSec, const AdvanceContext& context) = 0;
    // Adds what the kind draws in its current state for the camera of
    // context.splats. Not const: a view-dependent kind (LOD) keeps per-frame
    // state (morphing) between frames.
    virtual EmitResult emit(const EmitContext& context) = 0;
    // The time the kind's state is at, in seconds.
    virtual double time() const = 0;
    // Cells or voxels one advance evaluates: the size budget a loader (scene
    // files) checks against kMaxVoxels. 0 for kinds whose advance costs nothing.
    virtual std::uint64_t costCells() const = 0;

    // What the scene's lights see of the kind in its current state: fills
    // `out` with its density as emit() draws it with `draw` (voxels whose
    // opacity is the drawn one, the grid's dims, spacing and transform) and
    // returns true. The Scene then colours the splats the kind emitted by the
    // lights (self-shadowed) and lets it cast the frame's shadow
    // (EffectOptions::lighting). Default false: the kind is drawn unlit and
    // casts no shadow.
    virtual bool lightingDensity(const Materials& materials, const EmitOptions& draw, Grid& out) const {
        (void)materials, (void)draw, (void)out;
        return false;
    }

protected:
    EffectKind() = default;
    EffectKind(const EffectKind&) = default;
    EffectKind& operator=(const EffectKind&) = default;
    EffectKind(EffectKind&&) = default;
    EffectKind& operator=(EffectKind&&) = default;
};

} // namespace splatfx
