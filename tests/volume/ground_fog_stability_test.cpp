// Ground fog (Roettger & Ertl 2002, sec. 6) at its numerical edges
// (docs/STABILITY.md, "Ground fog"): each test is named after what would go
// wrong. Two references: the fog volume over the terrain in closed form (each
// triangle's area times the mean of its corners' clamped thicknesses), and,
// with an affine scalar (densityDepthWorld D), a vertical ray's integral of
// the scalar, density h^2 / (2 D) for a fog h deep there, against the
// emitted tetrahedra integrated along the same ray in double.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "splatfx/volume.hpp"
#include "volume_test_util.hpp"

using namespace splatfx;

namespace {

// A layer over heights given per point (x fastest), a flat fog top.
GroundFogDesc layer(glm::ivec2 dims, float spacing, std::vector<float> terrain, float top) {
    GroundFogDesc d;
    d.dims = dims;
    d.originWorld = {0.0f, 0.0f, 0.0f};
    d.spacingWorld = spacing;
    d.terrainHeight = std::move(terrain);
    d.fogTop.assign(d.terrainHeight.size(), top);
    return d;
}

std::vector<float> heights(glm::ivec2 dims, float (*h)(int, int)) {
    std::vector<float> v;
    for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) v.push_back(h(i, j));
    return v;
}

// The fog volume in closed form (the alternating triangulation: cell (i, j)
// is split along (i, j)-(i+1, j+1) when i + j is even).
double exactVolume(const GroundFogDesc& d) {
    auto h = [&](int i, int j) {
        const std::size_t k = std::size_t(i) + std::size_t(d.dims.x) * std::size_t(j);
        return std::max(double(d.fogTop[k]) - double(d.terrainHeight[k]), 0.0);
    };
    const double third = 0.5 * double(d.spacingWorld) * double(d.spacingWorld) / 3.0;
    double v = 0.0;
    for (int j = 0; j + 1 < d.dims.y; ++j)
        for (int i = 0; i + 1 < d.dims.x; ++i)
            v += ((i + j) & 1) == 0 ? third * (h(i, j) + h(i + 1, j) + h(i + 1, j + 1)) + third * (h(i, j) + h(i + 1, j + 1) + h(i, j + 1))
                                    : third * (h(i, j) + h(i + 1, j) + h(i, j + 1)) + third * (h(i + 1, j) + h(i + 1, j + 1) + h(i, j + 1));
    return v;
}

Camera above(const GroundFogDesc& d, float height) {
    const glm::vec3 c(0.5f * d.spacingWorld * float(d.dims.x - 1), 0.0f, 0.5f * d.spacingWorld * float(d.dims.y - 1));
    return Camera::lookAt(c + glm::vec3(0.3f, height, 0.7f) * std::max(1.0f, d.spacingWorld * float(d.dims.x)), c, {0, 1, 0}, glm::radians(70.0f),
                          {64, 48}, 0.01f, 1e7f);
}

struct Emitted {
    double volume = 0.0;
    bool finite = true, positive = true, scalarsInRange = true;
    std::size_t count = 0;
};
Emitted emitted(const GroundFog& fog, const Camera& cam, float density, const LodRefineDesc& refine = {}) {
    LodFrame f;
    EXPECT_TRUE(fog.update(cam, refine, f));
    Emitted e;
    e.count = f.tets.size();
    for (const Tetrahedron& t : f.tets) {
        const double v = voltest::tetVolume(t);
        e.volume += v;
        e.positive = e.positive && v > 0.0;
        for (int k = 0; k < 4; ++k) {
            const glm::vec3 p = t.position[std::size_t(k)];
            e.finite = e.finite && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
            const float s = t.scalar[std::size_t(k)];
            e.scalarsInRange = e.scalarsInRange && s >= 0.0f && s <= density * (1.0f + 1e-6f);
        }
    }
    return e;
}

// The scalar integrated along the vertical ray at (x, z), through every
// emitted tetrahedron (the scalar is linear in each: length x mean of the
// ends), in double.
double verticalRayIntegral(const GroundFog& fog, const Camera& cam, double x, double z) {
    LodFrame f;
    EXPECT_TRUE(fog.update(cam, LodRefineDesc{}, f));
    const glm::dvec3 o(x, 1e4, z), dir(0.0, -1.0, 0.0);
    double sum = 0.0;
    for (const Tetrahedron& t : f.tets) {
        const glm::dvec2 r = voltest::rayInterval(t, o, dir);
        if (!(r.y > r.x)) continue;
        auto scalarAt = [&](double s) {
            const glm::dvec4 b = voltest::barycentric(t, o + s * dir);
            return b.x * t.scalar[0] + b.y * t.scalar[1] + b.z * t.scalar[2] + b.w * t.scalar[3];
        };
        sum += (r.y - r.x) * 0.5 * (scalarAt(r.x) + scalarAt(r.y));
    }
    return sum;
}

float wavy(int i, int j) { return 1.5f * std::sin(0.9f * float(i)) * std::cos(0.7f * float(j)); }

} // namespace

// ---- The terrain and the top -----------------------------------------------------

// The fog top exactly at the terrain everywhere: no prism has height, none
// is emitted (not a layer of zero-volume tetrahedra).
TEST(GroundFogStability, TopExactlyOnTheTerrainEmitsNothing) {
    const glm::ivec2 dims{9, 9};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, wavy), 0.0f);
    d.fogTop = d.terrainHeight;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    EXPECT_EQ(fog->prismCount(), 0u);
    EXPECT_EQ(emitted(*fog, above(d, 2.0f), d.density).count, 0u);
}

// The top touches the terrain at single points (a hill reaching it exactly):
// the prisms there have a zero-height edge; the volume is still the closed
// form and no tetrahedron is inverted.
TEST(GroundFogStability, TopTouchingTheTerrainAtSinglePointsKeepsTheVolume) {
    const glm::ivec2 dims{9, 9};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, [](int i, int j) { return ((i + j) % 4 == 0) ? 1.0f : 0.0f; }), 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const Emitted e = emitted(*fog, above(d, 2.0f), d.density);
    EXPECT_TRUE(e.positive && e.finite);
    EXPECT_NEAR(e.volume, exactVolume(d), 1e-5 * exactVolume(d));
}

// Terrain poking through the top at alternate points (a checkerboard): the
// prisms there are clamped to zero thickness at those corners, never a
// negative thickness that would subtract fog.
TEST(GroundFogStability, TerrainAboveTheTopAtAlternatePointsClampsNotSubtracts) {
    const glm::ivec2 dims{9, 9};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, [](int i, int j) { return ((i + j) & 1) ? 3.0f : 0.0f; }), 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const Emitted e = emitted(*fog, above(d, 2.0f), d.density);
    EXPECT_TRUE(e.positive && e.finite && e.scalarsInRange);
    EXPECT_NEAR(e.volume, exactVolume(d), 1e-5 * exactVolume(d));
}

// A cliff under the fog top: a 1000-unit step between neighbouring points
// (the terrain drops from above the top to far below it). Its prisms are a
// thousand times taller than wide; the volume is exact and the vertical ray
// through the deep side integrates to density h^2 / (2 D).
TEST(GroundFogStability, ACliffUnderTheTopIntegratesExactly) {
    const glm::ivec2 dims{6, 6};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, [](int i, int) { return i < 3 ? 10.0f : -1000.0f; }), 5.0f);
    d.densityDepthWorld = 1005.0f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const Camera cam = above(d, 3.0f);
    const Emitted e = emitted(*fog, cam, d.density);
    EXPECT_TRUE(e.positive && e.finite && e.scalarsInRange);
    EXPECT_NEAR(e.volume, exactVolume(d), 1e-5 * exactVolume(d));
    // At x = 4.3 the terrain is -1000 on every corner around: h = 1005.
    const double want = double(d.density) * 1005.0 * 1005.0 / (2.0 * 1005.0);
    // Float positions of size 1000 (2^-14 absolute) over a ray of 1005: 1e-6 relative.
    EXPECT_NEAR(verticalRayIntegral(*fog, cam, 4.3, 2.2), want, 1e-5 * want);
}

// A vertical ray anywhere in a wavy valley with an affine scalar: the
// tetrahedra integrate the prism's field exactly (the split of the prism
// does not matter for an affine field).
TEST(GroundFogStability, VerticalRaysIntegrateTheAffineFieldExactly) {
    const glm::ivec2 dims{9, 9};
    GroundFogDesc d = layer(dims, 2.0f, heights(dims, wavy), 1.2f);
    d.densityDepthWorld = 3.0f;
    d.density = 0.8f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const Camera cam = above(d, 2.0f);
    int checked = 0;
    for (const glm::vec2 cell : {glm::vec2(2.7f, 3.2f), glm::vec2(5.2f, 1.6f), glm::vec2(0.4f, 7.9f)}) {
        // The terrain under the point: the plane of its triangle (alternating diagonals).
        const int i = int(cell.x), j = int(cell.y);
        const float u = cell.x - float(i), v = cell.y - float(j);
        auto H = [&](int a, int b) { return double(d.terrainHeight[std::size_t(a + dims.x * b)]); };
        double t;
        if (((i + j) & 1) == 0)
            t = u >= v ? H(i, j) + u * (H(i + 1, j) - H(i, j)) + v * (H(i + 1, j + 1) - H(i + 1, j))
                       : H(i, j) + v * (H(i, j + 1) - H(i, j)) + u * (H(i + 1, j + 1) - H(i, j + 1));
        else
            t = u + v <= 1.0f ? H(i, j) + u * (H(i + 1, j) - H(i, j)) + v * (H(i, j + 1) - H(i, j))
                              : H(i + 1, j + 1) + (1.0 - u) * (H(i, j + 1) - H(i + 1, j + 1)) + (1.0 - v) * (H(i + 1, j) - H(i + 1, j + 1));
        const double h = std::max(1.2 - t, 0.0);
        if (h <= 0.0 || 1.2 - std::max({H(i, j), H(i + 1, j), H(i, j + 1), H(i + 1, j + 1)}) <= 0.0) continue; // clamped prisms: not affine
        const double want = 0.8 * h * h / (2.0 * 3.0);
        EXPECT_NEAR(verticalRayIntegral(*fog, cam, cell.x * 2.0, cell.y * 2.0), want, 1e-5 + 1e-5 * want) << cell.x << " " << cell.y;
        ++checked;
    }
    EXPECT_GE(checked, 2) << "the points chosen must lie under fog on every corner";
}

// densityDepthWorld exactly the deepest fog: the scalar reaches density there
// and not a rounding step more. One float step under it is rounding (create()
// allows 10^-6 relative and the scalar stays within it); 10^-5 under is a
// fog deeper than stated, refused.
TEST(GroundFogStability, DensityDepthEqualToTheDeepestFogIsAccepted) {
    const glm::ivec2 dims{5, 5};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, [](int i, int j) { return -0.1f * float(i + j); }), 0.7f);
    d.densityDepthWorld = 0.7f + 0.8f; // deepest at (4, 4): 0.7 - (-0.8)
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    EXPECT_TRUE(emitted(*fog, above(d, 2.0f), d.density).scalarsInRange);
    d.densityDepthWorld = std::nextafter(1.5f, 0.0f);
    auto rounding = GroundFog::create(d);
    ASSERT_TRUE(rounding) << rounding.error();
    EXPECT_TRUE(emitted(*rounding, above(d, 2.0f), d.density).scalarsInRange);
    d.densityDepthWorld = 1.5f * (1.0f - 1e-5f);
    auto under = GroundFog::create(d);
    ASSERT_FALSE(under);
    EXPECT_NE(under.error().find("densityDepthWorld"), std::string::npos) << under.error();
}

// ---- Scale ---------------------------------------------------------------------------

// A fog 0.01 deep at an altitude of 10^6 (float resolution there: 0.0625):
// top and bottom may round to one height. Whatever is emitted is finite and
// positively oriented (a top rounded below its bottom would invert prisms).
TEST(GroundFogStability, ThinFogAtAMillionUnitsAltitudeIsNeverInverted) {
    const glm::ivec2 dims{5, 5};
    GroundFogDesc d = layer(dims, 100.0f, std::vector<float>(25, 1e6f), 1e6f + 0.01f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const Emitted e = emitted(*fog, above(d, 0.5f), d.density);
    EXPECT_TRUE(e.finite);
    EXPECT_TRUE(e.positive);
}

// Spacing 10^-4 and 10^4 world units: the same layer scaled; volumes scale
// by the square of the spacing, no tetrahedron degenerates.
TEST(GroundFogStability, SpacingsFromATenthOfAMillimetreToTenKilometresScaleTheVolume) {
    const glm::ivec2 dims{7, 7};
    for (float s : {1e-4f, 1e4f}) {
        GroundFogDesc d = layer(dims, s, heights(dims, wavy), 1.0f);
        auto fog = GroundFog::create(d);
        ASSERT_TRUE(fog) << fog.error();
        const Emitted e = emitted(*fog, above(d, 2.0f), d.density);
        EXPECT_TRUE(e.positive && e.finite) << s;
        EXPECT_NEAR(e.volume, exactVolume(d), 1e-4 * exactVolume(d)) << s;
    }
}

// The smallest grid, 2 x 2 points: one cell, two prisms, six tetrahedra at most.
TEST(GroundFogStability, ASingleCellGridIsTwoPrisms) {
    GroundFogDesc d = layer({2, 2}, 3.0f, {0.0f, 0.5f, 0.2f, 0.1f}, 2.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    EXPECT_EQ(fog->prismCount(), 2u);
    const Emitted e = emitted(*fog, above(d, 2.0f), d.density);
    EXPECT_LE(e.count, 6u);
    EXPECT_NEAR(e.volume, exactVolume(d), 1e-5 * exactVolume(d));
}

// ---- The camera ----------------------------------------------------------------------

// Looking straight down (the view direction parallel to every prism wall):
// the far-to-near split planes are vertical, so the order test is degenerate
// for them; every tetrahedron is still emitted once, finite.
TEST(GroundFogStability, LookingStraightDownEmitsEveryTetrahedronOnce) {
    const glm::ivec2 dims{9, 9};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, wavy), 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const glm::vec3 c(4.0f, 0.0f, 4.0f);
    const Camera down = Camera::lookAt(c + glm::vec3(0.0f, 20.0f, 0.0f), c, {0, 0, -1}, glm::radians(90.0f), {64, 64}, 0.01f, 100.0f);
    const Emitted e = emitted(*fog, down, d.density);
    EXPECT_TRUE(e.finite && e.positive);
    EXPECT_NEAR(e.volume, exactVolume(d), 1e-5 * exactVolume(d));
}

// The eye exactly on the fog top, and on a prism's vertical edge inside the
// fog: near-plane clipping cuts through the layer; all that is emitted is
// finite, positively oriented and inside the layer's bounds.
TEST(GroundFogStability, EyeOnTheTopAndOnAPrismEdgeClipsCleanly) {
    const glm::ivec2 dims{9, 9};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, wavy), 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const float edgeHeight = 0.5f * (d.terrainHeight[4 + 9 * 4] + 1.0f);
    for (const glm::vec3 eye : {glm::vec3(3.3f, 1.0f, 4.6f), glm::vec3(4.0f, edgeHeight, 4.0f)}) {
        const Camera cam = Camera::lookAt(eye, eye + glm::vec3(1.0f, -0.05f, 0.4f), {0, 1, 0}, glm::radians(80.0f), {64, 48}, 0.05f, 100.0f);
        LodFrame f;
        ASSERT_TRUE(fog->update(cam, LodRefineDesc{}, f));
        EXPECT_GT(f.tets.size(), 0u);
        const Aabb b = fog->boundsWorld();
        for (const Tetrahedron& t : f.tets) {
            EXPECT_GT(voltest::tetVolume(t), 0.0);
            for (const glm::vec3& p : t.position) {
                ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
                EXPECT_TRUE(p.y >= b.lo.y - 1e-4f && p.y <= b.hi.y + 1e-4f);
            }
        }
    }
}

// The eye under the terrain (a camera clipping into a hill): nothing breaks,
// the layer is emitted as from anywhere else.
TEST(GroundFogStability, AnEyeUnderTheTerrainStillGetsTheWholeLayer) {
    const glm::ivec2 dims{9, 9};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, wavy), 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    const glm::vec3 eye(4.5f, -5.0f, -6.0f);
    const Camera cam = Camera::lookAt(eye, {4.0f, 0.0f, 4.0f}, {0, 1, 0}, glm::radians(80.0f), {64, 48}, 0.05f, 100.0f);
    const Emitted e = emitted(*fog, cam, d.density);
    EXPECT_TRUE(e.finite && e.positive);
    EXPECT_NEAR(e.volume, exactVolume(d), 1e-5 * exactVolume(d));
}

// ---- The LOD -------------------------------------------------------------------------

// Flat terrain under a fog top that alone varies: the LOD's metric takes the
// top's deviation too, so refining fully gives the full-resolution volume.
TEST(GroundFogStability, LodOverFlatTerrainRefinesByTheTopAlone) {
    const glm::ivec2 dims{17, 17};
    GroundFogDesc d = layer(dims, 1.0f, std::vector<float>(17 * 17, 0.0f), 0.0f);
    for (int j = 0; j < 17; ++j)
        for (int i = 0; i < 17; ++i) d.fogTop[std::size_t(i + 17 * j)] = 1.0f + 0.8f * std::sin(0.8f * float(i)) * std::sin(0.6f * float(j));
    GroundFogDesc lodDesc = d;
    lodDesc.lod = true;
    lodDesc.minAccuracyC = 1e4f;
    auto lod = GroundFog::create(lodDesc);
    ASSERT_TRUE(lod) << lod.error();
    const Emitted e = emitted(*lod, above(d, 2.0f), d.density, LodRefineDesc{.detailC = 1e6f});
    EXPECT_TRUE(e.positive && e.finite);
    EXPECT_NEAR(e.volume, exactVolume(d), 1e-4 * exactVolume(d));
}

// A grid of 2^n + 2 points (the worst padding: nearly twice the points per
// side): the fog tapers to 0 in the padding within one coarse triangle and
// nothing of it reaches past the padded grid.
TEST(GroundFogStability, LodWithTheWorstPaddingStaysInsideItsBounds) {
    const glm::ivec2 dims{18, 18};
    GroundFogDesc d = layer(dims, 1.0f, heights(dims, wavy), 1.0f);
    d.lod = true;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog) << fog.error();
    EXPECT_EQ(fog->lodPointsPerSide(), 33);
    LodFrame f;
    ASSERT_TRUE(fog->update(above(d, 2.0f), LodRefineDesc{}, f));
    const Aabb b = fog->boundsWorld();
    for (const Tetrahedron& t : f.tets) {
        EXPECT_GT(voltest::tetVolume(t), 0.0);
        for (const glm::vec3& p : t.position) EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, b.lo - 1e-4f)) && glm::all(glm::lessThanEqual(p, b.hi + 1e-4f)));
    }
}
