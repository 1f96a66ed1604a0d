// Effects and presets: stateless frames, layers, counters, toggles, and
// conservative bounds that contain every splat of a long animation.
#include <cmath>

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <tuple>

#include <glm/gtc/matrix_transform.hpp>

#include "sanitized.hpp"
#include "splatfx/effect.hpp"
#include "splatfx/presets.hpp"

using namespace splatfx;

namespace {

bool sameVoxels(const Grid& a, const Grid& b) {
    if (a.voxels.size() != b.voxels.size() || a.transform != b.transform) return false;
    for (std::size_t i = 0; i < a.voxels.size(); ++i) {
        const Voxel &x = a.voxels[i], &y = b.voxels[i];
        if (x.cell != y.cell || x.opacity != y.opacity || x.texture != y.texture || x.phase != y.phase || x.colorCoord != y.colorCoord) return false;
    }
    return true;
}

// Every point of every splat (centre + u axisU + v axisV, u^2 + v^2 <= 1)
// lies within centre +- sqrt(axisU^2 + axisV^2) per axis.
void expectInside(const std::vector<Splat>& splats, const Aabb& box, const std::string& what) {
    for (const Splat& s : splats) {
        const glm::vec3 r = glm::sqrt(s.axisU * s.axisU + s.axisV * s.axisV);
        ASSERT_TRUE(box.contains(s.center - r) && box.contains(s.center + r))
            << what << ": splat at (" << s.center.x << ", " << s.center.y << ", " << s.center.z << ") extent (" << r.x << ", " << r.y << ", " << r.z
            << ") outside [" << box.lo.x << " " << box.lo.y << " " << box.lo.z << "] - [" << box.hi.x << " " << box.hi.y << " " << box.hi.z << "]";
    }
}

Camera cameraAt(double t) {
    // An orbiting camera, so splat ellipses are seen from many directions.
    const float a = float(t) * 0.7f;
    return Camera::lookAt({14.0f * std::cos(a), 3.0f + 4.0f * std::sin(0.3f * a), 14.0f * std::sin(a)}, {0, 3, 0}, {0, 1, 0}, glm::radians(50.0f),
                          {320, 240});
}

Motion wanderingMotion() {
    return Motion(
        {{.timeSec = 0, .pose = {.position = {-3, 0, 0}, .scale = glm::vec3(0.6f)}},
         {.timeSec = 4,
          .pose = {.position = {2, 1, 1}, .rotation = glm::angleAxis(0.8f, glm::normalize(glm::vec3(1, 1, 0))), .scale = {1.4f, 1.0f, 0.8f}},
          .easing = Easing::Smooth},
         {.timeSec = 9, .pose = {.position = {0, 0, -3}, .rotation = glm::angleAxis(-0.5f, glm::vec3(0, 0, 1))}}},
        {.velocity = {0.1f, 0, 0}, .spinRadPerSec = 0.9f, .bobAmplitude = {0, 0.4f, 0.2f}, .bobHz = 0.7f});
}

} // namespace

TEST(Effect, FireFramesArePureFunctionsOfTime) {
    Materials m(Footprint{});
    auto a = presets::fire(m, {.motion = wanderingMotion()});
    auto b = presets::fire(m, {.motion = wanderingMotion()});
    ASSERT_TRUE(a.ok()) << a.error();
    EXPECT_TRUE(a->isStateless());
    // a walks through many frames; b jumps straight to the last.
    for (int f = 0; f <= 240; ++f) a->update(f / 24.0);
    b->update(240 / 24.0);
    EXPECT_TRUE(sameVoxels(a->grid(), b->grid()));
    // And step() is update(time + dt).
    auto c = presets::fire(m, {.motion = wanderingMotion()});
    c->step(4.0);
    c->step(6.0);
    EXPECT_TRUE(sameVoxels(a->grid(), c->grid()));
}

TEST(Effect, FireTexturesRiseOneVoxelPerPropagationStep) {
    // Global dynamics in the preset: with cycling off, the texture a voxel
    // shows at step n + 1 is the one the voxel below showed at step n, plus 1.
    Materials m(Footprint{});
    auto fire = presets::fire(m, {.dims = {3, 10, 3}, .opacity = 1.0f, .propagationStepsPerSec = 10.0f});
    ASSERT_TRUE(fire.ok());
    fire->setToggles({.object = true, .global = true, .local = false});
    auto textureAt = [&](double t) {
        fire->update(t);
        std::map<std::tuple<int, int, int>, std::uint32_t> out;
        for (const Voxel& v : fire->grid().voxels) out[{v.cell.x, v.cell.y, v.cell.z}] = v.texture;
        return out;
    };
    const auto before = textureAt(2.05), after = textureAt(2.15);
    int checked = 0;
    for (const auto& [cell, tex] : after) {
        const auto [x, y, z] = cell;
        const auto below = before.find({x, y - 1, z});
        if (below == before.end()) continue;
        EXPECT_EQ(tex, below->second + 1);
        ++checked;
    }
    EXPECT_GT(checked, 20);
}

TEST(Effect, GrowthAndFadesChangeTheSparseGrid) {
    Materials m(Footprint{});
    const Motion grow({{.timeSec = 0, .pose = {.opacity = 1.0f, .growth = 0.0f}},
                       {.timeSec = 2, .pose = {.opacity = 1.0f, .growth = 1.0f}},
                       {.timeSec = 3, .pose = {.opacity = 0.5f, .growth = 1.0f}}});
    auto fire = presets::fire(m, {.motion = grow});
    ASSERT_TRUE(fire.ok());
    std::size_t last = 0;
    for (double t : {0.0, 0.5, 1.0, 1.5, 2.0}) {
        fire->update(t);
        EXPECT_GE(fire->grid().voxels.size(), last) << "the fire spreads";
        last = fire->grid().voxels.size();
    }
    fire->update(0.0);
    EXPECT_TRUE(fire->grid().voxels.empty()) << "growth 0: no material yet";
    fire->update(2.0);
    const Grid full = fire->grid();
    fire->update(3.0);
    ASSERT_EQ(fire->grid().voxels.size(), full.voxels.size());
    for (std::size_t i = 0; i < full.voxels.size(); ++i)
        EXPECT_FLOAT_EQ(fire->grid().voxels[i].opacity, 0.5f * full.voxels[i].opacity) << "keyed fade";
}

TEST(Effect, FireToSmokeDrawsTwoStylesThatShareTheMaterial) {
    Materials m(Footprint{});
    auto e = presets::fireToSmoke(m, {});
    ASSERT_TRUE(e.ok()) << e.error();
    ASSERT_EQ(e->layerCount(), 2u);
    EXPECT_NE(e->layer(0).style.textureSet, e->layer(1).style.textureSet);
    EXPECT_NE(e->layer(0).style.colorTable, e->layer(1).style.colorTable);
    e->update(1.3);
    // Per cell, the two layers' opacities add up to the effect's.
    std::map<std::tuple<int, int, int>, float> sum;
    for (std::size_t l = 0; l < 2; ++l)
        for (const Voxel& v : e->layerGrid(l).voxels) sum[{v.cell.x, v.cell.y, v.cell.z}] += v.opacity;
    for (const Voxel& v : e->grid().voxels) {
        const float layered = sum[{v.cell.x, v.cell.y, v.cell.z}];
        EXPECT_NEAR(layered, v.opacity, 1e-6f);
    }
    // Both appear in one splat list, with their own layers and colour rows.
    SplatBuilder b({.frustumCull = false});
    b.begin(cameraAt(0.0));
    const std::size_t n = e->emit(b, m);
    EXPECT_EQ(n, b.splats().size());
    const auto fireSet = m.set(e->layer(0).style.textureSet), smokeSet = m.set(e->layer(1).style.textureSet);
    int fire = 0, smoke = 0;
    for (const Splat& s : b.splats()) {
        if (s.layer >= fireSet.first && s.layer < fireSet.first + fireSet.count && s.colorRow == float(e->layer(0).style.colorTable)) ++fire;
        if (s.layer >= smokeSet.first && s.layer < smokeSet.first + smokeSet.count && s.colorRow == float(e->layer(1).style.colorTable)) ++smoke;
    }
    EXPECT_GT(fire, 50);
    EXPECT_GT(smoke, 50);
    EXPECT_EQ(std::size_t(fire + smoke), n);
}

TEST(Effect, SolverEffectsSimulateAndCount) {
    Materials m(Footprint{});
    auto smoke = presets::smoke(m, {.dims = {8, 12, 8}, .substeps = 2});
    ASSERT_TRUE(smoke.ok()) << smoke.error();
    EXPECT_FALSE(smoke->isStateless());
    EXPECT_EQ(smoke->counters().stepsSimulated, 0u);
    std::set<std::uint32_t> textures;
    for (int i = 0; i < 30; ++i) {
        smoke->step(1.0 / 15.0);
        for (const Voxel& v : smoke->grid().voxels) textures.insert(v.texture % 8);
    }
    EXPECT_EQ(smoke->counters().stepsSimulated, 60u) << "30 steps of 2 substeps";
    EXPECT_EQ(smoke->counters().voxelsUpdated, 60u * 8 * 12 * 8);
    EXPECT_FALSE(smoke->grid().voxels.empty()) << "the emitter made smoke";
    EXPECT_TRUE(smoke->grid().validate().ok());
    EXPECT_EQ(textures.size(), 8u) << "the smoke uses its whole texture set";

    auto fire = presets::fire(m, {});
    for (int i = 0; i < 10; ++i) fire->update(i * 0.1);
    EXPECT_EQ(fire->counters().stepsSimulated, 0u) << "stateless effects simulate nothing";
    EXPECT_EQ(fire->counters().updates, 10u);
    EXPECT_EQ(fire->counters().voxelsUpdated, 10u * 7 * 20 * 5);
}

TEST(Effect, TogglesFreezeEachScale) {
    Materials m(Footprint{});
    auto fire = presets::fire(m, {.motion = Motion({}, {.velocity = {1, 0, 0}})});
    fire->setToggles({.object = false, .global = false, .local = false});
    fire->update(0.0);
    const Grid g0 = fire->grid();
    fire->update(5.0);
    EXPECT_TRUE(sameVoxels(g0, fire->grid())) << "everything off: frozen at t = 0";
    fire->setToggles({.object = true, .global = false, .local = false});
    fire->update(5.0);
    EXPECT_NEAR(fire->grid().transform[3].x, 5.0f, 1e-5f) << "object dynamics back on";
    EXPECT_EQ(fire->grid().voxels[0].texture, g0.voxels[0].texture);
    fire->setToggles({.object = true, .global = false, .local = true});
    fire->update(5.0);
    int changed = 0;
    for (std::size_t i = 0; i < g0.voxels.size(); ++i) changed += fire->grid().voxels[i].texture != g0.voxels[i].texture;
    EXPECT_EQ(changed, int(g0.voxels.size())) << "local dynamics: 30 ticks later every voxel shows another texture";
}

TEST(Effect, BoundsContainEverySplatOverALongAnimation) {
    Materials m(Footprint{});
    struct Case {
        std::string name;
        Result<Effect> effect;
    };
    const Motion cart({{.timeSec = 0, .pose = {.position = {-4, 0, 0}}}, {.timeSec = 12, .pose = {.position = {4, 0, 1}}}});
    std::vector<Case> cases;
    cases.push_back({"fire", presets::fire(m, {.motion = wanderingMotion()})});
    cases.push_back({"steam", presets::steam(m, {.position = {1, 2, 0}, .motion = Motion({}, {.spinRadPerSec = 2.0f})})});
    cases.push_back({"fireToSmoke", presets::fireToSmoke(m, {.motion = wanderingMotion()})});
    cases.push_back({"ghosts", presets::ghosts(m, {.position = {0, 1, 0}})});
    cases.push_back({"smoke", presets::smoke(m, {.dims = {10, 12, 8}, .sourceOffset = {0, 0.5f, 0}, .sourceMotion = cart})});
    cases.push_back({"dust", presets::dust(m, {.sourceMotion = cart, .windWorld = {0.5f, 0, 0}})});
    // A grid with stretched kernels: bounds must include the stretch.
    Grid stretched = *Grid::box({4, 6, 3}, glm::vec3(0.4f, 0.6f, 0.5f));
    for (Voxel& v : stretched.voxels) v.stretch = glm::vec3(0.8f, 1.5f, -0.3f);
    stretched.transform = glm::rotate(glm::mat4(1.0f), 0.4f, glm::vec3(1, 0, 0));
    EffectDesc sd{.name = "stretched", .motion = wanderingMotion()};
    sd.footprintRadius = m.footprint().radius();
    cases.push_back({"stretched", Effect::fromGrid(stretched, sd)});
    // A baked sequence (Effect::fromSequence) on a rotated lattice, moving: material shifts between frames.
    GridSequence seq;
    seq.dims = {5, 6, 4};
    seq.spacing = glm::vec3(0.45f);
    seq.transform = glm::rotate(glm::translate(glm::mat4(1.0f), {0.5f, 1.0f, 0.0f}), 0.6f, glm::vec3(0, 0, 1));
    seq.framesPerSec = 3.0;
    for (int f = 0; f < 4; ++f) {
        GridSequenceFrame fr;
        for (std::size_t i = 0; i < seq.cellCount(); ++i) {
            fr.opticalDepth.push_back(float((i * 7 + std::size_t(f) * 5) % 11) * 0.1f);
            fr.velocityCellsPerSec.push_back({float(f) - 1.5f, 2.0f, 0.5f});
        }
        seq.frames.push_back(std::move(fr));
    }
    EffectDesc qd{.name = "sequence", .motion = wanderingMotion()};
    qd.textures.propagation.mode = Propagation::Velocity;
    qd.footprintRadius = m.footprint().radius();
    cases.push_back({"sequence", Effect::fromSequence(seq, qd)});

    const double duration = 20.0, dt = 1.0 / 12.0;
    // Every frame is simulated; sanitized, every third is emitted and checked.
    const int checkEvery = splatfx::test::count(1, 3);
    for (Case& c : cases) {
        ASSERT_TRUE(c.effect.ok()) << c.name << ": " << c.effect.error();
        Effect& e = *c.effect;
        const Aabb whole = e.bounds(0.0, duration);
        ASSERT_FALSE(whole.empty());
        SplatBuilder b({.frustumCull = false});
        std::size_t total = 0;
        for (int f = 0; f <= int(duration / dt); ++f) {
            const double t = f * dt;
            if (e.isStateless()) e.update(t);
            else if (f > 0) e.step(dt);
            if (f % checkEvery != 0) continue;
            b.begin(cameraAt(t));
            e.emit(b, m);
            total += b.splats().size();
            expectInside(b.splats(), whole, c.name + " over [0, 20]");
            expectInside(b.splats(), e.bounds(t - 0.01, t + 0.2), c.name + " at t = " + std::to_string(t));
            if (testing::Test::HasFatalFailure()) return;
        }
        EXPECT_GT(total, 1000u) << c.name << " must actually draw";
    }
}

TEST(Effect, BoundsAreNotWildlyLoose) {
    // A fire at rest: the bound is the lattice box grown by the splat extent.
    Materials m(Footprint{});
    auto fire = presets::fire(m, {});
    const Aabb b = fire->bounds(0.0, 100.0);
    // 7x20x5 cells at 0.5: lattice 3 x 9.5 x 2; splat reach R * spacing = 1.6 * 0.5 = 0.8
    // (the exact largest axis of a round kernel), plus the preset's centre jitter of 0.5 cells
    // per axis, bounded by its length 0.5 * sqrt(3) cells = 0.433; 1e-3 covers the 1e-4 relative slack.
    const float jitterReach = 0.5f * std::sqrt(3.0f) * 0.5f;
    EXPECT_NEAR(b.hi.x - b.lo.x, 3.0f + 2.0f * (0.8f + jitterReach), 1e-3f);
    EXPECT_NEAR(b.hi.y - b.lo.y, 9.5f + 2.0f * (0.8f + jitterReach), 1e-3f);
    // The paper's lattice (no variation): the kernel's reach alone.
    auto plain = presets::fire(m, {.variation = {}});
    const Aabb p = plain->bounds(0.0, 100.0);
    EXPECT_NEAR(p.hi.x - p.lo.x, 3.0f + 2.0f * 0.8f, 1e-3f);
    EXPECT_NEAR(p.hi.y - p.lo.y, 9.5f + 2.0f * 0.8f, 1e-3f);
}

TEST(Presets, ReportBadInputByField) {
    Materials m(Footprint{});
    const std::uint32_t sets = m.setCount();
    // Presets read no files (core): the caller's set is checked, and an empty one is named.
    auto bad = presets::fire(m, {.textureSet = TextureSet{}});
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error(), "FireDesc.textureSet: the texture set has no textures");
    EXPECT_EQ(m.setCount(), sets) << "a failed preset registers nothing";
    EXPECT_EQ(presets::fire(m, {.opacity = 0.0f}).error(), "FireDesc.opacity must be in (0, 1], got 0.000000");
    EXPECT_EQ(presets::fireToSmoke(m, {.split = 1.0f}).error(), "FireToSmokeDesc.split must be in (0, 1), got 1.000000");
    EXPECT_EQ(presets::fire(m, {.dims = {7, 0, 5}}).error(), "FireDesc.dims/spacing: box dims.y must be at least 1, got 0");
    EffectDesc d;
    d.layers = {{.heightFrom = 0.6f, .heightTo = 0.2f}};
    EXPECT_EQ(Effect::fromGrid(*Grid::box({2, 2, 2}), d).error(), "effect 'effect': layers[0].heightTo must be in [heightFrom, 1]");
    auto solver = FluidSolver::create({});
    EffectDesc moving;
    moving.motion = Motion({}, {.velocity = {1, 0, 0}});
    EXPECT_EQ(Effect::fromSolver(std::move(*solver), moving).error().rfind("effect 'effect': desc.motion must be at rest", 0), 0u);
}

TEST(Presets, GhostsUseFaces) {
    Materials m(Footprint{});
    auto g = presets::ghosts(m, {});
    ASSERT_TRUE(g.ok()) << g.error();
    EXPECT_EQ(m.set(g->layer(0).style.textureSet).count, 12u);
    // Random selection: a voxel's face changes between ticks, deterministically.
    auto h = presets::ghosts(m, {});
    g->update(3.0);
    h->update(3.0);
    EXPECT_TRUE(sameVoxels(g->grid(), h->grid()));
    const TextureSet faces = presets::proceduralFaces(4, 32, 1);
    ASSERT_EQ(faces.count(), 4);
    // Eyes are holes: the alpha at an eye is far below the cheek's.
    const auto& f = faces.layers[0];
    float minA = 1.0f, maxA = 0.0f;
    for (std::size_t i = 3; i < f.size(); i += 4) minA = std::min(minA, f[i]), maxA = std::max(maxA, f[i]);
    EXPECT_GT(maxA, 0.9f);
    EXPECT_LT(minA, 0.1f);
}

TEST(Presets, BadVariationIsNamed) {
    Materials m(Footprint{});
    auto bad = presets::fire(m, {.variation = {.jitter = 1.2f}});
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error(), "FireDesc.variation.jitter must be in [0, 1], got 1.200000");
    auto ghosts = presets::ghosts(m, {.variation = {.scaleLog2 = 2.0f}});
    ASSERT_FALSE(ghosts);
    EXPECT_EQ(ghosts.error(), "GhostsDesc.variation.scaleLog2 must be in [0, 1], got 2.000000");
    auto fire = presets::fire(m, {});
    EXPECT_FALSE(fire->setSplatVariation({.rotationRad = 4.0f}));
    EXPECT_TRUE(fire->setSplatVariation({}));
    EXPECT_FALSE(fire->layer(0).style.variation.any());
}
