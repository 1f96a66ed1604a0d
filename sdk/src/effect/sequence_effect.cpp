// The sequence kind of Effect: a baked simulation (GridSequence) played back
// as keyframed object dynamics (King et al. 1999 sec. 3.1, "explicitly
// changing the coarse voxel grid"), moved as a whole by the desc's Motion,
// with texture propagation along the recorded flow (sec. 3.2 generalised
// from "the voxel below" to the upwind voxel of the imported velocity) and
// stateless cycling on top (sec. 3.3).
//
// Propagation is step by step (TexturePropagator), but on a fixed clock:
// step k happens at time k / stepsPerSec and uses the sequence's fields at
// the start of its interval. The state at t is therefore a pure function of
// t: update(t) runs the missing steps, or replays from step 0 when t is
// earlier than the state. Frame t is the same whatever was rendered before
// (a render farm may start anywhere), at a cost linear in the steps replayed.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "effect_body.hpp"

namespace splatfx::detail {
namespace {

class SequenceBody final : public StatelessBody {
public:
    SequenceBody(GridSequence seq, EffectDesc d) : mSeq(std::move(seq)) {
        init(std::move(d), 0, mSeq.dims.y - 1);
        mPeakDepth = mSeq.maxDepth();
        mLocalBox.extend(latticePoint({0, 0, 0}));
        mLocalBox.extend(latticePoint(mSeq.dims - 1));
        reset();
        update(0.0);
        counters = {};
    }

    std::unique_ptr<EffectBody> clone() const override { return std::make_unique<SequenceBody>(*this); }
    // Stateless: update(t) depends on t alone (see the file comment), so Scene may evaluate frames in any order.
    const TextureDynamics& textureDynamics() const override { return mNoTextureDynamics; }
    void togglesChanged() override { reset(); }
    std::uint64_t costCells() const override { return mSeq.cellCount(); }

    void update(double t) override {
        assert(t >= 0.0 && t <= kMaxTimeSec && "Effect::update: timeSec must be in [0, kMaxTimeSec]");
        time = t;
        const double fieldsAt = desc.enabled.object ? t : 0.0;
        const Pose pose = desc.motion.sample(fieldsAt);
        advancePropagation(t);
        mSeq.sample(fieldsAt, grid, desc.sparse.minOpacity);
        grid.transform = pose.matrix() * mSeq.transform;
        const bool local = desc.enabled.local;
        std::size_t kept = 0;
        for (Voxel& v : grid.voxels) {
            v.opacity = std::clamp(v.opacity * pose.opacity, 0.0f, 1.0f);
            if (v.opacity <= 0.0f) continue;
            const TextureSample c = local ? cycleSample(v.cell, t, desc.textures.cycling, desc.textures.seed) : TextureSample{};
            v.texture = mPropagator.index(v.cell) + c.texture;
            v.phase = c.phase;
            grid.voxels[kept++] = v;
        }
        grid.voxels.resize(kept);
        ++counters.updates;
        counters.voxelsUpdated += mSeq.cellCount();
        splitLayers();
    }

    bool alive(double t, const AliveHints&) const override {
        return mPeakDepth > 0.0f && desc.motion.sample(desc.enabled.object ? t : 0.0).opacity > 0.0f;
    }

    // The whole lattice: material may be anywhere in it at some frame.
    Aabb bounds(double t0, double t1) const override { return sweptBounds(mLocalBox, mSeq.transform, mSeq.spacing, 0.0f, t0, t1); }

private:
    glm::vec3 latticePoint(glm::ivec3 c) const {
        Grid g;
        g.dims = mSeq.dims;
        g.spacing = mSeq.spacing;
        return g.localPosition(c);
    }

    void reset() {
        mPropagator = TexturePropagator(mSeq.dims, desc.textures.seed);
        mPropSteps = 0;
    }

    // Runs propagation steps up to floor(t * stepsPerSec) (see the file comment).
    void advancePropagation(double t) {
        const PropagationDesc& p = desc.textures.propagation;
        if (!desc.enabled.global || p.mode == Propagation::None) return;
        const std::int64_t target = propagationStep(t, p);
        if (target < mPropSteps) reset();
        const double dt = 1.0 / double(p.stepsPerSec);
        std::vector<std::uint8_t> occupied(mSeq.cellCount(), 0);
        while (mPropSteps < target) {
            const double at = desc.enabled.object ? double(mPropSteps) * dt : 0.0;
            mSeq.sampleDepth(at, mDepth);
            for (std::size_t i = 0; i < mDepth.size(); ++i) occupied[i] = mDepth[i] > 0.0f ? 1 : 0;
            if (p.mode == Propagation::Fixed) {
                mPropagator.stepFixed(p.direction, p.offset, occupied);
            } else {
                mSeq.sampleVelocity(at, mVelocity);
                mPropagator.advanceFlow(mVelocity, occupied, dt, p.offset);
            }
            ++mPropSteps;
            ++counters.propagationSteps;
        }
    }

    GridSequence mSeq;
    float mPeakDepth = 0.0f;
    Aabb mLocalBox;
    TexturePropagator mPropagator;
    std::int64_t mPropSteps = 0;          // propagation steps mPropagator has taken
    std::vector<float> mDepth;            // scratch: depth at a step's time
    std::vector<glm::vec3> mVelocity;     // scratch: velocity at a step's time
    TextureDynamics mNoTextureDynamics{}; // textureDynamics() of a sequence effect: empty
};

} // namespace

Result<std::unique_ptr<EffectBody>> makeSequenceBody(GridSequence sequence, EffectDesc desc) {
    if (Status s = sequence.validate(); !s) return makeError("effect '" + desc.name + "': " + s.error());
    const PropagationDesc& p = desc.textures.propagation;
    if (p.mode == Propagation::Velocity && !sequence.hasVelocity())
        return makeError("effect '" + desc.name +
                         "': textures.propagation.mode is Velocity but the sequence carries no velocity "
                         "(import a velocity grid, or choose Fixed or None)");
    if (p.mode == Propagation::Fixed && glm::any(glm::greaterThan(glm::abs(p.direction), sequence.dims)))
        return makeError("effect '" + desc.name + "': textures.propagation.direction is longer than the sequence's lattice");
    return std::unique_ptr<EffectBody>(std::make_unique<SequenceBody>(std::move(sequence), std::move(desc)));
}

} // namespace splatfx::detail
