// splatfx/effect.hpp: one animated effect: a coarse grid (or a solver) with
// its three scales of motion and how it is drawn.
//
// King et al. 1999, sec. 3: an effect moves at three disjoint scales. An
// Effect bundles them:
//   - object dynamics (sec. 3.1): a Motion (keyframes + procedure) and growth
//     applied to a base grid, or a FluidSolver with emitters on moving objects;
//   - global dynamics (sec. 3.2): texture propagation (PropagationDesc);
//   - local dynamics (sec. 3.3): texture cycling (CyclingDesc);
// plus one or more layers, each a SplatStyle over a height band of the
// lattice, so one effect can draw with two texture sets and colour tables
// (fire turning into smoke, sec. 2 step 4: "mixing effects ... with multiple
// color tables and differing texture sets").
//
// An Effect is an EffectKind (effect_kind.hpp), the interface Scene schedules
// by; it is a copyable value that owns one of the SDK's five kinds:
//   - grid effects (fromGrid) are stateless: update(t) computes frame t
//     directly from (voxel, t, seed), in any order, at no cost for skipped
//     frames. step(dt) is update(time() + dt); advanceTo(t) is update(t).
//   - procedural gases (fromProceduralGas) are stateless the same way: the
//     turbulent density is sampled into a fixed lattice at t.
//   - solver effects (fromSolver) are stateful: step(dt) simulates; update()
//     asserts; advanceTo(t) steps to t, catching up after a gap in a bounded
//     number of coarse steps (AdvanceContext).
//   - sequence effects (fromSequence) play a baked simulation (GridSequence,
//     e.g. from OpenVDB files through splatfx/vdb.hpp), interpolated between
//     frames; their texture propagation runs on a fixed clock and is replayed
//     as needed, so update(t) depends on t alone: stateless, at a cost linear
//     in the propagation steps replayed.
//   - particle effects (fromParticles) put splats at particle positions
//     (King et al. sec. 6, particles.hpp): a closed-form emitter evaluated at
//     t (stateless), plus particles a host hands in (setParticles).
// isStateless() tells which; bounds(t0, t1) is a conservative world box of
// every splat the effect can produce in [t0, t1] (motion and splat extent
// included), for culling by a scheduler. Other kinds implement EffectKind
// directly and are added to a Scene without being an Effect.
// It does not sort, render or own GPU resources; it does not read files
// (presets.hpp does, through Materials).
//
//   auto fire = splatfx::presets::fire(materials, {.dims = {7, 20, 5}});
//   fire->update(timeSec);                 // or fire->step(dtSec)
//   fire->emit(builder, materials);        // after builder.begin(camera)
//
// Threading: one thread at a time per effect; effects are independent.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "splatfx/dynamics.hpp"
#include "splatfx/effect_kind.hpp"
#include "splatfx/grid.hpp"
#include "splatfx/grid_sequence.hpp"
#include "splatfx/motion.hpp"
#include "splatfx/particles.hpp"
#include "splatfx/procedural_gas.hpp"
#include "splatfx/result.hpp"
#include "splatfx/solver.hpp"
#include "splatfx/splats.hpp"

namespace splatfx {

// One style over a band of the lattice's normalized height (0 = lowest
// lattice row, 1 = highest). Voxels in [heightFrom, heightTo] are drawn with
// `style`; with blend > 0 the layer fades in/out over `blend` around an inner
// edge, so two layers meeting at h overlap and their weights sum to 1.
struct EffectLayer {
    SplatStyle style{};      // texture set, colour table, textured, crossfade; default SplatStyle{}
    float heightFrom = 0.0f; // [0, 1]; default 0
    float heightTo = 1.0f;   // [heightFrom, 1]; default 1
    float blend = 0.0f;      // normalized height of the fade at inner edges, >= 0; default 0 (hard split)
    bool remapColor = false; // colour coordinate = position within [heightFrom, heightTo]; default false (keep the voxel's)
};

// Each scale of motion can be switched off (the viewer's toggles). Off means
// frozen at its t = 0 state, not removed.
struct DynamicsToggles {
    bool object = true; // sec. 3.1: motion, growth, fades, solver; default on
    bool global = true; // sec. 3.2: texture propagation; default on
    bool local = true;  // sec. 3.3: texture cycling; default on
};

struct EffectDesc {
    std::string name = "effect";       // used in messages; default "effect"
    Motion motion{};                   // object dynamics of the whole grid (grid effects only); default at rest
    GrowthDesc growth{};               // how Pose::growth reveals material; default from the lattice centre
    TextureDynamicsDesc textures{};    // global + local dynamics and their seed; default up, ordered cycling
    std::vector<EffectLayer> layers{}; // default (empty): one layer with SplatStyle{}
    SparseOutputDesc sparse{};         // solver effects: dense fields to voxels; default SparseOutputDesc{}
    DynamicsToggles enabled{};         // default all on
    // Support radius of the Materials footprint the effect is drawn with, in
    // voxel units (Footprint::radius()); bounds() depend on it. Presets set it.
    float footprintRadius = 1.6f; // default 1.6 (Kernel::CrawfisMax)
};

struct EffectCounters {
    std::uint64_t updates = 0;          // update() / step() calls that did work
    std::uint64_t stepsSimulated = 0;   // solver substeps
    std::uint64_t voxelsUpdated = 0;    // voxels (grid) or cells (solver) evaluated
    std::uint64_t propagationSteps = 0; // step-by-step texture propagation steps (solver effects)
};

namespace detail {
class EffectBody; // the kind's state and code: sdk/src/effect/{grid,solver}_effect.cpp
}

class Effect final : public EffectKind {
public:
    // A stateless effect over a base grid (its voxels' cells fix the lattice;
    // opacities, colour coordinates and stretch are the t = 0 material).
    // Fails on an invalid grid or desc; the message names the field.
    static Result<Effect> fromGrid(Grid base, EffectDesc desc);
    // A stateful effect driven by a solver. desc.motion must be at rest
    // (attach motion to the emitters instead: the smoke should trail).
    static Result<Effect> fromSolver(FluidSolver solver, EffectDesc desc);
    // A stateless turbulent gas (Ebert & Parent 1990, procedural_gas.hpp)
    // sampled into `lattice`'s cells (dims, spacing, transform; its voxels are
    // ignored) at every update; desc.motion moves the lattice through the
    // gas's world, desc.textures.cycling picks each cell's texture.
    // Fails on an invalid gas desc (the message names the field), a lattice
    // with no cells or over kMaxVoxels.
    static Result<Effect> fromProceduralGas(ProceduralGasDesc gas, Grid lattice, EffectDesc desc);
    // A baked simulation played back (grid_sequence.hpp; splatfx/vdb.hpp reads
    // OpenVDB files into one): frames interpolated at t, looping or clamped,
    // moved as a whole by desc.motion (its opacity fades it; growth is not
    // applied), voxels below desc.sparse.minOpacity left out, textures
    // propagated along the sequence's velocity (Propagation::Velocity) or a
    // fixed direction, on a fixed clock of stepsPerSec, so update(t) is a
    // function of t alone (earlier times replay from step 0: cost linear in
    // t * stepsPerSec). isStateless() is true. Fails on an invalid sequence,
    // or Propagation::Velocity without velocity; the message names the field.
    static Result<Effect> fromSequence(GridSequence sequence, EffectDesc desc);
    // Splats at particle positions (King et al. 1999, sec. 6; particles.hpp):
    // the emitter's particles, born at desc.motion's pose at their birth and
    // then flying free, drawn with desc.layers[0].style (at most one layer;
    // its variation's rotation, mirroring and scale per particle, no jitter),
    // plus any particles a host hands to setParticles. Stateless: update(t)
    // evaluates the emitter at t. Drawn unlit (lightingDensity is false).
    // Toggles: object off freezes the particles at t = 0, local off stops
    // their texture cycling. Fails on a bad emitter (checkParticleEmitter, its
    // particle budget included) or more than one layer; the message names the field.
    static Result<Effect> fromParticles(ParticleEmitterDesc emitter, EffectDesc desc);

    Effect(const Effect& other);
    Effect& operator=(const Effect& other);
    Effect(Effect&&) noexcept;
    Effect& operator=(Effect&&) noexcept;
    ~Effect() override;

    bool isStateless() const;
    // Stateless path: the effect at timeSec (in [0, kMaxTimeSec]), independent of earlier calls.
    // Expects isStateless().
    void update(double timeSec);
    // Advances by dtSec (>= 0): simulates a solver effect, or update(time() + dtSec).
    void step(double dtSec);
    double time() const override;

    // The whole effect now (every layer's voxels before the height split).
    const Grid& grid() const;
    std::size_t layerCount() const;
    const Grid& layerGrid(std::size_t i) const;
    const EffectLayer& layer(std::size_t i) const;

    // Adds every layer's (grid, style) to the builder (after builder.begin).
    // Expects materials with the footprint radius given in the desc and the
    // layers' texture sets and colour tables. Returns the splats added.
    std::size_t emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options = {}) const;
    // EffectKind: emit(context.splats, context.materials, context.draw).
    EmitResult emit(const EmitContext& context) override;
    // EffectKind: every layer's voxels with the opacity the splat builder
    // draws them with (style and draw opacity scales, colour-table alpha), on
    // the whole effect's lattice.
    bool lightingDensity(const Materials& materials, const EmitOptions& draw, Grid& out) const override;

    // Conservative world box of every splat over [t0, t1] (seconds): lattice
    // extent, motion over the interval, and the splat extent (footprint
    // radius times the kernel's largest axis, stretch included).
    Aabb bounds(double t0, double t1) const override;

    // EffectKind: grid effects are alive unless the motion's fade or growth
    // is at zero at timeSec; solver effects while an emitter is on or their
    // total density exceeds hints.deadDensity.
    bool alive(double timeSec, const AliveHints& hints) const override;
    // EffectKind: grid effects update(timeSec); solver effects step from the
    // time they were last brought to (by advanceTo or step) to timeSec in
    // n = min(ceil(gap / context.catchUpStepSec), context.maxCatchUpSteps)
    // equal steps, and do nothing when timeSec is not later.
    AdvanceResult advanceTo(double timeSec, const AdvanceContext& context) override;
    // EffectKind: base voxels (grid effects) or solver cells evaluated per advance.
    std::uint64_t costCells() const override;

    const EffectCounters& counters() const;
    const EffectDesc& desc() const;
    // Switches scales of motion on or off; takes effect at the next update/step.
    void setToggles(const DynamicsToggles& toggles);
    // Gives every layer this per-splat variation (splats.hpp; presets use
    // SplatVariation::recommended); bounds() follow. Fails, changing nothing,
    // on an out-of-range field (the message names it).
    Status setSplatVariation(const SplatVariation& variation);
    // A particle effect's host particles (an engine's own particle system),
    // replacing the previous set: drawn with the emitter's at every emit and
    // included in bounds() at any time, until replaced. Copied; positions in
    // world units. Fails on a kind other than fromParticles, or more than
    // kMaxParticles. Particles with non-finite fields are dropped when drawn.
    Status setParticles(std::span<const Particle> particles);
    // The solver of a solver effect, for emitters and inspection (nullptr otherwise).
    FluidSolver* solver();
    const FluidSolver* solver() const;
    // The stateless texture dynamics of a grid effect (empty for a solver effect).
    const TextureDynamics& textureDynamics() const;

private:
    explicit Effect(std::unique_ptr<detail::EffectBody> body);
    std::unique_ptr<detail::EffectBody> mBody; // never null (moved-from Effects excepted)
};

} // namespace splatfx
