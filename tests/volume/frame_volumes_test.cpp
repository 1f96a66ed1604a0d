// Volumes in the Frame: the interleaved back-to-front draw
// order of splats and tetrahedra, and Scene::prepare refining the volumes in view.
#include <gtest/gtest.h>

#include "splatfx/frame.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/scene_file.hpp"

using namespace splatfx;

namespace {

// The camera at the origin looking down -z: eye distance = -z for points on the axis.
Camera axisCamera() { return Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 1000.0f); }

Splat splatAt(float dist) {
    Splat s;
    s.center = {0.0f, 0.0f, -dist};
    s.depth = dist;
    return s;
}

Tetrahedron tetAt(float dist) {
    Tetrahedron t;
    // Centroid on the axis at `dist`.
    t.position = {glm::vec3(-0.1f, -0.1f, -dist - 0.1f), glm::vec3(0.3f, -0.1f, -dist - 0.1f), glm::vec3(-0.1f, 0.3f, -dist - 0.1f),
                  glm::vec3(-0.1f, -0.1f, -dist + 0.3f)};
    return t;
}

PreIntegrationTable smallTable() {
    return *PreIntegrationTable::create(*makeCloudTransfer({}), {.scalarResolution = 2, .lengthResolution = 2, .maxLengthWorld = 1.0f});
}

// Flattens batches into (kind, volume, index) in draw order.
std::vector<std::tuple<int, std::uint32_t, std::uint32_t>> flatten(const std::vector<DrawBatch>& b) {
    std::vector<std::tuple<int, std::uint32_t, std::uint32_t>> out;
    for (const DrawBatch& x : b)
        for (std::uint32_t i = x.begin; i < x.end; ++i) out.emplace_back(int(x.kind), x.volume, i);
    return out;
}

} // namespace

TEST(FrameVolumes, WithoutVolumesTheOrderIsOneSplatBatch) {
    std::vector<Splat> splats{splatAt(30), splatAt(20), splatAt(10)};
    std::vector<DrawBatch> order;
    interleaveBackToFront(splats, {}, axisCamera(), order);
    ASSERT_EQ(order.size(), 1u);
    EXPECT_EQ(order[0].kind, DrawBatch::Kind::Splats);
    EXPECT_EQ(order[0].begin, 0u);
    EXPECT_EQ(order[0].end, 3u);
}

// Splats and one volume at alternating distances interleave by distance.
TEST(FrameVolumes, SplatsAndTetrahedraInterleaveBackToFront) {
    const auto table = smallTable();
    const PreIntegrationTable* anyTable = &table;
    std::vector<Splat> splats{splatAt(50), splatAt(30), splatAt(10)};
    std::vector<FrameVolume> volumes(1);
    volumes[0].table = anyTable;
    volumes[0].lod.tets = {tetAt(40), tetAt(20)};
    std::vector<DrawBatch> order;
    interleaveBackToFront(splats, volumes, axisCamera(), order);
    using T = std::tuple<int, std::uint32_t, std::uint32_t>;
    const int S = int(DrawBatch::Kind::Splats), V = int(DrawBatch::Kind::Tetrahedra);
    const std::vector<T> want{{S, 0, 0}, {V, 0, 0}, {S, 0, 1}, {V, 0, 1}, {S, 0, 2}};
    EXPECT_EQ(flatten(order), want);
    EXPECT_EQ(order.size(), 5u); // no empty or split batches
}

// A tetrahedron list's own order is a visibility order and is never changed,
// even where its centroids are not sorted: the keys are the suffix maxima.
// A volume without a table is not drawn.
TEST(FrameVolumes, EachListKeepsItsOrderAndUndrawnVolumesAreLeftOut) {
    const auto table = smallTable();
    const PreIntegrationTable* anyTable = &table;
    std::vector<Splat> splats{splatAt(25)};
    std::vector<FrameVolume> volumes(2);
    volumes[0].table = anyTable;
    volumes[0].lod.tets = {tetAt(10), tetAt(40), tetAt(5)};
    volumes[1].table = nullptr;
    volumes[1].lod.tets = {tetAt(100)};
    std::vector<DrawBatch> order;
    interleaveBackToFront(splats, volumes, axisCamera(), order);
    using T = std::tuple<int, std::uint32_t, std::uint32_t>;
    const int S = int(DrawBatch::Kind::Splats), V = int(DrawBatch::Kind::Tetrahedra);
    // Keys 40, 40, 5: the first two before the splat (25), the last after it.
    const std::vector<T> want{{V, 0, 0}, {V, 0, 1}, {S, 0, 0}, {V, 0, 2}};
    EXPECT_EQ(flatten(order), want);
}

// Scene::prepare refines an enabled volume in view into the frame (its table
// attached), and leaves out one behind the camera or disabled.
TEST(FrameVolumes, ScenePreparesTheVolumesInView) {
    auto field = makeCloudVolume({.dims = {17, 17, 9}, .seed = 2, .featureCells = 6.0f, .coverage = 0.6f});
    ASSERT_TRUE(field);
    auto vol = LodVolume::create(*field, {.originWorld = {-8.0f, -8.0f, -40.0f}});
    auto tf = makeCloudTransfer({});
    ASSERT_TRUE(vol && tf);
    auto table = PreIntegrationTable::create(*tf, {.scalarResolution = 8, .lengthResolution = 8, .maxLengthWorld = 28.0f});
    ASSERT_TRUE(table);
    Scene scene;
    const EffectId id = scene.add(std::move(*vol), std::move(*tf), std::move(*table), {.name = "cloud"});
    Materials materials{Footprint{}};
    Frame frame;
    EXPECT_TRUE(scene.prepare(0.0, axisCamera(), materials, frame));
    ASSERT_EQ(frame.volumes().size(), 1u);
    EXPECT_NE(frame.volumes()[0].table, nullptr);
    EXPECT_GT(frame.volumes()[0].lod.tets.size(), 0u);
    EXPECT_EQ(frame.volumes()[0].lod.stats.emitted, frame.volumes()[0].lod.tets.size());
    ASSERT_FALSE(frame.drawOrder().empty());
    EXPECT_EQ(frame.drawOrder()[0].kind, DrawBatch::Kind::Tetrahedra);

    const Camera away = Camera::lookAt({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 1000.0f);
    EXPECT_TRUE(scene.prepare(1.0, away, materials, frame));
    EXPECT_TRUE(frame.volumes().empty());
    scene.setEnabled(id, false);
    EXPECT_TRUE(scene.prepare(2.0, axisCamera(), materials, frame));
    EXPECT_TRUE(frame.volumes().empty());
}

// The scene file's "volumes" block builds a cloud volume into the Scene
// (y up: the grid's second axis is the height), and bad fields are named.
TEST(FrameVolumes, SceneFileVolumesBlock) {
    Materials materials{Footprint{}};
    const std::string ok = R"({"format": "splatfx-scene", "version": 1,
        "volumes": [{"name": "cumulus", "kind": "clouds", "dims": [17, 9, 17], "position": [-8, 0, -8], "spacing": 1,
                     "coverage": 0.6, "featureCells": 6, "tableScalars": 8, "tableLengths": 8}]})";
    auto f = parseSceneFile(ok, "mem/scene.json", materials);
    ASSERT_TRUE(f) << f.error();
    ASSERT_EQ(f->volumes.size(), 1u);
    const EffectId id = f->volumes[0].id;
    ASSERT_NE(f->scene.findLodVolume(id), nullptr);
    EXPECT_EQ(f->scene.findLodVolume(id)->pointDims(), glm::ivec3(17, 9, 17));
    EXPECT_EQ(f->scene.options(id).name, "cumulus");
    EXPECT_EQ(f->volumes[0].name, "cumulus");
    EXPECT_EQ(f->volumes[0].kind, "clouds");
    const std::string bad = R"({"format": "splatfx-scene", "version": 1, "volumes": [{"kind": "smoke", "dims": [1, 9, 17]}]})";
    auto g = parseSceneFile(bad, "mem/scene.json", materials);
    ASSERT_FALSE(g);
    EXPECT_NE(g.error().find("volumes[0].kind"), std::string::npos) << g.error();
    EXPECT_NE(g.error().find("volumes[0].dims"), std::string::npos) << g.error();
}
