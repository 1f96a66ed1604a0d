// Every kind a Scene holds (splat effects, LOD volumes, ground fog, a host's
// own kind) lives in one list with one id space, is culled by the same range
// and frustum test, is switched off by id, and is counted; what an in-view
// LOD volume or fog layer puts into the Frame is exactly what its own
// update() gives.
#include <memory>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/cloud.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

Camera lookingAt(glm::vec3 target, glm::vec3 from) { return Camera::lookAt(from, target, {0, 1, 0}, glm::radians(50.0f), {320, 240}, 0.1f, 500.0f); }

// Sees the origin from +z: a fire at the origin, the fog layer around it and
// the cloud above it are all in view.
Camera front() { return lookingAt({0, 2, 0}, {0, 6, 40}); }
// Looks away from all of them (down +z, the scene behind the camera).
Camera away() { return lookingAt({0, 6, 100}, {0, 6, 40}); }

LodVolume cloud(glm::vec3 origin) {
    auto field = makeCloudVolume({.dims = {17, 17, 9}, .seed = 2, .featureCells = 6.0f, .coverage = 0.6f});
    auto vol = LodVolume::create(*field, {.originWorld = origin});
    EXPECT_TRUE(vol) << vol.error();
    return std::move(*vol);
}

// A 9 x 9 layer, 2 units of fog over flat ground at y = 0, centred on x, z.
GroundFog fogLayer(float x, float z, bool lod) {
    GroundFogDesc d;
    d.dims = {9, 9};
    d.originWorld = {x - 4.0f, 0.0f, z - 4.0f};
    d.terrainHeight.assign(81, 0.0f);
    d.fogTop.assign(81, 2.0f);
    d.lod = lod;
    auto fog = GroundFog::create(d);
    EXPECT_TRUE(fog) << fog.error();
    return std::move(*fog);
}

TransferFunction cloudTransfer() { return *makeCloudTransfer({}); }
TransferFunction fogTransfer() { return *makeGroundFogTransfer({0.9f, 0.9f, 0.9f}, 0.5f); }
PreIntegrationTable tableFor(const TransferFunction& tf) {
    return *PreIntegrationTable::create(tf, {.scalarResolution = 8, .lengthResolution = 8, .maxLengthWorld = 30.0f});
}

// A host's own kind: a static lattice of voxels that the lights may see.
class LitCube final : public EffectKind {
public:
    explicit LitCube(glm::vec3 centre) {
        mGrid = *Grid::box({3, 3, 3});
        mGrid.transform = glm::translate(glm::mat4(1.0f), centre - glm::vec3(1.0f));
    }
    Aabb bounds(double, double) const override {
        Aabb box;
        for (const Voxel& v : mGrid.voxels) box.extend(mGrid.worldPosition(v.cell));
        return box.expanded(2.0f); // unit spacing: a splat reaches at most the footprint radius (<= 2) from its voxel
    }
    bool alive(double, const AliveHints&) const override { return true; }
    AdvanceResult advanceTo(double, const AdvanceContext&) override { return {}; }
    EmitResult emit(const EmitContext& context) override {
        const std::size_t before = context.splats.splats().size();
        context.splats.add(mGrid, context.materials, {.textured = false});
        return {.splats = context.splats.splats().size() - before};
    }
    double time() const override { return 0.0; }
    std::uint64_t costCells() const override { return mGrid.voxels.size(); }
    bool lightingDensity(const Materials&, const EmitOptions&, Grid& out) const override {
        out = mGrid;
        return true;
    }

private:
    Grid mGrid;
};

// One of each kind, ids in the order added.
struct FourKinds {
    Materials materials{Footprint{}};
    Scene scene;
    EffectId fire = 0, clouds = 0, fog = 0, cube = 0;

    FourKinds() {
        fire = scene.add(*presets::fire(materials, {.position = {0, 0, 0}}), {.name = "fire"});
        const TransferFunction ct = cloudTransfer(), ft = fogTransfer();
        clouds = scene.add(cloud({-8, 10, -8}), ct, tableFor(ct), {.name = "clouds"});
        fog = scene.add(fogLayer(0, 0, true), ft, tableFor(ft), {.name = "fog", .keepTerrain = true});
        cube = scene.add(std::make_unique<LitCube>(glm::vec3(4, 1, 0)), {.name = "cube"});
    }
};

} // namespace

TEST(SceneKinds, OneIdSpaceAcrossKinds) {
    FourKinds s;
    EXPECT_EQ(s.fire, 0u);
    EXPECT_EQ(s.clouds, 1u);
    EXPECT_EQ(s.fog, 2u);
    EXPECT_EQ(s.cube, 3u);
    EXPECT_EQ(s.scene.size(), 4u);
    // Each id finds its own kind and no other.
    struct Want {
        EffectId id;
        bool effect, lodVolume, groundFog;
    };
    for (const Want& w :
         {Want{s.fire, true, false, false}, Want{s.clouds, false, true, false}, Want{s.fog, false, false, true}, Want{s.cube, false, false, false}}) {
        EXPECT_EQ(s.scene.findEffect(w.id) != nullptr, w.effect) << w.id;
        EXPECT_EQ(s.scene.findLodVolume(w.id) != nullptr, w.lodVolume) << w.id;
        EXPECT_EQ(s.scene.findGroundFog(w.id) != nullptr, w.groundFog) << w.id;
    }
    EXPECT_EQ(s.scene.findLodVolume(s.clouds)->pointDims(), glm::ivec3(17, 17, 9));
    // Options and status by the same ids.
    EXPECT_EQ(s.scene.options(s.fire).name, "fire");
    EXPECT_EQ(s.scene.options(s.clouds).name, "clouds");
    EXPECT_EQ(s.scene.options(s.fog).name, "fog");
    EXPECT_EQ(s.scene.options(s.cube).name, "cube");

    Frame frame;
    EXPECT_TRUE(s.scene.prepare(0.5, front(), s.materials, frame));
    for (EffectId id : {s.fire, s.clouds, s.fog, s.cube}) EXPECT_TRUE(s.scene.status(id).needed) << s.scene.options(id).name;
    EXPECT_GT(s.scene.status(s.fire).splatsDrawn, 0u);
    EXPECT_GT(s.scene.status(s.cube).splatsDrawn, 0u);
    EXPECT_EQ(s.scene.status(s.clouds).splatsDrawn, 0u);
    EXPECT_GT(s.scene.status(s.clouds).tetrahedraDrawn, 0u);
    EXPECT_GT(s.scene.status(s.fog).tetrahedraDrawn, 0u);
    // The frame's volumes come in id order: the cloud, then the fog.
    ASSERT_EQ(frame.volumes().size(), 2u);
    EXPECT_EQ(frame.volumes()[0].lod.tets.size(), s.scene.status(s.clouds).tetrahedraDrawn);
    EXPECT_EQ(frame.volumes()[1].lod.tets.size(), s.scene.status(s.fog).tetrahedraDrawn);
    EXPECT_FALSE(s.scene.groundFogTerrain(s.fog).empty()) << "keepTerrain: the terrain the frame refined";
    EXPECT_TRUE(s.scene.groundFogTerrain(s.clouds).empty()) << "not a fog layer";
}

TEST(SceneKinds, CloudsAndGroundFogOutOfViewAreCulledAndSkipped) {
    FourKinds s;
    Frame frame;
    EXPECT_TRUE(s.scene.prepare(0.0, away(), s.materials, frame));
    for (EffectId id : {s.clouds, s.fog}) {
        const EffectStatus& st = s.scene.status(id);
        EXPECT_TRUE(st.inRange) << s.scene.options(id).name;
        EXPECT_FALSE(st.inView) << s.scene.options(id).name;
        EXPECT_FALSE(st.needed) << s.scene.options(id).name;
        EXPECT_EQ(st.framesSkipped, 1u) << s.scene.options(id).name;
        EXPECT_EQ(st.tetrahedraDrawn, 0u) << s.scene.options(id).name;
    }
    EXPECT_TRUE(frame.volumes().empty()) << "nothing refined or emitted for volumes behind the camera";
    EXPECT_TRUE(s.scene.groundFogTerrain(s.fog).empty());
    EXPECT_EQ(frame.counters().needed, 0u);

    // Only the fog in view: the cloud (above, out of a low, level view) stays culled.
    const Camera low = lookingAt({0, 0.5f, 0}, {0, 0.5f, 12});
    ASSERT_FALSE(Scene::inFrustum(s.scene.findLodVolume(s.clouds)->boundsWorld(), low)) << "the test's view must miss the cloud";
    EXPECT_TRUE(s.scene.prepare(0.1, low, s.materials, frame));
    EXPECT_FALSE(s.scene.status(s.clouds).needed);
    EXPECT_EQ(s.scene.status(s.clouds).framesSkipped, 2u);
    EXPECT_TRUE(s.scene.status(s.fog).needed);
    ASSERT_EQ(frame.volumes().size(), 1u);
    EXPECT_EQ(frame.volumes()[0].lod.tets.size(), s.scene.status(s.fog).tetrahedraDrawn);

    // Out of range: the same test as for effects.
    s.scene.options(s.fog).rangeWorld = 5.0f;
    EXPECT_TRUE(s.scene.prepare(0.2, front(), s.materials, frame));
    EXPECT_FALSE(s.scene.status(s.fog).inRange);
    EXPECT_FALSE(s.scene.status(s.fog).needed);
    EXPECT_TRUE(s.scene.status(s.clouds).needed);
    ASSERT_EQ(frame.volumes().size(), 1u) << "the cloud only";
    EXPECT_EQ(frame.volumes()[0].lod.tets.size(), s.scene.status(s.clouds).tetrahedraDrawn);
}

TEST(SceneKinds, AnyKindIsSwitchedOffById) {
    for (int off = 0; off < 4; ++off) {
        FourKinds s;
        const EffectId id = EffectId(off);
        s.scene.setEnabled(id, false);
        Frame frame;
        EXPECT_TRUE(s.scene.prepare(0.5, front(), s.materials, frame));
        const EffectStatus& st = s.scene.status(id);
        EXPECT_FALSE(st.enabled) << s.scene.options(id).name;
        EXPECT_FALSE(st.needed) << s.scene.options(id).name;
        EXPECT_EQ(st.splatsDrawn + st.tetrahedraDrawn, 0u) << s.scene.options(id).name;
        EXPECT_EQ(frame.counters().needed, 3u) << s.scene.options(id).name;
        EXPECT_EQ(frame.counters().drawn, 3u) << s.scene.options(id).name;
        const std::size_t volumes = (id == s.clouds || id == s.fog) ? 1u : 2u;
        EXPECT_EQ(frame.volumes().size(), volumes) << s.scene.options(id).name;
        std::uint64_t splats = 0;
        for (EffectId other = 0; other < s.scene.size(); ++other) splats += s.scene.status(other).splatsDrawn;
        EXPECT_EQ(frame.splats().size(), splats) << s.scene.options(id).name;
    }
}

TEST(SceneKinds, CountersCountEveryKind) {
    FourKinds s;
    Frame frame;
    EXPECT_TRUE(s.scene.prepare(0.5, front(), s.materials, frame));
    EXPECT_EQ(s.scene.counters().declared, 4u);
    EXPECT_EQ(s.scene.counters().needed, 4u);
    EXPECT_EQ(s.scene.counters().simulated, 4u);
    EXPECT_EQ(s.scene.counters().tetrahedra, s.scene.status(s.clouds).tetrahedraDrawn + s.scene.status(s.fog).tetrahedraDrawn);
    EXPECT_EQ(frame.counters().declared, 4u);
    EXPECT_EQ(frame.counters().needed, 4u);
    EXPECT_EQ(frame.counters().drawn, 4u);

    EXPECT_TRUE(s.scene.prepare(0.6, away(), s.materials, frame));
    EXPECT_EQ(frame.counters().declared, 4u);
    EXPECT_EQ(frame.counters().needed, 0u);
    EXPECT_EQ(frame.counters().simulated, 0u);
    EXPECT_EQ(frame.counters().drawn, 0u);
    EXPECT_EQ(s.scene.counters().tetrahedra, 0u);
}

// What the Scene emits for an in-view LOD volume or fog layer is exactly what
// the volume's own update gives for that camera and refinement: same
// tetrahedra, same order, the table attached.
TEST(SceneKinds, InViewVolumesEmitExactlyTheirOwnRefinement) {
    const TransferFunction ct = cloudTransfer(), ft = fogTransfer();
    for (bool lod : {false, true}) {
        Scene scene;
        const LodRefineDesc refine{.detailC = 3.0f};
        const EffectId c = scene.add(cloud({-8, 10, -8}), ct, tableFor(ct), {.name = "clouds", .refine = refine});
        const EffectId f = scene.add(fogLayer(0, 0, lod), ft, tableFor(ft), {.name = "fog", .refine = refine});
        Materials materials{Footprint{}};
        Frame frame;
        // Two frames: the LOD volume's morph state carries over between them.
        LodVolume ownCloud = cloud({-8, 10, -8});
        const GroundFog ownFog = fogLayer(0, 0, lod);
        for (int i = 0; i < 2; ++i) {
            const Camera cam = lookingAt({0, 2, 0}, {float(i), 6, 40});
            EXPECT_TRUE(scene.prepare(0.1 * i, cam, materials, frame));
            LodFrame wantCloud, wantFog;
            ASSERT_TRUE(ownCloud.update(cam, refine, &ct, wantCloud));
            ASSERT_TRUE(ownFog.update(cam, refine, wantFog));
            ASSERT_EQ(frame.volumes().size(), 2u);
            const LodFrame& gotCloud = frame.volumes()[0].lod;
            const LodFrame& gotFog = frame.volumes()[1].lod;
            ASSERT_EQ(gotCloud.tets.size(), wantCloud.tets.size());
            ASSERT_EQ(gotFog.tets.size(), wantFog.tets.size());
            for (std::size_t k = 0; k < gotCloud.tets.size(); ++k) {
                EXPECT_EQ(gotCloud.tets[k].position, wantCloud.tets[k].position);
                EXPECT_EQ(gotCloud.tets[k].scalar, wantCloud.tets[k].scalar);
            }
            for (std::size_t k = 0; k < gotFog.tets.size(); ++k) {
                EXPECT_EQ(gotFog.tets[k].position, wantFog.tets[k].position);
                EXPECT_EQ(gotFog.tets[k].scalar, wantFog.tets[k].scalar);
            }
            EXPECT_NE(frame.volumes()[0].table, nullptr);
            EXPECT_NE(frame.volumes()[1].table, nullptr);
        }
        EXPECT_EQ(scene.status(c).framesNeeded, 2u);
        EXPECT_EQ(scene.status(f).framesNeeded, 2u);
    }
}

// The fog layer's bounds hold everything it emits (at full resolution and
// with the LOD's padded grid), so culling by them never drops visible fog.
TEST(SceneKinds, GroundFogBoundsHoldEveryTetrahedronAndTerrainTriangle) {
    for (bool lod : {false, true}) {
        GroundFogDesc d;
        d.dims = {11, 7}; // not 2^n + 1: the LOD pads, and fog tapers into the padding
        d.originWorld = {-3.0f, 0.0f, 2.0f};
        d.spacingWorld = 1.5f;
        for (int j = 0; j < 7; ++j)
            for (int i = 0; i < 11; ++i) {
                d.terrainHeight.push_back(0.3f * float(i) - 0.2f * float(j));
                d.fogTop.push_back(2.5f - 0.1f * float(i * j % 5));
            }
        d.lod = lod;
        auto fog = GroundFog::create(d);
        ASSERT_TRUE(fog) << fog.error();
        const Aabb box = fog->boundsWorld();
        for (const glm::vec3 eye : {glm::vec3(5, 12, 30), glm::vec3(-20, 3, 4), glm::vec3(4, 1, 6)}) {
            const Camera cam = lookingAt({4, 1, 6}, eye + glm::vec3(0.0f, 0.0f, 0.01f));
            LodFrame out;
            std::vector<glm::vec3> terrain;
            ASSERT_TRUE(fog->update(cam, {.detailC = 0.5f, .clipNear = false}, out, &terrain));
            ASSERT_GT(out.tets.size(), 0u);
            for (const Tetrahedron& t : out.tets)
                for (const glm::vec3& p : t.position) EXPECT_TRUE(box.contains(p)) << p.x << " " << p.y << " " << p.z << (lod ? " (LOD)" : "");
            for (const glm::vec3& p : terrain) EXPECT_TRUE(box.contains(p)) << p.x << " " << p.y << " " << p.z << (lod ? " (LOD)" : "");
        }
    }
}

// Lighting goes by what a kind exposes, not by its type: a host's kind with a
// density is lit like an Effect; plain LOD volumes expose none and stay unlit
// even when asked. Ground fog is lit by its own model (GroundFog::setLighting,
// issue 27) when asked.
TEST(SceneKinds, LightingAppliesToEveryKindThatExposesADensity) {
    FourKinds s;
    ASSERT_TRUE(s.scene.addLight(Light::directional({0.3f, -1.0f, 0.2f})));
    for (EffectId id : {s.fire, s.clouds, s.fog, s.cube}) s.scene.setLighting(id, {.enabled = true, .selfShadow = SelfShadow::Off});
    Frame frame;
    EXPECT_TRUE(s.scene.prepare(0.5, front(), s.materials, frame));
    EXPECT_TRUE(s.scene.lightingError().empty()) << s.scene.lightingError();
    EXPECT_TRUE(s.scene.status(s.fire).lit);
    EXPECT_TRUE(s.scene.status(s.cube).lit);
    EXPECT_FALSE(s.scene.status(s.clouds).lit);
    EXPECT_TRUE(s.scene.status(s.fog).lit);
    EXPECT_EQ(frame.counters().litEffects, 3u);
    EXPECT_TRUE(frame.shadow().valid) << "the lit kinds cast the frame's shadow";
}

// A lit Cloud in a Scene follows the scene's first directional light: relit
// when that light moves, not when it stays, and not while the cloud is out
// of view; unlit, it keeps its own sun. What it puts into the Frame is its
// own update() for the camera, drawn with its table.
TEST(SceneKinds, LitCloudFollowsTheSceneSun) {
    CloudCreateDesc cd;
    cd.cloud = {.dims = {17, 17, 9}, .seed = 2, .featureCells = 6.0f, .coverage = 0.6f};
    cd.volume.originWorld = {-8.0f, 10.0f, -4.0f};
    cd.table = {.scalarResolution = 8, .lengthResolution = 8};
    auto made = Cloud::create(cd);
    ASSERT_TRUE(made) << made.error();
    Scene scene;
    const EffectId id = scene.add(std::move(*made), {.name = "cloud", .lighting = {.enabled = true}});
    ASSERT_TRUE(scene.addLight(Light::point({0.0f, 30.0f, 0.0f}))); // not a sun: skipped
    ASSERT_TRUE(scene.addLight(Light::directional({0.2f, -1.0f, 0.1f})));
    const Materials materials{Footprint{}};
    Frame frame;
    const Cloud* cloud = scene.findCloud(id);
    ASSERT_NE(cloud, nullptr);
    EXPECT_EQ(cloud->relights(), 1u);
    ASSERT_TRUE(scene.prepare(0.0, front(), materials, frame));
    EXPECT_EQ(cloud->relights(), 2u);
    EXPECT_EQ(cloud->lighting().sun.direction, glm::vec3(0.2f, -1.0f, 0.1f));
    EXPECT_TRUE(scene.status(id).lit);
    ASSERT_TRUE(scene.prepare(0.1, front(), materials, frame));
    EXPECT_EQ(cloud->relights(), 2u); // the sun stayed
    ASSERT_EQ(frame.volumes().size(), 1u);
    EXPECT_EQ(frame.volumes()[0].table, &cloud->table());
    Cloud copy = *scene.findCloud(id);
    LodFrame own;
    ASSERT_TRUE(copy.update(front(), {}, own));
    ASSERT_EQ(own.tets.size(), frame.volumes()[0].lod.tets.size());
    for (std::size_t i = 0; i < own.tets.size(); ++i) EXPECT_EQ(own.tets[i].scalar, frame.volumes()[0].lod.tets[i].scalar);

    ASSERT_TRUE(scene.setLight(1, Light::directional({0.6f, -1.0f, 0.1f}))); // the sun moves
    ASSERT_TRUE(scene.prepare(0.2, front(), materials, frame));
    EXPECT_EQ(cloud->relights(), 3u);
    ASSERT_TRUE(scene.setLight(1, Light::directional({0.9f, -1.0f, 0.1f})));
    ASSERT_TRUE(scene.prepare(0.3, away(), materials, frame)); // out of view: no work
    EXPECT_EQ(cloud->relights(), 3u);
    ASSERT_TRUE(scene.prepare(0.4, front(), materials, frame)); // back in view: catches the sun up once
    EXPECT_EQ(cloud->relights(), 4u);
    scene.setLighting(id, {.enabled = false});
    ASSERT_TRUE(scene.setLight(1, Light::directional({-0.5f, -1.0f, 0.1f})));
    ASSERT_TRUE(scene.prepare(0.5, front(), materials, frame));
    EXPECT_EQ(cloud->relights(), 4u);
    EXPECT_FALSE(scene.status(id).lit);
}

// A lit cloud casts into the scene shadow: a uniform cloud (extinction sigma
// everywhere, 9x5x9 points, spacing 1) with the sun straight down. Below its
// middle the field it casts through holds sigma over its 4 cells of height
// and falls to zero over one more cell at each end (an effect's convention,
// cloud.hpp): depth sigma (4 + 1) nats. The table sweeps down with the
// trapezoid rule at node spacing D = 6 / 63 (its box is the field's support,
// 4 + 2 cells high); on a piecewise-linear profile each of the 4 slope kinks
// (jump sigma per cell) costs at most D^2 / 8 of it: |error| <= sigma D^2 / 2
// nats, and x, z are uniform there (bilinear exact). The shadow does not
// depend on whether the cloud is in view (scheduled by light influence).
TEST(SceneKinds, LitCloudCastsIntoTheSceneShadow) {
    CloudCreateDesc cd;
    cd.cloud = {.dims = {9, 5, 9}, .seed = 2, .featureCells = 6.0f, .coverage = 0.6f};
    cd.volume.originWorld = {-4.0f, 20.0f, -4.0f};
    cd.transfer.maxExtinctionPerWorld = 2.0f;
    cd.table = {.scalarResolution = 8, .lengthResolution = 8};
    auto made = Cloud::create(cd);
    ASSERT_TRUE(made) << made.error();
    const double sigma = 2.0 * 0.2;
    ASSERT_TRUE(made->setDensity(std::vector<float>(made->density().size(), 0.2f)));
    Scene scene;
    const EffectId id = scene.add(std::move(*made), {.name = "cloud", .lighting = {.enabled = true}});
    ASSERT_TRUE(scene.addLight(Light::directional({0.0f, -1.0f, 0.0f})));
    const Materials materials{Footprint{}};
    Frame frame;
    // Seeing the cloud and the ground under it.
    const Camera both = lookingAt({0, 10, 0}, {0, 12, 60});
    ASSERT_TRUE(scene.prepare(0.0, both, materials, frame));
    EXPECT_TRUE(scene.status(id).inView);
    EXPECT_TRUE(scene.status(id).inSceneShadow);
    EXPECT_EQ(scene.counters().sceneShadowCasters, 1u);
    const FrameShadow& sh = frame.shadow();
    ASSERT_TRUE(sh.valid);
    const glm::ivec3 n = sh.dims;
    // The bottom node under the middle: the ray from it to the sun crosses the whole cloud.
    const int ix = n.x / 2, iz = n.z / 2;
    const double depthNats = double(sh.depth[std::size_t(ix) + std::size_t(n.x) * std::size_t(n.y) * std::size_t(iz)]) * std::log(2.0);
    const double D = 6.0 / double(n.y - 1);
    EXPECT_NEAR(depthNats, sigma * 5.0, sigma * D * D / 2.0 + 1e-5);
    const std::vector<float> seen = sh.depth;

    // Looking down at the ground only, the cloud out of view above: it still casts.
    const Camera ground = Camera::lookAt({0, 5, 0.1f}, {0, 0, 0}, {0, 1, 0}, glm::radians(40.0f), {320, 240}, 0.1f, 500.0f);
    ASSERT_TRUE(scene.prepare(0.1, ground, materials, frame));
    EXPECT_FALSE(scene.status(id).inView);
    EXPECT_TRUE(scene.status(id).castsIntoView);
    EXPECT_TRUE(scene.status(id).inSceneShadow);
    ASSERT_TRUE(frame.shadow().valid);
    EXPECT_EQ(frame.shadow().depth, seen);

    // Unlit, it casts nothing.
    scene.setLighting(id, {.enabled = false});
    ASSERT_TRUE(scene.prepare(0.2, both, materials, frame));
    EXPECT_FALSE(scene.status(id).inSceneShadow);
    EXPECT_FALSE(frame.shadow().valid);
}
