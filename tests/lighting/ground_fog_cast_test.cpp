// Ground fog casts (volume.hpp, GroundFogCaster; scene.hpp): a lit layer
// darkens the lit effects in it or beyond it toward a light by exactly the
// layer's transmittance, and shadows the scene through the scene shadow
// table. The truth is the reference's continuous layer,
// integrateGroundFogRay's transmittance along the ray to the light (terrain
// and thickness linear per triangle, the scalar linear in height or the
// paper's ratio, integrated by halving 4-point Gauss-Legendre; its own
// error estimate is added to every tolerance).
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

glm::vec3 unpack(std::uint32_t c) { return glm::vec3(float(c & 255u), float((c >> 8) & 255u), float((c >> 16) & 255u)) / 255.0f; }

// The reference transmittance from p along dir (unit) over [0, tFar].
double referenceT(const GroundFogDesc& d, const TransferFunction& tf, glm::dvec3 p, glm::dvec3 dir, double tFar, double* err) {
    GroundFogRayStats st;
    integrateGroundFogRay(d, tf, p, dir, 0.0, tFar, 1e-12, 20, &st);
    *err = st.errorEstimate;
    return st.transmittance;
}

// A hilly 9x7 layer (spacing 0.75): terrain and top vary on both axes, the
// top below the terrain (no fog) at two points, so rays cross triangles with
// every thickness, the layer's edges and the gaps.
GroundFogDesc hillyFog(float densityDepth) {
    GroundFogDesc d;
    d.dims = {9, 7};
    d.originWorld = {-1.0f, 0.0f, 0.5f};
    d.spacingWorld = 0.75f;
    d.densityDepthWorld = densityDepth;
    for (int j = 0; j < 7; ++j)
        for (int i = 0; i < 9; ++i) {
            const float h = 0.4f * std::sin(0.9f * float(i)) + 0.3f * std::cos(0.7f * float(j)) + 0.05f * float(i);
            d.terrainHeight.push_back(h);
            d.fogTop.push_back(h + 0.6f + 0.5f * std::cos(0.5f * float(i + j)));
        }
    d.fogTop[12] = d.terrainHeight[12] - 0.1f; // no fog at two points
    d.fogTop[40] = d.terrainHeight[40];
    return d;
}

} // namespace

// The caster's optical depth is the layer's, in log2 units: from points
// below, inside and above the layer, toward suns from straight above to
// grazing, and along segments to point lights inside and outside it; in the
// paper's ratio scalar and in the affine one (densityDepthWorld).
// Tolerance: the caster integrates in closed form in double and returns a
// float: 2^-24 relative to the depth (<= 12 nats here: 8e-7), plus the
// reference's own error estimate; as transmittance, T x that.
TEST(GroundFogCast, CasterDepthIsTheLayersAlongRaysAndSegments) {
    for (float densityDepth : {0.0f, 2.0f}) {
        const GroundFogDesc d = hillyFog(densityDepth);
        const float ext = 1.7f;
        const TransferFunction tf = *makeGroundFogTransfer(glm::vec3(1.0f), ext);
        auto fog = GroundFog::create(d);
        ASSERT_TRUE(fog) << fog.error();
        auto caster = GroundFogCaster::create(*fog, ext);
        ASSERT_TRUE(caster) << caster.error();
        ASSERT_FALSE(caster->empty());
        std::size_t shadowed = 0, checked = 0;
        const glm::vec3 suns[] = {{0.0f, -1.0f, 0.0f}, {0.4f, -1.0f, 0.3f}, {-1.0f, -0.35f, 0.2f}, {0.05f, -0.02f, -1.0f}};
        for (int j = 0; j <= 5; ++j)
            for (int i = 0; i <= 6; ++i)
                for (float y : {-0.2f, 0.2f, 0.55f, 0.9f, 1.6f}) {
                    const glm::vec3 p(-1.2f + 1.06f * float(i), y, 0.4f + 0.94f * float(j));
                    for (glm::vec3 sun : suns) {
                        const Light light = Light::directional(sun);
                        const double depth = double(caster->opticalDepthToLight(p, light)) * std::log(2.0);
                        double err = 0.0;
                        const double want = referenceT(d, tf, glm::dvec3(p), -glm::normalize(glm::dvec3(sun)), 1e4, &err);
                        EXPECT_NEAR(std::exp(-depth), want, want * 8e-7 + 2.0 * err) << p.x << "," << p.y << "," << p.z << " sun " << sun.x;
                        shadowed += want < 0.9 ? 1 : 0;
                        ++checked;
                    }
                    // A point light inside the layer's box and one beyond it: the segment only.
                    for (glm::vec3 at : {glm::vec3(2.0f, 0.7f, 2.5f), glm::vec3(-3.0f, 2.0f, 6.0f)}) {
                        const glm::dvec3 to = glm::dvec3(at) - glm::dvec3(p);
                        const double len = glm::length(to);
                        const double depth = double(caster->opticalDepthToLight(p, Light::point(at))) * std::log(2.0);
                        double err = 0.0;
                        const double want = referenceT(d, tf, glm::dvec3(p), to / len, len, &err);
                        EXPECT_NEAR(std::exp(-depth), want, want * 8e-7 + 2.0 * err) << p.x << "," << p.y << "," << p.z << " light " << at.x;
                        ++checked;
                    }
                }
        EXPECT_GT(shadowed, checked / 12); // the layer is in the way of many of the rays (127 of 1260 here)
    }
}

// The extinction the scene shadow table samples at its nodes: on a flat
// layer it is ext x density x (top - y) / thickness (the paper's scalar), in
// log2 units, and 0 below the terrain, above the top and beyond the grid.
TEST(GroundFogCast, ExtinctionIsTheLayersScalarInLog2Units) {
    GroundFogDesc d;
    d.dims = {5, 5};
    d.terrainHeight.assign(25, 1.0f);
    d.fogTop.assign(25, 3.0f);
    d.density = 0.8f;
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    auto caster = *GroundFogCaster::create(*fog, 1.5f);
    for (float y : {1.0f, 1.5f, 2.25f, 3.0f}) {
        const double want = 1.5 * double(0.8f) * (3.0 - double(y)) / 2.0 / std::log(2.0);
        // Computed in double, returned as float: one rounding, 2^-24 relative (the double arithmetic's own error is ~1e-16).
        EXPECT_NEAR(caster.at({2.3f, y, 1.7f}), want, want * 0x1p-24 + 1e-12);
    }
    EXPECT_EQ(caster.at({2.3f, 0.99f, 1.7f}), 0.0f);
    EXPECT_EQ(caster.at({2.3f, 3.01f, 1.7f}), 0.0f);
    EXPECT_EQ(caster.at({4.01f, 2.0f, 1.7f}), 0.0f);
    EXPECT_EQ(caster.boundsMin(), glm::vec3(0.0f, 1.0f, 0.0f));
    EXPECT_EQ(caster.boundsMax(), glm::vec3(4.0f, 3.0f, 4.0f));
}

namespace {

// A flat layer 1.5 thick over 9x9 points (spacing 1) beside a 2x2x2 plume of
// opacity 0.5, lit isotropically with albedo 1, no self-shadowing: a plume
// splat's colour is its white base times the fog's transmittance toward the
// light (the plume's own shadow off; no other caster).
struct PlumeInFog {
    Materials materials{Footprint{}};
    Scene scene;
    GroundFogDesc fogDesc;
    TransferFunction fogTransfer = *makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, 1.2f);
    EffectId fog = 0, plume = 0;
    std::uint32_t row = 0;
    Frame frame;

    explicit PlumeInFog(glm::vec3 plumeAt) {
        fogDesc.dims = {9, 9};
        fogDesc.terrainHeight.assign(81, 0.0f);
        fogDesc.fogTop.assign(81, 1.5f);
        auto table = PreIntegrationTable::create(fogTransfer, {.scalarResolution = 4, .lengthResolution = 4});
        fog = scene.add(*GroundFog::create(fogDesc), fogTransfer, *table, {.name = "fog", .lighting = {.enabled = true}});
        row = materials.addColorTable(ColorTable::constant({1.0f, 1.0f, 1.0f, 1.0f}));
        Grid g = *Grid::box({2, 2, 2});
        for (Voxel& v : g.voxels) v.opacity = 0.5f;
        g.transform = glm::translate(glm::mat4(1.0f), plumeAt - g.localPosition({0, 0, 0}));
        EffectDesc desc;
        desc.name = "plume";
        desc.layers = {EffectLayer{.style = {.colorTable = row, .textured = false}}};
        plume = scene.add(*Effect::fromGrid(g, desc),
                          {.name = "plume", .lighting = {.enabled = true, .gas = {.albedo = 1.0f}, .selfShadow = SelfShadow::Off}});
    }

    // Every plume splat's colour against the reference T toward `light`;
    // returns the smallest T. Tolerance: the colour is packed to 8 bits (half
    // a level), the caster's float depth moves T by < 1e-6 (above), plus the
    // reference's error estimate.
    double check(const Light& light) {
        double minT = 1.0;
        std::size_t n = 0;
        for (const Splat& sp : frame.splats()) {
            if (std::lround(sp.colorRow) != long(row)) continue;
            const glm::dvec3 c(sp.center);
            double err = 0.0, want;
            if (light.type == LightType::Directional) {
                want = referenceT(fogDesc, fogTransfer, c, -glm::normalize(glm::dvec3(light.direction)), 1e4, &err);
            } else {
                const glm::dvec3 to = glm::dvec3(light.position) - c;
                want = referenceT(fogDesc, fogTransfer, c, glm::normalize(to), glm::length(to), &err);
            }
            const glm::vec3 got = unpack(sp.color);
            for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want, 0.5 / 255.0 + 1e-6 + 2.0 * err) << c.x << "," << c.y << "," << c.z;
            minT = std::min(minT, want);
            ++n;
        }
        EXPECT_EQ(n, 8u);
        return minT;
    }

    // Each plume splat's packed colour by its centre (the order depends on the camera).
    std::map<std::tuple<float, float, float>, std::uint32_t> plumeColours() const {
        std::map<std::tuple<float, float, float>, std::uint32_t> out;
        for (const Splat& sp : frame.splats())
            if (std::lround(sp.colorRow) == long(row)) out[{sp.center.x, sp.center.y, sp.center.z}] = sp.color;
        return out;
    }
};

} // namespace

// A plume straddling the fog's top under a slanted sun: its lower splats are
// darkened by exactly the fog's transmittance toward the sun, its upper ones
// (above the top, the sun's rays leaving upward) not at all. Moving the sun
// moves the shadow (the layer is traced again, its caster unchanged); a point
// light inside the fog shadows along the segment to it only.
TEST(GroundFogCast, APlumeInTheFogIsDarkenedByTheLayersTransmittanceTowardTheLight) {
    PlumeInFog s({3.5f, 0.5f, 3.5f}); // voxel centres at y 0.5 and 1.5: inside and at the 1.5 top
    s.scene.setSceneShadow({.enabled = false}); // the splats only (the next test has the table)
    const Camera cam = Camera::lookAt({4.0f, 6.0f, 16.0f}, {4.0f, 1.0f, 4.0f}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.1f, 100.0f);
    ASSERT_TRUE(s.scene.addLight(Light::directional({0.5f, -1.0f, 0.3f})));
    ASSERT_TRUE(s.scene.prepare(0.0, cam, s.materials, s.frame));
    EXPECT_TRUE(s.scene.lightingError().empty()) << s.scene.lightingError();
    ASSERT_TRUE(s.scene.status(s.plume).lit);
    EXPECT_LT(s.check(s.scene.lights()[0]), 0.8); // the lower splats really are in the fog's shadow
    EXPECT_EQ(s.scene.counters().crossShadowPairs, 1u); // the fog for the plume
    // Not casting: the plume sees the sun unattenuated.
    s.scene.options(s.fog).lighting.castsShadow = false;
    ASSERT_TRUE(s.scene.prepare(0.05, cam, s.materials, s.frame));
    for (const auto& [at, colour] : s.plumeColours()) EXPECT_EQ(colour & 0xffffffu, 0xffffffu);
    s.scene.options(s.fog).lighting.castsShadow = true;
    // The sun moves: the shadow follows.
    ASSERT_TRUE(s.scene.setLight(0, Light::directional({-0.8f, -0.4f, 0.1f})));
    ASSERT_TRUE(s.scene.prepare(0.1, cam, s.materials, s.frame));
    EXPECT_LT(s.check(s.scene.lights()[0]), 0.5);
    // A point light in the fog, 1.5 units beside the plume: only the segment to it counts.
    ASSERT_TRUE(s.scene.setLight(0, Light::point({6.5f, 0.6f, 4.0f}, glm::vec3(1.0f), 3.0f)));
    ASSERT_TRUE(s.scene.prepare(0.2, cam, s.materials, s.frame));
    // The point light's irradiance is not 1: compare T through the lit factor's ratio to the unshadowed one.
    s.scene.options(s.fog).lighting.castsShadow = false;
    Frame open;
    ASSERT_TRUE(s.scene.prepare(0.3, cam, s.materials, open));
    std::map<std::tuple<float, float, float>, glm::vec3> unshadowed;
    for (const Splat& sp : open.splats())
        if (std::lround(sp.colorRow) == long(s.row)) unshadowed[{sp.center.x, sp.center.y, sp.center.z}] = unpack(sp.color);
    std::size_t n = 0;
    for (const Splat& sp : s.frame.splats()) {
        if (std::lround(sp.colorRow) != long(s.row)) continue;
        const glm::dvec3 c(sp.center);
        const glm::dvec3 to = glm::dvec3(6.5, 0.6, 4.0) - c;
        double err = 0.0;
        const double want = referenceT(s.fogDesc, s.fogTransfer, c, glm::normalize(to), glm::length(to), &err);
        const glm::vec3 lit = unshadowed[{sp.center.x, sp.center.y, sp.center.z}];
        ASSERT_GT(lit.x, 0.2f);
        ASSERT_LT(lit.x, 1.0f); // not clamped: the ratio means T
        // Both colours are 8-bit (half a level each); their ratio's error is that over the unshadowed colour.
        EXPECT_NEAR(unpack(sp.color).x / lit.x, want, (0.5 / 255.0) * (1.0 + want) / lit.x + 1e-6 + 2.0 * err) << c.x << "," << c.y;
        EXPECT_LT(want, 0.95);
        ++n;
    }
    EXPECT_EQ(n, 8u);
}

// The scene shadow under the fog is the layer's transmittance. A flat layer
// (density linear in height, constant across) alone in the table, under a
// slanted sun whose ray from each node pierces the upper face of its
// neighbour cube (the sun's slope 4 below the nodes' aspect 8/63 : 1.5/63 =
// 5.3): the table's sweep adds trapezoid steps of a density linear along
// them and interpolates depths that are constant across, so at every
// terrain node whose ray to the sun leaves through the layer's top well
// clear of its side it is exact up to float rounding: 63 steps of about 4
// roundings each (2^-24 relative) on the depth D: T D 63 x 4 x 2^-24, plus
// the reference's estimate. "Well clear": the face interpolation spreads
// each node's dependence over its neighbours (a binomial spread of 3.4
// nodes' standard deviation across x over the 63 steps, 2.1 across z), so a
// chain near the side (beyond which the table has no fog) is mixed into
// nodes a few spreads away; 1.2 units (9 nodes) from the side the depth is
// within 2e-6 of exact (measured: 6e-5 at 0.6 units, 2e-6 at 1.0, 1e-8 at
// 1.4), under the rounding bound. The
// shadow follows the fog's own extinction (setTransfer) and the sun, and
// turning the camera away from the fog leaves it, and the colours of a
// plume beside it in its shadow, unchanged bit for bit.
TEST(GroundFogCast, TheSceneShadowUnderTheFogIsTheLayersTransmittance) {
    PlumeInFog s({10.0f, 0.5f, 3.5f}); // beside the layer (x in [0, 8]), its lower splats below its top
    s.scene.options(s.plume).lighting.castsShadow = false; // the fog alone in the table
    s.scene.setSceneShadow({.dims = glm::ivec3(64)});
    const glm::vec3 travel(1.0f, -0.25f, 0.1f); // toward the sun: -x and up
    ASSERT_TRUE(s.scene.addLight(Light::directional(travel)));
    const Camera both = Camera::lookAt({4.0f, 8.0f, 20.0f}, {6.0f, 0.5f, 4.0f}, {0, 1, 0}, glm::radians(60.0f), {64, 48}, 0.1f, 100.0f);
    ASSERT_TRUE(s.scene.prepare(0.0, both, s.materials, s.frame));
    EXPECT_TRUE(s.scene.lightingError().empty()) << s.scene.lightingError();
    EXPECT_TRUE(s.scene.status(s.fog).inSceneShadow);
    const glm::dvec3 toSun = -glm::normalize(glm::dvec3(travel));
    auto checkTerrain = [&](const FrameShadow& f, double darkerThan) {
        EXPECT_TRUE(f.valid);
        const glm::mat4 tableToWorld = glm::inverse(f.worldToTable);
        std::size_t checked = 0;
        for (int iz = 0; iz < f.dims.z; ++iz)
            for (int ix = 0; ix < f.dims.x; ++ix) {
                const glm::vec3 u(float(ix) / float(f.dims.x - 1), 0.0f, float(iz) / float(f.dims.z - 1));
                const glm::vec3 p = glm::vec3(tableToWorld * glm::vec4(u, 1.0f));
                EXPECT_NEAR(p.y, 0.0f, 1e-6f); // the table's bottom is the terrain
                const glm::dvec3 top = glm::dvec3(p.x, 0.0, p.z) + toSun * (1.5 / toSun.y); // where the ray leaves the top
                if (top.x < 1.2 || top.z < 1.2) continue;                                    // ... or near the side
                double err = 0.0;
                const double want = referenceT(s.fogDesc, s.fogTransfer, glm::dvec3(p.x, 0.0, p.z), toSun, 1e4, &err);
                const double got = std::exp2(-double(f.depth[std::size_t(ix) + std::size_t(f.dims.x) * std::size_t(f.dims.y) * std::size_t(iz)]));
                EXPECT_NEAR(got, want, want * -std::log(want) * 63.0 * 4.0 * 0x1p-24 + 2.0 * err) << p.x << "," << p.z;
                EXPECT_LT(want, darkerThan); // the comparison means something
                ++checked;
            }
        EXPECT_GT(checked, 200u);
    };
    checkTerrain(s.frame.shadow(), 0.05);
    const std::vector<float> seen = s.frame.shadow().depth;
    const auto plumeSeen = s.plumeColours();
    EXPECT_LT(s.check(s.scene.lights()[0]), 0.8); // the plume beside the fog, in its shadow

    // Looking down at the plume only: the fog is out of view, its shadow still reaches the view.
    const Camera plumeOnly = Camera::lookAt({10.5f, 6.0f, 4.0f}, {10.5f, 0.0f, 4.01f}, {0, 1, 0}, glm::radians(30.0f), {64, 64}, 0.1f, 6.2f);
    Frame turned;
    ASSERT_TRUE(s.scene.prepare(0.1, plumeOnly, s.materials, turned));
    EXPECT_FALSE(s.scene.status(s.fog).inView);
    EXPECT_TRUE(s.scene.status(s.fog).castsIntoView);
    EXPECT_TRUE(s.scene.status(s.plume).inView);
    ASSERT_TRUE(turned.shadow().valid);
    EXPECT_EQ(turned.shadow().depth, seen);
    std::swap(s.frame, turned);
    EXPECT_EQ(s.plumeColours(), plumeSeen);

    // The fog's own change: twice the extinction, the table rebuilt, still the layer's.
    const std::uint64_t builds = s.scene.sceneShadowBuilds(0);
    s.fogTransfer = *makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, 2.4f);
    s.scene.setTransfer(s.fog, s.fogTransfer, *PreIntegrationTable::create(s.fogTransfer, {.scalarResolution = 4, .lengthResolution = 4}));
    ASSERT_TRUE(s.scene.prepare(0.2, both, s.materials, s.frame));
    EXPECT_EQ(s.scene.sceneShadowBuilds(0), builds + 1);
    checkTerrain(s.frame.shadow(), 0.05 * 0.05);
    // The sun moves: rebuilt again.
    ASSERT_TRUE(s.scene.setLight(0, Light::directional({-0.3f, -1.0f, 0.6f})));
    ASSERT_TRUE(s.scene.prepare(0.3, both, s.materials, s.frame));
    EXPECT_EQ(s.scene.sceneShadowBuilds(0), builds + 2);
}

// Bad input: a caster with a negative or NaN extinction is refused naming
// the field; in a Scene, a casting layer whose transfer function is not
// makeGroundFogTransfer's form, even out of view, says so in lightingError
// and casts nothing; points that are not finite cast no depth (no NaN).
TEST(GroundFogCast, BadInputIsRefusedNamingTheField) {
    GroundFogDesc d;
    d.dims = {4, 4};
    d.terrainHeight.assign(16, 0.0f);
    d.fogTop.assign(16, 1.0f);
    auto fog = GroundFog::create(d);
    ASSERT_TRUE(fog);
    for (float bad : {-1.0f, std::nanf(""), INFINITY}) {
        auto c = GroundFogCaster::create(*fog, bad);
        ASSERT_FALSE(c);
        EXPECT_NE(c.error().find("GroundFogCaster: extinctionPerWorld must be finite and >= 0"), std::string::npos) << c.error();
    }
    auto none = GroundFogCaster::create(*fog, 0.0f); // no extinction: casts nothing
    ASSERT_TRUE(none);
    EXPECT_TRUE(none->empty());
    auto c = *GroundFogCaster::create(*fog, 1.0f);
    const float nan = std::nanf("");
    EXPECT_EQ(c.opticalDepth({nan, 0.5f, 1.0f}, {1.0f, 2.0f, 1.0f}), 0.0f);
    EXPECT_EQ(c.opticalDepthToLight({1.0f, 0.5f, INFINITY}, Light::directional({0, -1, 0})), 0.0f);
    EXPECT_EQ(c.opticalDepthToLight({1.0f, 0.5f, 1.0f}, Light::point({1.0f, 0.5f, 1.0f})), 0.0f); // the light at the point
    EXPECT_EQ(c.at({nan, 0.5f, 1.0f}), 0.0f);

    // A ramp transfer on a casting layer out of view (only its shadow could reach the view).
    Materials materials{Footprint{}};
    Scene scene;
    const TransferFunction ramp = *TransferFunction::create({{0.0f, glm::vec3(1.0f), 0.0f}, {1.0f, glm::vec3(0.2f), 1.0f}});
    const EffectId id = scene.add(*GroundFog::create(d), ramp, *PreIntegrationTable::create(ramp, {.scalarResolution = 4, .lengthResolution = 4}),
                                  {.name = "mist", .lighting = {.enabled = true}});
    ASSERT_TRUE(scene.addLight(Light::directional({1.0f, -0.3f, 0.0f})));
    Frame frame;
    const Camera away = Camera::lookAt({6.0f, 3.0f, 1.5f}, {6.0f, 0.0f, 1.51f}, {0, 1, 0}, glm::radians(30.0f), {64, 64}, 0.1f, 3.5f);
    ASSERT_TRUE(scene.prepare(0.0, away, materials, frame));
    EXPECT_FALSE(scene.status(id).inView);
    EXPECT_NE(scene.lightingError().find("effect 'mist': lighting: a lit ground fog needs a transfer function of makeGroundFogTransfer's form"),
              std::string::npos)
        << scene.lightingError();
    EXPECT_FALSE(scene.status(id).inSceneShadow);
    EXPECT_FALSE(frame.shadow().valid);
}
