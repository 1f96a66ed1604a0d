// Volumes as light sources (issue 27 item 3): the exact irradiance an
// emissive volume gives a surface (reference::emittedIrradianceExact) against
// the point-source law, and the point lights fitted to its emission
// (fitEmittedLights, emittedIrradiance) against that exact irradiance.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/emitted_light.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A round splat of world support radius a centred at c, its plane facing p
// (what a camera at p would build), plain footprint (layer 0), colour row `row`.
Splat facing(glm::vec3 c, glm::vec3 p, float a, float density, std::uint32_t row) {
    const glm::vec3 w = glm::normalize(p - c);
    const glm::vec3 helper = std::abs(w.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 u = glm::normalize(glm::cross(helper, w)), v = glm::cross(w, u);
    Splat s;
    s.center = c;
    s.density = density;
    s.axisU = u * a;
    s.axisV = v * a;
    s.colorRow = float(row);
    s.colorCoord = 0.5f;
    s.depth = glm::length(p - c);
    return s;
}

// Closed form of one plain splat's radiant intensity (premultiplied colour
// integrated over its disc): colour x a^2 x 2 pi x integral_0^1 q (1 - 2^(-rho F(Rq)/F(0))) dq,
// the exact window as the reference evaluates it (composite Simpson, 2000
// intervals on a smooth integrand: far below float rounding).
double plainIntensity(const Footprint& fp, double a, double density) {
    const double R = fp.radius(), F0 = fp.exact(0.0);
    const int n = 2000;
    auto f = [&](double q) { return q * -std::expm1(-std::log(2.0) * density * fp.exact(R * q) / F0); };
    double sum = f(0.0) + f(1.0);
    for (int i = 1; i < n; ++i) sum += f(double(i) / n) * (i % 2 ? 4.0 : 2.0);
    return a * a * 2.0 * kPi * sum / (3.0 * n);
}

// A small fire: nx x ny x nz voxels of `spacing`, its base centred at the
// origin, flame-like opacity falling with height, turbulent textures.
Grid smallFire(glm::ivec3 dims, float spacing, float peak, std::uint32_t frame) {
    Grid g = *Grid::box(dims, glm::vec3(spacing));
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-0.5f * spacing * float(dims.x - 1), 0.0f, -0.5f * spacing * float(dims.z - 1)));
    for (Voxel& v : g.voxels) {
        const float h = float(v.cell.y) / float(std::max(dims.y - 1, 1));
        v.opacity = peak * (1.0f - 0.6f * h);
        v.colorCoord = h;
        v.texture = std::uint32_t(v.cell.x * 7 + v.cell.y * 3 + v.cell.z * 5) + frame;
    }
    return g;
}

struct FireMaterials {
    Materials m{Footprint{}};
    std::uint32_t set = 0, row = 0;
    FireMaterials() {
        set = m.addTextureSet(TextureSet::turbulence({.count = 8, .size = 32, .seed = 3}));
        row = m.addColorTable(ColorTable::fire());
    }
};

std::vector<Splat> fireSplats(const FireMaterials& fm, const Grid& g, glm::vec3 eye) {
    SplatBuilder b(SplatBuilderDesc{.frustumCull = false});
    b.begin(Camera::lookAt(eye, glm::vec3(0.0f, 0.2f, 0.0f), std::abs(eye.y) > 0.9f * glm::length(eye) ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0),
                           1.2f, {64, 64}));
    b.add(g, fm.m, {.textureSet = fm.set, .colorTable = fm.row, .textured = true});
    return b.splats();
}

double sum3(glm::dvec3 v) { return v.x + v.y + v.z; }

// A colour row at coordinate t, linearly between entries (as the fit reads it).
glm::vec3 rowColorAt(const Materials& m, std::uint32_t row, float t) {
    const std::vector<glm::vec4>& r = m.colorRow(row);
    const float f = std::clamp(t, 0.0f, 1.0f) * float(r.size() - 1);
    const std::size_t i = std::min(std::size_t(f), r.size() - 1), j = std::min(i + 1, r.size() - 1);
    return glm::vec3(r[i]) * (1.0f - (f - float(i))) + glm::vec3(r[j]) * (f - float(i));
}

} // namespace

// The reference against the point-source law: one small plain splat seen
// from d = 20 radii gives E = I cos(theta) / d^2, I in closed form; a surface
// turned away gets exactly 0.
TEST(EmittedLight, ExactReferenceFollowsThePointSourceLawWithItsCosine) {
    Materials m{Footprint{}};
    const std::uint32_t row = m.addColorTable(ColorTable::constant({1.0f, 0.5f, 0.25f, 1.0f}));
    const glm::vec3 p(0.0f), c(0.0f, 0.0f, -2.0f);
    const float a = 0.1f, density = 1.5f;
    const std::vector<Splat> splats{facing(c, p, a, density, row)};
    const double I = plainIntensity(m.footprint(), a, density);
    const double d = 2.0;
    for (double theta : {0.0, kPi / 3.0}) {
        const glm::dvec3 n(0.0, std::sin(theta), -std::cos(theta));
        auto e = emittedIrradianceExact(splats, m, glm::dvec3(p), n, {.faceSize = 256});
        ASSERT_TRUE(e) << e.error();
        const double law = I * std::cos(theta) / (d * d);
        // A disc of radius a at distance d facing p: each element's two
        // cosines over rho^2 give d^2 / rho^4 >= (1 - 2 a^2/d^2) / d^2 (the
        // tilt's first-order term cancels over the symmetric disc), so the
        // law is off by at most 2 (a/d)^2 relative; the quadrature by its
        // error estimate (|E(n) - E(n/2)|, above the midpoint rule's (E(n) - E(n/2))/3).
        const double tol = 2.0 * (a / d) * (a / d) * law + e->errorEstimate;
        EXPECT_NEAR(e->irradiance.x, law, tol) << "theta " << theta;
        EXPECT_NEAR(e->irradiance.y, 0.5 * law, tol);
        EXPECT_NEAR(e->irradiance.z, 0.25 * law, tol);
    }
    // Behind the surface: the disc spans a/d = 0.05 rad, so a normal turned
    // 100 degrees from it sees none of it.
    const double behind = kPi * 100.0 / 180.0;
    auto e = emittedIrradianceExact(splats, m, glm::dvec3(p), glm::dvec3(0.0, std::sin(behind), -std::cos(behind)), {.faceSize = 64});
    ASSERT_TRUE(e) << e.error();
    EXPECT_EQ(e->irradiance, glm::dvec3(0.0));
}

namespace {

// The fit's own quadrature of a plain splat's intensity: the stored layer-0
// window point-sampled where fitEmittedLights samples it (every
// (layerSize / 16)-th texel centre), here with the exact window in double:
// its difference from plainIntensity is the fit's quadrature error.
double sampledIntensity(const Footprint& fp, int layerSize, double a, double density) {
    const double R = fp.radius(), F0 = fp.exact(0.0);
    const int stride = std::max(1, layerSize / 16);
    double sum = 0.0;
    int count = 0;
    for (int y = stride / 2; y < layerSize; y += stride)
        for (int x = stride / 2; x < layerSize; x += stride, ++count) {
            const double u = (x + 0.5) / layerSize * 2.0 - 1.0, v = (y + 0.5) / layerSize * 2.0 - 1.0;
            sum += -std::expm1(-std::log(2.0) * density * fp.exact(R * std::sqrt(u * u + v * v)) / F0);
        }
    return sum / count * 4.0 * a * a;
}

// Largest |stored layer-0 alpha - exact window| over texel centres (the
// footprint table's interpolation and float rounding).
double storedWindowError(const Materials& m) {
    const Footprint& fp = m.footprint();
    const int n = m.layerSize();
    const double R = fp.radius(), F0 = fp.exact(0.0);
    double worst = 0.0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double u = (x + 0.5) / n * 2.0 - 1.0, v = (y + 0.5) / n * 2.0 - 1.0;
            const double w = fp.exact(R * std::sqrt(u * u + v * v)) / F0;
            worst = std::max(worst, std::abs(double(m.layer(0)[(std::size_t(y) * n + x) * 4 + 3]) - w));
        }
    return worst;
}

// The exact irradiance of splats (occlusion between them left out: each
// splat's reference irradiance summed), channel sum, with what bounds the fit
// against it apart from the multipole terms: each splat's intensity
// quadrature in the fit and the stored window, the disc's departure from the
// point law, and the reference's error estimate. Every splat draws a layer of
// constant detail level(layer) (1: the plain footprint).
struct FarTruth {
    double truth = 0.0, slack = 0.0;
};
template <class Level>
FarTruth farTruth(const std::vector<Splat>& splats, const Materials& m, std::uint32_t row, glm::vec3 p, glm::vec3 n, int faceSize, Level level) {
    FarTruth t;
    const double wErr = storedWindowError(m);
    for (const Splat& s : splats) {
        auto e = emittedIrradianceExact({s}, m, glm::dvec3(p), glm::dvec3(n), {.faceSize = faceSize});
        EXPECT_TRUE(e) << e.error();
        if (!e) continue;
        t.truth += sum3(e->irradiance);
        const double a = std::sqrt(glm::length(glm::cross(s.axisU, s.axisV))), rho = s.density * level(s.layer);
        const double I = plainIntensity(m.footprint(), a, rho), d2 = glm::dot(s.center - p, s.center - p);
        const double colour = sum3(glm::dvec3(rowColorAt(m, row, s.colorCoord)));
        t.slack += 3.0 * e->errorEstimate + colour / d2 *
                                                (std::abs(sampledIntensity(m.footprint(), m.layerSize(), a, rho) - I) +
                                                 std::log(2.0) * rho * wErr * 4.0 * a * a + 2.0 * a * a / d2 * I + 256.0 * 0x1p-24 * I);
    }
    return t;
}

// The fit's multipole error towards p: the weighted centroid cancels the
// dipole term, and the Taylor remainder of the kernel g(y) = n.y / |y|^3,
// whose Hessian has norm <= 24 / |y|^4, is <= 12 I sigma^2 / (d - s)^4 per
// light (sigma its RMS spread, = its radius; s its farthest splat from it,
// here over all splats); the softening d^2 + sigma^2 takes at most I / d^2 x sigma^2 / d^2.
double multipoleBound(const std::vector<EmittedLight>& lights, const std::vector<Splat>& splats, glm::vec3 p) {
    double bound = 0.0;
    for (const EmittedLight& l : lights) {
        double s = 0.0;
        for (const Splat& sp : splats) s = std::max(s, double(glm::length(sp.center - l.position)));
        const double I = sum3(glm::dvec3(l.intensity)), d = glm::length(l.position - p), r2 = double(l.radius) * l.radius;
        bound += 12.0 * I * r2 / std::pow(d - s, 4.0) + I / (d * d) * r2 / (d * d);
    }
    return bound;
}

} // namespace

// One splat is one light at its centre: its intensity is the splat's
// emission up to the fit's quadrature, so it meets the reference far away.
TEST(EmittedLight, OneSplatFitsOneLightWithItsIntensity) {
    Materials m{Footprint{}};
    const std::uint32_t row = m.addColorTable(ColorTable::constant({1.0f, 0.5f, 0.25f, 1.0f}));
    const glm::vec3 p(0.0f), c(0.3f, 0.1f, -2.0f);
    const float a = 0.1f, density = 1.5f;
    const std::vector<Splat> splats{facing(c, p, a, density, row)};
    auto lights = fitEmittedLights(splats, m, {.enabled = true, .lights = 3, .occlusion = false});
    ASSERT_TRUE(lights) << lights.error();
    ASSERT_EQ(lights->size(), 1u) << "fewer lights than asked when fewer splats emit";
    const EmittedLight& l = (*lights)[0];
    EXPECT_EQ(l.position, c);
    EXPECT_EQ(l.radius, 0.0f);
    EXPECT_EQ(l.escapePlus, glm::vec3(1.0f));
    const double I = plainIntensity(m.footprint(), a, density);
    // The fit's quadrature error, and the stored window's (alpha moves by at
    // most ln 2 rho dw per sample, over the quad's area 4 a^2); float sums of
    // 256 samples add 256 x 2^-24 relative.
    const double tol = std::abs(sampledIntensity(m.footprint(), m.layerSize(), a, density) - I) +
                       std::log(2.0) * density * storedWindowError(m) * 4.0 * a * a + 256.0 * 0x1p-24 * I;
    EXPECT_NEAR(l.intensity.x, I, tol);
    EXPECT_NEAR(l.intensity.y, 0.5 * I, tol);
    EXPECT_NEAR(l.intensity.z, 0.25 * I, tol);
    // And towards a point, as the reference says (theta = 0).
    const glm::vec3 n = glm::normalize(c - p);
    auto e = emittedIrradianceExact(splats, m, glm::dvec3(p), glm::dvec3(n), {.faceSize = 256});
    ASSERT_TRUE(e) << e.error();
    const double d2 = glm::dot(c - p, c - p);
    const glm::vec3 fit = emittedIrradiance(*lights, p, n);
    EXPECT_NEAR(fit.x, e->irradiance.x, tol / d2 + 2.0 * a * a / d2 * I / d2 + e->errorEstimate);
}

// Far from the fire the fitted lights approach the emission's exact
// irradiance as (spread / distance)^2 (multipoleBound). Occlusion off: the
// truth is each splat's exact irradiance summed.
TEST(EmittedLight, FarFieldFitMeetsTheExactIrradianceWithinTheMultipoleBound) {
    Materials m{Footprint{}};
    const std::uint32_t row = m.addColorTable(ColorTable::gradient({{0.0f, {1.0f, 0.9f, 0.6f, 1.0f}}, {1.0f, {0.9f, 0.3f, 0.05f, 1.0f}}}));
    Grid g = *Grid::box({3, 4, 2}, glm::vec3(0.15f));
    for (Voxel& v : g.voxels) v.opacity = 0.3f + 0.1f * float((v.cell.x + 2 * v.cell.y + v.cell.z) % 4), v.colorCoord = float(v.cell.y) / 3.0f;
    const glm::vec3 centre = g.worldPosition({1, 1, 0}) + glm::vec3(0.0f, 0.075f, 0.075f);
    double previous = 1e30;
    for (float dist : {2.4f, 4.8f}) {
        const glm::vec3 p = centre + glm::normalize(glm::vec3(0.6f, 0.2f, 1.0f)) * dist;
        const glm::vec3 n = glm::normalize(centre - p + glm::vec3(0.0f, 0.3f, 0.0f) * dist);
        SplatBuilder b(SplatBuilderDesc{.frustumCull = false});
        b.begin(Camera::lookAt(p, centre, {0, 1, 0}, 1.2f, {32, 32}));
        b.add(g, m, {.colorTable = row, .textured = false});
        // About 8 pixels across each splat's disc at either distance.
        const FarTruth t = farTruth(b.splats(), m, row, p, n, int(40.0f * dist), [](int) { return 1.0; });
        for (int lightsAsked : {1, 3}) {
            auto lights = fitEmittedLights(b.splats(), m, {.enabled = true, .lights = lightsAsked, .occlusion = false});
            ASSERT_TRUE(lights) << lights.error();
            ASSERT_EQ(int(lights->size()), lightsAsked);
            // The dipole term vanishes only if the lights' intensity-weighted
            // centroid is the splats': checked directly against the splats'
            // closed-form intensities. Weights off by at most eps relative
            // (the fit's quadrature and stored window, as farTruth) move a
            // weighted mean by at most 2 eps / (1 - eps) x the splats' spread.
            glm::dvec3 cFit(0.0), cRef(0.0);
            double wFit = 0.0, wRef = 0.0, eps = 0.0, spread = 0.0;
            for (const EmittedLight& l : *lights) cFit += sum3(glm::dvec3(l.intensity)) * glm::dvec3(l.position), wFit += sum3(glm::dvec3(l.intensity));
            for (const Splat& sp : b.splats()) {
                const double a = std::sqrt(glm::length(glm::cross(sp.axisU, sp.axisV)));
                const double I = plainIntensity(m.footprint(), a, sp.density);
                const double w = sum3(glm::dvec3(rowColorAt(m, row, sp.colorCoord))) * I;
                cRef += w * glm::dvec3(sp.center), wRef += w;
                eps = std::max(eps, (std::abs(sampledIntensity(m.footprint(), m.layerSize(), a, sp.density) - I) +
                                     std::log(2.0) * sp.density * storedWindowError(m) * 4.0 * a * a) / I + 512.0 * 0x1p-24);
            }
            cFit /= wFit, cRef /= wRef;
            for (const Splat& sp : b.splats()) spread = std::max(spread, glm::length(glm::dvec3(sp.center) - cRef));
            EXPECT_LT(glm::length(cFit - cRef), 2.0 * eps / (1.0 - eps) * spread + 1e-6) << "the lights' centroid is the emission's";
            const double bound = multipoleBound(*lights, b.splats(), p);
            const double fit = sum3(glm::dvec3(emittedIrradiance(*lights, p, n)));
            EXPECT_NEAR(fit, t.truth, bound + t.slack) << lightsAsked << " lights at " << dist;
            if (lightsAsked == 1) {
                EXPECT_LT(bound / t.truth, 0.5 * previous) << "the bound falls as (spread / d)^2";
                previous = bound / t.truth;
            }
        }
    }
}

// Flicker: voxels cycling through textures of different brightness (the
// texture dynamics) change the exact irradiance frame to frame; the lights,
// refitted each frame, follow it within the far-field bound of each frame
// (a light frozen at frame 0 would miss by more than that bound).
TEST(EmittedLight, FittedIntensityFollowsTheTextureCyclingFrameToFrame) {
    Materials m{Footprint{}};
    const std::uint32_t row = m.addColorTable(ColorTable::fire());
    // Four textures of constant detail: the cycle's brightness, a closed form per frame.
    const double levels[4] = {1.0, 0.35, 0.7, 0.15};
    TextureSet set;
    set.size = m.layerSize();
    for (double l : levels) {
        std::vector<float> t(std::size_t(set.size) * set.size * 4, 1.0f);
        for (std::size_t i = 3; i < t.size(); i += 4) t[i] = float(l);
        set.layers.push_back(t);
    }
    const std::uint32_t id = m.addTextureSet(set);
    const std::uint32_t first = m.set(id).first;
    auto level = [&](int layer) { return levels[layer - int(first)]; };
    Grid g = *Grid::box({3, 3, 2}, glm::vec3(0.15f));
    const glm::vec3 centre = g.worldPosition({1, 1, 0}) + glm::vec3(0.0f, 0.0f, 0.075f);
    const glm::vec3 p = centre + glm::normalize(glm::vec3(-0.3f, 0.5f, 1.0f)) * 3.0f;
    const glm::vec3 n = glm::normalize(centre - p);
    std::vector<EmittedLight> frame0;
    for (std::uint32_t frame = 0; frame < 4; ++frame) {
        for (Voxel& v : g.voxels) {
            v.opacity = 0.5f, v.colorCoord = 0.2f + 0.2f * float(v.cell.y);
            // Most voxels in step (the fire brightens and dims), a few out of step.
            v.texture = frame + (v.cell.x == 2 && v.cell.z == 1 ? 1u : 0u);
        }
        SplatBuilder b(SplatBuilderDesc{.frustumCull = false});
        b.begin(Camera::lookAt(p, centre, {0, 1, 0}, 1.2f, {32, 32}));
        b.add(g, m, {.textureSet = id, .colorTable = row, .textured = true});
        const FarTruth t = farTruth(b.splats(), m, row, p, n, 120, level);
        auto lights = fitEmittedLights(b.splats(), m, {.enabled = true, .lights = 2, .occlusion = false});
        ASSERT_TRUE(lights) << lights.error();
        const double tol = multipoleBound(*lights, b.splats(), p) + t.slack;
        const double fit = sum3(glm::dvec3(emittedIrradiance(*lights, p, n)));
        EXPECT_NEAR(fit, t.truth, tol) << "frame " << frame;
        if (frame == 0) frame0 = *lights;
        const double frozen = sum3(glm::dvec3(emittedIrradiance(frame0, p, n)));
        if (frame > 0) {
            EXPECT_GT(std::abs(frozen - t.truth), tol) << "the cycle changes the light by more than the bound, frame " << frame;
        }
    }
}

namespace {

// A static fire effect (plain splats) at the origin, emitting light with `reach`.
struct FireScene {
    Materials materials{Footprint{}};
    Scene scene;
    EffectId fire = 0;
    explicit FireScene(float reach) {
        const std::uint32_t row = materials.addColorTable(ColorTable::fire());
        Grid g = *Grid::box({3, 4, 3}, glm::vec3(0.2f));
        for (Voxel& v : g.voxels) v.opacity = 0.5f, v.colorCoord = float(v.cell.y) / 3.0f;
        g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(-0.2f, 0.0f, -0.2f));
        EffectDesc desc;
        desc.name = "fire";
        desc.layers = {EffectLayer{.style = {.colorTable = row, .textured = false}}};
        fire = scene.add(*Effect::fromGrid(g, desc), {.name = "fire", .emitsLight = {.enabled = true, .lights = 2, .reachWorld = reach}});
    }
};

// An eye 6 m from the fire: looking at it, and turned 90 degrees onto the
// ground 3 m beside it (the fire outside the view, its light on that ground).
Camera towardsFire() { return Camera::lookAt({0.0f, 2.0f, 6.0f}, {0.0f, 0.4f, 0.0f}, {0, 1, 0}, glm::radians(40.0f), {64, 48}, 0.1f, 100.0f); }
Camera awayFromFire() { return Camera::lookAt({0.0f, 2.0f, 6.0f}, {-5.0f, 0.0f, 5.0f}, {0, 1, 0}, glm::radians(40.0f), {64, 48}, 0.1f, 100.0f); }

} // namespace

// An emitter out of view still lights what is in view (scheduled by its
// reach, not its visibility), with the same lights as when it is seen; beyond
// its reach it is neither advanced nor fitted.
TEST(EmittedLight, AnEmitterOutOfViewStillLightsTheViewWithinItsReach) {
    FireScene seen(8.0f), unseen(8.0f), far(1.0f);
    Frame a, b, c;
    ASSERT_TRUE(seen.scene.prepare(0.0, towardsFire(), seen.materials, a));
    ASSERT_TRUE(unseen.scene.prepare(0.0, awayFromFire(), unseen.materials, b));
    ASSERT_TRUE(far.scene.prepare(0.0, awayFromFire(), far.materials, c));
    EXPECT_TRUE(seen.scene.status(seen.fire).needed);
    const EffectStatus& s = unseen.scene.status(unseen.fire);
    EXPECT_FALSE(s.inView);
    EXPECT_TRUE(s.lightsIntoView);
    EXPECT_EQ(s.splatsDrawn, 0u) << "advanced for its light, not drawn";
    ASSERT_EQ(a.emittedLights().size(), 2u);
    ASSERT_EQ(b.emittedLights().size(), a.emittedLights().size());
    // The fit takes every splat whatever the view (no frustum culling); only
    // the billboards' orientation differs, which leaves each splat's area,
    // hence its emission, unchanged up to float rounding of the axes' cross
    // product (a few ulps; 1e-5 relative is 80 ulps of a sum of 36).
    for (std::size_t i = 0; i < a.emittedLights().size(); ++i) {
        const EmittedLight &la = a.emittedLights()[i], &lb = b.emittedLights()[i];
        EXPECT_LT(glm::length(la.position - lb.position), 1e-5f);
        EXPECT_LT(glm::length(la.intensity - lb.intensity), 1e-5f * glm::length(la.intensity));
    }
    const glm::vec3 ground(-3.0f, 0.0f, 1.0f);
    EXPECT_GT(emittedIrradiance(b.emittedLights(), ground, {0, 1, 0}).x, 0.0f);
    const EffectStatus& f = far.scene.status(far.fire);
    EXPECT_FALSE(f.lightsIntoView || f.needed);
    EXPECT_TRUE(c.emittedLights().empty());
}

// Same splats, same lights, bit for bit; the order of the splats does not change them beyond rounding.
TEST(EmittedLight, FitIsDeterministic) {
    FireMaterials fm;
    const std::vector<Splat> splats = fireSplats(fm, smallFire({3, 5, 3}, 0.15f, 0.6f, 2), {0.5f, 1.0f, 4.0f});
    const EmittedLightDesc desc{.enabled = true, .lights = 4};
    auto x = fitEmittedLights(splats, fm.m, desc), y = fitEmittedLights(splats, fm.m, desc);
    ASSERT_TRUE(x && y);
    EXPECT_TRUE(test::sameLights(*x, *y));
}

// Bad descs and inputs: named errors, never a crash or a NaN light.
TEST(EmittedLight, BadDescsAndInputsGiveNamedErrors) {
    FireMaterials fm;
    const std::vector<Splat> splats = fireSplats(fm, smallFire({2, 3, 2}, 0.15f, 0.6f, 0), {0.0f, 1.0f, 4.0f});
    auto fails = [&](EmittedLightDesc d, const char* field) {
        auto r = fitEmittedLights(splats, fm.m, d);
        ASSERT_FALSE(r) << field;
        EXPECT_NE(r.error().find(field), std::string::npos) << r.error();
    };
    fails({.enabled = true, .lights = 0}, "EmittedLightDesc.lights");
    fails({.enabled = true, .lights = kMaxEmittedLights + 1}, "EmittedLightDesc.lights");
    fails({.enabled = true, .scale = -1.0f}, "EmittedLightDesc.scale");
    fails({.enabled = true, .scale = std::numeric_limits<float>::quiet_NaN()}, "EmittedLightDesc.scale");
    fails({.enabled = true, .scale = std::numeric_limits<float>::infinity()}, "EmittedLightDesc.scale");
    fails({.enabled = true, .reachWorld = 0.0f}, "EmittedLightDesc.reachWorld");
    fails({.enabled = true, .reachWorld = std::numeric_limits<float>::quiet_NaN()}, "EmittedLightDesc.reachWorld");
    // A finite scale whose lights overflow float (a 10 m splat emits about
    // 300 x its colour): an error naming it, not an infinite light.
    const std::vector<Splat> big{facing({0, 0, -20}, {0, 0, 0}, 10.0f, 2.0f, fm.row)};
    auto over = fitEmittedLights(big, fm.m, {.enabled = true, .scale = 3e38f});
    ASSERT_FALSE(over);
    EXPECT_NE(over.error().find("EmittedLightDesc.scale"), std::string::npos) << over.error();
    // The reference: a zero or NaN normal, a NaN point, a bad face size.
    auto ref = [&](glm::dvec3 p, glm::dvec3 n, IrradianceExactDesc d, const char* field) {
        auto r = emittedIrradianceExact(splats, fm.m, p, n, d);
        ASSERT_FALSE(r) << field;
        EXPECT_NE(r.error().find(field), std::string::npos) << r.error();
    };
    ref({0, 0, 3}, {0, 0, 0}, {}, "normal");
    ref({0, 0, 3}, {std::nan(""), 1, 0}, {}, "normal");
    ref({std::nan(""), 0, 3}, {0, 0, -1}, {}, "point");
    ref({0, 0, 3}, {0, 0, -1}, {.faceSize = 1}, "IrradianceExactDesc.faceSize");
    ref({0, 0, 3}, {0, 0, -1}, {.nearDistance = 0.0}, "IrradianceExactDesc.nearDistance");
}

// Splats with NaN or huge coordinates (a simulation blown up, a unit
// mistake) are skipped or fitted without overflow: every light finite.
TEST(EmittedLight, NonFiniteAndHugeSplatsLeaveFiniteLights) {
    FireMaterials fm;
    std::vector<Splat> splats = fireSplats(fm, smallFire({2, 3, 2}, 0.15f, 0.6f, 0), {0.0f, 1.0f, 4.0f});
    auto clean = fitEmittedLights(splats, fm.m, {.enabled = true, .lights = 2});
    ASSERT_TRUE(clean);
    Splat bad = splats[0];
    bad.center = glm::vec3(std::nanf(""), 0.0f, 0.0f);
    splats.push_back(bad);
    bad = splats[0];
    bad.axisU = glm::vec3(std::numeric_limits<float>::infinity(), 0.0f, 0.0f);
    splats.push_back(bad);
    bad = splats[0];
    bad.density = std::nanf("");
    splats.push_back(bad);
    auto r = fitEmittedLights(splats, fm.m, {.enabled = true, .lights = 2});
    ASSERT_TRUE(r) << r.error();
    ASSERT_EQ(r->size(), clean->size()) << "the non-finite splats are skipped";
    for (std::size_t i = 0; i < r->size(); ++i) EXPECT_EQ((*r)[i].intensity, (*clean)[i].intensity);
    // One far splat (1e30 m away): finite lights, and the occlusion grid does not overflow.
    bad = splats[0];
    bad.center = glm::vec3(1e30f, -1e30f, 1e30f);
    splats.push_back(bad);
    bad = splats[0]; // 4 |U x V| near float's largest
    bad.axisU *= 1.5e19f, bad.axisV *= 1.5e19f;
    splats.push_back(bad);
    auto h = fitEmittedLights(splats, fm.m, {.enabled = true, .lights = 3});
    ASSERT_TRUE(h) << h.error();
    for (const EmittedLight& l : *h) {
        EXPECT_TRUE(std::isfinite(l.radius) && std::isfinite(l.intensity.x) && std::isfinite(l.escapePlus.x) && std::isfinite(l.escapeMinus.y));
        EXPECT_TRUE(std::isfinite(l.position.x));
    }
    // emittedIrradiance at a light's own position: no division by zero.
    const glm::vec3 e = emittedIrradiance(*clean, (*clean)[0].position, {0, 1, 0});
    EXPECT_TRUE(std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z));
}

// A splat alone has nothing in front of it: occlusion on, all its light
// leaves (escape shares exactly 1, the grid as without occlusion). The
// binned optical depth once counted the splat's own opacity in its bin, so a
// lone splat of opacity 0.3 kept half its light, and a whole fire was fitted
// too dark (docs/BENCHMARKS.md, "Volumes as light").
TEST(EmittedLight, ALoneSplatDoesNotOccludeItsOwnLight) {
    Materials m{Footprint{}};
    const std::uint32_t row = m.addColorTable(ColorTable::constant({1.0f, 0.5f, 0.25f, 1.0f}));
    const std::vector<Splat> splats{facing({0.3f, 0.5f, -2.0f}, {0.0f, 0.0f, 0.0f}, 0.2f, 4.0f, row)};
    auto lights = fitEmittedLights(splats, m, {.enabled = true, .occlusion = true});
    ASSERT_TRUE(lights) << lights.error();
    ASSERT_EQ(lights->size(), 1u);
    EXPECT_EQ((*lights)[0].escapePlus, glm::vec3(1.0f));
    EXPECT_EQ((*lights)[0].escapeMinus, glm::vec3(1.0f));
    auto on = fitEmittedGrid(splats, m, {.enabled = true, .mode = EmittedLightMode::Grid, .occlusion = true});
    auto off = fitEmittedGrid(splats, m, {.enabled = true, .mode = EmittedLightMode::Grid, .occlusion = false});
    ASSERT_TRUE(on && off);
    ASSERT_EQ(on->nodes.size(), 27u);
    for (std::size_t i = 0; i < on->nodes.size(); ++i)
        for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(on->nodes[i][k], off->nodes[i][k]) << "node " << i << " normal " << k;
}

// A grid node against the exact irradiance of one plain splat facing it.
// The node stores I cos / (d^2 + a^2); the exact is cos x the integral of
// L d^2 / (d^2 + rho^2)^2 over the disc (the tilt's first-order term cancels
// over the symmetric disc; every ray within a/d = 0.06 rad of the centre's,
// so no cosine clamps). Both lie in [(1 + a^2/d^2)^-2, 1] x I cos / d^2, so
// they differ by at most 1 - (1 + a^2/d^2)^-2 of it; plus the fit's intensity
// quadrature (as OneSplatFitsOneLightWithItsIntensity) and the reference's
// error estimate. The sampler at the node returns the node's value (weight
// exactly 1), and the normal facing away from the splat gets exactly 0.
TEST(EmittedLight, GridNodeMeetsTheExactIrradianceOfOneSplat) {
    Materials m{Footprint{}};
    const std::uint32_t row = m.addColorTable(ColorTable::constant({1.0f, 0.5f, 0.25f, 1.0f}));
    const glm::vec3 c(0.2f, 0.4f, -0.3f);
    const float margin = 1.0f, a = 0.1f, density = 1.5f;
    const glm::vec3 node = c - glm::vec3(margin); // the grid's first corner
    const std::vector<Splat> splats{facing(c, node, a, density, row)};
    auto g = fitEmittedGrid(splats, m, {.enabled = true, .mode = EmittedLightMode::Grid, .gridDims = {2, 2, 2}, .gridMargin = margin});
    ASSERT_TRUE(g) << g.error();
    ASSERT_EQ(g->boxMin, node);
    EXPECT_EQ(g->centre, c);
    const double I = plainIntensity(m.footprint(), a, density);
    const double quadrature = std::abs(sampledIntensity(m.footprint(), m.layerSize(), a, density) - I) +
                              std::log(2.0) * density * storedWindowError(m) * 4.0 * a * a + 256.0 * 0x1p-24 * I;
    const double d2 = glm::dot(c - node, c - node), cosine = 1.0 / std::sqrt(3.0);
    for (int axis = 0; axis < 3; ++axis) {
        glm::dvec3 n(0.0);
        n[axis] = 1.0;
        auto e = emittedIrradianceExact(splats, m, glm::dvec3(node), n, {.faceSize = 256});
        ASSERT_TRUE(e) << e.error();
        const double law = I * cosine / d2;
        const double tol = (1.0 - 1.0 / ((1.0 + a * a / d2) * (1.0 + a * a / d2))) * law + quadrature * cosine / d2 + e->errorEstimate;
        const glm::vec3 stored = g->nodes[0][std::size_t(2 * axis)];
        EXPECT_NEAR(stored.x, e->irradiance.x, tol) << "axis " << axis;
        EXPECT_NEAR(stored.z, e->irradiance.z, 0.25 * tol) << "axis " << axis;
        EXPECT_EQ(emittedIrradiance(*g, node, glm::vec3(n)), stored);
        EXPECT_EQ(g->nodes[0][std::size_t(2 * axis + 1)], glm::vec3(0.0f)) << "the splat lies on the + side";
    }
}

// The sampler on a grid filled from a point source at its centre c
// (E(+-a) = I max(+-w_a, 0) / d^2 at each node): inside the box trilinear
// (halfway between two nodes, their mean); beyond a corner, on the ray from c
// through it, the point source itself (the corner's values are exact, so the
// intensity read there is I and the departure there is 0 for an axis normal);
// continuous across the box's faces. Float rounding: a few dozen operations
// on values of order 1: 64 ulp.
TEST(EmittedLight, GridSamplerIsTrilinearInsideAndThePointSourceBeyondACorner) {
    const glm::vec3 c(0.2f, -0.1f, 0.3f), I(2.0f, 1.0f, 0.5f);
    EmittedGrid g;
    g.dims = {2, 2, 2};
    g.boxMin = glm::vec3(-1.0f), g.boxMax = glm::vec3(1.0f);
    g.centre = c;
    g.nodes.resize(8);
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 node(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f);
        const glm::vec3 w = glm::normalize(c - node);
        const float d2 = glm::dot(c - node, c - node);
        auto& values = g.nodes[std::size_t(i)];
        for (int a = 0; a < 3; ++a) {
            values[std::size_t(2 * a)] = I * (std::max(w[a], 0.0f) / d2);
            values[std::size_t(2 * a + 1)] = I * (std::max(-w[a], 0.0f) / d2);
        }
    }
    const float ulp64 = 64.0f * 0x1p-24f;
    const glm::vec3 mid = emittedIrradiance(g, {0.0f, -1.0f, -1.0f}, {0, 1, 0}); // between nodes 0 and 1
    const glm::vec3 mean = 0.5f * (g.nodes[0][2] + g.nodes[1][2]);
    EXPECT_NEAR(mid.x, mean.x, mean.x * ulp64);
    const glm::vec3 corner(1.0f);
    for (float s : {2.0f, 5.0f})
        for (glm::vec3 n : {glm::vec3(-1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, -1)}) {
            const glm::vec3 p = c + s * (corner - c);
            const glm::vec3 law = I * (std::max(glm::dot(n, glm::normalize(c - p)), 0.0f) / glm::dot(c - p, c - p));
            const glm::vec3 e = emittedIrradiance(g, p, n);
            EXPECT_NEAR(e.x, law.x, law.x * ulp64 + 1e-30f) << "s " << s;
            EXPECT_NEAR(e.z, law.z, law.z * ulp64 + 1e-30f) << "s " << s;
        }
    // Continuous across a face: the change from the face point to one h
    // outside is linear in h (a smooth function of d^2 = 0.69 + O(h)), so
    // h = 1e-4 changes it by 0.1 of what h = 1e-3 does, up to the O(h^2)
    // term (1e-3 / 0.69 of it: 0.2 leaves that twice over) and rounding; a
    // jump at the face would change both alike.
    const glm::vec3 atFace = emittedIrradiance(g, {1.0f, 0.1f, 0.2f}, {-1, 0, 0});
    const float far = std::abs(emittedIrradiance(g, {1.001f, 0.1f, 0.2f}, {-1, 0, 0}).x - atFace.x);
    const float near = std::abs(emittedIrradiance(g, {1.0001f, 0.1f, 0.2f}, {-1, 0, 0}).x - atFace.x);
    EXPECT_GT(atFace.x, 0.0f);
    EXPECT_GT(far, 0.0f);
    EXPECT_LT(near, 0.2f * far + atFace.x * ulp64);
    EmittedGrid none;
    EXPECT_EQ(emittedIrradiance(none, {0, 0, 0}, {0, 1, 0}), glm::vec3(0.0f));
}

// A Scene effect in grid mode gives the frame its grid (the desc's dims,
// around the fire) and no point lights; fitted again, bit for bit the same.
TEST(EmittedLight, SceneFillsTheFramesGridInGridMode) {
    FireScene fs(8.0f);
    EffectOptions& o = fs.scene.options(fs.fire);
    o.emitsLight.mode = EmittedLightMode::Grid;
    o.emitsLight.gridDims = {2, 4, 2};
    Frame a, b;
    ASSERT_TRUE(fs.scene.prepare(0.0, towardsFire(), fs.materials, a));
    ASSERT_TRUE(fs.scene.lightingError().empty()) << fs.scene.lightingError();
    EXPECT_TRUE(a.emittedLights().empty());
    ASSERT_EQ(a.emittedGrid().dims, glm::ivec3(2, 4, 2));
    EXPECT_GT(emittedIrradiance(a.emittedGrid(), {1.5f, 0.0f, 0.0f}, {0, 1, 0}).x, 0.0f);
    ASSERT_TRUE(fs.scene.prepare(0.0, towardsFire(), fs.materials, b));
    ASSERT_EQ(b.emittedGrid().nodes.size(), a.emittedGrid().nodes.size());
    for (std::size_t i = 0; i < a.emittedGrid().nodes.size(); ++i)
        for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(b.emittedGrid().nodes[i][k], a.emittedGrid().nodes[i][k]);
}

// Bad grid descs: named errors; huge and non-finite splats: a finite grid.
TEST(EmittedLight, BadGridDescsGiveNamedErrorsAndHugeSplatsAFiniteGrid) {
    FireMaterials fm;
    std::vector<Splat> splats = fireSplats(fm, smallFire({2, 3, 2}, 0.15f, 0.6f, 0), {0.0f, 1.0f, 4.0f});
    auto fails = [&](EmittedLightDesc d, const char* field) {
        auto r = fitEmittedGrid(splats, fm.m, d);
        ASSERT_FALSE(r) << field;
        EXPECT_NE(r.error().find(field), std::string::npos) << r.error();
    };
    fails({.enabled = true, .mode = EmittedLightMode::Grid, .gridDims = {1, 3, 3}}, "EmittedLightDesc.gridDims");
    fails({.enabled = true, .mode = EmittedLightMode::Grid, .gridDims = {4, 4, 4}}, "EmittedLightDesc.gridDims"); // 64 nodes
    fails({.enabled = true, .mode = EmittedLightMode::Grid, .gridDims = {2, -2, 2}}, "EmittedLightDesc.gridDims");
    fails({.enabled = true, .mode = EmittedLightMode::Grid, .gridMargin = -0.1f}, "EmittedLightDesc.gridMargin");
    fails({.enabled = true, .mode = EmittedLightMode::Grid, .gridMargin = std::numeric_limits<float>::quiet_NaN()}, "EmittedLightDesc.gridMargin");
    fails({.enabled = true, .mode = EmittedLightMode(7)}, "EmittedLightDesc.mode");
    Splat bad = splats[0];
    bad.center = glm::vec3(std::nanf(""), 0.0f, 0.0f);
    splats.push_back(bad);
    bad = splats[0];
    bad.center = glm::vec3(1e30f, -1e30f, 1e30f);
    splats.push_back(bad);
    auto g = fitEmittedGrid(splats, fm.m, {.enabled = true, .mode = EmittedLightMode::Grid});
    ASSERT_TRUE(g) << g.error();
    for (const auto& node : g->nodes)
        for (const glm::vec3& v : node) EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
    const glm::vec3 e = emittedIrradiance(*g, g->centre, {0, 1, 0});
    EXPECT_TRUE(std::isfinite(e.x));
    // A NaN point, or a host's grid with a flat box: 0, no float-to-int of a NaN.
    EXPECT_EQ(emittedIrradiance(*g, glm::vec3(std::nanf("")), {0, 1, 0}), glm::vec3(0.0f));
    EmittedGrid flat = *g;
    flat.boxMax.x = flat.boxMin.x;
    EXPECT_EQ(emittedIrradiance(flat, flat.boxMin, {0, 1, 0}), glm::vec3(0.0f));
}
