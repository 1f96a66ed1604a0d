// The extension point (effect_kind.hpp): a kind the SDK has never seen is
// scheduled by Scene exactly like the shipped ones (culled out of view,
// advanced and emitted in view, caught up after a gap), and the solver kind's
// catch-up policy, now inside the kind, steps as documented.
#include <cmath>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/effect_kind.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

Camera lookingAt(glm::vec3 target, glm::vec3 from) { return Camera::lookAt(from, target, {0, 1, 0}, glm::radians(50.0f), {320, 240}, 0.1f, 500.0f); }

// What the Scene asked of the test kind, kept outside it so the test can read
// it after the Scene owns the kind.
struct Calls {
    int advances = 0;
    int emits = 0;
    double lastAdvanceTo = -1.0;
    bool lastResumed = false;
    EmitOptions lastEmit{};
};

// A test-only kind: a static 2x2x2 cube of voxels centred at `centre`, alive
// until `lifetimeSec`, stateful in the simplest way (it reports a catch-up
// when it is resumed after a gap, as a solver would).
class StaticCube final : public EffectKind {
public:
    StaticCube(glm::vec3 centre, double lifetimeSec, Calls& calls) : mLifetimeSec(lifetimeSec), mCalls(calls) {
        mGrid = *Grid::box({2, 2, 2});
        mGrid.transform = glm::translate(glm::mat4(1.0f), centre - glm::vec3(0.5f));
    }

    Aabb bounds(double, double) const override {
        Aabb box;
        for (const Voxel& v : mGrid.voxels) box.extend(mGrid.worldPosition(v.cell));
        // Unit spacing, no rotation or stretch: a splat reaches the footprint
        // radius (at most 2 voxel units for the footprints in splatfx) from its voxel.
        return box.expanded(2.0f);
    }
    bool alive(double timeSec, const AliveHints&) const override { return timeSec < mLifetimeSec; }
    AdvanceResult advanceTo(double timeSec, const AdvanceContext& context) override {
        ++mCalls.advances;
        mCalls.lastAdvanceTo = timeSec;
        mCalls.lastResumed = context.resumed;
        const bool gap = timeSec > mTime;
        mTime = timeSec;
        return {.steps = gap ? 1 : 0, .caughtUp = gap && context.resumed};
    }
    EmitResult emit(const EmitContext& context) override {
        ++mCalls.emits;
        mCalls.lastEmit = context.draw;
        const std::size_t before = context.splats.splats().size();
        context.splats.add(mGrid, context.materials, {.textured = false, .opacityScale = context.draw.opacityScale});
        return {.splats = context.splats.splats().size() - before};
    }
    double time() const override { return mTime; }
    std::uint64_t costCells() const override { return mGrid.voxels.size(); }

private:
    Grid mGrid;
    double mTime = 0.0;
    double mLifetimeSec;
    Calls& mCalls;
};

} // namespace

TEST(EffectKind, ATestOnlyKindIsCulledOutOfViewAndEmittedInView) {
    Materials m{Footprint{}};
    ASSERT_LE(m.footprint().radius(), 2.0f) << "StaticCube::bounds assumes a footprint radius of at most 2";
    Calls calls;
    Scene scene;
    const EffectId cube = scene.add(std::make_unique<StaticCube>(glm::vec3(0, 3, 0), 100.0, calls), {.name = "cube", .draw = {.opacityScale = 0.5f}});
    EXPECT_EQ(scene.findEffect(cube), nullptr) << "a kind that is not an Effect has no Effect";
    EXPECT_EQ(scene.kind(cube).costCells(), 8u);

    const Camera towards = lookingAt({0, 3, 0}, {0, 4, 20});
    const Camera away = lookingAt({0, 3, 40}, {0, 4, 20}); // the cube is behind this camera
    Frame frame;

    // In view: advanced to t, emitted with its draw options times the caller's.
    EXPECT_TRUE(scene.prepare(0.5, towards, m, frame, {.opacityScale = 0.5f}));
    EXPECT_TRUE(scene.status(cube).inView);
    EXPECT_TRUE(scene.status(cube).needed);
    EXPECT_EQ(calls.advances, 1);
    EXPECT_EQ(calls.lastAdvanceTo, 0.5);
    EXPECT_FALSE(calls.lastResumed) << "the first advance is not a return";
    EXPECT_EQ(calls.emits, 1);
    EXPECT_FLOAT_EQ(calls.lastEmit.opacityScale, 0.25f); // 0.5 (EffectOptions::draw) * 0.5 (prepare)
    EXPECT_EQ(scene.status(cube).splatsDrawn, 8u) << "one splat per voxel of the cube";
    EXPECT_EQ(frame.splats().size(), 8u);
    EXPECT_EQ(frame.counters().drawn, 1u);

    // Out of view: neither advanced nor emitted, nothing in the frame.
    for (int f = 1; f <= 10; ++f) EXPECT_TRUE(scene.prepare(0.5 + f / 30.0, away, m, frame));
    EXPECT_FALSE(scene.status(cube).inView);
    EXPECT_FALSE(scene.status(cube).needed);
    EXPECT_EQ(calls.advances, 1);
    EXPECT_EQ(calls.emits, 1);
    EXPECT_EQ(scene.status(cube).splatsDrawn, 0u);
    EXPECT_EQ(frame.splats().size(), 0u);
    EXPECT_EQ(scene.status(cube).framesSkipped, 10u);

    // Back in view: resumed, and the Scene counts the catch-up the kind reports.
    EXPECT_TRUE(scene.prepare(1.0, towards, m, frame));
    EXPECT_EQ(calls.advances, 2);
    EXPECT_TRUE(calls.lastResumed);
    EXPECT_EQ(calls.lastAdvanceTo, 1.0);
    EXPECT_EQ(scene.status(cube).catchUps, 1u);
    EXPECT_EQ(frame.splats().size(), 8u);
    // Seen again next frame: not resumed.
    EXPECT_TRUE(scene.prepare(1.0 + 1.0 / 30.0, towards, m, frame));
    EXPECT_FALSE(calls.lastResumed);
    EXPECT_EQ(scene.status(cube).catchUps, 1u);
}

TEST(EffectKind, ADeadKindInViewIsNotAdvancedOrDrawn) {
    Materials m{Footprint{}};
    Calls calls;
    Scene scene;
    const EffectId cube = scene.add(std::make_unique<StaticCube>(glm::vec3(0, 3, 0), 1.0, calls));
    const Camera towards = lookingAt({0, 3, 0}, {0, 4, 20});
    Frame frame;
    EXPECT_TRUE(scene.prepare(0.5, towards, m, frame));
    EXPECT_EQ(calls.advances, 1);
    EXPECT_TRUE(scene.prepare(1.5, towards, m, frame)); // past its lifetime
    EXPECT_TRUE(scene.status(cube).inView);
    EXPECT_FALSE(scene.status(cube).alive);
    EXPECT_FALSE(scene.status(cube).needed);
    EXPECT_EQ(calls.advances, 1);
    EXPECT_EQ(frame.splats().size(), 0u);
}

TEST(EffectKind, AnEffectAddedAsAKindIsStillFoundAsAnEffect) {
    Materials m{Footprint{}};
    Scene scene;
    auto fire = presets::fire(m, {});
    ASSERT_TRUE(fire) << fire.error();
    const EffectId id = scene.add(std::unique_ptr<EffectKind>(std::make_unique<Effect>(*fire)));
    ASSERT_NE(scene.findEffect(id), nullptr);
    EXPECT_EQ(&scene.effect(id), &scene.kind(id));
    EXPECT_TRUE(scene.effect(id).isStateless());
}

// The catch-up policy moved from Scene into the solver kind: advancing by a
// gap takes n = min(ceil(gap / catchUpStepSec), maxCatchUpSteps) equal steps,
// the same state as stepping those n steps by hand (the solver is deterministic).
TEST(EffectKind, SolverEffectCatchesUpInBoundedEqualSteps) {
    Materials m{Footprint{}};
    auto smoke = presets::smoke(m, {});
    ASSERT_TRUE(smoke) << smoke.error();
    Effect byHand = *smoke;
    Effect advanced = *smoke;
    const int substeps = advanced.solver()->desc().substeps;

    // 1 s at 1/30 s would be 30 steps; the context allows 8.
    const AdvanceContext context{.catchUpStepSec = 1.0 / 30.0, .maxCatchUpSteps = 8, .resumed = true};
    const AdvanceResult r = advanced.advanceTo(1.0, context);
    EXPECT_EQ(r.steps, 8);
    EXPECT_TRUE(r.caughtUp);
    EXPECT_EQ(advanced.counters().stepsSimulated, std::uint64_t(8 * substeps));
    for (int i = 0; i < 8; ++i) byHand.step(1.0 / 8);
    ASSERT_EQ(advanced.solver()->density().size(), byHand.solver()->density().size());
    EXPECT_EQ(advanced.solver()->density(), byHand.solver()->density()) << "advanceTo must be exactly its n steps";

    // A short gap takes ceil(gap / catchUpStepSec) steps; no gap takes none.
    const AdvanceResult shortGap = advanced.advanceTo(1.0 + 0.05, {.catchUpStepSec = 1.0 / 30.0, .maxCatchUpSteps = 8});
    EXPECT_EQ(shortGap.steps, 2); // ceil(0.05 * 30) = 2
    EXPECT_FALSE(shortGap.caughtUp) << "not resumed: ordinary steps";
    EXPECT_EQ(advanced.advanceTo(1.05, {}).steps, 0);
    EXPECT_EQ(advanced.counters().stepsSimulated, std::uint64_t(10 * substeps));

    // Alive while the emitter is on; dead once it is off and the density is below the hint.
    EXPECT_TRUE(advanced.alive(1.05, {}));
    for (Emitter& e : advanced.solver()->emitters()) e.desc.rate = 0.0f;
    const double total = advanced.solver()->totalDensity();
    ASSERT_GT(total, 0.0);
    EXPECT_TRUE(advanced.alive(1.05, {.deadDensity = 0.5 * total}));
    EXPECT_FALSE(advanced.alive(1.05, {.deadDensity = 2.0 * total}));
}

TEST(EffectKind, GridEffectAdvancesByEvaluatingTheTime) {
    Materials m{Footprint{}};
    auto fire = presets::fire(m, {});
    ASSERT_TRUE(fire) << fire.error();
    Effect advanced = *fire;
    Effect updated = *fire;
    const AdvanceResult r = advanced.advanceTo(2.5, {.resumed = true});
    EXPECT_FALSE(r.caughtUp) << "a stateless kind has nothing to catch up";
    updated.update(2.5);
    ASSERT_EQ(advanced.grid().voxels.size(), updated.grid().voxels.size());
    for (std::size_t i = 0; i < advanced.grid().voxels.size(); ++i) {
        EXPECT_EQ(advanced.grid().voxels[i].texture, updated.grid().voxels[i].texture);
        EXPECT_EQ(advanced.grid().voxels[i].opacity, updated.grid().voxels[i].opacity);
    }
    EXPECT_EQ(advanced.costCells(), updated.costCells());
    EXPECT_GE(advanced.costCells(), advanced.grid().voxels.size()) << "the cost counts every base voxel, grown or not";
}
