// The lit volume reference (reference.hpp, LitVolumeDesc; issue 24, item 1):
// lighting.hpp's model at every sample point of the continuous field, with
// the transmittance to each light through that field, and the error of the
// real-time lighting decomposed against it into its parts: per-voxel
// lighting, the light's field (trilinear DensityField), the shadow table's
// resolution, the HG lobe fit and the 8-bit lit colour. The hard cases at
// the end are listed in docs/STABILITY.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "image_stats.hpp"
#include "splatfx/reference.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A 3x3x3 blob (spacing 0.25) of one colour, seen from the side of an oblique sun.
struct LitBlob {
    Materials materials{Footprint{}};
    Grid grid = test::gaussianBlob(3, 0.25f, 0.7f);
    glm::vec4 base{0.8f, 0.7f, 0.6f, 1.0f};
    glm::vec3 centre{0.0f};
    Camera camera;
    LitVolumeDesc lit;
    LitBlob() {
        materials.addColorTable(ColorTable::constant(base));
        for (const Voxel& v : grid.voxels) centre += grid.worldPosition(v.cell) / float(grid.voxels.size());
        camera = Camera::lookAt(centre + glm::vec3(0.9f, 0.5f, 2.4f), centre, {0, 1, 0}, 0.55f, {32, 24}, 0.1f, 20.0f);
        lit.lights = {Light::directional({0.6f, -0.7f, -0.4f}, glm::vec3(1.0f), 1.6f)};
        const HgLobe lobes[] = {{.g = 0.82f, .weight = 0.992f}, {.g = -0.54f, .weight = 0.008f}}; // the bench's 2-lobe fit
        lit.gas = {.phase = *PhaseFunction::create(lobes), .albedo = 0.9f, .ambient = glm::vec3(0.05f)};
    }
    std::vector<glm::vec3> centres() const {
        std::vector<glm::vec3> p;
        for (const Voxel& v : grid.voxels) p.push_back(grid.worldPosition(v.cell));
        return p;
    }
    // Lit colours per voxel: base times the model's factor at the voxel centre with these shadows.
    std::vector<glm::vec3> colours(const ShadowProvider* shadows, const GasLightingDesc& gas) const {
        std::vector<glm::vec3> f;
        EXPECT_TRUE(lightPoints(centres(), grid.spacing.x, camera.eye(), lit.lights, shadows, gas, f));
        for (glm::vec3& c : f) c *= glm::vec3(base);
        return f;
    }
    VolumeField field(std::span<const glm::vec3> colours = {}) const {
        VolumeField f(materials);
        f.add(grid, {.textured = false}, colours);
        return f;
    }
};

// Cornette-Shanks (g = 0.75): the exact phase the two lobes above are fitted to (tools/bench/shadows.cpp).
double cornetteShanks(double mu) {
    const double g = 0.75, g2 = g * g;
    return 3.0 / (8.0 * kPi) * (1.0 - g2) * (1.0 + mu * mu) / ((2.0 + g2) * std::pow(1.0 + g2 - 2.0 * g * mu, 1.5));
}

// The 8-bit lit colour a Scene writes into the splat (scene_lighting.cpp, packLit) read back: for
// colours <= 1, round(c 255) / 255.
glm::vec3 eightBit(glm::vec3 c) {
    for (int a = 0; a < 3; ++a) c[a] = std::floor(std::clamp(c[a], 0.0f, 1.0f) * 255.0f + 0.5f) / 255.0f;
    return c;
}

double maxVoxelDiff(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    double m = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) m = std::max(m, double(std::abs(a[i][c] - b[i][c])));
    return m;
}
// Largest pixel opacity (1 - T): every per-voxel colour term is at most this times the largest
// change of a voxel colour, because the pixel is sum_steps w_s * (colour mean) with weights
// w_s >= 0 summing to 1 - T that do not depend on the colours (a fixed step makes them identical).

// sup over each kernel's support of |base (f(x) - f(c_j))|: what replacing the lit factor at
// every sample point by its value at the voxel centre can change a colour by (the image changes by
// at most (1 - T) times it; see maxAlpha). Sampled on a 7^3 lattice over each support's bounding
// box (a superset of the support). A point of the box is within half a lattice step of a sample
// along each axis, so where f is close to linear on a lattice cell (it is smooth on that scale)
// it differs from that sample by at most half the three axis steps: 1.5 times the largest change
// between lattice neighbours.
double perVoxelBound(const LitBlob& s, const VolumeField& field, const LitVolumeDesc& lit, const std::vector<glm::vec3>& voxelColours) {
    const double R = s.materials.footprint().radius() * s.grid.spacing.x;
    const glm::dvec3 eye(s.camera.eye());
    const std::vector<glm::vec3> cs = s.centres();
    constexpr int n = 7;
    double worst = 0.0, step = 0.0;
    for (std::size_t j = 0; j < cs.size(); ++j) {
        std::vector<glm::dvec3> f(n * n * n);
        for (int k = 0; k < n; ++k)
            for (int jj = 0; jj < n; ++jj)
                for (int i = 0; i < n; ++i) {
                    const glm::dvec3 x = glm::dvec3(cs[j]) + R * (glm::dvec3(i, jj, k) / double(n - 1) * 2.0 - 1.0);
                    f[std::size_t(i + n * (jj + n * k))] = litFactor(field, x, eye, lit) * glm::dvec3(s.base);
                }
        for (int k = 0; k < n; ++k)
            for (int jj = 0; jj < n; ++jj)
                for (int i = 0; i < n; ++i) {
                    const glm::dvec3 v = f[std::size_t(i + n * (jj + n * k))];
                    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(v[c] - double(voxelColours[j][c])));
                    if (i + 1 < n) step = std::max(step, glm::length(f[std::size_t(i + 1 + n * (jj + n * k))] - v));
                    if (jj + 1 < n) step = std::max(step, glm::length(f[std::size_t(i + n * (jj + 1 + n * k))] - v));
                    if (k + 1 < n) step = std::max(step, glm::length(f[std::size_t(i + n * (jj + n * (k + 1)))] - v));
                }
    }
    return worst + 1.5 * step;
}

} // namespace

TEST(LitReference, SegmentDepthOverAWholeChordEqualsTheClosedFormLineIntegral) {
    // lineOpticalDepth sums each kernel's footprint F(q) (Footprint::exact, converged to double
    // precision); the segment integrator splits per kernel and refines. For Crawfis-Max the first
    // 6-point rule is already exact (degree 10 along a line); the Gaussian needs doublings.
    // Tolerance: 1e-9 relative (both quadratures agree with a 2-million-panel Simpson rule to
    // ~1e-14; the sum of 27 terms rounds far below it). A wrong Gauss weight in the 8th digit
    // shows here as 2.5e-9.
    for (Kernel kernel : {Kernel::CrawfisMax, Kernel::Gaussian}) {
        Materials m{Footprint{{.kernel = kernel}}};
        m.addColorTable(ColorTable::constant(glm::vec4(1.0f)));
        VolumeField f(m);
        f.add(test::gaussianBlob(3, 0.25f, 0.7f), {.textured = false});
        for (glm::dvec3 dir : {glm::dvec3(1, 0, 0), glm::dvec3(0.3, -0.8, 0.5), glm::dvec3(1, 1, 1)}) {
            const glm::dvec3 o(0.21, 0.27, 0.24), d = glm::normalize(dir);
            const double line = f.lineOpticalDepth(o, d), seg = f.segmentOpticalDepth(o - 10.0 * d, o + 10.0 * d);
            ASSERT_GT(line, 0.2);
            EXPECT_NEAR(seg, line, 1e-9 * line) << "kernel " << int(kernel);
        }
    }
}

TEST(LitReference, EmissionOnlyReproducesTheUnlitVolumeReferenceBitForBit) {
    // Factor exactly 1 at every sample (emission 1, albedo 0): the lit path multiplies by 1.0,
    // so the image must be identical, not merely close.
    LitBlob s;
    const VolumeField f = s.field();
    LitVolumeDesc lit = s.lit;
    lit.gas.emission = 1.0f, lit.gas.albedo = 0.0f;
    auto unlit = renderVolumeExact(f, s.camera, {.threads = 1});
    auto lit1 = renderVolumeExact(f, s.camera, {.threads = 1, .lighting = &lit});
    ASSERT_TRUE(unlit && lit1);
    EXPECT_EQ(unlit->pixels, lit1->pixels);
    EXPECT_GT(test::maxAlpha(*unlit), 0.5);
}

TEST(LitReference, TheFactorIsTheModelOfLightingHppAtEveryPoint) {
    // At the voxel centres (farther than half a voxel from every light) lightPoints with the
    // reference's own shadows computes the same formula in float: relative 1e-5 (float rounding of
    // a dozen operations, ~1e-6, with margin for the phase's 1.5 power near its peak).
    LitBlob s;
    const VolumeField f = s.field();
    s.lit.lights = {Light::directional({0.6f, -0.7f, -0.4f}, glm::vec3(1.0f, 0.9f, 0.8f), 1.3f),
                    Light::point(s.centre + glm::vec3(0.9f, 0.2f, -0.3f), glm::vec3(0.5f, 0.6f, 1.0f), 0.7f),
                    Light::spot(s.centre + glm::vec3(-0.4f, 1.2f, 0.1f), {0.3f, -1.0f, 0.0f}, 0.2f, 0.5f, glm::vec3(1.0f), 2.0f)};
    s.lit.gas.multipleScattering = 0.2f, s.lit.gas.emission = 0.1f;
    const VolumeFieldShadows shadows(f, s.lit.lights);
    std::vector<glm::vec3> model;
    ASSERT_TRUE(lightPoints(s.centres(), s.grid.spacing.x, s.camera.eye(), s.lit.lights, &shadows, s.lit.gas, model));
    const std::vector<glm::vec3> cs = s.centres();
    for (std::size_t i = 0; i < cs.size(); ++i) {
        const glm::dvec3 ref = litFactor(f, glm::dvec3(cs[i]), glm::dvec3(s.camera.eye()), s.lit);
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(model[i][c], ref[c], 1e-5 * ref[c]) << "voxel " << i;
    }
}

TEST(LitReference, ErrorDecomposesIntoPerVoxelLightFieldTableLobeAndEightBitTerms) {
    LitBlob s;
    const VolumeField f = s.field();
    const glm::dvec3 eye(s.camera.eye());

    // The reference: lit at every sample point. Tolerance 1e-6 per pixel (its own estimate).
    VolumeExactStats refStats;
    auto exact = renderVolumeExact(f, s.camera, {.tolerance = 1e-6, .lighting = &s.lit}, &refStats);
    ASSERT_TRUE(exact) << exact.error();
    ASSERT_EQ(refStats.unconverged, 0u);

    // Per voxel, with the reference's own shadows: the per-voxel lighting alone.
    const VolumeFieldShadows exactShadows(f, s.lit.lights);
    const std::vector<glm::vec3> voxel = s.colours(&exactShadows, s.lit.gas);
    for (const glm::vec3& c : voxel) ASSERT_LE(std::max({c.r, c.g, c.b}), 1.0f) << "the 8-bit bound below assumes colours <= 1";
    VolumeExactStats voxStats;
    auto perVoxel = renderVolumeExact(s.field(voxel), s.camera, {.tolerance = 1e-6}, &voxStats);
    ASSERT_TRUE(perVoxel);
    const double alpha = test::maxAlpha(*exact);
    const double quad = refStats.maxErrorEstimate + voxStats.maxErrorEstimate;
    const double perVoxelTerm = test::maxDiff(*exact, *perVoxel);
    const double perVoxelLimit = alpha * perVoxelBound(s, f, s.lit, voxel) + quad;
    EXPECT_LE(perVoxelTerm, perVoxelLimit);
    // Resolved: the term stands well above the reference's own error (else it would not "show").
    EXPECT_GT(perVoxelTerm, 100.0 * quad);

    // The remaining terms change voxel colours only; with a fixed step the images are the same
    // convex combination of them, so each image term is at most alpha times the largest voxel change.
    const double h = 0.25 * 0.25 * 0.25;
    auto image = [&](const std::vector<glm::vec3>& c) { return *renderVolumeExact(s.field(c), s.camera, {.fixedStep = h}); };
    const Image base = image(voxel);
    auto term = [&](const char* name, const std::vector<glm::vec3>& c, double voxelBound) {
        const double v = maxVoxelDiff(c, voxel), img = test::maxDiff(image(c), base);
        EXPECT_LE(v, voxelBound) << name;
        EXPECT_LE(img, alpha * v * (1.0 + 1e-6) + 1e-7) << name; // float image rounding
        std::printf("  %-38s voxels %.3f/255, image %.3f/255\n", name, 255.0 * v, 255.0 * img);
        return v;
    };
    std::printf("lit 3x3x3 blob, 32x24: per-voxel lighting %.3f/255 (bound %.3f), reference error %.1e\n", 255.0 * perVoxelTerm,
                255.0 * perVoxelLimit, quad);

    // The light's field: splatfx traces the trilinear DensityField, the reference the kernel sum.
    // Bounded by the whole scattered term (transmittance in [0, 1]); measured and printed.
    auto density = DensityField::fromGrid(s.grid);
    ASSERT_TRUE(density);
    const ShadowTracer tracer(*density, s.lit.lights);
    const std::vector<glm::vec3> traced = s.colours(&tracer, s.lit.gas);
    double scatterMax = 0.0;
    for (const glm::vec3& c : voxel) scatterMax = std::max(scatterMax, double(std::max({c.r, c.g, c.b})));
    term("light's field (trilinear vs kernels)", traced, scatterMax);

    // The table: against tracing the same DensityField, first order in the node spacing
    // (lighting.hpp). Over two doublings the error must fall by at least 2 (order >= 0.5: half the
    // nominal order, room for the pre-asymptotic range of a 3-voxel field), and fall at each step.
    double prev = 1e300, first = 0.0, last = 0.0;
    for (int n : {8, 16, 32}) {
        ShadowTables tables({.dims = glm::ivec3(n)});
        ASSERT_TRUE(tables.update(*density, s.lit.lights));
        const std::vector<glm::vec3> tabled = s.colours(&tables, s.lit.gas);
        double e = 0.0;
        for (std::size_t i = 0; i < tabled.size(); ++i)
            for (int c = 0; c < 3; ++c) e = std::max(e, double(std::abs(tabled[i][c] - traced[i][c])));
        char name[64];
        std::snprintf(name, sizeof name, "table %d^3 (vs tracing: %.3f/255)", n, 255.0 * e);
        term(name, tabled, scatterMax);
        EXPECT_LT(e, prev) << n;
        prev = e;
        (n == 8 ? first : last) = e;
    }
    EXPECT_LE(last, 0.5 * first);

    // The lobe fit: the model's two lobes against the exact Cornette-Shanks phase they stand for,
    // per voxel with the reference's shadows. Bound: albedo * E * 4 pi * max_mu |p_fit - p_cs| * base.
    LitVolumeDesc cs = s.lit;
    cs.phase = cornetteShanks;
    std::vector<glm::vec3> csColours;
    for (const glm::vec3& c : s.centres()) csColours.push_back(glm::vec3(litFactor(f, glm::dvec3(c), eye, cs)) * glm::vec3(s.base));
    double phaseGap = 0.0;
    for (int k = 0; k <= 2000; ++k) {
        const double mu = -1.0 + k / 1000.0;
        phaseGap = std::max(phaseGap, std::abs(double(s.lit.gas.phase(float(mu))) - cornetteShanks(mu)));
    }
    term("HG lobe fit (2 lobes vs Cornette-Shanks)", csColours,
         s.lit.gas.albedo * s.lit.lights[0].intensity * 4.0 * kPi * phaseGap * s.base.r * (1.0 + 1e-5));

    // The 8-bit lit colour: half a level per channel.
    std::vector<glm::vec3> packed;
    for (const glm::vec3& c : voxel) packed.push_back(eightBit(c));
    term("8-bit lit colour", packed, 0.5 / 255.0 + 1e-7);
}

// ---------------------------------------------------------------- hard cases (docs/STABILITY.md)

TEST(LitReferenceHardCases, APointLightExactlyOnAVoxelCentreIsFiniteIsotropicAndUnshadowedThere) {
    // Zero distance: no direction to the light (a NaN phase), a zero-length shadow segment (0/0).
    // With radiusWorld = half a voxel both the model and the reference take the irradiance at
    // that radius and the isotropic phase, and T = 1 exactly: the factor is emission +
    // albedo (ambient + I / r^2 (1 + ms)). Relative 1e-6 (float).
    LitBlob s;
    const VolumeField f = s.field();
    const glm::vec3 at = s.grid.worldPosition({1, 1, 1});
    const float r = 0.5f * s.grid.spacing.x;
    Light light = Light::point(at, glm::vec3(1.0f), 0.02f);
    light.radiusWorld = r;
    s.lit.lights = {light};
    s.lit.gas.multipleScattering = 0.25f;
    EXPECT_EQ(f.opticalDepthToLight(glm::dvec3(at), light), 0.0);
    const double expected = double(s.lit.gas.albedo) * (double(0.05f) + double(0.02f) / (double(r) * r) * (1.0 + double(0.25f)));
    const glm::dvec3 ref = litFactor(f, glm::dvec3(at), glm::dvec3(s.camera.eye()), s.lit);
    const VolumeFieldShadows shadows(f, s.lit.lights);
    std::vector<glm::vec3> model;
    const glm::vec3 p[] = {at};
    ASSERT_TRUE(lightPoints(p, s.grid.spacing.x, s.camera.eye(), s.lit.lights, &shadows, s.lit.gas, model));
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(ref[c], expected, 1e-12 * expected);
        EXPECT_NEAR(model[0][c], expected, 1e-6 * expected);
    }
    // And the image around it is finite (the source jumps at r, where the phase turns isotropic,
    // so the step halving converges only to first order there: a few halvings, not convergence).
    auto img = renderVolumeExact(f, s.camera, {.tolerance = 1e-4, .maxHalvings = 3, .lighting = &s.lit});
    ASSERT_TRUE(img);
    for (float v : img->pixels) ASSERT_TRUE(std::isfinite(v));
}

TEST(LitReferenceHardCases, ASpotConeEdgeThroughTheVolumeKeepsThePerVoxelErrorWithinItsBound) {
    // The cone's smooth step (0.30 to 0.32 rad) cuts through the blob: voxels on either side of
    // it are lit fully or not at all, while sample points between them are partly lit. The
    // per-voxel error must stay within the sup bound (perVoxelBound), and the reference's factor
    // along a line across the edge must be the smoothstep times the unspotted factor, exactly.
    LitBlob s;
    const VolumeField f = s.field();
    const glm::vec3 apex = s.centre + glm::vec3(0.0f, 1.5f, 0.0f);
    const glm::vec3 axis = glm::normalize(s.centre + glm::vec3(0.35f, 0.0f, 0.0f) - apex);
    s.lit.lights = {Light::spot(apex, axis, 0.30f, 0.32f, glm::vec3(1.0f), 3.0f)};
    s.lit.gas.ambient = glm::vec3(0.0f);
    LitVolumeDesc point = s.lit;
    point.lights = {Light::point(apex, glm::vec3(1.0f), 3.0f)};
    const glm::dvec3 eye(s.camera.eye());
    int partial = 0;
    for (int k = 0; k <= 400; ++k) {
        const glm::dvec3 x = glm::dvec3(s.centre) + glm::dvec3(-0.4 + 0.8 * k / 400.0, 0.0, 0.0);
        const double cosA = glm::dot(glm::normalize(x - glm::dvec3(apex)), glm::normalize(glm::dvec3(axis)));
        const double cosOuter = std::cos(double(0.32f)), cosInner = std::cos(double(0.30f));
        const double t = std::clamp((cosA - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
        const double ss = t * t * (3.0 - 2.0 * t);
        partial += ss > 0.0 && ss < 1.0;
        const glm::dvec3 spot = litFactor(f, x, eye, s.lit), full = litFactor(f, x, eye, point);
        ASSERT_NEAR(spot.r, ss * full.r, 1e-12 * full.r) << k;
    }
    EXPECT_GT(partial, 3) << "the line must cross the cone's edge";
    const VolumeFieldShadows shadows(f, s.lit.lights);
    const std::vector<glm::vec3> voxel = s.colours(&shadows, s.lit.gas);
    VolumeExactStats a, b;
    auto exact = renderVolumeExact(f, s.camera, {.tolerance = 1e-6, .lighting = &s.lit}, &a);
    auto perVoxel = renderVolumeExact(s.field(voxel), s.camera, {.tolerance = 1e-6}, &b);
    ASSERT_TRUE(exact && perVoxel);
    const double term = test::maxDiff(*exact, *perVoxel);
    EXPECT_LE(term, test::maxAlpha(*exact) * perVoxelBound(s, f, s.lit, voxel) + a.maxErrorEstimate + b.maxErrorEstimate);
    EXPECT_GT(term, 1.0 / 255.0) << "a hard cone edge must show as per-voxel error";
}

TEST(LitReferenceHardCases, ASunGrazingTheSlabAlongItsRowsMatchesThePerKernelChordIntegrals) {
    // A 6x1x1 row lit exactly along its axis, and along a line just inside the supports' rim
    // (distance R (1 - 1e-9) from the centres): every kernel boundary falls at the same points
    // (the line through all centres) or the chords almost vanish (a discriminant near 0). The
    // depth to the light must equal the sum of each kernel's partial line integral,
    // Footprint::exactBefore (an independent quadrature). Relative 1e-9 of the centre-line
    // depth: both sides are Gauss rules converged far below it.
    Materials m{Footprint{}};
    m.addColorTable(ColorTable::constant(glm::vec4(1.0f)));
    Grid g = *Grid::box({6, 1, 1}, glm::vec3(0.2f));
    for (Voxel& v : g.voxels) v.opacity = 0.5f;
    VolumeField f(m);
    f.add(g, {.textured = false});
    const Footprint& fp = m.footprint();
    const double sp = double(0.2f), R = fp.radius(); // the grid's float spacing
    const Light sun = Light::directional({1.0f, 0.0f, 0.0f}); // travels +x: the light is at -x
    const double centreLine = f.kernels()[0].scale * sp * fp.exact(0.0) * 6.0;
    for (double offset : {0.0, R * (1.0 - 1e-9)}) {
        for (int probe = 0; probe <= 10; ++probe) {
            const glm::dvec3 c0 = f.kernels()[0].center;
            const glm::dvec3 x = c0 + glm::dvec3(sp * (probe * 0.5 - 0.3), offset * sp, 0.0);
            double expected = 0.0;
            for (const auto& k : f.kernels()) expected += k.scale * sp * fp.exactBefore(offset, (x.x - k.center.x) / sp);
            EXPECT_NEAR(f.opticalDepthToLight(x, sun), expected, 1e-9 * centreLine) << "offset " << offset << " probe " << probe;
        }
    }
}

TEST(LitReferenceHardCases, HgLobesAtGPlusMinusOneStillIntegrateToOneOverTheSphere) {
    // |g| = 1 - 1e-6 (the model's limit): each lobe's peak is 1e-12 wide in 1 - mu, which a
    // cosine in double resolves only to 1e-16 absolute, so the reference takes 1 -+ mu as given.
    // Integrated in log(1 - mu) and log(1 + mu) (Gauss on 200 panels per decade-spanning half),
    // the sum of the lobes must integrate to 1: 2 pi int p dmu = 1 for every HG lobe.
    // Tolerance 1e-8: the log-substituted Gauss rule on a smooth integrand is far below it.
    const HgLobe lobes[] = {{.g = 1.0f - 1e-6f, .weight = 0.5f}, {.g = -(1.0f - 1e-6f), .weight = 0.5f}};
    LitVolumeDesc d;
    d.gas.phase = *PhaseFunction::create(lobes);
    auto integrateHalf = [&](bool forward) {
        // forward: u = 1 - mu in [1e-18, 1]; else u = 1 + mu. p du with u = e^s.
        constexpr double x5[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
        constexpr double w5[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};
        const double a = std::log(1e-18), b = 0.0;
        const int panels = 4000;
        double sum = 0.0;
        for (int p = 0; p < panels; ++p) {
            const double m = a + (p + 0.5) * (b - a) / panels, h = (b - a) / panels;
            for (int i = 0; i < 5; ++i) {
                const double u = std::exp(m + 0.5 * h * x5[i]);
                const double val = forward ? litPhase(d, 1.0 - u, u, 2.0 - u) : litPhase(d, u - 1.0, 2.0 - u, u);
                sum += w5[i] * 0.5 * h * val * u;
            }
        }
        // Below u = 1e-18 the lobe is flat (its width in u is (1 - g)^2 / 2g = 5e-13): p(0) * 1e-18.
        sum += 1e-18 * (forward ? litPhase(d, 1.0, 0.0, 2.0) : litPhase(d, -1.0, 2.0, 0.0));
        return 2.0 * kPi * sum;
    };
    EXPECT_NEAR(integrateHalf(true) + integrateHalf(false), 1.0, 1e-8);
    // The peaks are where they belong: (1 + g) / (4 pi (1 - g)^2) / 2 each at mu = +-1.
    const double g = double(1.0f - 1e-6f), peak = 0.5 * (1.0 + g) / (4.0 * kPi * (1.0 - g) * (1.0 - g));
    EXPECT_NEAR(litPhase(d, 1.0, 0.0, 2.0), peak, 1e-6 * peak);
    EXPECT_NEAR(litPhase(d, -1.0, 2.0, 0.0), peak, 1e-6 * peak);
}

TEST(LitReferenceHardCases, ASingleVoxelLitFromInsideMatchesARadialQuadrature) {
    // One voxel, a point light at its centre (radiusWorld r0), the eye on the axis through both:
    // the middle pixel's ray passes through the light. Along that ray everything is radial, so
    // the pixel is a 1D integral with closed-form pieces: sigma(t) = scale h(|t - tc| / sp),
    // the view transmittance from it, the light's transmittance along the radius (Footprint::
    // exactBefore), E = I / max(d, r0)^2 and the phase at mu = +1 in front of the light, -1
    // behind it (isotropic within r0). Integrated here by Gauss on 4000 panels split at the kinks;
    // tolerance: the reference's own error estimate plus 1e-7.
    Materials m{Footprint{}};
    m.addColorTable(ColorTable::constant(glm::vec4(1.0f)));
    Grid g;
    g.spacing = glm::vec3(0.3f);
    g.voxels.push_back({.cell = {0, 0, 0}, .opacity = 0.6f});
    VolumeField f(m);
    f.add(g, {.textured = false});
    ASSERT_EQ(f.kernels().size(), 1u);
    const glm::dvec3 c = f.kernels()[0].center;
    const double sp = double(0.3f), r0 = double(0.05f), I = double(0.02f), gg = double(0.4f), albedo = double(0.9f); // as the floats below hold them
    Light light = Light::point(glm::vec3(c), glm::vec3(1.0f), float(I));
    light.radiusWorld = float(r0);
    LitVolumeDesc lit;
    lit.lights = {light};
    const HgLobe lobe[] = {{.g = float(gg), .weight = 1.0f}};
    lit.gas = {.phase = *PhaseFunction::create(lobe), .albedo = float(albedo)};
    const double eyeDist = 2.0;
    const Camera cam = Camera::lookAt(glm::vec3(c) + glm::vec3(0.0f, 0.0f, float(eyeDist)), glm::vec3(c), {0, 1, 0}, 0.4f, {5, 5}, 0.1f, 10.0f);
    VolumeExactStats st;
    auto img = renderVolumeExact(f, cam, {.tolerance = 1e-8, .maxHalvings = 14, .lighting = &lit}, &st);
    ASSERT_TRUE(img);

    const Footprint& fp = m.footprint();
    const double scale = f.kernels()[0].scale, R = fp.radius() * sp;
    auto hg = [&](double mu) { return (1 - gg * gg) / (4 * kPi * std::pow(1 + gg * gg - 2 * gg * mu, 1.5)); };
    constexpr double x5[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
    constexpr double w5[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};
    // s: signed distance from the centre along the view ray (towards the far side), in [-R, R].
    double C = 0.0, tauView = 0.0;
    const double knots[] = {-R, -r0, 0.0, r0, R};
    for (int piece = 0; piece < 4; ++piece) {
        const int panels = 1000;
        const double a = knots[piece], b = knots[piece + 1], h = (b - a) / panels;
        for (int p = 0; p < panels; ++p) {
            double dTau = 0.0, src = 0.0;
            for (int i = 0; i < 5; ++i) {
                const double s = a + (p + 0.5) * h + 0.5 * h * x5[i];
                const double sigma = scale * fp.kernel(std::abs(s) / sp);
                const double d = std::abs(s);
                // Light's depth from the point to the centre: the radial partial integral.
                const double tauL = scale * sp * (0.5 * fp.exact(0.0) - fp.exactBefore(0.0, -d / sp));
                // In front of the light (s < 0) it travels towards the eye: mu = +1.
                const double p4 = d < r0 ? 1.0 : 4 * kPi * hg(s < 0.0 ? 1.0 : -1.0);
                const double E = I / std::pow(std::max(d, r0), 2.0);
                dTau += w5[i] * 0.5 * h * sigma;
                src += w5[i] * 0.5 * h * sigma * albedo * E * p4 * std::exp(-tauL) * std::exp(-(tauView + 0.0));
            }
            // The view transmittance inside one tiny panel: first order is enough at 4000 panels
            // (the panel's own dTau is ~1e-4, its second-order effect ~1e-9).
            C += src * std::exp(-0.5 * dTau) / 1.0;
            tauView += dTau;
        }
    }
    EXPECT_NEAR(img->at(2, 2, 0), C, st.maxErrorEstimate + 1e-7);
    EXPECT_NEAR(img->at(2, 2, 3), 1.0 - std::exp(-tauView), 1e-7);
    EXPECT_GT(C, 0.05) << "the light inside must show";
}

TEST(LitReference, ABadLightOrGasDescIsNamedAndNothingIsRendered) {
    LitBlob s;
    const VolumeField f = s.field();
    LitVolumeDesc bad = s.lit;
    bad.lights.push_back(Light::point({0, 0, 0}));
    bad.lights[1].intensity = -1.0f;
    auto a = renderVolumeExact(f, s.camera, {.lighting = &bad});
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("renderVolumeExact: desc.lighting: lights[1].intensity must be a finite number >= 0"), std::string::npos) << a.error();
    bad = s.lit;
    bad.gas.albedo = 1.5f;
    auto b = renderVolumeExact(f, s.camera, {.lighting = &bad});
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().find("renderVolumeExact: desc.lighting: GasLightingDesc.albedo must be in [0, 1]"), std::string::npos) << b.error();
}
