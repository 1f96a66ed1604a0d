// The LOD ground fog (GroundFogDesc::lod, Roettger & Ertl 2002 sec. 6 with
// the metric of sec. 2.2 and the geomorphing of sec. 3): full refinement is
// the full-resolution layer, the mesh is conforming for random cameras, the
// morph makes a refinement threshold continuous, back-to-front order, error
// against the full layer falling with c, and hard cases.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/volume.hpp"
#include "volume_test_util.hpp"

using namespace splatfx;

namespace {

// Valleys: a wavy terrain, the fog top flat at `top`.
GroundFogDesc valleys(glm::ivec2 dims, float top, bool lod = true) {
    GroundFogDesc d;
    d.dims = dims;
    d.originWorld = {-10.0f, 0.0f, -10.0f};
    d.spacingWorld = 20.0f / float(dims.x - 1);
    for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) {
            const float x = float(i) / float(dims.x - 1), z = float(j) / float(dims.y - 1);
            d.terrainHeight.push_back(2.0f * std::sin(6.0f * x) * std::cos(5.0f * z) + 0.5f * x);
            d.fogTop.push_back(top);
        }
    d.lod = lod;
    return d;
}

Camera farCamera() { return Camera::lookAt({-30.0f, 25.0f, -24.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.1f, 500.0f); }
Camera insideCamera() { return Camera::lookAt({0.5f, 0.6f, 0.3f}, {8.0f, 0.2f, 3.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.3f, 500.0f); }

using TetKey = std::array<float, 28>;
std::vector<TetKey> sortedKeys(const std::vector<Tetrahedron>& tets) {
    std::vector<TetKey> k;
    for (const Tetrahedron& t : tets) {
        TetKey a{};
        std::size_t i = 0;
        for (const glm::vec3& p : t.position) a[i++] = p.x, a[i++] = p.y, a[i++] = p.z;
        for (float s : t.scalar) a[i++] = s;
        for (float m : t.lengthScale) a[i++] = m;
        k.push_back(a);
    }
    std::sort(k.begin(), k.end());
    return k;
}

// Triangles as sorted vertex triples (orientation checked separately).
using TriKey = std::array<float, 9>;
std::vector<TriKey> sortedTriangles(const std::vector<glm::vec3>& tri) {
    std::vector<TriKey> out;
    for (std::size_t i = 0; i + 2 < tri.size(); i += 3) {
        std::array<std::array<float, 3>, 3> v;
        for (int k = 0; k < 3; ++k) v[std::size_t(k)] = {tri[i + std::size_t(k)].x, tri[i + std::size_t(k)].y, tri[i + std::size_t(k)].z};
        std::sort(v.begin(), v.end());
        TriKey t;
        for (int k = 0; k < 9; ++k) t[std::size_t(k)] = v[std::size_t(k / 3)][std::size_t(k % 3)];
        out.push_back(t);
    }
    std::sort(out.begin(), out.end());
    return out;
}

// With minAccuracyC 1e9: e >= 2 everywhere, so w = 1; no culling (the full layer has none).
const LodRefineDesc kFull{.detailC = 1e9f, .frustumCull = false};

} // namespace

// Fully refined, the 4-8 mesh is the alternating-diagonal grid: the same
// tetrahedra (bit for bit, as a set) and the same terrain triangles as the
// full-resolution layer, from outside and from inside the fog (clipped), for
// a 2^n+1 grid, a padded one (17x13 -> 17x17) and the 2x2 grid.
TEST(GroundFogLod, FullRefinementEqualsTheFullResolutionLayer) {
    for (glm::ivec2 dims : {glm::ivec2(17, 17), glm::ivec2(17, 13), glm::ivec2(2, 2), glm::ivec2(6, 3)}) {
        GroundFogDesc fd = valleys(dims, 0.8f, false);
        if (dims == glm::ivec2(2, 2)) fd.fogTop = {3.0f, 3.0f, 3.0f, 3.0f};
        GroundFogDesc ld = fd;
        ld.lod = true;
        ld.minAccuracyC = 1e9f;
        auto full = GroundFog::create(fd);
        auto lod = GroundFog::create(ld);
        ASSERT_TRUE(full && lod) << (full ? lod.error() : full.error());
        for (const Camera& cam : {farCamera(), insideCamera()}) {
            LodFrame a, b;
            std::vector<glm::vec3> ta, tb;
            // Neither culls (the full-resolution layer's culling is tested below).
            ASSERT_TRUE(full->update(cam, LodRefineDesc{.frustumCull = false}, a, &ta));
            ASSERT_TRUE(lod->update(cam, kFull, b, &tb));
            ASSERT_GT(a.tets.size(), 0u);
            EXPECT_EQ(a.tets.size(), b.tets.size()) << dims.x << "x" << dims.y;
            EXPECT_EQ(sortedKeys(a.tets), sortedKeys(b.tets)) << dims.x << "x" << dims.y;
            EXPECT_EQ(a.stats.clippedInput, b.stats.clippedInput);
            EXPECT_EQ(a.stats.fullResolution, b.stats.fullResolution);
            EXPECT_EQ(ta.size(), 6u * std::size_t(dims.x - 1) * std::size_t(dims.y - 1));
            EXPECT_EQ(sortedTriangles(ta), sortedTriangles(tb)) << dims.x << "x" << dims.y;
        }
    }
}

// For random cameras and c the LOD terrain is a conforming triangulation of
// the grid's rectangle: every edge not on its border is shared by exactly two
// triangles (a T-vertex or a crack leaves edges used once; a vertex morphed
// differently by its two diamond triangles gives two positions, so unmatched
// edges too), the triangles face up and their areas add up to the square's.
TEST(GroundFogLod, MeshIsConformingForRandomCameras) {
    // 33x33 is a 2^n+1 grid; 33x21 is padded to 33x33 and its coarse
    // triangles across the last row are cut at the grid's edge.
    for (glm::ivec2 dims : {glm::ivec2(33, 33), glm::ivec2(33, 21)}) {
        const GroundFogDesc d = valleys(dims, 0.8f);
        auto fog = GroundFog::create(d);
        ASSERT_TRUE(fog) << fog.error();
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        const float lo = -10.0f, hiX = d.originWorld.x + float(dims.x - 1) * d.spacingWorld,
                    hiZ = d.originWorld.z + float(dims.y - 1) * d.spacingWorld;
        const double areaExact = double(hiX - lo) * double(hiZ - lo);
        std::uint64_t minTris = ~0ull, maxTris = 0;
        for (int trial = 0; trial < 40; ++trial) {
            const glm::vec3 eye{15.0f * u(rng), 3.0f + 6.0f * (u(rng) + 1.0f), 15.0f * u(rng)};
            const Camera cam = Camera::lookAt(eye, {u(rng), 0.0f, u(rng)}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 500.0f);
            LodRefineDesc r;
            r.detailC = std::pow(10.0f, 2.0f * (u(rng) + 1.0f) - 1.0f); // 0.1 .. 1000
            r.morph = trial % 3 != 0;
            LodFrame f;
            std::vector<glm::vec3> tri;
            ASSERT_TRUE(fog->update(cam, r, f, &tri));
            ASSERT_EQ(tri.size() % 3, 0u);
            minTris = std::min<std::uint64_t>(minTris, tri.size() / 3);
            maxTris = std::max<std::uint64_t>(maxTris, tri.size() / 3);
            std::map<std::array<float, 6>, int> edges;
            double area = 0.0;
            for (std::size_t i = 0; i < tri.size(); i += 3) {
                const glm::dvec3 a(tri[i]), b(tri[i + 1]), c(tri[i + 2]);
                const double up = (b.z - a.z) * (c.x - a.x) - (b.x - a.x) * (c.z - a.z); // y of cross(b-a, c-a)
                EXPECT_GT(up, 0.0) << "counter-clockwise from above";
                area += 0.5 * up;
                for (int k = 0; k < 3; ++k) {
                    glm::vec3 p = tri[i + std::size_t(k)], q = tri[i + std::size_t((k + 1) % 3)];
                    EXPECT_TRUE(p.x >= lo && p.x <= hiX && p.z >= lo && p.z <= hiZ) << "a terrain vertex beyond the grid";
                    if (std::tie(q.x, q.y, q.z) < std::tie(p.x, p.y, p.z)) std::swap(p, q);
                    ++edges[{p.x, p.y, p.z, q.x, q.y, q.z}];
                }
            }
            // The grid's rectangle; cut points are float (x or z fractional): 1e-5 relative.
            EXPECT_NEAR(area, areaExact, 1e-5 * areaExact);
            int bad = 0;
            for (const auto& [e, n] : edges) {
                const bool border = (e[0] == e[3] && (e[0] == lo || e[0] == hiX)) || (e[2] == e[5] && (e[2] == lo || e[2] == hiZ));
                if (n != (border ? 1 : 2)) ++bad;
            }
            EXPECT_EQ(bad, 0) << dims.x << "x" << dims.y << " trial " << trial;
            // No fog beyond the grid either.
            for (const Tetrahedron& t : f.tets)
                for (const glm::vec3& p : t.position) ASSERT_TRUE(p.x <= hiX && p.z <= hiZ) << "fog beyond the grid";
        }
        EXPECT_LT(minTris, maxTris) << "the cameras should give different meshes";
    }
}

// Morphing (sec. 3): as the eye crosses a refinement threshold by a tiny
// step, the fog along vertical rays next to the new vertices changes by
// almost nothing; without morphing the same step pops (the vertex jumps from
// the coarse edge to its true height). Threshold found by bisection on the
// eye path with morphing off (where the split count changes).
TEST(GroundFogLod, MorphingMakesARefinementThresholdContinuous) {
    const GroundFogDesc d = valleys({33, 33}, 3.0f); // fog everywhere: thickness follows the terrain
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    auto tf = makeGroundFogTransfer({1, 1, 1}, 0.8f);
    ASSERT_TRUE(tf);
    const glm::vec3 A{-40.0f, 12.0f, -30.0f}, B{-12.0f, 6.0f, -9.0f};
    auto camAt = [&](double s) {
        const glm::vec3 eye = A + float(s) * (B - A);
        return Camera::lookAt(eye, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 500.0f);
    };
    // No culling: the rays are vertical, some of their prisms may be out of the camera's view.
    const LodRefineDesc on{.detailC = 3.0f, .morph = true, .frustumCull = false}, off{.detailC = 3.0f, .morph = false, .frustumCull = false};
    auto splits = [&](double s) {
        LodFrame f;
        EXPECT_TRUE(fog->update(camAt(s), off, f));
        return f.stats.nodesRefined;
    };
    // The terrain height of a triangle list at (x, z) (NaN outside).
    auto heightAt = [](const std::vector<glm::vec3>& tri, double x, double z) {
        for (std::size_t i = 0; i + 2 < tri.size(); i += 3) {
            const glm::dvec3 a(tri[i]), b(tri[i + 1]), c(tri[i + 2]);
            const double det = (b.x - a.x) * (c.z - a.z) - (c.x - a.x) * (b.z - a.z);
            const double u = ((x - a.x) * (c.z - a.z) - (c.x - a.x) * (z - a.z)) / det;
            const double v = ((b.x - a.x) * (z - a.z) - (x - a.x) * (b.z - a.z)) / det;
            if (u >= -1e-9 && v >= -1e-9 && u + v <= 1.0 + 1e-9) return a.y + u * (b.y - a.y) + v * (c.y - a.y);
        }
        return std::nan("");
    };
    // Scan the path for changes of the split count, bisect each down to a
    // step of ~1e-4 world, and keep the one whose changed vertices jump most
    // (a vertex of almost no deviation pops by almost nothing: no test).
    const double pathLength = double(glm::length(B - A));
    double bestJump = 0.0, s0 = 0.0, s1 = 0.0;
    std::set<std::array<float, 2>> fresh;
    std::uint64_t prev = splits(0.0);
    for (int k = 1; k <= 64 && bestJump < 0.05; ++k) {
        const std::uint64_t now = splits(k / 64.0);
        if (now == prev) continue;
        prev = now;
        double lo = (k - 1) / 64.0, hi = k / 64.0;
        const std::uint64_t nLo = splits(lo);
        while ((hi - lo) * pathLength > 1e-4) {
            const double m = 0.5 * (lo + hi);
            (splits(m) == nLo ? lo : hi) = m;
        }
        std::vector<glm::vec3> t0, t1;
        LodFrame f0, f1;
        EXPECT_TRUE(fog->update(camAt(lo), off, f0, &t0));
        EXPECT_TRUE(fog->update(camAt(hi), off, f1, &t1));
        // The vertices in one mesh and not in the other (split or merged), and their jump.
        std::set<std::array<float, 3>> p0, p1;
        for (const glm::vec3& p : t0) p0.insert({p.x, p.y, p.z});
        for (const glm::vec3& p : t1) p1.insert({p.x, p.y, p.z});
        std::set<std::array<float, 2>> changed;
        double jump = 0.0;
        for (const auto& p : p1)
            if (!p0.count(p)) changed.insert({p[0], p[2]}), jump = std::max(jump, std::abs(double(p[1]) - heightAt(t0, p[0], p[2])));
        for (const auto& p : p0)
            if (!p1.count(p)) changed.insert({p[0], p[2]}), jump = std::max(jump, std::abs(double(p[1]) - heightAt(t1, p[0], p[2])));
        if (jump > bestJump) bestJump = jump, s0 = lo, s1 = hi, fresh = changed;
    }
    ASSERT_GE(bestJump, 0.05) << "the path should cross a threshold that moves the terrain";
    // The same layer with the affine density model (the scalar the same for
    // any split of a prism): its thresholds are the same (Delta does not
    // depend on density). The thickness here is at most 3 + 2.5 = 5.5 <= 6.
    GroundFogDesc ad = d;
    ad.densityDepthWorld = 6.0f;
    auto affine = GroundFog::create(ad);
    ASSERT_TRUE(affine) << affine.error();
    // Vertical rays just beside each changed vertex (not on it: a ray along a
    // prism edge would count every tetrahedron sharing it).
    std::vector<glm::dvec2> at;
    for (const auto& xz : fresh)
        for (glm::dvec2 o2 : {glm::dvec2(0.013, 0.007), glm::dvec2(-0.011, 0.017), glm::dvec2(0.005, -0.019)})
            at.push_back(glm::dvec2(xz[0], xz[1]) + o2);
    auto change = [&](const GroundFog& layer, const LodRefineDesc& r, double* terrainChange) {
        LodFrame a, b;
        std::vector<glm::vec3> ta, tb;
        EXPECT_TRUE(layer.update(camAt(s0), r, a, &ta));
        EXPECT_TRUE(layer.update(camAt(s1), r, b, &tb));
        double worst = 0.0;
        *terrainChange = 0.0;
        for (glm::dvec2 p : at) {
            const glm::dvec3 o(p.x, 100.0, p.y), dir(0.0, -1.0, 0.0);
            const double ia = integrateRay(a.tets, *tf, o, dir, 0.0, 300.0).a, ib = integrateRay(b.tets, *tf, o, dir, 0.0, 300.0).a;
            worst = std::max(worst, std::abs(ia - ib));
            *terrainChange = std::max(*terrainChange, std::abs(heightAt(ta, p.x, p.y) - heightAt(tb, p.x, p.y)));
        }
        return worst;
    };
    double jumpOff = 0.0, jumpOn = 0.0, unused = 0.0;
    const double pop = change(*affine, off, &jumpOff), smooth = change(*affine, on, &jumpOn);
    const double popPaper = change(*fog, off, &unused), smoothPaper = change(*fog, on, &unused);
    // The pop moves the terrain (and so the thickness) next to the rays by
    // about bestJump >= 0.05; alpha = 1 - exp(-0.8 * 0.5 * density-weighted
    // thickness) changes by well over 1e-3 for that.
    EXPECT_GT(jumpOff, 0.02) << "the terrain next to the rays pops without morphing";
    EXPECT_GT(pop, 1e-3) << "jump " << bestJump;
    // With morphing w = e - 1 starts at 0 on the threshold and moves by
    // ~ e * step / distance ~ 1e-4 / 15 per step: the change is ~1e-5 of the
    // pop and of its descendants'; 1e-2 leaves room for rounding (float heights).
    EXPECT_LT(jumpOn, 1e-2 * jumpOff) << "the terrain (and the fog's bottom and top) morphs";
    EXPECT_LT(smooth, 1e-2 * pop) << "pop " << pop << " morphed " << smooth;
    // The paper's density model (density at the terrain, 0 at the top,
    // linear per tetrahedron) re-splits the prisms at a refinement: the fog
    // changes there although the geometry does not (measured, not bounded:
    // docs/volume.md).
    RecordProperty("affinePop", std::to_string(pop));
    RecordProperty("affineMorphed", std::to_string(smooth));
    RecordProperty("paperModelPop", std::to_string(popPaper));
    RecordProperty("paperModelMorphed", std::to_string(smoothPaper));
}

// Along any ray from the eye a tetrahedron later in the list is never behind
// an earlier one (the bintree as BSP, MPVO inside prisms and clipped pieces),
// outside the fog and inside it, morphing on.
TEST(GroundFogLod, BackToFrontAlongRaysOutsideAndInside) {
    const GroundFogDesc d = valleys({33, 33}, 0.8f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    for (int ci = 0; ci < 2; ++ci) {
        const Camera cam = ci == 0 ? farCamera() : insideCamera();
        LodFrame f;
        ASSERT_TRUE(fog->update(cam, LodRefineDesc{.detailC = 3.0f}, f));
        EXPECT_LT(f.tets.size(), f.stats.fullResolution) << "the LOD should be coarser than the grid here";
        std::mt19937 rng(3);
        std::uniform_real_distribution<double> u(-0.45, 0.45);
        int crossings = 0, wrong = 0;
        for (int r = 0; r < 300; ++r) {
            const glm::dvec3 dir = glm::normalize(glm::dvec3(cam.forward()) + u(rng) * glm::dvec3(cam.right()) + u(rng) * glm::dvec3(cam.up()));
            double lastIn = 1e300;
            for (const Tetrahedron& t : f.tets) {
                const glm::dvec2 iv = voltest::rayInterval(t, glm::dvec3(cam.eye()), dir);
                if (!(iv.y - iv.x > 1e-6) || iv.y <= 0.0) continue;
                ++crossings;
                if (iv.x > lastIn + 1e-5) ++wrong;
                lastIn = std::min(lastIn, iv.x);
            }
        }
        EXPECT_GT(crossings, 50); // the coarse mesh has fewer tetrahedra than the grid's test
        EXPECT_EQ(wrong, 0) << "camera " << ci;
        if (ci == 1) { EXPECT_GT(f.stats.clippedInput, 0u); }
    }
}

// The error against the full-resolution layer (alpha along eye rays) falls
// as c grows, while the tetrahedra grow toward the full count; at c = 0 the
// mesh is coarsest.
TEST(GroundFogLod, ErrorFallsWithDetailC) {
    const GroundFogDesc d = valleys({33, 33}, 1.2f);
    GroundFogDesc fd = d;
    fd.lod = false;
    auto fog = GroundFog::create(d);
    auto full = GroundFog::create(fd);
    ASSERT_TRUE(fog && full);
    auto tf = makeGroundFogTransfer({1, 1, 1}, 0.8f);
    ASSERT_TRUE(tf);
    const Camera cam = farCamera();
    LodFrame ref;
    ASSERT_TRUE(full->update(cam, ref));
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.4, 0.4);
    std::vector<glm::dvec3> dirs;
    for (int r = 0; r < 150; ++r)
        dirs.push_back(glm::normalize(glm::dvec3(cam.forward()) + u(rng) * glm::dvec3(cam.right()) + u(rng) * glm::dvec3(cam.up())));
    std::vector<double> refA;
    for (const glm::dvec3& dir : dirs) refA.push_back(integrateRay(ref.tets, *tf, glm::dvec3(cam.eye()), dir, 0.0, 1e4).a);
    double lastErr = 1e300;
    std::uint64_t lastCount = 0;
    std::vector<double> errs;
    for (float c : {0.0f, 0.3f, 3.0f, 30.0f}) {
        LodFrame f;
        ASSERT_TRUE(fog->update(cam, LodRefineDesc{.detailC = c}, f));
        double se = 0.0;
        for (std::size_t i = 0; i < dirs.size(); ++i) {
            const double a = integrateRay(f.tets, *tf, glm::dvec3(cam.eye()), dirs[i], 0.0, 1e4).a;
            se += (a - refA[i]) * (a - refA[i]);
        }
        const double rmse = std::sqrt(se / double(dirs.size()));
        errs.push_back(rmse);
        EXPECT_GE(f.tets.size(), lastCount) << "c " << c;
        EXPECT_LE(rmse, lastErr * 1.05) << "c " << c; // 5%: the ray sample is finite; the trend is the point
        lastErr = rmse, lastCount = f.tets.size();
    }
    EXPECT_LT(errs.back(), 0.5 * errs.front()) << "c = 30 against c = 0";
    EXPECT_GT(errs.front(), 0.0);
}

// Flat terrain and flat fog top: every Delta is 0, the mesh stays coarse
// from afar and the prisms still tile the fog exactly (area x thickness).
TEST(GroundFogLod, FlatTerrainIsCoarseAndExact) {
    GroundFogDesc d = valleys({65, 65}, 1.0f);
    std::fill(d.terrainHeight.begin(), d.terrainHeight.end(), 0.25f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    const Camera cam = Camera::lookAt({-80.0f, 60.0f, -70.0f}, {0, 0, 0}, {0, 1, 0}, glm::radians(40.0f), {64, 48}, 0.1f, 500.0f);
    LodFrame f;
    ASSERT_TRUE(fog->update(cam, LodRefineDesc{.detailC = 1000.0f}, f));
    double v = 0.0;
    for (const Tetrahedron& t : f.tets) v += voltest::tetVolume(t);
    EXPECT_NEAR(v, 400.0 * 0.75, 1e-5 * 300.0); // float positions on a 2^-k lattice
    EXPECT_LT(f.tets.size() * 20, f.stats.fullResolution) << f.tets.size() << " of " << f.stats.fullResolution;
}

TEST(GroundFogLod, NoFogAnywhereEmitsNothingButTheTerrain) {
    const GroundFogDesc d = valleys({17, 17}, -50.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    LodFrame f;
    std::vector<glm::vec3> tri;
    ASSERT_TRUE(fog->update(farCamera(), LodRefineDesc{}, f, &tri));
    EXPECT_EQ(f.tets.size(), 0u);
    EXPECT_EQ(f.stats.fullResolution, 0u);
    EXPECT_GT(tri.size(), 0u);
}

// The eye exactly on a grid vertex (distance 0: e is infinite there) and
// inside the bounding radii: no crash, finite output, still conforming in count.
TEST(GroundFogLod, CameraOnAVertex) {
    const GroundFogDesc d = valleys({17, 17}, 0.8f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    const glm::vec3 eye{d.originWorld.x + 8.0f * d.spacingWorld, d.terrainHeight[8 + 17 * 8], d.originWorld.z + 8.0f * d.spacingWorld};
    const Camera cam = Camera::lookAt(eye, eye + glm::vec3(1.0f, 0.1f, 0.3f), {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.05f, 500.0f);
    LodFrame f;
    std::vector<glm::vec3> tri;
    ASSERT_TRUE(fog->update(cam, LodRefineDesc{}, f, &tri));
    EXPECT_GT(f.tets.size(), 0u);
    for (const Tetrahedron& t : f.tets)
        for (const glm::vec3& p : t.position) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    // Next to the eye the mesh is at full resolution (e is infinite within r).
    int unitTrianglesAtEye = 0;
    for (std::size_t i = 0; i < tri.size(); i += 3) {
        bool touches = false;
        for (int k = 0; k < 3; ++k) touches |= tri[i + std::size_t(k)].x == eye.x && tri[i + std::size_t(k)].z == eye.z;
        if (touches) ++unitTrianglesAtEye;
    }
    EXPECT_GE(unitTrianglesAtEye, 4);
}

TEST(GroundFogLod, BadInputIsAnError) {
    GroundFogDesc d = valleys({9, 9}, 1.0f);
    d.terrainHeight[5] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(GroundFog::create(d));
    d = valleys({9, 9}, 1.0f);
    d.fogTop[5] = 1e30f;
    EXPECT_FALSE(GroundFog::create(d));
    d = valleys({9, 9}, 1.0f);
    d.minAccuracyC = 0.0f;
    auto a = GroundFog::create(d);
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("minAccuracyC"), std::string::npos);
    d.minAccuracyC = std::numeric_limits<float>::infinity();
    EXPECT_FALSE(GroundFog::create(d));
    d = valleys({9, 9}, 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    LodFrame f;
    EXPECT_FALSE(fog->update(farCamera(), LodRefineDesc{.detailC = std::numeric_limits<float>::quiet_NaN()}, f));
    EXPECT_FALSE(fog->update(farCamera(), LodRefineDesc{.detailC = -1.0f}, f));
    // The affine density must cover the deepest fog (else the scalar would pass 1).
    d = valleys({9, 9}, 1.0f);
    d.densityDepthWorld = 0.1f;
    auto shallow = GroundFog::create(d);
    ASSERT_FALSE(shallow);
    EXPECT_NE(shallow.error().find("densityDepthWorld"), std::string::npos);
    d.densityDepthWorld = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(GroundFog::create(d));
    d.densityDepthWorld = -1.0f;
    EXPECT_FALSE(GroundFog::create(d));
    d.densityDepthWorld = 10.0f; // the valleys' fog is at most 1 + 2.5 deep
    EXPECT_TRUE(GroundFog::create(d));
}

// Memory: 16 bytes per padded point (bytesFor is what memoryBytes reports);
// the full-resolution layer keeps its two height arrays.
TEST(GroundFogLod, MemoryIsStatedExactly) {
    for (glm::ivec2 dims : {glm::ivec2(17, 13), glm::ivec2(2, 2), glm::ivec2(33, 40)}) {
        GroundFogDesc d = valleys(dims, 0.5f);
        auto fog = GroundFog::create(d);
        ASSERT_TRUE(fog);
        const std::size_t n = std::size_t(fog->lodPointsPerSide());
        EXPECT_GE(int(n), std::max(dims.x, dims.y));
        EXPECT_EQ(fog->memoryBytes(), 16u * n * n);
        EXPECT_EQ(fog->memoryBytes(), GroundFog::bytesFor(dims, true));
        d.lod = false;
        auto fullFog = GroundFog::create(d);
        ASSERT_TRUE(fullFog);
        EXPECT_EQ(fullFog->memoryBytes(), GroundFog::bytesFor(dims, false));
    }
    EXPECT_EQ(GroundFog::bytesFor({17, 13}, true), 16u * 17u * 17u);
    EXPECT_EQ(GroundFog::bytesFor({18, 2}, true), 16u * 33u * 33u);
}

// Frustum culling (LodRefineDesc::frustumCull) drops subtrees outside the
// view only: along rays inside the frustum the fog is the same as without
// culling (the same pieces, so the same double sum), with fewer tetrahedra;
// the terrain output stays the whole mesh.
TEST(GroundFogLod, FrustumCullingDropsOnlyWhatIsOutOfView) {
    const GroundFogDesc d = valleys({33, 33}, 0.8f);
    auto fog = GroundFog::create(d);
    auto tf = makeGroundFogTransfer({1, 1, 1}, 0.8f);
    ASSERT_TRUE(fog && tf);
    const Camera cam = Camera::lookAt({-6.0f, 3.0f, -6.0f}, {4.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(40.0f), {64, 48}, 0.1f, 500.0f);
    LodFrame culled, all;
    std::vector<glm::vec3> tc, ta;
    ASSERT_TRUE(fog->update(cam, LodRefineDesc{.detailC = 10.0f, .frustumCull = true}, culled, &tc));
    ASSERT_TRUE(fog->update(cam, LodRefineDesc{.detailC = 10.0f, .frustumCull = false}, all, &ta));
    EXPECT_GT(culled.stats.nodesCulled, 0u);
    EXPECT_LT(culled.tets.size(), all.tets.size());
    EXPECT_EQ(sortedTriangles(tc), sortedTriangles(ta));
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-0.3, 0.3); // tan(20 deg) = 0.36 vertically: inside the frustum
    int hits = 0;
    for (int r = 0; r < 120; ++r) {
        const glm::dvec3 dir = glm::dvec3(cam.forward()) + u(rng) * glm::dvec3(cam.right()) + u(rng) * glm::dvec3(cam.up());
        const glm::dvec4 a = integrateRay(culled.tets, *tf, glm::dvec3(cam.eye()), dir, 0.0, 1e4);
        const glm::dvec4 b = integrateRay(all.tets, *tf, glm::dvec3(cam.eye()), dir, 0.0, 1e4);
        hits += b.a > 1e-3;
        EXPECT_EQ(a, b) << "ray " << r;
    }
    EXPECT_GT(hits, 30);
}

// The full-resolution layer is culled too (issue 24 item 4): BSP nodes (sort
// free: rows, then cells) whose box is outside the frustum emit no prisms.
// Every dropped tetrahedron lies behind one frustum plane, rays inside the
// frustum integrate the same fog, and the host's terrain is the whole grid.
TEST(GroundFogLod, FullResolutionFrustumCullingDropsOnlyWhatIsOutOfView) {
    const Camera cam = Camera::lookAt({-6.0f, 3.0f, -6.0f}, {4.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(40.0f), {64, 48}, 0.1f, 500.0f);
    const glm::mat4 vp = cam.proj * cam.view;
    auto behindOnePlane = [&](const Tetrahedron& t) {
        for (int i = 0; i < 3; ++i)
            for (float sign : {-1.0f, 1.0f}) {
                const glm::vec4 pl = glm::vec4(vp[0][3], vp[1][3], vp[2][3], vp[3][3]) + sign * glm::vec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
                bool all = true;
                for (const glm::vec3& p : t.position) all = all && glm::dot(glm::vec3(pl), p) + pl.w < 0.0f;
                if (all) return true;
            }
        return false;
    };
    for (bool sortFree : {false, true}) {
        GroundFogDesc d = valleys({33, 33}, 0.8f, false);
        d.sortFree = sortFree;
        auto fog = GroundFog::create(d);
        auto tf = makeGroundFogTransfer({1, 1, 1}, 0.8f);
        ASSERT_TRUE(fog && tf);
        LodFrame culled, all;
        std::vector<glm::vec3> tc, ta;
        ASSERT_TRUE(fog->update(cam, LodRefineDesc{.frustumCull = true}, culled, &tc));
        ASSERT_TRUE(fog->update(cam, LodRefineDesc{.frustumCull = false}, all, &ta));
        EXPECT_GT(culled.stats.nodesCulled, 0u) << sortFree;
        EXPECT_EQ(all.stats.nodesCulled, 0u);
        EXPECT_LT(culled.tets.size() * 3, all.tets.size() * 2) << "a third or more of the grid is out of this view";
        EXPECT_EQ(culled.stats.fullResolution, all.stats.fullResolution);
        EXPECT_EQ(sortedTriangles(tc), sortedTriangles(ta));
        // What was dropped is out of view: the kept tetrahedra are the full list's, in its order, less
        // only tetrahedra wholly behind one plane.
        std::size_t k = 0, dropped = 0;
        for (const Tetrahedron& t : all.tets) {
            if (k < culled.tets.size() && culled.tets[k].position == t.position && culled.tets[k].scalar == t.scalar) {
                ++k;
                continue;
            }
            ++dropped;
            ASSERT_TRUE(behindOnePlane(t)) << "a dropped tetrahedron reaches into the view";
        }
        EXPECT_EQ(k, culled.tets.size()) << "the kept ones are a subsequence of the full list";
        EXPECT_EQ(dropped, all.tets.size() - culled.tets.size());
        std::mt19937 rng(9);
        std::uniform_real_distribution<double> u(-0.3, 0.3); // tan(20 deg) = 0.36 vertically: inside the frustum
        int hits = 0;
        for (int r = 0; r < 120; ++r) {
            const glm::dvec3 dir = glm::dvec3(cam.forward()) + u(rng) * glm::dvec3(cam.right()) + u(rng) * glm::dvec3(cam.up());
            const glm::dvec4 a = integrateRay(culled.tets, *tf, glm::dvec3(cam.eye()), dir, 0.0, 1e4);
            const glm::dvec4 b = integrateRay(all.tets, *tf, glm::dvec3(cam.eye()), dir, 0.0, 1e4);
            hits += b.a > 1e-3;
            EXPECT_EQ(a, b) << "ray " << r;
        }
        EXPECT_GT(hits, 30);
    }
}

// The sort-free model (eq. 10) on the LOD terrain: the same tetrahedra as
// the sorted LOD layer, in a fixed (view-independent) order.
TEST(GroundFogLod, SortFreeEmitsTheSameTetrahedra) {
    GroundFogDesc d = valleys({33, 33}, 0.8f);
    GroundFogDesc free = d;
    free.sortFree = true;
    auto sorted = GroundFog::create(d);
    auto unsorted = GroundFog::create(free);
    ASSERT_TRUE(sorted && unsorted);
    for (const Camera& cam : {farCamera(), insideCamera()}) {
        LodFrame a, b;
        ASSERT_TRUE(sorted->update(cam, LodRefineDesc{.detailC = 3.0f}, a));
        ASSERT_TRUE(unsorted->update(cam, LodRefineDesc{.detailC = 3.0f}, b));
        ASSERT_GT(a.tets.size(), 0u);
        EXPECT_EQ(sortedKeys(a.tets), sortedKeys(b.tets));
    }
}
