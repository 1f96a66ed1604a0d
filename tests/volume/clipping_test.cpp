// Volumetric clipping at a plane (sec. 4.3): the general cases against closed
// forms, and the hard ones (plane through a vertex, along a face, degenerate
// tetrahedra).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/volume.hpp"
#include "volume_test_util.hpp"

using namespace splatfx;
using voltest::tetVolume;

namespace {

// A linear field, so every clipped vertex's value can be checked exactly.
float field(glm::vec3 p) { return 0.1f + 0.2f * p.x + 0.3f * p.y - 0.15f * p.z; }

Tetrahedron makeTet(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    Tetrahedron t;
    t.position = {a, b, c, d};
    for (int i = 0; i < 4; ++i) {
        t.scalar[std::size_t(i)] = field(t.position[std::size_t(i)]);
        t.lengthScale[std::size_t(i)] = 1.0f;
    }
    return t;
}

const Tetrahedron kTet = makeTet({0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}); // volume 4/3

void expectValid(const std::vector<Tetrahedron>& out, glm::vec3 n, float offset) {
    for (const Tetrahedron& t : out) {
        EXPECT_GT(tetVolume(t), 0.0); // positively oriented, not degenerate
        for (int i = 0; i < 4; ++i) {
            EXPECT_GE(glm::dot(n, t.position[std::size_t(i)]) - offset, -1e-6f);
            // Interpolated along edges of a linear field: exact up to float rounding (values ~1).
            EXPECT_NEAR(t.scalar[std::size_t(i)], field(t.position[std::size_t(i)]), 1e-6f);
        }
    }
}

double sumVolume(const std::vector<Tetrahedron>& v) {
    double s = 0.0;
    for (const Tetrahedron& t : v) s += tetVolume(t);
    return s;
}

} // namespace

TEST(Clipping, OneVertexCutOffLeavesAPrismOfThree) {
    // x >= 1.5 removes... keep x <= 1.5 side: normal -x, offset -1.5. Vertex (2,0,0) is cut off.
    std::vector<Tetrahedron> out;
    EXPECT_EQ(clipTetrahedron(kTet, {-1, 0, 0}, -1.5f, out), 3);
    expectValid(out, {-1, 0, 0}, -1.5f);
    // The removed tip is similar with ratio 0.5/2: volume (1/4)^3 of the whole.
    EXPECT_NEAR(sumVolume(out), 4.0 / 3.0 * (1.0 - 1.0 / 64.0), 1e-6);
}

TEST(Clipping, ThreeVerticesCutOffLeaveATetrahedron) {
    std::vector<Tetrahedron> out;
    EXPECT_EQ(clipTetrahedron(kTet, {1, 0, 0}, 1.5f, out), 1);
    expectValid(out, {1, 0, 0}, 1.5f);
    EXPECT_NEAR(sumVolume(out), 4.0 / 3.0 / 64.0, 1e-6);
}

TEST(Clipping, TwoAndTwoLeavesAPrismOfHalfTheVolume) {
    // A plane through the midpoints of the four edges joining {v0, v3} to {v1, v2}
    // (parallel to the opposite edges v0v3 and v1v2) halves any tetrahedron.
    const glm::vec3 n = glm::normalize(glm::vec3(1, 1, 0));
    const float offset = glm::dot(n, glm::vec3(1, 0, 0)); // midpoint of v0v1
    std::vector<Tetrahedron> out;
    EXPECT_EQ(clipTetrahedron(kTet, n, offset, out), 3);
    expectValid(out, n, offset);
    EXPECT_NEAR(sumVolume(out), 2.0 / 3.0, 1e-6);
}

TEST(ClippingHardCases, PlaneThroughAVertex) {
    std::vector<Tetrahedron> out;
    // Through v1 = (2,0,0), the rest on the visible side: untouched.
    EXPECT_EQ(clipTetrahedron(kTet, {-1, 0, 0}, -2.0f, out), 1);
    EXPECT_NEAR(sumVolume(out), 4.0 / 3.0, 1e-7);
    out.clear();
    // Through v1, the rest behind: only a point is visible, nothing is emitted.
    EXPECT_EQ(clipTetrahedron(kTet, {1, 0, 0}, 2.0f, out), 0);
    EXPECT_TRUE(out.empty());
}

TEST(ClippingHardCases, PlaneAlongAFace) {
    std::vector<Tetrahedron> out;
    // The face z = 0 on the plane, v3 on the visible side: untouched.
    EXPECT_EQ(clipTetrahedron(kTet, {0, 0, 1}, 0.0f, out), 1);
    EXPECT_NEAR(sumVolume(out), 4.0 / 3.0, 1e-7);
    out.clear();
    // v3 behind: only the face is visible, nothing is emitted.
    EXPECT_EQ(clipTetrahedron(kTet, {0, 0, -1}, 0.0f, out), 0);
}

TEST(ClippingHardCases, DegenerateTetrahedraAreDropped) {
    std::vector<Tetrahedron> out;
    const Tetrahedron flat = makeTet({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0});
    EXPECT_EQ(clipTetrahedron(flat, {0, 0, 1}, -1.0f, out), 0); // fully visible but zero volume
    EXPECT_EQ(clipTetrahedron(flat, {1, 0, 0}, 0.5f, out), 0);  // cut
    const Tetrahedron point = makeTet({1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1});
    EXPECT_EQ(clipTetrahedron(point, {1, 0, 0}, 0.0f, out), 0);
    Tetrahedron bad = kTet;
    bad.position[0].x = std::nanf("");
    EXPECT_EQ(clipTetrahedron(bad, {1, 0, 0}, 0.0f, out), 0);
    EXPECT_TRUE(out.empty());
}

TEST(ClippingHardCases, CutThroughAVertexAndAcrossTheOpposite) {
    // Plane x = y passes through v0 and v3 and splits v1 from v2: two prisms degenerate to tetrahedra.
    const glm::vec3 n = glm::normalize(glm::vec3(1, -1, 0));
    std::vector<Tetrahedron> out;
    const int k = clipTetrahedron(kTet, n, 0.0f, out);
    EXPECT_GE(k, 1);
    expectValid(out, n, 0.0f);
    EXPECT_NEAR(sumVolume(out), 2.0 / 3.0, 1e-6);
}
