// Grid sequences (a baked simulation on the coarse lattice) and the effect
// that plays them: frame positions (loop, clamp), interpolation of optical
// depth and colour, validation messages, texture propagation along the
// recorded flow, and frames that depend on the time alone. Core only.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/effect.hpp"
#include "splatfx/grid_sequence.hpp"

using namespace splatfx;

namespace {

GridSequence line(int cells, int frames, float depth) {
    GridSequence s;
    s.dims = {cells, 1, 1};
    s.framesPerSec = 10.0;
    for (int f = 0; f < frames; ++f)
        s.frames.push_back({.opticalDepth = std::vector<float>(std::size_t(cells), depth), .colorCoord = {}, .velocityCellsPerSec = {}});
    return s;
}

} // namespace

TEST(GridSequence, PositionLoopsOrClamps) {
    GridSequence s = line(1, 4, 1.0f);
    SequencePosition p = s.position(0.25); // frame 2.5
    EXPECT_EQ(p.a, 2u);
    EXPECT_EQ(p.b, 3u);
    EXPECT_FLOAT_EQ(p.weight, 0.5f);
    p = s.position(0.35); // frame 3.5: the last frame blends into the first
    EXPECT_EQ(p.a, 3u);
    EXPECT_EQ(p.b, 0u);
    EXPECT_FLOAT_EQ(p.weight, 0.5f);
    p = s.position(0.45); // one period (0.4 s) later than 0.05
    EXPECT_EQ(p.a, 0u);
    EXPECT_EQ(p.b, 1u);
    EXPECT_NEAR(p.weight, 0.5f, 1e-5f);
    EXPECT_DOUBLE_EQ(s.durationSec(), 0.4);
    s.end = SequenceEnd::Clamp;
    p = s.position(0.35);
    EXPECT_EQ(p.a, 3u);
    EXPECT_EQ(p.b, 3u);
    EXPECT_EQ(p.weight, 0.0f);
    EXPECT_DOUBLE_EQ(s.durationSec(), 0.3);
    p = s.position(-1.0);
    EXPECT_EQ(p.a, 0u);
    EXPECT_EQ(p.weight, 0.0f);
}

// Depth is linear in density, so it interpolates linearly; the colour is
// the depth-weighted mean of the two frames' (the mixed material's colour).
TEST(GridSequence, InterpolatesDepthAndColour) {
    GridSequence s = line(1, 2, 0.0f);
    s.end = SequenceEnd::Clamp;
    s.frames[0] = {.opticalDepth = {1.0f}, .colorCoord = {0.0f}, .velocityCellsPerSec = {}};
    s.frames[1] = {.opticalDepth = {3.0f}, .colorCoord = {1.0f}, .velocityCellsPerSec = {}};
    ASSERT_TRUE(s.validate()) << s.validate().error();
    Grid g;
    s.sample(0.05, g); // half-way
    ASSERT_EQ(g.voxels.size(), 1u);
    EXPECT_NEAR(g.voxels[0].opacity, 1.0 - std::exp(-2.0), 1e-6);
    EXPECT_NEAR(g.voxels[0].colorCoord, (0.5 * 1.0 * 0.0 + 0.5 * 3.0 * 1.0) / 2.0, 1e-6);
    // minOpacity leaves thin cells out.
    s.sample(0.05, g, 0.9f);
    EXPECT_TRUE(g.voxels.empty());
}

TEST(GridSequence, ValidateNamesFrameCellAndField) {
    GridSequence s = line(3, 2, 0.5f);
    EXPECT_TRUE(s.validate());
    s.frames[1].opticalDepth[2] = std::nanf("");
    EXPECT_EQ(s.validate().error(), "grid sequence frame 1: cell (2, 0, 0): opticalDepth is nan; expected a finite value >= 0");
    s.frames[1].opticalDepth = {1.0f};
    EXPECT_EQ(s.validate().error(), "grid sequence frame 1: opticalDepth holds 1 values; expected 3");
    s = line(3, 2, 0.5f);
    s.frames[1].colorCoord = {0.0f, 0.5f, 1.0f};
    EXPECT_NE(s.validate().error().find("every frame or none must carry colour"), std::string::npos) << s.validate().error();
    s = line(3, 0, 0.5f);
    EXPECT_EQ(s.validate().error(), "grid sequence: no frames");
}

// Sec. 3.2 along an imported flow: with a uniform +x velocity of 4 cells/s,
// after 1 s every cell shows the texture that started 4 cells upwind, plus
// one offset per hop; cells nearer the inflow are reseeded.
TEST(SequenceEffect, TexturesTravelAlongTheImportedFlow) {
    GridSequence s = line(16, 1, 1.0f);
    s.frames[0].velocityCellsPerSec.assign(16, glm::vec3(4.0f, 0.0f, 0.0f));
    EffectDesc desc;
    desc.textures.seed = 5;
    desc.textures.propagation = {.mode = Propagation::Velocity, .stepsPerSec = 8.0f, .offset = 1};
    desc.textures.cycling.mode = Cycling::None;
    desc.sparse.minOpacity = 0.0f;
    auto fx = Effect::fromSequence(s, desc);
    ASSERT_TRUE(fx) << fx.error();
    fx->update(1.0);
    ASSERT_EQ(fx->grid().voxels.size(), 16u);
    for (const Voxel& v : fx->grid().voxels) {
        if (v.cell.x < 4) continue;
        EXPECT_EQ(v.texture, initialIndex(v.cell - glm::ivec3(4, 0, 0), 5) + 4u) << "cell " << v.cell.x;
    }
    // Global dynamics off: every cell keeps its initial texture.
    fx->setToggles({.object = true, .global = false, .local = true});
    fx->update(1.0);
    for (const Voxel& v : fx->grid().voxels) EXPECT_EQ(v.texture, initialIndex(v.cell, 5));
}

// The state at t is a function of t (propagation on a fixed clock, replayed
// when going back): any order of frames gives the same frame, as a render
// farm splitting a sequence needs.
TEST(SequenceEffect, FrameDependsOnTimeAlone) {
    GridSequence s = line(12, 3, 0.0f);
    for (int f = 0; f < 3; ++f)
        for (int x = 0; x < 12; ++x) {
            s.frames[std::size_t(f)].opticalDepth[std::size_t(x)] = 0.1f * float((x + f) % 5);
            s.frames[std::size_t(f)].velocityCellsPerSec.push_back(glm::vec3(float(f + 1), 0.0f, 0.0f));
        }
    EffectDesc desc;
    desc.textures.propagation.mode = Propagation::Velocity;
    desc.sparse.minOpacity = 0.0f;
    auto a = Effect::fromSequence(s, desc);
    auto b = Effect::fromSequence(s, desc);
    ASSERT_TRUE(a && b);
    a->update(1.7);
    b->update(3.0);
    b->update(0.4);
    b->update(1.7);
    ASSERT_EQ(a->grid().voxels.size(), b->grid().voxels.size());
    for (std::size_t i = 0; i < a->grid().voxels.size(); ++i) {
        const Voxel &x = a->grid().voxels[i], &y = b->grid().voxels[i];
        EXPECT_EQ(x.cell, y.cell);
        EXPECT_EQ(x.texture, y.texture);
        EXPECT_EQ(x.phase, y.phase);
        EXPECT_EQ(x.opacity, y.opacity);
    }
    EXPECT_TRUE(a->isStateless());
}

// Keyframed playback: between frames the effect shows the interpolated
// grid, moved by the desc's motion; bounds hold the whole lattice.
TEST(SequenceEffect, PlaysFramesAsKeyframesUnderMotion) {
    GridSequence s = line(4, 2, 0.0f);
    s.end = SequenceEnd::Clamp;
    s.frames[0].opticalDepth = {1.0f, 0.0f, 0.0f, 0.0f};
    s.frames[1].opticalDepth = {0.0f, 0.0f, 0.0f, 2.0f};
    EffectDesc desc;
    desc.textures.propagation.mode = Propagation::None;
    desc.sparse.minOpacity = 0.0f;
    desc.motion = Motion({{.timeSec = 0.0, .pose = {.position = {0, 0, 0}}}, {.timeSec = 1.0, .pose = {.position = {10, 0, 0}}}});
    auto fx = Effect::fromSequence(s, desc);
    ASSERT_TRUE(fx) << fx.error();
    fx->update(0.025); // a quarter of the way from frame 0 to frame 1
    ASSERT_EQ(fx->grid().voxels.size(), 2u);
    EXPECT_NEAR(fx->grid().voxels[0].opacity, 1.0 - std::exp(-0.75), 1e-6);
    EXPECT_NEAR(fx->grid().voxels[1].opacity, 1.0 - std::exp(-0.5), 1e-6);
    EXPECT_NEAR(fx->grid().transform[3].x, 0.25f, 1e-5f);
    fx->update(5.0); // clamped at the last frame, at the end of the motion
    ASSERT_EQ(fx->grid().voxels.size(), 1u);
    EXPECT_EQ(fx->grid().voxels[0].cell.x, 3);
    const Aabb box = fx->bounds(0.0, 5.0);
    EXPECT_TRUE(box.contains(fx->grid().worldPosition({3, 0, 0})));
    EXPECT_TRUE(box.contains(glm::vec3(fx->grid().transform * glm::vec4(fx->grid().localPosition({0, 0, 0}), 1.0f)) - glm::vec3(10, 0, 0)));
}

TEST(SequenceEffect, VelocityPropagationNeedsVelocity) {
    EffectDesc desc;
    desc.name = "plume";
    desc.textures.propagation.mode = Propagation::Velocity;
    auto fx = Effect::fromSequence(line(4, 1, 1.0f), desc);
    ASSERT_FALSE(fx);
    EXPECT_NE(fx.error().find("effect 'plume': textures.propagation.mode is Velocity but the sequence carries no velocity"), std::string::npos)
        << fx.error();
    auto bad = Effect::fromSequence(line(4, 0, 1.0f), desc);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(), "effect 'plume': grid sequence: no frames");
}
