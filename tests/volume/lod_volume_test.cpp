// LodVolume: error propagation, refinement, conforming mesh, alternating
// decomposition, morphing continuity, back-to-front order, and the hard cases
// (camera on a vertex / inside a tetrahedron, all-zero and all-one fields,
// n = 1 and the largest n under a memory budget).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <cstdio>
#include <random>
#include <string>
#include <tuple>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/volume.hpp"
#include "volume_test_util.hpp"

using namespace splatfx;
using voltest::barycentric;
using voltest::tetVolume;

namespace {

LodRefineDesc allOff(float c) {
    LodRefineDesc r;
    r.detailC = c;
    r.frustumCull = false;
    r.zeroOpacityTest = false;
    r.clipNear = false;
    return r;
}

Camera cameraAt(glm::vec3 eye, glm::vec3 target, float nearPlane = 0.05f) {
    return Camera::lookAt(eye, target, {0, 0, 1}, glm::radians(60.0f), {64, 48}, nearPlane, 1000.0f);
}

// The emitted mesh's piecewise-linear scalar at p (first tetrahedron holding it).
bool meshValue(const std::vector<Tetrahedron>& tets, glm::dvec3 p, double& out) {
    for (const Tetrahedron& t : tets) {
        glm::vec3 lo = t.position[0], hi = t.position[0];
        for (const glm::vec3& q : t.position) {
            lo = glm::min(lo, q);
            hi = glm::max(hi, q);
        }
        if (p.x < lo.x - 1e-6 || p.y < lo.y - 1e-6 || p.z < lo.z - 1e-6 || p.x > hi.x + 1e-6 || p.y > hi.y + 1e-6 || p.z > hi.z + 1e-6) continue;
        const glm::dvec4 b = barycentric(t, p);
        if (b.x < -1e-9 || b.y < -1e-9 || b.z < -1e-9 || b.w < -1e-9) continue;
        out = b.x * t.scalar[0] + b.y * t.scalar[1] + b.z * t.scalar[2] + b.w * t.scalar[3];
        return true;
    }
    return false;
}

} // namespace

TEST(LodVolume, KMaxIsEquationFour) {
    auto v = LodVolume::create(voltest::randomField({9, 9, 9}, 1), {.minAccuracyC = 3.0f});
    ASSERT_TRUE(v) << v.error();
    EXPECT_DOUBLE_EQ(v->kMax(), 3.0 / (6.0 - std::sqrt(3.0) / 2.0));
}

TEST(LodVolume, KMaxPropagationMakesParentErrorAtLeastKMaxTimesChild) {
    for (DeltaMode mode : {DeltaMode::Max, DeltaMode::Average}) {
        auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 2, true), {.delta = mode});
        ASSERT_TRUE(v) << v.error();
        ASSERT_EQ(v->rootLevel(), 4);
        int pairs = 0;
        for (int l = 2; l <= v->rootLevel(); ++l) {
            const int nodes = 1 << (v->rootLevel() - l);
            for (int z = 0; z < nodes; ++z)
                for (int y = 0; y < nodes; ++y)
                    for (int x = 0; x < nodes; ++x) {
                        const glm::ivec3 n(x, y, z);
                        const double parent = v->deltaAt(l, n);
                        // The stored (16-bit, rounded up) error never understates the local one.
                        EXPECT_GE(parent, v->localDeltaAt(l, n));
                        for (int c = 0; c < 8; ++c) {
                            const glm::ivec3 ch = n * 2 + glm::ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
                            EXPECT_GE(parent, v->kMax() * v->deltaAt(l - 1, ch)) << "level " << l;
                            ++pairs;
                        }
                    }
        }
        EXPECT_EQ(pairs, 8 * (1 + 8 + 64)); // parents at levels 4, 3, 2
    }
}

TEST(LodVolume, PropagationMakesAParentRefineWheneverAChildWould) {
    // Eq. 2: e_child > 1 implies e > 1, for any eye (this is what eq. 4-5 are for).
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 3), {});
    ASSERT_TRUE(v) << v.error();
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-10.0f, 26.0f);
    int childRefines = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const glm::vec3 eye(u(rng), u(rng), u(rng));
        for (float c : {1.0f, 30.0f, 300.0f})
            for (int l = 2; l <= v->rootLevel(); ++l) {
                const int nodes = 1 << (v->rootLevel() - l);
                for (int z = 0; z < nodes; ++z)
                    for (int y = 0; y < nodes; ++y)
                        for (int x = 0; x < nodes; ++x) {
                            const glm::ivec3 n(x, y, z);
                            const double e = v->errorMetric(l, n, eye, c);
                            for (int k = 0; k < 8; ++k) {
                                const glm::ivec3 ch = n * 2 + glm::ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                                if (v->errorMetric(l - 1, ch, eye, c) > 1.0) {
                                    ++childRefines;
                                    EXPECT_GT(e, 1.0);
                                }
                            }
                        }
            }
    }
    EXPECT_GT(childRefines, 1000); // the implication was exercised
}

TEST(LodVolume, AlternatingOrientationGivesAFaceToFaceFinestMesh) {
    // Neighbours use complementary corner sets for the centre tetrahedron (Fig. 1).
    EXPECT_EQ(LodVolume::centreTetCorners({0, 0, 0}) ^ LodVolume::centreTetCorners({1, 0, 0}), 0xFFu);
    EXPECT_EQ(LodVolume::centreTetCorners({0, 0, 0}), LodVolume::centreTetCorners({1, 1, 0}));
    EXPECT_EQ(LodVolume::centreTetCorners({0, 0, 0}), 0b01101001u); // corners 0, 3, 5, 6
    // Refine everything: every interior triangle is shared by exactly two tetrahedra,
    // which fails if two neighbours split their common face along different diagonals.
    auto v = LodVolume::create(voltest::randomField({9, 9, 9}, 4), {});
    ASSERT_TRUE(v) << v.error();
    LodFrame f;
    ASSERT_TRUE(v->update(cameraAt({4, 4, 4}, {8, 4, 4}), allOff(1e9f), nullptr, f));
    ASSERT_EQ(f.tets.size(), v->fullResolutionTets());
    std::map<std::array<std::tuple<int, int, int>, 3>, int> faces;
    for (const Tetrahedron& t : f.tets)
        for (int skip = 0; skip < 4; ++skip) {
            std::array<std::tuple<int, int, int>, 3> key;
            int k = 0;
            for (int i = 0; i < 4; ++i)
                if (i != skip) {
                    const glm::ivec3 p(glm::round(t.position[std::size_t(i)]));
                    key[std::size_t(k++)] = {p.x, p.y, p.z};
                }
            std::sort(key.begin(), key.end());
            ++faces[key];
        }
    for (const auto& entry : faces) {
        const auto& key = entry.first; // a plain reference: clang 14 cannot capture a structured binding
        const int count = entry.second;
        bool boundary = false;
        for (int a = 0; a < 3; ++a) {
            auto coord = [&](int i) {
                return a == 0 ? std::get<0>(key[std::size_t(i)]) : a == 1 ? std::get<1>(key[std::size_t(i)]) : std::get<2>(key[std::size_t(i)]);
            };
            if (coord(0) == coord(1) && coord(1) == coord(2) && (coord(0) == 0 || coord(0) == 8)) boundary = true;
        }
        EXPECT_EQ(count, boundary ? 1 : 2);
    }
}

namespace {

// The conforming invariant: (1) a grid point carries one value in every tetrahedron
// that has it as a vertex; (2) a vertex lying on a face or edge of a coarser
// tetrahedron (a T-vertex) has that tetrahedron's interpolated value. With both,
// the piecewise-linear field is continuous across every face. (3) The tetrahedra
// tile the domain (volumes sum to it).
void expectConforming(const LodVolume& v, const std::vector<Tetrahedron>& tets, int& tVertexChecks, int& levelsSeen) {
    std::map<std::tuple<float, float, float>, float> value;
    double volume = 0.0;
    std::map<double, int> sizes;
    for (const Tetrahedron& t : tets) {
        volume += tetVolume(t);
        double edge = 0.0;
        for (int i = 1; i < 4; ++i) edge = std::max(edge, double(glm::length(t.position[std::size_t(i)] - t.position[0])));
        ++sizes[std::round(edge * 1000.0)];
        for (int i = 0; i < 4; ++i) {
            const auto key = std::make_tuple(t.position[std::size_t(i)].x, t.position[std::size_t(i)].y, t.position[std::size_t(i)].z);
            auto [it, inserted] = value.insert({key, t.scalar[std::size_t(i)]});
            if (!inserted) { EXPECT_EQ(it->second, t.scalar[std::size_t(i)]) << "a vertex carries two values"; }
        }
    }
    const glm::dvec3 ext = glm::dvec3(v.pointDims() - 1) * double(v.spacingWorld());
    EXPECT_NEAR(volume, ext.x * ext.y * ext.z, 1e-6 * ext.x * ext.y * ext.z);
    levelsSeen = int(sizes.size());
    for (const auto& [key, s] : value) {
        const glm::dvec3 p(std::get<0>(key), std::get<1>(key), std::get<2>(key));
        for (const Tetrahedron& t : tets) {
            bool isVertex = false;
            for (const glm::vec3& q : t.position)
                if (glm::dvec3(q) == p) isVertex = true;
            if (isVertex) continue;
            glm::vec3 lo = t.position[0], hi = t.position[0];
            for (const glm::vec3& q : t.position) {
                lo = glm::min(lo, q);
                hi = glm::max(hi, q);
            }
            if (p.x < lo.x || p.y < lo.y || p.z < lo.z || p.x > hi.x || p.y > hi.y || p.z > hi.z) continue;
            const glm::dvec4 b = barycentric(t, p);
            // On the tetrahedron's boundary (one barycentric zero), never inside it:
            // a vertex strictly inside another tetrahedron would be an overlap.
            const double bmin = std::min({b.x, b.y, b.z, b.w});
            if (bmin < -1e-9) continue;
            EXPECT_LT(bmin, 1e-9) << "a vertex lies inside another tetrahedron";
            const double interp = b.x * t.scalar[0] + b.y * t.scalar[1] + b.z * t.scalar[2] + b.w * t.scalar[3];
            // Both sides are a few float operations on values in [0, 1]: 32 float ulps at 1.
            EXPECT_NEAR(interp, double(s), 4e-6) << "T-vertex value differs from the coarser side";
            ++tVertexChecks;
        }
    }
}

} // namespace

TEST(LodVolume, RefinementProducesAConformingMesh) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 5), {});
    ASSERT_TRUE(v) << v.error();
    int checks = 0, maxLevels = 0;
    const glm::vec3 eyes[] = {{-6, 3, 8}, {8.3f, 8.1f, 7.7f}, {2, 15, 1}, {30, 30, 30}};
    for (const glm::vec3& eye : eyes)
        for (bool morph : {true, false}) {
            LodFrame f;
            // c = 2 mixes four leaf sizes for this field (c = 10 already refines it all).
            LodRefineDesc r = allOff(2.0f);
            r.morph = morph;
            ASSERT_TRUE(v->update(cameraAt(eye, {8, 8, 8}), r, nullptr, f));
            int levels = 0;
            expectConforming(*v, f.tets, checks, levels);
            maxLevels = std::max(maxLevels, levels);
        }
    EXPECT_GE(maxLevels, 3); // leaves of three sizes meet: T-vertices were there to check
    EXPECT_GT(checks, 100);
}

namespace {

// Largest change of the emitted field at fixed probes between consecutive
// frames of an eye moving `step` per frame.
double largestProbeJump(LodVolume& v, bool morph, float step, int frames, const std::vector<glm::dvec3>& probes) {
    LodRefineDesc r = allOff(2.0f); // mixed levels along the flight (c = 10 refines all of it)
    r.morph = morph;
    std::vector<double> prev;
    double worst = 0.0;
    for (int i = 0; i < frames; ++i) {
        const glm::vec3 eye = glm::vec3(-20.0f, 5.3f, 6.1f) + glm::vec3(step * float(i), 0.0f, 0.0f);
        LodFrame f;
        EXPECT_TRUE(v.update(cameraAt(eye, eye + glm::vec3(1, 0, 0)), r, nullptr, f));
        std::vector<double> cur(probes.size());
        for (std::size_t k = 0; k < probes.size(); ++k) EXPECT_TRUE(meshValue(f.tets, probes[k], cur[k]));
        if (!prev.empty())
            for (std::size_t k = 0; k < probes.size(); ++k) worst = std::max(worst, std::fabs(cur[k] - prev[k]));
        prev = cur;
    }
    return worst;
}

} // namespace

TEST(LodVolume, MorphingKeepsTheFieldContinuousAndWithoutItItJumps) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 6), {});
    ASSERT_TRUE(v) << v.error();
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> u(0.0, 16.0);
    std::vector<glm::dvec3> probes;
    for (int i = 0; i < 60; ++i) probes.push_back({u(rng), u(rng), u(rng)});
    const float step = 0.02f;
    const int frames = 1200; // eye from x = -20 to x = 4: into the volume
    // Bound: a vertex value (1 - w) coarse + w S (eq. 8) moves by |dw| |S - coarse| <= |dw|
    // per level it depends on (its own and, through `coarse`, every coarser one).
    // While e' is in (0, 1), e is in (1, 2) so d >= s C / 2 and |de| <= e |dd| / d <= 4 step / (s C);
    // the 8-bit e' adds up to 1/254 per change. A probe is a convex combination of vertices.
    double bound = 0.0;
    for (int l = 1; l <= v->rootLevel(); ++l) {
        const double s = double(1 << l) * v->spacingWorld();
        bound += 4.0 * step / (s * v->minAccuracyC() - 2.0 * step) + 1.0 / 254.0;
    }
    const double withMorph = largestProbeJump(*v, true, step, frames, probes);
    const double without = largestProbeJump(*v, false, step, frames, probes);
    std::printf("largest per-frame probe change: with morphing %.4f, without %.4f, bound %.4f\n", withMorph, without, bound);
    EXPECT_LE(withMorph, bound);
    EXPECT_GT(without, bound) << "without morphing the field should pop";
    EXPECT_GT(without, 4.0 * withMorph);
}

namespace {

// Later tetrahedra must be nearer: along any ray from the eye, a tetrahedron
// emitted after another is not behind it (the octree's BSP order, sec. 4, is a
// visibility order for convex cells).
void expectBackToFront(const std::vector<Tetrahedron>& tets, glm::dvec3 eye, const std::vector<glm::dvec3>& dirs, int& overlaps) {
    for (const glm::dvec3& d : dirs) {
        std::vector<std::pair<std::size_t, glm::dvec2>> hits;
        for (std::size_t i = 0; i < tets.size(); ++i) {
            const glm::dvec2 iv = voltest::rayInterval(tets[i], eye, d);
            if (iv.y - std::max(iv.x, 0.0) > 1e-4) hits.push_back({i, glm::dvec2(std::max(iv.x, 0.0), iv.y)});
        }
        // Emission order is index order; a later one must end before an earlier one starts.
        // 1e-4: positions are floats of size <= 40 (1e-5 rounding), ten times that.
        for (std::size_t a = 0; a < hits.size(); ++a)
            for (std::size_t b = a + 1; b < hits.size(); ++b) {
                EXPECT_GE(hits[a].second.x, hits[b].second.y - 1e-4)
                    << "tet " << hits[b].first << " emitted after " << hits[a].first << " but behind it";
                ++overlaps;
            }
    }
}

std::vector<glm::dvec3> viewRays(const Camera& cam, int n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    std::vector<glm::dvec3> dirs;
    for (int i = 0; i < n; ++i)
        dirs.push_back(glm::normalize(glm::dvec3(cam.forward()) + u(rng) * glm::dvec3(cam.right()) + u(rng) * glm::dvec3(cam.up())));
    return dirs;
}

} // namespace

TEST(LodVolume, EmittedTetrahedraAreInBackToFrontOrder) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 9), {});
    ASSERT_TRUE(v) << v.error();
    int overlaps = 0;
    const std::pair<glm::vec3, glm::vec3> views[] = {
        {{-12, 5, 20}, {8, 8, 8}}, {{8.2f, 7.9f, 8.1f}, {16, 3, 9}}, {{25, -3, 4}, {4, 9, 12}}, {{3.5f, 3.5f, 3.5f}, {3.5f, 20, 3.5f}}};
    for (const auto& [eye, target] : views) {
        const Camera cam = cameraAt(eye, target, 0.3f);
        LodRefineDesc r;
        r.detailC = 2.0f; // mixed leaf sizes
        r.zeroOpacityTest = false;
        LodFrame f;
        ASSERT_TRUE(v->update(cam, r, nullptr, f));
        ASSERT_FALSE(f.tets.empty());
        expectBackToFront(f.tets, glm::dvec3(eye), viewRays(cam, 40, 11), overlaps);
    }
    EXPECT_GT(overlaps, 1000);
}

TEST(LodVolume, OrthographicViewsAreOrderedAlongTheViewDirection) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 19), {});
    ASSERT_TRUE(v) << v.error();
    const glm::vec3 eye(-10, 30, 25), target(8, 8, 8);
    const Camera cam =
        Camera::fromMatrices(glm::lookAt(eye, target, glm::vec3(0, 0, 1)), glm::ortho(-15.0f, 15.0f, -12.0f, 12.0f, 0.5f, 200.0f), {64, 48});
    ASSERT_FALSE(cam.perspective());
    LodRefineDesc r;
    r.detailC = 2.0f;
    r.zeroOpacityTest = false;
    LodFrame f;
    ASSERT_TRUE(v->update(cam, r, nullptr, f));
    ASSERT_FALSE(f.tets.empty());
    // Parallel rays along the view direction from a grid of points on the near plane.
    int overlaps = 0;
    for (int i = 0; i < 30; ++i) {
        const glm::dvec3 o =
            glm::dvec3(eye) + double((i % 6) - 2.5) * 2.0 * glm::dvec3(cam.right()) + double((i / 6) - 2.0) * 2.0 * glm::dvec3(cam.up());
        expectBackToFront(f.tets, o, {glm::dvec3(cam.forward())}, overlaps);
    }
    EXPECT_GT(overlaps, 200);
}

TEST(LodVolume, RootForestIsOrderedBackToFrontToo) {
    // 33x33x9 points: 4x4x1 roots of n = 3.
    auto v = LodVolume::create(voltest::randomField({33, 33, 9}, 10), {});
    ASSERT_TRUE(v) << v.error();
    EXPECT_EQ(v->roots(), glm::ivec3(4, 4, 1));
    const Camera cam = cameraAt({-5, 40, 15}, {16, 10, 4}, 0.3f);
    LodRefineDesc r;
    r.detailC = 2.0f;
    r.zeroOpacityTest = false;
    LodFrame f;
    ASSERT_TRUE(v->update(cam, r, nullptr, f));
    int overlaps = 0;
    expectBackToFront(f.tets, glm::dvec3(-5, 40, 15), viewRays(cam, 30, 12), overlaps);
    EXPECT_GT(overlaps, 200);
}

TEST(LodVolumeHardCases, CameraOnAVertexAndInsideATetrahedron) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 13), {});
    ASSERT_TRUE(v) << v.error();
    for (const glm::vec3 eye : {glm::vec3(8, 8, 8), glm::vec3(8.31f, 8.27f, 8.12f)}) {
        // Looking along +x: the visible part of the box is x >= eye.x + near.
        const float nearPlane = 0.1f;
        const Camera cam = Camera::lookAt(eye, eye + glm::vec3(1, 0, 0), {0, 0, 1}, glm::radians(60.0f), {64, 48}, nearPlane, 1000.0f);
        LodRefineDesc r = allOff(30.0f);
        r.clipNear = true;
        LodFrame f;
        ASSERT_TRUE(v->update(cam, r, nullptr, f));
        double volume = 0.0;
        for (const Tetrahedron& t : f.tets) {
            for (int i = 0; i < 4; ++i) {
                ASSERT_TRUE(std::isfinite(t.position[std::size_t(i)].x) && std::isfinite(t.scalar[std::size_t(i)]));
                // Visible side of the near plane (float rounding of the cut: 1e-5 at size 16).
                EXPECT_GE(t.position[std::size_t(i)].x, eye.x + nearPlane - 1e-5f);
            }
            EXPECT_GT(tetVolume(t), 0.0);
            volume += tetVolume(t);
        }
        EXPECT_NEAR(volume, (16.0 - double(eye.x + nearPlane)) * 256.0, 1e-5 * 4096.0);
        EXPECT_GT(f.stats.clippedInput, 0u);
    }
}

TEST(LodVolumeHardCases, AllZerosAndAllOnes) {
    auto tf = makeCloudTransfer({});
    ASSERT_TRUE(tf) << tf.error();
    const Camera cam = cameraAt({-10, 8, 8}, {8, 8, 8});
    {
        auto v = LodVolume::create(voltest::constantField({17, 17, 17}, 0.0f), {});
        ASSERT_TRUE(v) << v.error();
        EXPECT_EQ(v->deltaAt(v->rootLevel(), {0, 0, 0}), 0.0);
        LodFrame f;
        ASSERT_TRUE(v->update(cam, {}, &*tf, f));
        EXPECT_TRUE(f.tets.empty()) << "zero density is below the threshold: the ZOT drops it all";
        EXPECT_EQ(v->integrateRay(*tf, {-10, 8, 8}, {1, 0, 0}, 0.0, 100.0), glm::dvec4(0.0));
    }
    {
        auto v = LodVolume::create(voltest::constantField({17, 17, 17}, 1.0f), {});
        ASSERT_TRUE(v) << v.error();
        LodFrame f;
        ASSERT_TRUE(v->update(cam, {}, &*tf, f));
        ASSERT_FALSE(f.tets.empty());
        for (const Tetrahedron& t : f.tets)
            for (float s : t.scalar) EXPECT_EQ(s, 1.0f);
        // A ray through 16 units of density 1: alpha = 1 - exp(-rho(1) 16), colour kappa(1) alpha.
        const glm::dvec4 r = v->integrateRay(*tf, {-10, 8.3, 8.7}, {1, 0, 0}, 0.0, 100.0);
        const double a = 1.0 - std::exp(-2.0 * 16.0);
        EXPECT_NEAR(r.a, a, 1e-12);
        EXPECT_NEAR(r.b, double(0.45f) * a, 1e-9);
    }
}

TEST(LodVolumeHardCases, SmallestVolumeNIsOne) {
    auto v = LodVolume::create(voltest::randomField({3, 3, 3}, 14), {});
    ASSERT_TRUE(v) << v.error();
    EXPECT_EQ(v->rootLevel(), 1);
    EXPECT_EQ(v->fullResolutionTets(), 40u);
    for (float c : {0.0f, 1e9f}) {
        LodFrame f;
        ASSERT_TRUE(v->update(cameraAt({1.2f, 0.9f, 10}, {1, 1, 1}), allOff(c), nullptr, f));
        int dummy = 0, levels = 0;
        expectConforming(*v, f.tets, dummy, levels);
        EXPECT_TRUE(f.tets.size() == 5 || f.tets.size() == 40);
    }
}

TEST(LodVolumeHardCases, LargestNUnderTheMemoryBudgetAndAClearErrorBeyond) {
    // A small budget keeps the test light; the rule is the same for the 1 GiB default
    // (largest cube n = 9, 231 MB with one field).
    const std::size_t budget = std::size_t(1) << 20; // 1 MiB
    int largest = 1;
    while (LodVolume::bytesFor(glm::ivec3((1 << (largest + 1)) + 1), false) <= budget) ++largest;
    EXPECT_EQ(largest, 6); // 65^3 points at ~1.71 bytes each = 470 kB; 129^3 would be 3.7 MB
    EXPECT_LE(LodVolume::bytesFor(glm::ivec3(513), false), std::size_t(1) << 30);
    EXPECT_GT(LodVolume::bytesFor(glm::ivec3(1025), false), std::size_t(1) << 30);
    const int side = (1 << largest) + 1;
    auto v = LodVolume::create(voltest::constantField(glm::ivec3(side), 0.25f), {.memoryBudgetBytes = budget});
    ASSERT_TRUE(v) << v.error();
    EXPECT_EQ(v->rootLevel(), largest);
    EXPECT_LE(v->memoryBytes(), budget);
    EXPECT_EQ(v->memoryBytes(), LodVolume::bytesFor(glm::ivec3(side), false));
    const int beyond = (1 << (largest + 1)) + 1;
    splatfx::ScalarVolume big;
    big.dims = glm::ivec3(beyond);
    big.scalar.assign(std::size_t(beyond) * beyond * beyond, 0.0f);
    auto w = LodVolume::create(big, {.memoryBudgetBytes = budget});
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().find("memoryBudgetBytes"), std::string::npos) << w.error();
}

TEST(LodVolumeHardCases, BadInputGetsAMessageNamingTheField) {
    auto field = voltest::randomField({5, 5, 5}, 15);
    field.scalar[7] = std::nanf("");
    auto a = LodVolume::create(field, {});
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("ScalarVolume.scalar[7]"), std::string::npos) << a.error();
    field.scalar[7] = 0.5f;
    field.scalar.pop_back();
    auto b = LodVolume::create(field, {});
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().find("ScalarVolume.scalar"), std::string::npos) << b.error();
    auto c = LodVolume::create(voltest::randomField({5, 5, 5}, 15), {.minAccuracyC = 1.5f});
    ASSERT_FALSE(c);
    EXPECT_NE(c.error().find("minAccuracyC"), std::string::npos) << c.error();
    auto d = LodVolume::create(voltest::randomField({1, 5, 5}, 15), {});
    ASSERT_FALSE(d);
    EXPECT_NE(d.error().find("dims"), std::string::npos) << d.error();
    auto v = LodVolume::create(voltest::randomField({5, 5, 5}, 15), {});
    ASSERT_TRUE(v);
    LodFrame f;
    Camera cam = cameraAt({-3, 2, 2}, {2, 2, 2});
    Status s = v->update(cam, {}, nullptr, f);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("zeroOpacityTest"), std::string::npos) << s.error();
    cam.view[3][0] = std::numeric_limits<float>::infinity();
    Status s2 = v->update(cam, allOff(1.0f), nullptr, f);
    ASSERT_FALSE(s2);
    EXPECT_NE(s2.error().find("camera"), std::string::npos) << s2.error();
}

TEST(LodVolume, PaddingToTwoToTheNPlusOne) {
    auto v = LodVolume::create(voltest::constantField({10, 6, 5}, 0.5f), {.padValue = 0.0f});
    ASSERT_TRUE(v) << v.error();
    // Smallest side 5 -> n = 2 (4 cells per root); 9 cells along x need 3 roots.
    EXPECT_EQ(v->rootLevel(), 2);
    EXPECT_EQ(v->pointDims(), glm::ivec3(13, 9, 5));
    EXPECT_EQ(v->scalarAt({9, 5, 4}), float(std::lround(0.5f * 255.0f)) / 255.0f);
    EXPECT_EQ(v->scalarAt({10, 5, 4}), 0.0f);
}

TEST(LodVolume, RayThroughTheFinestMeshMatchesFineQuadrature) {
    auto field = voltest::randomField({9, 9, 9}, 16, true);
    auto v = LodVolume::create(field, {});
    ASSERT_TRUE(v) << v.error();
    auto tf = TransferFunction::create({{0.0f, {1, 0.2f, 0.1f}, 0.0f}, {0.3f, {0.2f, 1, 0.3f}, 0.4f}, {1.0f, {0.1f, 0.3f, 1}, 1.5f}});
    ASSERT_TRUE(tf) << tf.error();
    const glm::dvec3 o(-1.3, 2.21, 3.7), d = glm::normalize(glm::dvec3(1.0, 0.31, 0.17));
    const glm::dvec4 exact = v->integrateRay(*tf, o, d, 0.0, 20.0);
    // Independent path: midpoint rule on the sampled finest field over exactly the part of
    // the ray inside the grid (slab test), step h and h/2.
    double tIn = 0.0, tOut = 20.0;
    for (int a = 0; a < 3; ++a) {
        double ta = (0.0 - o[a]) / d[a], tb = (8.0 - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        tIn = std::max(tIn, ta);
        tOut = std::min(tOut, tb);
    }
    ASSERT_GT(tOut, tIn);
    auto quad = [&](int steps) {
        glm::dvec3 c(0.0);
        double T = 1.0;
        const double h = (tOut - tIn) / steps;
        for (int i = 0; i < steps; ++i) {
            const glm::dvec3 p = o + d * (tIn + (i + 0.5) * h);
            const glm::dvec2 s = v->sampleFinest(p);
            const double k = tf->extinction(s.x) * s.y;
            const double a = 1.0 - std::exp(-k * h);
            c += T * tf->color(s.x) * a;
            T *= 1.0 - a;
        }
        return glm::dvec4(c, 1.0 - T);
    };
    const glm::dvec4 q1 = quad(20000), q2 = quad(40000);
    EXPECT_GT(exact.a, 0.3);
    for (int ch = 0; ch < 4; ++ch) {
        // Midpoint rule is second order (kinks only at tetrahedron faces): its error at h/2
        // is ~1/3 of |q1 - q2|; 2x that leaves 6x room for the non-asymptotic part.
        EXPECT_NEAR(exact[ch], q2[ch], 2.0 * std::fabs(q1[ch] - q2[ch]) + 1e-9) << "channel " << ch;
    }
}

TEST(LodVolume, RayThroughTheEmittedFinestMeshEqualsTheGridReference) {
    // Fully refined, the emitted list is the finest mesh: both integrators see one
    // piecewise-linear field (same 8-bit values, integer positions), so they agree
    // to the segment integrator's accuracy (1e-12) plus float barycentrics (~1e-7).
    auto v = LodVolume::create(voltest::randomField({9, 9, 9}, 17, true), {});
    ASSERT_TRUE(v) << v.error();
    auto tf = TransferFunction::create({{0.0f, {1, 0.2f, 0.1f}, 0.0f}, {0.3f, {0.2f, 1, 0.3f}, 0.4f}, {1.0f, {0.1f, 0.3f, 1}, 1.5f}});
    ASSERT_TRUE(tf);
    LodFrame f;
    ASSERT_TRUE(v->update(cameraAt({-3, 4, 4}, {4, 4, 4}), allOff(1e9f), nullptr, f));
    ASSERT_EQ(f.tets.size(), v->fullResolutionTets());
    std::mt19937 rng(18);
    std::uniform_real_distribution<double> u(0.5, 7.5);
    for (int i = 0; i < 20; ++i) {
        const glm::dvec3 o(-3.0, u(rng), u(rng));
        const glm::dvec3 d = glm::normalize(glm::dvec3(11.0, u(rng), u(rng)) - o);
        const glm::dvec4 a = v->integrateRay(*tf, o, d, 0.0, 30.0);
        const glm::dvec4 b = integrateRay(f.tets, *tf, o, d, 0.0, 30.0);
        for (int ch = 0; ch < 4; ++ch) EXPECT_NEAR(a[ch], b[ch], 1e-6) << "ray " << i << " channel " << ch;
    }
}

TEST(LodVolumeHardCases, NonFiniteRaysAndPointsGiveZero) {
    auto v = LodVolume::create(voltest::randomField({5, 5, 5}, 20), {});
    ASSERT_TRUE(v);
    auto tf = makeCloudTransfer({});
    ASSERT_TRUE(tf);
    const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(v->integrateRay(*tf, {nan, 1, 1}, {1, 0, 0}, 0.0, 10.0), glm::dvec4(0.0));
    EXPECT_EQ(v->integrateRay(*tf, {-1, 1, 1}, {inf, 0, 0}, 0.0, 10.0), glm::dvec4(0.0));
    EXPECT_EQ(v->integrateRay(*tf, {-1, 1, 1}, {0, 0, 0}, 0.0, 10.0), glm::dvec4(0.0));
    EXPECT_EQ(v->sampleFinest({nan, 0, 0}), glm::dvec2(0.0));
    const glm::dvec4 r = v->integrateRay(*tf, {-1, 1.5, 1.5}, {1, 0, 0}, 0.0, inf); // to infinity: the grid ends it
    EXPECT_TRUE(std::isfinite(r.a));
}

// ---- More edges (issue 24, item 3; docs/STABILITY.md, "LOD clouds") -------------------

// A node of zero deviation beside one of huge deviation: a constant field
// with a single spike. Propagation must refine the spike's ancestors and
// their neighbours enough to stay conforming, and the flat part stays coarse.
TEST(LodVolumeHardCases, AFlatNodeBesideASpikeStaysConforming) {
    ScalarVolume field = voltest::constantField({33, 33, 33}, 0.3f);
    field.scalar[std::size_t(20 + 33 * (16 + 33 * 16))] = 1.0f;
    auto v = LodVolume::create(field, {});
    ASSERT_TRUE(v) << v.error();
    LodFrame f;
    ASSERT_TRUE(v->update(cameraAt({-20, 16, 16}, {16, 16, 16}), allOff(30.0f), nullptr, f));
    int tChecks = 0, levels = 0;
    expectConforming(*v, f.tets, tChecks, levels);
    EXPECT_GE(levels, 3) << "fine at the spike, coarse in the flat field";
    EXPECT_LT(f.tets.size(), v->fullResolutionTets() / 4);
    double at = -1.0;
    ASSERT_TRUE(meshValue(f.tets, {20.0, 16.0, 16.0}, at));
    EXPECT_NEAR(at, 1.0, 1.0 / 255.0) << "the spike itself is drawn at full resolution";
}

// Dims far from 2^n + 1 on each axis (17 x 5 x 33): padded with padValue;
// the mesh tiles the padded box and carries the pad value outside the data.
TEST(LodVolumeHardCases, UnevenDimsArePaddedAndTiled) {
    for (float pad : {0.0f, 1.0f}) {
        auto v = LodVolume::create(voltest::randomField({17, 5, 33}, 31), {.padValue = pad});
        ASSERT_TRUE(v) << v.error();
        LodFrame f;
        ASSERT_TRUE(v->update(cameraAt({-20, 10, 10}, {8, 2, 16}), allOff(1e9f), nullptr, f));
        int tChecks = 0, levels = 0;
        expectConforming(*v, f.tets, tChecks, levels);
        const glm::ivec3 dims = v->pointDims();
        if (dims.y > 5) { EXPECT_EQ(v->scalarAt({0, dims.y - 1, 0}), pad); }
    }
}

// C at the smallest float above sqrt(3), eq. 4's limit: K_max is eq. 4's
// value there, the mesh is conforming; sqrt(3) itself (as a float, just
// under it) is refused naming the field.
TEST(LodVolumeHardCases, MinAccuracyCJustAboveItsLimitGivesEquationFour) {
    const float c = 1.7320509f;
    ASSERT_GT(double(c), std::sqrt(3.0));
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 32), {.minAccuracyC = c});
    ASSERT_TRUE(v) << v.error();
    EXPECT_NEAR(v->kMax(), double(c) / (2.0 * double(c) - 0.5 * std::sqrt(3.0)), 1e-12);
    auto under = LodVolume::create(voltest::randomField({5, 5, 5}, 32), {.minAccuracyC = std::nextafter(c, 0.0f)});
    ASSERT_FALSE(under);
    EXPECT_NE(under.error().find("minAccuracyC"), std::string::npos) << under.error();
    LodFrame f;
    ASSERT_TRUE(v->update(cameraAt({-10, 8, 8}, {8, 8, 8}), allOff(10.0f), nullptr, f));
    int tChecks = 0, levels = 0;
    expectConforming(*v, f.tets, tChecks, levels);
}

// An eye 10^6 units away: every error metric is tiny, the roots alone are
// drawn; at 10^-6 from a grid point (inside r of every node) everything is fine.
TEST(LodVolumeHardCases, EyeAMillionUnitsAwayDrawsTheRootsAndAMicronAwayTheFinest) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 33), {});
    ASSERT_TRUE(v) << v.error();
    LodFrame far, near;
    ASSERT_TRUE(v->update(cameraAt({-1e6f, 8, 8}, {8, 8, 8}), allOff(10.0f), nullptr, far));
    EXPECT_EQ(far.tets.size(), 5u * std::size_t(v->roots().x * v->roots().y * v->roots().z));
    ASSERT_TRUE(v->update(cameraAt({8.000001f, 8, 8}, {16, 8, 8}), allOff(10.0f), nullptr, near));
    int tChecks = 0, levels = 0;
    expectConforming(*v, near.tets, tChecks, levels);
    EXPECT_GT(near.tets.size(), far.tets.size());
}

// The near plane coplanar with a face of the box (the eye on the face,
// looking along its normal): the clipped volume is the box beyond the plane.
TEST(LodVolumeHardCases, NearPlaneCoplanarWithTheBoxFace) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 34), {});
    ASSERT_TRUE(v) << v.error();
    const float nearPlane = 0.1f;
    const Camera cam = Camera::lookAt({-0.1f, 8, 8}, {16, 8, 8}, {0, 0, 1}, glm::radians(60.0f), {64, 48}, nearPlane, 1000.0f);
    LodRefineDesc r = allOff(10.0f);
    r.clipNear = true;
    LodFrame f;
    ASSERT_TRUE(v->update(cam, r, nullptr, f));
    double volume = 0.0;
    for (const Tetrahedron& t : f.tets) {
        EXPECT_GT(tetVolume(t), 0.0);
        volume += tetVolume(t);
    }
    EXPECT_NEAR(volume, 16.0 * 16.0 * 16.0, 1e-5 * 4096.0) << "the plane is the face: nothing is cut away";
}

// A ray exactly in a plane of shared faces (x = 8, a lattice plane) and one
// 10^-9 beside it: the integral is continuous (no face counted twice or skipped).
TEST(LodVolumeHardCases, ARayInAPlaneOfSharedFacesIntegratesContinuously) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 35), {});
    ASSERT_TRUE(v) << v.error();
    auto tf = TransferFunction::create({{0.0f, {1, 0.2f, 0.1f}, 0.1f}, {1.0f, {0.1f, 0.3f, 1}, 0.6f}});
    ASSERT_TRUE(tf);
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.0, 1.0, 0.37));
    const glm::dvec4 on = v->integrateRay(*tf, {8.0, -1.0, 2.0}, d, 0.0, 40.0);
    const glm::dvec4 beside = v->integrateRay(*tf, {8.0 + 1e-9, -1.0, 2.0}, d, 0.0, 40.0);
    for (int ch = 0; ch < 4; ++ch) EXPECT_NEAR(on[ch], beside[ch], 1e-6) << ch;
    EXPECT_GT(on.a, 0.1);
}

// A ray through a grid point shared by 24 tetrahedra and along a lattice
// edge: as continuous as one 10^-9 off it.
TEST(LodVolumeHardCases, ARayThroughAGridPointAndAlongAnEdge) {
    auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 36), {});
    ASSERT_TRUE(v) << v.error();
    auto tf = TransferFunction::create({{0.0f, {1, 0.2f, 0.1f}, 0.1f}, {1.0f, {0.1f, 0.3f, 1}, 0.6f}});
    ASSERT_TRUE(tf);
    for (const glm::dvec3 d : {glm::normalize(glm::dvec3(1.0, 1.0, 1.0)), glm::dvec3(1.0, 0.0, 0.0)}) {
        const glm::dvec3 through(8.0, 8.0, 8.0);
        const glm::dvec4 on = v->integrateRay(*tf, through - 20.0 * d, d, 0.0, 60.0);
        const glm::dvec4 off = v->integrateRay(*tf, through - 20.0 * d + glm::dvec3(0.0, 1e-9, -1e-9), d, 0.0, 60.0);
        for (int ch = 0; ch < 4; ++ch) EXPECT_NEAR(on[ch], off[ch], 1e-6) << ch;
    }
}

// Length scales of 0 everywhere (no extinction length at all): finite
// tetrahedra and a finite, transparent-or-not but never NaN ray integral.
TEST(LodVolumeHardCases, ZeroLengthScalesEverywhereStayFinite) {
    ScalarVolume field = voltest::randomField({9, 9, 9}, 37, true);
    std::fill(field.lengthScale.begin(), field.lengthScale.end(), 0.0f);
    auto v = LodVolume::create(field, {});
    ASSERT_TRUE(v) << v.error();
    auto tf = makeCloudTransfer({});
    ASSERT_TRUE(tf);
    LodFrame f;
    ASSERT_TRUE(v->update(cameraAt({-10, 4, 4}, {4, 4, 4}), allOff(10.0f), nullptr, f));
    for (const Tetrahedron& t : f.tets)
        for (float l : t.lengthScale) ASSERT_EQ(l, 0.0f);
    const glm::dvec4 r = v->integrateRay(*tf, {-1, 4.2, 3.9}, {1, 0, 0}, 0.0, 20.0);
    for (int ch = 0; ch < 4; ++ch) EXPECT_TRUE(std::isfinite(r[ch]));
}

// Grid spacings of 10^-4 and 10^4: the mesh scales, no tetrahedron degenerates.
TEST(LodVolumeHardCases, SpacingsFromATenthOfAMillimetreToTenKilometres) {
    for (float s : {1e-4f, 1e4f}) {
        auto v = LodVolume::create(voltest::randomField({9, 9, 9}, 38), {.originWorld = glm::vec3(3.0f * s), .spacingWorld = s});
        ASSERT_TRUE(v) << v.error();
        const glm::vec3 c = v->originWorld() + glm::vec3(4.0f * s);
        LodFrame f;
        ASSERT_TRUE(v->update(cameraAt(c - glm::vec3(10.0f * s, 0, 0), c), allOff(1e9f), nullptr, f));
        int tChecks = 0, levels = 0;
        expectConforming(*v, f.tets, tChecks, levels);
    }
}

// An explicit root level equal to the grid's own (one root for the whole
// volume) and the smallest (roots of 2 cells: a forest of 4^3 roots).
TEST(LodVolumeHardCases, OneRootOrAForestOfTheSmallestRoots) {
    for (int root : {4, 1}) {
        auto v = LodVolume::create(voltest::randomField({17, 17, 17}, 39), {.rootLevel = root});
        ASSERT_TRUE(v) << v.error();
        EXPECT_EQ(v->rootLevel(), root);
        LodFrame f;
        ASSERT_TRUE(v->update(cameraAt({-10, 8, 8}, {8, 8, 8}), allOff(10.0f), nullptr, f));
        int tChecks = 0, levels = 0;
        expectConforming(*v, f.tets, tChecks, levels);
    }
}
