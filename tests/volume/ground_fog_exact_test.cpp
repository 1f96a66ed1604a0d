// Ground fog (Roettger & Ertl 2002, sec. 6) against its continuous field
// (renderGroundFogExact / integrateGroundFogRay): the emitted tetrahedra at
// full resolution, LOD and sort-free, each measured against the field, and
// the field's own numerical edges (docs/STABILITY.md, "Ground fog") against
// closed forms.
//
// Tolerances. Both sides are double-precision integrals: the field's and
// renderTetraExact's step-halving error estimates bound their quadrature.
// What is left is float: GroundFog emits float positions and scalars, each
// within half an ulp of the double value the field uses. A vertex moved by
// delta moves the terrain under a ray by at most slope * delta vertically,
// which shortens or lengthens the ray's stretch in the fog by slope * delta /
// sin(theta) (theta: the ray's angle to the terrain) at most, where the
// scalar is at most `density`; the top is where the scalar is 0, so moving it
// costs nothing to first order. Scalars carry a relative error of 2^-24.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/reference.hpp"
#include "splatfx/volume.hpp"
#include "volume_test_util.hpp"

using namespace splatfx;

namespace {

constexpr double kFloatEps = 1.0 / 16777216.0; // 2^-24, half an ulp relative

// Valleys: a wavy terrain under a flat top (the same as ground_fog_test.cpp's).
GroundFogDesc valleys(glm::ivec2 dims, float top, float densityDepth) {
    GroundFogDesc d;
    d.dims = dims;
    d.originWorld = {-10.0f, 0.0f, -10.0f};
    d.spacingWorld = 20.0f / float(dims.x - 1);
    d.densityDepthWorld = densityDepth;
    for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) {
            const float x = float(i) / float(dims.x - 1), z = float(j) / float(dims.y - 1);
            d.terrainHeight.push_back(2.0f * std::sin(6.0f * x) * std::cos(5.0f * z) + 0.5f * x);
            d.fogTop.push_back(top);
        }
    return d;
}

// A flat layer: terrain `bottom`, top `top` everywhere.
GroundFogDesc slab(glm::ivec2 dims, float spacing, float bottom, float top) {
    GroundFogDesc d;
    d.dims = dims;
    d.spacingWorld = spacing;
    d.terrainHeight.assign(std::size_t(dims.x) * std::size_t(dims.y), bottom);
    d.fogTop.assign(d.terrainHeight.size(), top);
    return d;
}

TransferFunction fogTransfer(float extinction) { return *makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, extinction); }

// Looking down on the valleys from the south-west at about 40 degrees.
Camera valleyCamera() { return Camera::lookAt({-22.0f, 16.0f, -18.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(55.0f), {40, 30}, 0.1f, 200.0f); }

double maxDiff(const Image& a, const Image& b) {
    double m = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) m = std::max(m, std::abs(double(a.pixels[i]) - double(b.pixels[i])));
    return m;
}
double meanDiff(const Image& a, const Image& b) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) s += std::abs(double(a.pixels[i]) - double(b.pixels[i]));
    return s / double(std::max<std::size_t>(a.pixels.size(), 1));
}

// The tetrahedra composited in list order, as the GL pass blends them (each
// drawn "over" what is there; sort-free, eq. 10, is the same blend with one
// colour): every tetrahedron's stretch of the ray integrated by integrateSegment.
glm::dvec4 listOrder(const std::vector<Tetrahedron>& tets, const TransferFunction& tf, glm::dvec3 o, glm::dvec3 d, double tNear, double tFar) {
    glm::dvec4 acc(0.0);
    for (const Tetrahedron& t : tets) {
        const glm::dvec2 iv = voltest::rayInterval(t, o, d);
        const double a = std::max(iv.x, tNear), b = std::min(iv.y, tFar);
        if (!(b > a)) continue;
        auto scalarAt = [&](double tt) {
            const glm::dvec4 l = voltest::barycentric(t, o + tt * d);
            return l.x * t.scalar[0] + l.y * t.scalar[1] + l.z * t.scalar[2] + l.w * t.scalar[3];
        };
        const glm::dvec4 seg = integrateSegment(tf, scalarAt(a), scalarAt(b), (b - a) * glm::length(d));
        acc = seg + (1.0 - seg.a) * acc;
    }
    return acc;
}

// An image of listOrder through every pixel (GL pixel centres, near to far).
Image listOrderImage(const std::vector<Tetrahedron>& tets, const TransferFunction& tf, const Camera& cam) {
    Image out;
    out.width = cam.viewport.x, out.height = cam.viewport.y, out.channels = 4;
    out.pixels.assign(std::size_t(out.width) * out.height * 4, 0.0f);
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            const double nx = (x + 0.5) / out.width * 2.0 - 1.0, ny = 1.0 - (y + 0.5) / out.height * 2.0;
            const glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
            const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
            const glm::dvec4 c = listOrder(tets, tf, p0, glm::normalize(p1 - p0), 0.0, glm::length(p1 - p0));
            for (int ch = 0; ch < 4; ++ch) out.at(x, y, ch) = float(c[ch]);
        }
    return out;
}

std::vector<Tetrahedron> emit(const GroundFogDesc& d, const Camera& cam, const LodRefineDesc& refine = {}) {
    auto fog = GroundFog::create(d);
    EXPECT_TRUE(fog) << fog.error();
    LodFrame f;
    EXPECT_TRUE(fog->update(cam, refine, f));
    return f.tets;
}

} // namespace

// ---------------------------------------------------------------------------
// The tetrahedra against the field
// ---------------------------------------------------------------------------

// With an affine scalar (densityDepthWorld > 0) every prism's three
// tetrahedra hold the field exactly, so full resolution, sorted, integrated in
// double, is the field up to quadrature and float rounding.
TEST(GroundFogExact, FullResolutionAffineTetrahedraAreTheField) {
    const GroundFogDesc d = valleys({17, 13}, 0.8f, 3.0f);
    const TransferFunction tf = fogTransfer(1.5f);
    const Camera cam = valleyCamera();
    GroundFogExactStats fs;
    TetraExactStats ts;
    auto field = renderGroundFogExact(d, tf, cam, {}, &fs);
    auto tets = renderTetraExact(emit(d, cam), tf, cam, {.tolerance = 1e-7}, &ts);
    ASSERT_TRUE(field) << field.error();
    ASSERT_TRUE(tets) << tets.error();
    EXPECT_EQ(fs.unconverged, 0u);
    EXPECT_EQ(ts.unconverged, 0u);
    EXPECT_GT(fs.pieces, 0u);
    // Float: |coordinates| <= 10 and heights <= 3 round by <= 10 * 2^-24;
    // the terrain's slope is <= 2 * 6 / (20 / 16) < 10 per world unit
    // (d/dx of 2 sin(6x) over a 20-unit grid, plus the tilt), the camera's
    // rays meet it at sin(theta) >= 0.1 outside grazing silhouettes (pixels
    // there see the terrain edge-on and are bounded by the same term with
    // the ray's whole length: not at this pitch), the scalar there is <=
    // 0.8 / 3, extinction 1.5 per unit scalar, <= 4 terrain crossings.
    const double floatTerm = 4.0 * 1.5 * (0.8 / 3.0) * 10.0 * (10.0 * kFloatEps) / 0.1 + 1e-6;
    const double bound = fs.maxErrorEstimate + ts.maxErrorEstimate + floatTerm;
    EXPECT_LT(maxDiff(*field, *tets), bound) << "bound " << bound;
    // Not empty: the fog covers a good part of the view.
    double alpha = 0.0;
    for (std::size_t i = 3; i < field->pixels.size(); i += 4) alpha = std::max(alpha, double(field->pixels[i]));
    EXPECT_GT(alpha, 0.3);
}

// The paper's scalar (density at the terrain, 0 at the top) is affine only
// where the thickness is constant: a tilted slab of constant thickness is
// held exactly, a layer of varying thickness is not (the tetrahedral split
// bends the scalar along verticals: the error the field reference exposes).
TEST(GroundFogExact, PapersScalarIsExactOnlyUnderConstantThickness) {
    GroundFogDesc tilted = slab({9, 9}, 2.0f, 0.0f, 0.0f);
    for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 9; ++i) {
            const std::size_t k = std::size_t(i) + 9u * std::size_t(j);
            tilted.terrainHeight[k] = 0.3f * float(i) - 0.2f * float(j);
            tilted.fogTop[k] = tilted.terrainHeight[k] + 1.5f;
        }
    const TransferFunction tf = fogTransfer(1.0f);
    const Camera cam = Camera::lookAt({-6.0f, 9.0f, -5.0f}, {8.0f, 0.0f, 8.0f}, {0, 1, 0}, glm::radians(55.0f), {32, 24}, 0.1f, 200.0f);
    GroundFogExactStats fs;
    TetraExactStats ts;
    auto field = renderGroundFogExact(tilted, tf, cam, {}, &fs);
    auto tets = renderTetraExact(emit(tilted, cam), tf, cam, {.tolerance = 1e-7}, &ts);
    ASSERT_TRUE(field && tets);
    // Float: coordinates <= 16, slope 0.3: 4 crossings at sin(theta) >= 0.2.
    const double floatTerm = 4.0 * 1.0 * 1.0 * 0.3 * (16.0 * kFloatEps) / 0.2 + 1e-6;
    EXPECT_LT(maxDiff(*field, *tets), fs.maxErrorEstimate + ts.maxErrorEstimate + floatTerm);

    // Varying thickness: the split's error is far above that bound (it is a
    // modelling difference, docs/BENCHMARKS.md measures it).
    const GroundFogDesc d = valleys({17, 13}, 0.8f, 0.0f);
    const Camera vc = valleyCamera();
    auto field2 = renderGroundFogExact(d, tf, vc, {}, &fs);
    auto tets2 = renderTetraExact(emit(d, vc), tf, vc, {.tolerance = 1e-7}, &ts);
    ASSERT_TRUE(field2 && tets2);
    EXPECT_GT(maxDiff(*field2, *tets2), 100.0 * (fs.maxErrorEstimate + ts.maxErrorEstimate + 1e-4));
}

// The LOD (sec. 6 with the metric of sec. 2.2, geomorphed): its error
// against the field falls as c tightens, and fully refined it is the full
// resolution layer (the field up to the float bound of the test above).
TEST(GroundFogExact, LodErrorFallsAsTheAccuracyTightens) {
    GroundFogDesc d = valleys({33, 33}, 0.8f, 3.0f);
    d.lod = true;
    d.minAccuracyC = 1.0f;
    const TransferFunction tf = fogTransfer(1.5f);
    const Camera cam = Camera::lookAt({-22.0f, 16.0f, -18.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(55.0f), {24, 18}, 0.1f, 200.0f);
    GroundFogExactStats fs;
    auto field = renderGroundFogExact(d, tf, cam, {}, &fs);
    ASSERT_TRUE(field);
    std::vector<double> errors;
    std::vector<std::size_t> counts;
    double estimates = fs.maxErrorEstimate;
    for (float c : {0.0f, 2.0f, 20.0f, 1e6f}) {
        const std::vector<Tetrahedron> tets = emit(d, cam, {.detailC = c});
        TetraExactStats ts;
        auto img = renderTetraExact(tets, tf, cam, {.tolerance = 1e-7}, &ts);
        ASSERT_TRUE(img);
        estimates += ts.maxErrorEstimate;
        errors.push_back(meanDiff(*field, *img));
        counts.push_back(tets.size());
    }
    for (std::size_t k = 1; k < errors.size(); ++k) {
        EXPECT_GT(counts[k], counts[k - 1]) << "c step " << k;
        // A finer mesh may be locally worse; over the image it must not be.
        EXPECT_LT(errors[k], errors[k - 1] + estimates) << "c step " << k;
    }
    // Coarsest: a real error (a 33x33 layer drawn with a handful of prisms).
    EXPECT_GT(errors.front(), 10.0 * errors.back() + estimates);
    // c = 1e6: every vertex with any deviation refined; what remains is float
    // (as the full-resolution test, coordinates <= 10) on every pixel's mean.
    EXPECT_LT(errors.back(), estimates + 4.0 * 1.5 * (0.8 / 3.0) * 10.0 * (10.0 * kFloatEps) / 0.1 + 1e-6);
}

// Sort-free (eq. 10): the tetrahedra in grid order, blended in that order.
// With one fog colour the blends commute (volume.hpp), so the list-order
// composite is the field up to the float bound; the sorted list composited the
// same way is too, and the two differ only by rounding of commuted products.
TEST(GroundFogExact, SortFreeWithOneColourIsTheField) {
    GroundFogDesc d = valleys({9, 9}, 0.8f, 3.0f);
    const TransferFunction tf = fogTransfer(1.5f);
    const Camera cam = Camera::lookAt({-22.0f, 16.0f, -18.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(55.0f), {24, 18}, 0.1f, 200.0f);
    GroundFogExactStats fs;
    auto field = renderGroundFogExact(d, tf, cam, {}, &fs);
    ASSERT_TRUE(field);
    const Image sorted = listOrderImage(emit(d, cam), tf, cam);
    d.sortFree = true;
    const Image free = listOrderImage(emit(d, cam), tf, cam);
    // integrateSegment's relative error ~1e-12 per segment, a few hundred segments per ray.
    EXPECT_LT(maxDiff(sorted, free), 1e-9);
    // Float bound as in FullResolutionAffineTetrahedraAreTheField (coarser grid: slope < 2 * 6 / 2.5 + 0.5 < 10).
    EXPECT_LT(maxDiff(*field, free), fs.maxErrorEstimate + 4.0 * 1.5 * (0.8 / 3.0) * 10.0 * (10.0 * kFloatEps) / 0.1 + 1e-6);
}

// With a colour that varies with the scalar, sort-free blends out of order:
// the field reference measures that error (docs/BENCHMARKS.md), far above the
// sorted list's, which stays at the float bound.
TEST(GroundFogExact, SortFreeWithAColourRampShowsItsOrderError) {
    GroundFogDesc d = valleys({9, 9}, 0.8f, 3.0f);
    auto ramp = TransferFunction::create({{0.0f, {1.0f, 0.2f, 0.1f}, 0.0f}, {1.0f, {0.1f, 0.3f, 1.0f}, 3.0f}});
    ASSERT_TRUE(ramp);
    const Camera cam = Camera::lookAt({-22.0f, 16.0f, -18.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(55.0f), {24, 18}, 0.1f, 200.0f);
    GroundFogExactStats fs;
    auto field = renderGroundFogExact(d, *ramp, cam, {}, &fs);
    ASSERT_TRUE(field);
    const double floatTerm = fs.maxErrorEstimate + 4.0 * 3.0 * (0.8 / 3.0) * 10.0 * (10.0 * kFloatEps) / 0.1 + 1e-6;
    EXPECT_LT(maxDiff(*field, listOrderImage(emit(d, cam), *ramp, cam)), floatTerm);
    d.sortFree = true;
    EXPECT_GT(maxDiff(*field, listOrderImage(emit(d, cam), *ramp, cam)), 100.0 * floatTerm);
}

// The host's depth (the terrain drawn first) ends every ray where it says,
// in the camera's convention, and the background shows through by T: the
// same as renderTetraExact on the tetrahedra, with the cut inside the layer.
TEST(GroundFogExact, HostDepthAndBackgroundFollowTheOtherReferences) {
    // A flat layer 0..2, the eye inside it at y = 1 looking level: a ray is
    // still in the fog at view depth z when |tan(pitch)| < 1 / z.
    const GroundFogDesc d = slab({9, 9}, 4.0f, 0.0f, 2.0f);
    const TransferFunction tf = fogTransfer(0.2f);
    const Camera cam = Camera::lookAt({-4.0f, 1.0f, 16.0f}, {32.0f, 1.0f, 16.0f}, {0, 1, 0}, glm::radians(20.0f), {16, 12}, 0.1f, 200.0f);
    Image depth;
    depth.width = 16, depth.height = 12, depth.channels = 1;
    depth.pixels.assign(16 * 12, 0.0f);
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 16; ++x) {
            // View depths 8 to 23 across the view, as GL window depths (near 0.1, far 200).
            const double z = 8.0 + double(x);
            depth.at(x, y, 0) = float(200.0 / 199.9 * (1.0 - 0.1 / z));
        }
    const ReferenceHost host{.background = {0.1f, 0.2f, 0.3f, 1.0f}, .depth = &depth};
    GroundFogExactStats fs;
    TetraExactStats ts;
    auto field = renderGroundFogExact(d, tf, cam, {.host = host}, &fs);
    auto tets = renderTetraExact(emit(d, cam), tf, cam, {.host = host, .tolerance = 1e-7}, &ts);
    ASSERT_TRUE(field && tets);
    // Flat layer, heights exact in float: the scalars' rounding (2^-24
    // relative, a few times) on optical depths <= 0.2 * 40, and the clipped
    // near faces (coordinates <= 32) at extinction <= 0.2.
    EXPECT_LT(maxDiff(*field, *tets), fs.maxErrorEstimate + ts.maxErrorEstimate + 0.2 * 40.0 * 4.0 * kFloatEps + 0.2 * 32.0 * kFloatEps);
    // The depth cuts inside the layer: fog in front of it, less than without it.
    auto whole = renderGroundFogExact(d, tf, cam, {.host = {.background = {0.1f, 0.2f, 0.3f, 1.0f}}});
    ASSERT_TRUE(whole);
    int cut = 0;
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 16; ++x) {
            const double with = field->at(x, y, 0) - 0.1, without = whole->at(x, y, 0) - 0.1; // the fog's red over the background's
            cut += with > 1e-3 && without > with + 1e-3 ? 1 : 0;
        }
    // Column x cuts at z = 8 + x: the rows (1.67 degrees apart, 20 degrees
    // in all) with |pitch| < atan(1 / z), 8 rows at x = 0 down to 2 at x = 15,
    // about 75 pixels; rays that leave the layer before the cut are not cut.
    EXPECT_GT(cut, 16 * 12 / 3);
}

// An orthographic camera looking straight down: every pixel ray is a
// vertical, along which the paper's scalar falls linearly from `density` to 0
// over the thickness h, so the optical depth is extinction * density * h / 2.
// With h affine in (x, z) (terrain 0, top 1 + 0.25 i + 0.125 j) each pixel has
// its closed form at its centre, which pins GL's pixel conventions (centres,
// top row first) for the orthographic mapping.
TEST(GroundFogExact, OrthographicStraightDownIsTheVerticalIntegralAtPixelCentres) {
    GroundFogDesc d = slab({9, 9}, 1.0f, 0.0f, 0.0f);
    d.density = 0.75f;
    for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 9; ++i) d.fogTop[std::size_t(i) + 9u * std::size_t(j)] = 1.0f + 0.25f * float(i) + 0.125f * float(j);
    const TransferFunction tf = fogTransfer(0.5f);
    // Eye above (4, 4), up -z: screen right is +x, screen up is -z; the box is 8 x 6 world units.
    const glm::ivec2 size{16, 12};
    const Camera cam = Camera::fromMatrices(glm::lookAt(glm::vec3(4.0f, 10.0f, 4.0f), glm::vec3(4.0f, 0.0f, 4.0f), glm::vec3(0.0f, 0.0f, -1.0f)),
                                            glm::ortho(-4.0f, 4.0f, -3.0f, 3.0f, 0.5f, 20.0f), size);
    ASSERT_FALSE(cam.perspective());
    GroundFogExactStats fs;
    auto img = renderGroundFogExact(d, tf, cam, {}, &fs);
    ASSERT_TRUE(img) << img.error();
    double worst = 0.0;
    for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) {
            const double wx = (4.0 - 4.0) + (x + 0.5) * 0.5;         // pixel centre from the box's left edge, x = 0
            const double wz = 4.0 - (3.0 - (y + 0.5) * 0.5);         // top row first: screen up is -z
            const double h = 1.0 + 0.25 * wx + 0.125 * wz;           // the top (terrain 0), affine
            const double alpha = -std::expm1(-0.5 * 0.75 * h / 2.0); // extinction 0.5 per unit scalar; density 0.75f is exact in float
            worst = std::max(worst, std::abs(double(img->at(x, y, 3)) - alpha));
        }
    // The scalar is linear along each vertical, so 4-point Gauss-Legendre is
    // exact up to rounding; the float image (2^-24) and the float camera's
    // unprojected pixel centres (|x|, |z| <= 8, relative 2^-24, times dh/dx
    // <= 0.25 and d alpha / dh <= 0.19) are what is left.
    EXPECT_LT(worst, fs.maxErrorEstimate + 2.0 * kFloatEps + 8.0 * kFloatEps * 0.25 * 0.19 * 8.0);
}

// The outside validation kept: tools/validate/ground_fog.py (standard library
// only, written from the definition: point-wise field, midpoint rule with
// 200,000 and 400,000 steps) printed these values for its case, the same as
// `splatfx-bench groundfog --validate-case`. Each ray's tolerance is the
// script's own step-doubling estimate (the midpoint rule is first order at
// the layer's boundaries, so its 2N result is off by about the N-2N
// difference) plus the 5e-8 of its 7 printed decimals.
TEST(GroundFogExact, AgreesWithTheIndependentQuadrature) {
    GroundFogDesc d;
    d.dims = {3, 3};
    d.originWorld = {-1.0f, 0.0f, 0.5f};
    d.spacingWorld = 1.5f;
    d.terrainHeight = {0.0f, 0.4f, 1.1f, 0.2f, -0.3f, 0.6f, 0.9f, 0.1f, -0.2f};
    d.fogTop = {1.2f, 1.0f, 0.9f, 1.4f, 1.6f, 1.0f, 1.3f, 0.8f, 1.1f};
    d.density = 0.8f;
    auto tf = TransferFunction::create({{0.0f, {1.0f, 0.9f, 0.8f}, 0.0f}, {0.4f, {0.6f, 0.7f, 0.9f}, 1.2f}, {1.0f, {0.2f, 0.3f, 0.7f}, 2.0f}});
    ASSERT_TRUE(tf);
    const glm::dvec3 rays[4][2] = {{{-2.0, 2.5, 0.0}, {1.0, -0.6, 0.7}},
                                   {{3.5, 0.8, 1.2}, {-1.0, 0.05, 0.3}},
                                   {{0.1, 3.0, 2.0}, {0.05, -1.0, 0.02}},
                                   {{-1.5, 0.7, 3.9}, {1.0, 0.0, -0.8}}};
    struct Expected {
        glm::dvec4 rgba;
        double estimate;
    };
    const Expected paper[4] = {{{0.6346155, 0.6791503, 0.8050912, 0.9355138}, 2.8e-6},
                               {{0.6513922, 0.6994947, 0.8183733, 0.9344965}, 1.5e-6},
                               {{0.5128357, 0.5665983, 0.7135334, 0.8366037}, 7.1e-6},
                               {{0.4746828, 0.5718185, 0.8262737, 0.9849529}, 6.1e-6}};
    const Expected affine[4] = {{{0.6387196, 0.6394742, 0.6806205, 0.8002861}, 4.5e-6},
                                {{0.6270608, 0.6078574, 0.6158432, 0.7358175}, 2.1e-6},
                                {{0.5220036, 0.5570492, 0.6529528, 0.7541835}, 8.7e-6},
                                {{0.6813281, 0.6894008, 0.7451020, 0.8718419}, 1.9e-6}};
    for (float depth : {0.0f, 2.5f}) {
        d.densityDepthWorld = depth;
        for (int r = 0; r < 4; ++r) {
            const Expected& e = depth == 0.0f ? paper[r] : affine[r];
            GroundFogRayStats rs;
            const glm::dvec4 c = integrateGroundFogRay(d, *tf, rays[r][0], glm::normalize(rays[r][1]), 0.0, 10.0, 1e-9, 14, &rs);
            for (int ch = 0; ch < 4; ++ch)
                EXPECT_NEAR(c[ch], e.rgba[ch], e.estimate + 5e-8 + rs.errorEstimate) << "depth " << depth << " ray " << r << " channel " << ch;
        }
    }
}

TEST(GroundFogExact, BadInputNamesTheField) {
    const GroundFogDesc d = valleys({5, 5}, 0.8f, 0.0f);
    const TransferFunction tf = fogTransfer(1.0f);
    const Camera cam = valleyCamera();
    auto a = renderGroundFogExact(d, tf, cam, {.tolerance = 0.0});
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("desc.tolerance"), std::string::npos) << a.error();
    auto b = renderGroundFogExact(d, tf, cam, {.maxHalvings = 0});
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().find("desc.maxHalvings"), std::string::npos) << b.error();
    GroundFogDesc bad = d;
    bad.fogTop.pop_back();
    auto c = renderGroundFogExact(bad, tf, cam);
    ASSERT_FALSE(c);
    EXPECT_NE(c.error().find("GroundFogDesc.fogTop"), std::string::npos) << c.error();
    Image wrong;
    wrong.width = 3, wrong.height = 3, wrong.channels = 1, wrong.pixels.assign(9, 0.5f);
    auto e = renderGroundFogExact(d, tf, cam, {.host = {.depth = &wrong}});
    ASSERT_FALSE(e);
    EXPECT_NE(e.error().find("host.depth"), std::string::npos) << e.error();
    // A non-finite ray has no fog (and no NaN).
    EXPECT_EQ(integrateGroundFogRay(d, tf, {NAN, 0, 0}, {1, 0, 0}, 0.0, 10.0), glm::dvec4(0.0));
}

// ---------------------------------------------------------------------------
// Hard cases (docs/STABILITY.md, "Ground fog"), against closed forms
// ---------------------------------------------------------------------------

// A slab 0..2, the paper's scalar density (2 - y) / 2. A ray in the top
// plane sees scalar 0 (no fog, and no 0/0); one delta below it sees the
// constant scalar density delta / 2 over its whole length in the grid.
TEST(GroundFogStability, ARayInTheFogTopPlaneSeesOnlyTheZeroScalar) {
    GroundFogDesc d = slab({9, 9}, 1.0f, 0.0f, 2.0f);
    d.density = 1.0f;
    const TransferFunction tf = fogTransfer(4.0f);
    const Camera cam = Camera::lookAt({-3.0f, 5.0f, -3.0f}, {4.0f, 0.0f, 4.0f}, {0, 1, 0}, glm::radians(60.0f), {16, 12}, 0.1f, 100.0f);
    const std::vector<Tetrahedron> tets = emit(d, cam);
    const glm::dvec3 o(-1.0, 2.0, 3.3), dir(1.0, 0.0, 0.1); // enters at x = 0, leaves at x = 8 (z 3.4 .. 4.2)
    const glm::dvec4 inPlane = integrateGroundFogRay(d, tf, o, dir, 0.0, 100.0);
    EXPECT_EQ(inPlane, glm::dvec4(0.0)); // scalar exactly 0: extinction exactly 0
    EXPECT_EQ(integrateRay(tets, tf, o, dir, 0.0, 100.0).a, 0.0);
    const double delta = 1e-3;
    const double L = 8.0 * std::sqrt(1.01); // x from 0 to 8 along (1, 0, 0.1)
    const double exact = -std::expm1(-4.0 * (delta / 2.0) * L);
    GroundFogRayStats rs;
    const glm::dvec4 below = integrateGroundFogRay(d, tf, o - glm::dvec3(0.0, delta, 0.0), dir, 0.0, 100.0, 1e-10, 14, &rs);
    // The scalar is constant: Gauss-Legendre is exact up to rounding (1e-15 per step).
    EXPECT_NEAR(below.a, exact, 1e-12 + rs.errorEstimate);
    // The tetrahedra: heights 0 and 2 are exact in float, so only the ray's
    // scalar interpolation rounds (relative 2^-24 of the 5e-4 scalar).
    EXPECT_NEAR(integrateRay(tets, tf, o - glm::dvec3(0.0, delta, 0.0), dir, 0.0, 100.0).a, exact, 4.0 * L * 5e-4 * 8.0 * kFloatEps + 1e-12);
}

// The eye inside the layer, looking level: the near plane cuts the
// tetrahedra (sec. 4.3) and the field starts at the near plane. Along the
// level ray through the eye the scalar is constant, density (2 - 1) / 2, to
// the grid's edge: a closed form. The image agrees with the clipped tetrahedra.
TEST(GroundFogStability, AnEyeInsideTheLayerIntegratesFromTheNearPlane) {
    const GroundFogDesc d = slab({9, 9}, 2.0f, 0.0f, 2.0f);
    const TransferFunction tf = fogTransfer(0.5f);
    const glm::dvec3 eye(3.0, 1.0, 5.0);
    const double exact = -std::expm1(-0.5 * 0.5 * (16.0 - 3.0)); // to x = 16
    GroundFogRayStats rs;
    EXPECT_NEAR(integrateGroundFogRay(d, tf, eye, {1.0, 0.0, 0.0}, 0.0, 1e3, 1e-10, 14, &rs).a, exact, 1e-12 + rs.errorEstimate);
    // The eye is inside cell (1, 2) (x = 1.5, z = 2.5 cells), not on a prism face.
    const Camera cam = Camera::lookAt(glm::vec3(eye), glm::vec3(eye) + glm::vec3(1.0f, -0.1f, 0.3f), {0, 1, 0}, glm::radians(70.0f), {16, 12}, 0.05f, 100.0f);
    LodFrame f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    ASSERT_TRUE(fog->update(cam, f));
    EXPECT_GT(f.stats.clippedInput, 0u);
    GroundFogExactStats fs;
    TetraExactStats ts;
    auto field = renderGroundFogExact(d, tf, cam, {}, &fs);
    auto tets = renderTetraExact(f.tets, tf, cam, {.tolerance = 1e-7}, &ts);
    ASSERT_TRUE(field && tets);
    // Flat layer, heights exact in float: only the clip's interpolated
    // vertices round, in position (coordinates <= 16: the near face moves by
    // <= 16 * 2^-24 where the extinction is <= 0.5) and in scalar (a few
    // roundings of 2^-24 relative on an optical depth <= 0.5 * 23, the grid's diagonal).
    EXPECT_LT(maxDiff(*field, *tets), fs.maxErrorEstimate + ts.maxErrorEstimate + 0.5 * 16.0 * kFloatEps + 0.5 * 23.0 * 4.0 * kFloatEps);
    // Fog in every direction from inside: every ray crosses at least the
    // scalar's profile from the eye to the top (straight up: optical depth
    // 0.5 * integral of (1 - u) / 2 over u in [0, 1] = 0.125, more when
    // oblique or downward) less what lies before the near plane (<= 0.1
    // units at scalar <= 1/2: 0.025); the sides of the grid are >= 11 units away.
    double alpha = 1.0;
    for (std::size_t i = 3; i < field->pixels.size(); i += 4) alpha = std::min(alpha, double(field->pixels[i]));
    EXPECT_GT(alpha, -std::expm1(-(0.125 - 0.025)));
}

// A ridge: terrain 0 but 3 along the column i = 4, top 4, affine scalar
// (4 - y) / 4. A level ray at y = 3 across the ridge touches the terrain at
// the crest only; it is in fog along its whole stretch over the grid, with
// scalar 1/4: no gap at the tangent point (a ray dipping "under" the crest
// by rounding), no piece counted twice.
TEST(GroundFogStability, ARayGrazingARidgeCrestStaysInTheFog) {
    GroundFogDesc d = slab({9, 5}, 1.0f, 0.0f, 4.0f);
    d.densityDepthWorld = 4.0f;
    for (int j = 0; j < 5; ++j) d.terrainHeight[4 + 9 * std::size_t(j)] = 3.0f;
    const TransferFunction tf = fogTransfer(1.0f);
    const glm::dvec3 o(-1.0, 3.0, 1.7), dir(1.0, 0.0, 0.0);
    const double exact = -std::expm1(-1.0 * 0.25 * 8.0);
    GroundFogRayStats rs;
    EXPECT_NEAR(integrateGroundFogRay(d, tf, o, dir, 0.0, 100.0, 1e-10, 14, &rs).a, exact, 1e-12 + rs.errorEstimate);
    // The tetrahedra (heights exact in float; scalar 3/4.. rounding 2^-24 relative over 8 units).
    const Camera cam = Camera::lookAt({-3.0f, 6.0f, -3.0f}, {4.0f, 0.0f, 2.0f}, {0, 1, 0}, glm::radians(60.0f), {16, 12}, 0.1f, 100.0f);
    EXPECT_NEAR(integrateRay(emit(d, cam), tf, o, dir, 0.0, 100.0).a, exact, 8.0 * 0.25 * 8.0 * kFloatEps + 1e-12);
    // 1e-9 lower, the crest (slope 3 each side) cuts the ray over 2e-9 / 3
    // units, losing at most that much optical depth at extinction <= 1, and
    // the scalar rises by 1e-9 / 4 over the 8 units: |d alpha| < 3e-9, no jump.
    EXPECT_NEAR(integrateGroundFogRay(d, tf, o - glm::dvec3(0.0, 1e-9, 0.0), dir, 0.0, 100.0, 1e-10).a, exact, 1e-8);
}

// A one-sample spike in the top: 1 everywhere, 5 at point (4, 2); flat
// terrain 0, affine scalar (top - y) / 5. A level ray at y = 3 along the grid
// line z = 2 (the shared edge of the spike's triangles) is in fog where the
// top, linear from 1 to 5 to 1 over x in [3, 5], is above 3: x in [3.5, 4.5],
// with (top - 3) / 5 = (2 - 4 |x - 4|) / 5: optical depth 1 * (1 / 5) * 1.
TEST(GroundFogStability, AOneSampleSpikeInTheTopIsATentAlongItsEdges) {
    GroundFogDesc d = slab({9, 5}, 1.0f, 0.0f, 1.0f);
    d.densityDepthWorld = 5.0f;
    d.fogTop[4 + 9 * 2] = 5.0f;
    const TransferFunction tf = fogTransfer(1.0f);
    const glm::dvec3 o(-1.0, 3.0, 2.0), dir(1.0, 0.0, 0.0);
    const double exact = -std::expm1(-0.2);
    GroundFogRayStats rs;
    EXPECT_NEAR(integrateGroundFogRay(d, tf, o, dir, 0.0, 100.0, 1e-10, 14, &rs).a, exact, 1e-12 + rs.errorEstimate);
    // Oblique rays through the spike: the tetrahedra hold the affine field
    // exactly (coordinates <= 8, top slope 4, sin(theta) >= 0.2 at this pitch).
    const Camera cam = Camera::lookAt({1.0f, 7.0f, -2.0f}, {4.0f, 1.0f, 2.0f}, {0, 1, 0}, glm::radians(40.0f), {16, 12}, 0.1f, 100.0f);
    GroundFogExactStats fs;
    TetraExactStats ts;
    auto field = renderGroundFogExact(d, tf, cam, {}, &fs);
    auto tets = renderTetraExact(emit(d, cam), tf, cam, {.tolerance = 1e-7}, &ts);
    ASSERT_TRUE(field && tets);
    EXPECT_LT(maxDiff(*field, *tets), fs.maxErrorEstimate + ts.maxErrorEstimate + 4.0 * 1.0 * 1.0 * 4.0 * (8.0 * kFloatEps) / 0.2 + 1e-7);
}

// A level ray along the diagonal of every cell it crosses: through a grid
// vertex at every step (x and z lines crossed at the same t), along the
// split diagonal in the even cells and across it in none. Slab 0..2, the
// paper's scalar, y = 1: scalar 1/2 over the whole diagonal, 8 sqrt 2 long.
TEST(GroundFogStability, ARayThroughEveryGridVertexCountsEachCellOnce) {
    const GroundFogDesc d = slab({9, 9}, 1.0f, 0.0f, 2.0f);
    const TransferFunction tf = fogTransfer(0.3f);
    const glm::dvec3 o(-1.0, 1.0, -1.0), dir(1.0, 0.0, 1.0);
    const double exact = -std::expm1(-double(0.3f) * 0.5 * 8.0 * std::sqrt(2.0)); // the transfer's extinction is the float 0.3f
    GroundFogRayStats rs;
    EXPECT_NEAR(integrateGroundFogRay(d, tf, o, dir, 0.0, 100.0, 1e-10, 14, &rs).a, exact, 1e-12 + rs.errorEstimate);
    // And the same along the anti-diagonal (the odd cells' split).
    EXPECT_NEAR(integrateGroundFogRay(d, tf, {9.0, 1.0, -1.0}, {-1.0, 0.0, 1.0}, 0.0, 100.0, 1e-10).a, exact, 1e-10);
    // The tetrahedra along the same ray run through their shared faces and edges.
    const Camera cam = Camera::lookAt({-3.0f, 5.0f, -3.0f}, {4.0f, 0.0f, 4.0f}, {0, 1, 0}, glm::radians(60.0f), {16, 12}, 0.1f, 100.0f);
    EXPECT_NEAR(integrateRay(emit(d, cam), tf, o, dir, 0.0, 100.0).a, exact, 8.0 * 0.3 * 0.5 * 12.0 * kFloatEps + 1e-12);
}

// The layer 100 km from the origin (x, z ~ 1e5, where a float's ulp is 2^-7):
// the field in double does not care (the same ray relative to the layer gives
// the same answer as at the origin); the float tetrahedra are off by half an
// ulp per vertex and their image stays within the float bound for that ulp.
TEST(GroundFogStability, HugeHorizontalCoordinatesKeepTheLayerWithinHalfAnUlp) {
    GroundFogDesc near0 = valleys({9, 9}, 0.8f, 3.0f);
    near0.originWorld = {0.0f, 0.0f, 0.0f};
    near0.spacingWorld = 0.3f;
    GroundFogDesc far = near0;
    far.originWorld = {100000.0f, 0.0f, -100000.0f};
    const TransferFunction tf = fogTransfer(1.5f);
    const glm::dvec3 shift(100000.0, 0.0, -100000.0);
    for (const glm::dvec3& o : {glm::dvec3(-1.0, 3.0, -0.5), glm::dvec3(0.2, 2.5, -1.0)}) {
        const glm::dvec3 dir(0.4, -0.5, 0.5);
        const glm::dvec4 a = integrateGroundFogRay(near0, tf, o, dir, 0.0, 100.0, 1e-10);
        const glm::dvec4 b = integrateGroundFogRay(far, tf, o + shift, dir, 0.0, 100.0, 1e-10);
        // Double: 1e5 * 2^-53 per coordinate, times the slope and scalar: < 1e-9.
        EXPECT_NEAR(a.a, b.a, 1e-9);
        EXPECT_GT(a.a, 0.01);
    }
    const Camera cam = Camera::lookAt(glm::vec3(shift) + glm::vec3(-2.0f, 4.0f, -2.0f), glm::vec3(shift) + glm::vec3(1.2f, 0.0f, 1.2f), {0, 1, 0},
                                      glm::radians(50.0f), {16, 12}, 0.1f, 100.0f);
    GroundFogExactStats fs;
    TetraExactStats ts;
    auto field = renderGroundFogExact(far, tf, cam, {}, &fs);
    auto tets = renderTetraExact(emit(far, cam), tf, cam, {.tolerance = 1e-7}, &ts);
    ASSERT_TRUE(field && tets);
    // Float: vertices within half an ulp at 1e5 (2^-8) horizontally; the
    // terrain's slope <= 2 * 6 / 2.4 + 0.5 / 2.4 < 6, the scalar <= 0.8 / 3,
    // extinction 1.5, <= 4 terrain crossings at sin(theta) >= 0.3 at this pitch.
    const double floatTerm = 4.0 * 1.5 * (0.8 / 3.0) * 6.0 * (1.0 / 256.0) / 0.3;
    EXPECT_LT(maxDiff(*field, *tets), fs.maxErrorEstimate + ts.maxErrorEstimate + floatTerm);
    double alpha = 0.0;
    for (std::size_t i = 3; i < field->pixels.size(); i += 4) alpha = std::max(alpha, double(field->pixels[i]));
    EXPECT_GT(alpha, 0.1);
}
