// The stateful kind of Effect: a FluidSolver whose emitters ride moving
// objects (object dynamics, King et al. 1999 sec. 3.1, made physical), its
// dense fields turned into sparse voxels each step, and texture propagation
// stepped along the occupied cells (sec. 3.2) with stateless cycling on top
// (sec. 3.3). State accumulates, so a skipped interval must be simulated:
// advanceTo() covers it in a bounded number of coarse steps.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "effect_body.hpp"

namespace splatfx::detail {
namespace {

constexpr int kMaxPropagationSteps = 4096; // propagation steps per step() call; beyond it the state is all seeded anyway

class SolverBody final : public EffectBody {
public:
    SolverBody(FluidSolver solver, EffectDesc d) : mSolver(std::move(solver)) {
        init(std::move(d), 0, mSolver.dims().y - 1);
        mPropagator = TexturePropagator(mSolver.dims(), desc.textures.seed);
        time = mSimulatedTo = mSolver.time();
        step(0.0);
        counters = {};
    }

    std::unique_ptr<EffectBody> clone() const override { return std::make_unique<SolverBody>(*this); }
    bool stateless() const override { return false; }
    FluidSolver* solver() override { return &mSolver; }
    const TextureDynamics& textureDynamics() const override { return mNoTextureDynamics; }
    std::uint64_t costCells() const override {
        const glm::ivec3 d = mSolver.dims();
        return std::uint64_t(d.x) * std::uint64_t(d.y) * std::uint64_t(d.z);
    }

    void update(double) override { assert(false && "Effect::update: a solver effect advances with step(dtSec)"); }

    void step(double dt) override {
        assert(std::isfinite(dt) && dt >= 0.0 && "Effect::step: dtSec must be finite and >= 0");
        FluidSolver& s = mSolver;
        if (desc.enabled.object) {
            s.step(dt);
            counters.stepsSimulated += std::uint64_t(s.desc().substeps);
            counters.voxelsUpdated += std::uint64_t(s.desc().substeps) * s.density().size();
        }
        time += dt;
        mSimulatedTo = time;
        s.toGrid(grid, desc.sparse);

        // Occupancy: which cells hold material now (the lattice propagation walks).
        std::vector<std::uint8_t> occupied(s.density().size(), 0);
        for (const Voxel& v : grid.voxels) occupied[s.cellIndex(v.cell)] = 1;

        const PropagationDesc& p = desc.textures.propagation;
        if (desc.enabled.global && p.mode == Propagation::Fixed) {
            const std::int64_t target = propagationStep(time, p);
            int budget = kMaxPropagationSteps;
            while (mPropagator.steps() < target && budget-- > 0) {
                mPropagator.stepFixed(p.direction, p.offset, occupied);
                ++counters.propagationSteps;
            }
        } else if (desc.enabled.global && p.mode == Propagation::Velocity && dt > 0.0) {
            // Follow the solver's flow (sec. 3.2 generalised from "the voxel below").
            std::vector<glm::vec3> vel = s.cellVelocities();
            for (glm::vec3& v : vel) v /= s.desc().spacing;
            mPropagator.advanceFlow(vel, occupied, dt, p.offset);
            ++counters.propagationSteps;
        }
        const bool local = desc.enabled.local;
        for (Voxel& v : grid.voxels) {
            TextureSample c = local ? cycleSample(v.cell, time, desc.textures.cycling, desc.textures.seed) : TextureSample{};
            v.texture = mPropagator.index(v.cell) + c.texture;
            v.phase = c.phase;
        }
        ++counters.updates;
        splitLayers();
    }

    // Steps from where the last advance left off to t: ordinary steps when
    // seen every frame, a bounded number of coarse ones after a gap (the
    // solver is unconditionally stable; the error of this catch-up against
    // full simulation is measured in docs/BENCHMARKS.md).
    AdvanceResult advanceTo(double t, const AdvanceContext& c) override {
        const double gap = t - mSimulatedTo;
        if (!(gap > 0.0)) return {};
        const double wanted = std::ceil(gap / std::max(c.catchUpStepSec, 1e-6));
        const int n = int(std::clamp(wanted, 1.0, double(std::max(c.maxCatchUpSteps, 1))));
        for (int i = 0; i < n; ++i) step(gap / n);
        // The target, not the sum of the steps, so rounding never leaves a sliver to step next frame.
        mSimulatedTo = t;
        return {.steps = n, .caughtUp = c.resumed};
    }

    bool alive(double, const AliveHints& hints) const override {
        for (const Emitter& em : mSolver.emitters())
            if (em.desc.density > 0.0f && em.desc.rate > 0.0f) return true;
        return mSolver.totalDensity() > hints.deadDensity;
    }

    Aabb bounds(double t0, double t1) const override {
        (void)t0, (void)t1; // the solver box does not move: emitters move inside it
        Aabb local;
        local.extend(mSolver.localPosition({0, 0, 0}));
        local.extend(mSolver.localPosition(mSolver.dims() - 1));
        const glm::mat4& transform = mSolver.desc().transform;
        const float maxStretch = desc.sparse.stretchPerSpeed > 0.0f ? desc.sparse.maxStretch : 0.0f;
        return withSplatExtent(transformBox(local, transform), 1.0f, transform, mSolver.desc().spacing, maxStretch);
    }

private:
    FluidSolver mSolver;
    TexturePropagator mPropagator;
    double mSimulatedTo = 0.0;            // time the last step() or advanceTo() brought the effect to
    TextureDynamics mNoTextureDynamics{}; // textureDynamics() of a solver effect: empty
};

} // namespace

Result<std::unique_ptr<EffectBody>> makeSolverBody(FluidSolver solver, EffectDesc desc) {
    if (!desc.motion.isStatic())
        return makeError("effect '" + desc.name +
                         "': desc.motion must be at rest for a solver effect; attach the motion to "
                         "its emitters (the material then trails behind the moving object)");
    if (desc.textures.propagation.mode == Propagation::Fixed) {
        const glm::ivec3 d = desc.textures.propagation.direction;
        if (glm::any(glm::greaterThan(glm::abs(d), solver.dims())))
            return makeError("effect '" + desc.name + "': textures.propagation.direction is longer than the solver grid");
    }
    return std::unique_ptr<EffectBody>(std::make_unique<SolverBody>(std::move(solver), std::move(desc)));
}

} // namespace splatfx::detail
