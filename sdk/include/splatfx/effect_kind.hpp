// splatfx/effect_kind.hpp: the one interface a Scene schedules effects by,
// and the extension point for new kinds of effect.
//
// An EffectKind is anything that occupies a world box over time, can say
// whether it has material now, can be brought to a time t, and can emit
// splats into a frame. Scene (scene.hpp) decides per frame which kinds are
// needed (enabled, in range, in view by bounds(), alive()) and calls
// advanceTo() and emit() on exactly those; it knows nothing else about them.
// The kinds the SDK ships are all behind `Effect` (effect.hpp): the
// stateless grid effect (base grid + Motion + growth + texture dynamics,
// King et al. 1999 sec. 3.1-3.3, evaluated at t directly), the stateful
// solver effect (FluidSolver + emitters + texture propagation, stepped, and
// caught up in bounded coarse steps after a gap), the procedural gas (Ebert &
// Parent's turbulent densities sampled at t) and the sequence effect (a baked
// simulation played back, e.g. imported from OpenVDB).
// It does not own materials, sort or render (the Frame and the renderer do).
//
// How to add a kind (a cloud volume, a procedural gas):
//   1. derive from EffectKind and implement the six functions below. bounds()
//      must be conservative (every splat emit() can produce over [t0, t1],
//      splat extent included), or the Scene culls material that is visible;
//   2. a stateless kind evaluates advanceTo(t) directly; a stateful one steps
//      from time() to t, and when AdvanceContext::resumed is set it catches up
//      in at most AdvanceContext::maxCatchUpSteps steps (bounded cost) and
//      reports it in AdvanceResult::caughtUp;
//   3. add it with Scene::add(std::make_unique<MyKind>(...), options). Scene,
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

#include "splatfx/materials.hpp"
#include "splatfx/motion.hpp"
#include "splatfx/splats.hpp"

namespace splatfx {

// How one emit() is drawn; Scene combines the caller's with EffectOptions::draw.
struct EmitOptions {
    bool textured = true;      // false: traditional splats for every layer (Fig. 1a); default true
    float opacityScale = 1.0f; // multiplies each layer's style.opacityScale; default 1
};

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

class EffectKind {
public:
    virtual ~EffectKind() = default;

    // Conservative world box of every splat emit() can produce at any time in
    // [t0, t1] (seconds; either order). Empty when the kind draws nothing.
    virtual Aabb bounds(double t0, double t1) const = 0;
    // Whether material is present at timeSec (so advancing and drawing can matter).
    // Called only for kinds in view; must be cheap and must not advance.
    virtual bool alive(double timeSec, const AliveHints& hints) const = 0;
    // Brings the kind to timeSec (>= time() for stateful kinds; stateless
    // kinds accept any finite t >= 0).
    virtual AdvanceResult advanceTo(double timeSec, const AdvanceContext& context) = 0;
    // Adds the splats of the kind's current state to the builder (after
    // builder.begin). Returns the number of splats added.
    virtual std::size_t emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) const = 0;
    // The time the kind's state is at, in seconds.
    virtual double time() const = 0;
    // Cells or voxels one advance evaluates: the size budget a loader (scene
    // files) checks against kMaxVoxels.
    virtual std::uint64_t costCells() const = 0;

protected:
    EffectKind() = default;
    EffectKind(const EffectKind&) = default;
    EffectKind& operator=(const EffectKind&) = default;
    EffectKind(EffectKind&&) = default;
    EffectKind& operator=(EffectKind&&) = default;
};

} // namespace splatfx
