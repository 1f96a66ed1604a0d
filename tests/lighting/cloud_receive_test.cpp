// Clouds receive the shadows of other volumes (cloud.hpp, Cloud::setLight's
// casters): each grid point's transmittance towards each light is its own one
// (through the cloud) times exp2(-depth) through every caster whose box its
// ray to the light meets. The truths: the closed forms of a uniform cloud
// (exp(-sigma L), L the ray's length inside the grid's box) and of a uniform
// caster (a box of constant extinction: e x the ray's length inside it; a
// block of equal voxels seen through its interior: n voxels x their depth).
// A restricted relight (only the casters changed) equals a full one bit for
// bit; a caster that cannot shadow the cloud costs nothing.
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/cloud.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

// [t0, t1] of the segment p + t d, t in [0, tMax], inside the box; false if it misses. Double.
bool clip(glm::dvec3 p, glm::dvec3 d, double tMax, glm::dvec3 lo, glm::dvec3 hi, double& t0, double& t1) {
    t0 = 0.0, t1 = tMax;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
            if (p[a] < lo[a] || p[a] > hi[a]) return false;
            continue;
        }
        double ta = (lo[a] - p[a]) / d[a], tb = (hi[a] - p[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    return t0 <= t1;
}

// Length of the ray from p toward the light inside the box (double).
double lengthInside(glm::dvec3 p, const Light& light, glm::dvec3 lo, glm::dvec3 hi) {
    const bool dir = light.type == LightType::Directional;
    const glm::dvec3 d = dir ? -glm::normalize(glm::dvec3(light.direction)) : glm::dvec3(light.position) - p;
    double t0 = 0.0, t1 = 0.0;
    if (!clip(p, d, dir ? 1e30 : 1.0, lo, hi, t0, t1)) return 0.0;
    return (t1 - t0) * glm::length(d);
}

// A box of constant extinction (log2 units per world unit): its depths in closed form.
class UniformBox final : public ShadowCaster {
public:
    UniformBox(glm::vec3 lo, glm::vec3 hi, float extinction) : mLo(lo), mHi(hi), mExt(extinction) {}
    float at(glm::vec3 w) const override {
        return glm::all(glm::greaterThanEqual(w, mLo)) && glm::all(glm::lessThanEqual(w, mHi)) ? mExt : 0.0f;
    }
    float opticalDepth(glm::vec3 a, glm::vec3 b) const override {
        double t0 = 0.0, t1 = 0.0;
        const glm::dvec3 d = glm::dvec3(b) - glm::dvec3(a);
        return clip(glm::dvec3(a), d, 1.0, mLo, mHi, t0, t1) ? float(double(mExt) * (t1 - t0) * glm::length(d)) : 0.0f;
    }
    float opticalDepthToLight(glm::vec3 w, const Light& light) const override {
        return float(double(mExt) * lengthInside(glm::dvec3(w), light, mLo, mHi));
    }
    bool empty() const override { return !(mExt > 0.0f); }
    glm::vec3 boundsMin() const override { return mLo; }
    glm::vec3 boundsMax() const override { return mHi; }
    std::uint64_t fingerprint() const override {
        std::uint64_t h = 1469598103934665603ull;
        for (float v : {mLo.x, mLo.y, mLo.z, mHi.x, mHi.y, mHi.z, mExt}) h = (h ^ std::uint64_t(std::bit_cast<std::uint32_t>(v))) * 1099511628211ull;
        return h;
    }

private:
    glm::vec3 mLo, mHi;
    float mExt;
};

// A cube of n^3 voxels of equal opacity with its first voxel centre at `at`.
DensityField voxelBlock(glm::vec3 at, int n, float opacity) {
    Grid g = *Grid::box({n, n, n});
    for (Voxel& v : g.voxels) v.opacity = opacity;
    g.transform = glm::translate(glm::mat4(1.0f), at - g.localPosition({0, 0, 0}));
    return *DensityField::fromGrid(g);
}

constexpr float kMaxExtinction = 0.25f, kDensity = 0.5f; // sigma = 0.125 per world unit

// A 9x9x7-point cloud of spacing 1 at the origin (grid axes are world axes).
CloudCreateDesc uniformDesc(CloudLighting lighting) {
    CloudCreateDesc cd;
    cd.cloud = {.dims = {9, 9, 7}, .seed = 3};
    cd.lighting = std::move(lighting);
    cd.transfer.maxExtinctionPerWorld = kMaxExtinction;
    cd.transfer.threshold = 0.05f;
    cd.table = {.scalarResolution = 4, .lengthResolution = 8};
    return cd;
}

Cloud uniformCloud(const CloudLighting& lighting) {
    auto c = Cloud::create(uniformDesc(lighting));
    EXPECT_TRUE(c) << c.error();
    EXPECT_TRUE(c->setDensity(std::vector<float>(c->density().size(), kDensity)));
    return std::move(*c);
}

glm::vec3 pointOf(const Cloud& c, std::size_t i) {
    const glm::ivec3 n = c.dims();
    const int x = int(i % std::size_t(n.x)), y = int((i / std::size_t(n.x)) % std::size_t(n.y)), z = int(i / (std::size_t(n.x) * std::size_t(n.y)));
    return c.volume().originWorld() + glm::vec3(x, y, z) * c.volume().spacingWorld();
}

// The LOD field's stored values at every grid point (what the tetrahedra draw).
std::vector<float> lodValues(const Cloud& c) {
    std::vector<float> out;
    const glm::ivec3 n = c.dims();
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) out.push_back(c.volume().scalarAt({x, y, z})), out.push_back(c.volume().lengthScaleAt({x, y, z}));
    return out;
}

} // namespace

// Every grid point's transmittance, towards a slanted sun and a point light
// above, is exp(-sigma L) (L: the ray's length inside the cloud's box)
// times exp2(-e L_c) (L_c: its length inside a uniform caster box that
// shadows part of the cloud for each light); the received depth alone is
// e L_c. Both models: the Roettger model's own T is exp(-lightExtinctionPerCell
// f cells). Tolerance: the cloud's own T is a sweep (the sun; one trapezoid
// step per plane, <= 8 planes) or a trace through <= 12 trilinear cells (the
// point light), each step rounding a few times (<= 4 x 2^-24 relative) on a
// depth D <= 4 nats (own plus caster): |dT| <= T x 12 x 4 x 2^-24 x D, plus
// the product's own rounding (4 x 2^-24 T), plus the caster's float depth
// (2^-24 e L_c, e L_c <= 3). The sweep is exact for a uniform field only
// with the sun along an axis or a diagonal: the sun here travels down a
// diagonal of the x-z plane, (1, 0, -1).
TEST(CloudReceive, TransmittanceIsTheCloudsTimesTheCastersExactly) {
    const Light sun = Light::directional({1.0f, 0.0f, -1.0f});
    const Light bulb = Light::point({4.0f, 4.0f, 30.0f}, glm::vec3(1.0f), 400.0f);
    const UniformBox box({2.5f, 1.5f, 8.0f}, {6.5f, 6.5f, 9.5f}, 1.3f); // above the cloud's top (z = 6)
    const ShadowCaster* casters[] = {&box};
    const glm::dvec3 lo(0.0), hi(8.0, 8.0, 6.0);
    for (CloudLightModel model : {CloudLightModel::LowAlbedo, CloudLightModel::Roettger}) {
        CloudLighting L;
        L.model = model;
        L.sun = sun;
        if (model == CloudLightModel::LowAlbedo) L.lights = {bulb};
        Cloud c = uniformCloud(L);
        ASSERT_TRUE(c.setLight(L, casters));
        const double sigma = model == CloudLightModel::LowAlbedo ? double(kMaxExtinction) * double(kDensity) : 0.6 * double(kDensity); // per world (spacing 1)
        std::size_t shadowed = 0;
        const std::size_t lights = model == CloudLightModel::LowAlbedo ? 2 : 1;
        for (std::size_t slot = 0; slot < lights; ++slot) {
            const Light& l = slot == 0 ? sun : bulb;
            const std::vector<float>& T = slot == 0 ? c.sunTransmittance() : c.lightTransmittance(0);
            const std::vector<float>& depth = c.receivedDepth(slot);
            ASSERT_EQ(T.size(), c.density().size());
            ASSERT_EQ(depth.size(), c.density().size());
            for (std::size_t i = 0; i < T.size(); ++i) {
                const glm::dvec3 p(pointOf(c, i));
                const double tau = 1.3 * lengthInside(p, l, glm::dvec3(box.boundsMin()), glm::dvec3(box.boundsMax()));
                const double own = sigma * lengthInside(p, l, lo, hi);
                const double want = std::exp(-own) * std::exp2(-tau);
                const double eps = 0x1p-24;
                EXPECT_NEAR(double(depth[i]), tau, eps * tau + 1e-7) << "light " << slot << " point " << i;
                EXPECT_NEAR(double(T[i]), want, want * (12.0 * 4.0 * eps * (own + tau * std::log(2.0)) + 4.0 * eps + eps * tau))
                    << "light " << slot << " point " << i;
                shadowed += tau > 0.5 ? 1 : 0;
            }
        }
        EXPECT_GT(shadowed, 20u); // the caster darkens a real part of the cloud, for each model
    }
}

// The same against a caster of the scene's own kind: a 4^3 block of voxels of
// opacity 0.75 (2 log2 units each) above the cloud, the sun straight down: a
// grid point under the block's interior (between its first and last voxel
// centres, where the trilinear field is flat) receives 4 x 2 = 8 log2 units,
// one beyond its footprint by more than a cell none. Tolerance: the field's
// exact piecewise-cubic integral in float, a few roundings per cell crossed
// (<= 6 cells): 6 x 4 x 2^-24 relative; the transmittance as in the test above.
TEST(CloudReceive, AVoxelBlockAboveDarkensTheColumnsUnderIt) {
    CloudLighting L;
    L.model = CloudLightModel::LowAlbedo;
    L.sun = Light::directional({0.0f, 0.0f, -1.0f});
    Cloud c = uniformCloud(L);
    const DensityField block = voxelBlock({2.0f, 3.0f, 10.0f}, 4, 0.75f);
    const ShadowCaster* casters[] = {&block};
    ASSERT_TRUE(c.setLight(L, casters));
    std::size_t under = 0, clear = 0;
    for (std::size_t i = 0; i < c.density().size(); ++i) {
        const glm::vec3 p = pointOf(c, i);
        const float d = c.receivedDepth(0)[i];
        if (p.x >= 2.0f && p.x <= 5.0f && p.y >= 3.0f && p.y <= 6.0f) {
            EXPECT_NEAR(d, 8.0f, 8.0f * 6.0f * 4.0f * 0x1p-24f) << i;
            // The cloud's own part: the sweep down the z axis, exact for a uniform field (<= 6 steps).
            const double own = double(kMaxExtinction) * double(kDensity) * (6.0 - double(p.z));
            const double want = std::exp(-own) * std::exp2(-8.0);
            EXPECT_NEAR(double(c.sunTransmittance()[i]), want, want * (6.0 * 4.0 * 0x1p-24 * (own + 8.0 * std::log(2.0)) + 4.0 * 0x1p-24)) << i;
            ++under;
        } else if (p.x < 1.0f - 1e-3f || p.x > 6.0f + 1e-3f || p.y < 2.0f - 1e-3f || p.y > 7.0f + 1e-3f) {
            EXPECT_EQ(d, 0.0f) << i;
            ++clear;
        }
    }
    EXPECT_EQ(under, 4u * 4u * 7u);
    EXPECT_GT(clear, 200u);
}

// A plume (a voxel block) moves above a noise cloud lit by a slanted sun and
// a point light (the multi-light path: the source per grid point and its
// scale): the restricted relight (only the points under the old and new
// boxes traced again) leaves the transmittances, the received depths, the
// scale and the LOD fields bit for bit as a full relight of a fresh cloud
// under the same casters, traces fewer points than the full relight, and does
// no sweep, for a slanted and a horizontal sun; a second cloud taken through the same calls is identical
// (determinism).
TEST(CloudReceive, ARestrictedRelightEqualsAFullOneBitForBit) {
  // A slanted sun, and a horizontal one (its rays never leave a z plane).
  for (glm::vec3 sunTravel : {glm::vec3(0.3f, 0.2f, -1.0f), glm::vec3(-1.0f, -0.3f, 0.0f)}) {
    SCOPED_TRACE(sunTravel.z);
    CloudLighting L;
    L.model = CloudLightModel::LowAlbedo;
    L.sun = Light::directional(sunTravel);
    L.lights = {Light::point({10.0f, 4.0f, 16.0f}, glm::vec3(1.0f), 300.0f)};
    L.gas.phase = *PhaseFunction::create(std::vector<HgLobe>{{0.6f, 1.0f}});
    CloudCreateDesc cd = uniformDesc(L);
    cd.cloud.dims = {17, 13, 9};
    cd.cloud.coverage = 0.7f;
    cd.volume.originWorld = {0.37f, -1.3f, 0.11f}; // grid points off the float lattice: GridShadows' weights round
    cd.volume.spacingWorld = 0.93f;
    // Above the cloud for the slanted sun, beside it (toward +x) for the horizontal one.
    const bool flat = sunTravel.z == 0.0f;
    const DensityField still = flat ? voxelBlock({18.0f, 9.0f, 1.0f}, 3, 0.5f) : voxelBlock({12.0f, 2.0f, 11.0f}, 3, 0.5f);
    const DensityField before = flat ? voxelBlock({18.0f, 3.0f, 2.0f}, 4, 0.6f) : voxelBlock({2.0f, 3.0f, 10.0f}, 4, 0.6f);
    const DensityField after = flat ? voxelBlock({19.5f, 5.0f, 3.5f}, 4, 0.6f) : voxelBlock({4.5f, 5.0f, 10.5f}, 4, 0.6f);
    const ShadowCaster* first[] = {&before, &still};
    const ShadowCaster* second[] = {&after, &still};
    CloudCreateDesc fresh = cd;
    fresh.lighting = {}; // Roettger under the default sun: the setLight below is a full relight
    Cloud full = *Cloud::create(fresh);
    ASSERT_TRUE(full.setLight(L, second));
    EXPECT_GT(full.relights(), 1u);
    EXPECT_GE(full.receivePoints(), full.density().size()); // every point, for each light a caster can shadow it from
    auto run = [&](Cloud& c) {
        ASSERT_TRUE(c.setLight(L, first));
        const std::uint64_t relights = c.relights(), points = c.receivePoints(), restricted = c.restrictedRelights();
        ASSERT_TRUE(c.setLight(L, second));
        EXPECT_EQ(c.relights(), relights);                 // no sweep
        EXPECT_EQ(c.restrictedRelights(), restricted + 1); // one restricted relight
        const std::uint64_t traced = c.receivePoints() - points;
        EXPECT_GT(traced, 0u);
        EXPECT_LT(traced, full.receivePoints()); // fewer than the full relight's
    };
    Cloud a = *Cloud::create(cd), b = *Cloud::create(cd);
    run(a);
    run(b);
    for (const Cloud* c : {&a, &b}) {
        EXPECT_EQ(c->sunTransmittance(), full.sunTransmittance());
        EXPECT_EQ(c->lightTransmittance(0), full.lightTransmittance(0));
        EXPECT_EQ(c->receivedDepth(0), full.receivedDepth(0));
        EXPECT_EQ(c->receivedDepth(1), full.receivedDepth(1));
        EXPECT_EQ(c->lightScale(), full.lightScale());
        EXPECT_EQ(lodValues(*c), lodValues(full));
    }
    // The move changed something: the points under the old box are lit again.
    float most = 0.0f;
    for (float d : full.receivedDepth(0)) most = std::max(most, d);
    EXPECT_GT(most, 2.0f);
  }
}

// A caster whose box cannot shadow the cloud for any light (beside it and
// below its top, the sun straight down; behind it from the point light)
// costs nothing when it moves or appears: no point traced again, no
// relight, no table; moved into the shadow volume it is traced.
TEST(CloudReceive, ACasterThatCannotShadowTheCloudCostsNothing) {
    CloudLighting L;
    L.model = CloudLightModel::LowAlbedo;
    L.sun = Light::directional({0.0f, 0.0f, -1.0f});
    L.lights = {Light::point({4.0f, 4.0f, 20.0f}, glm::vec3(1.0f), 100.0f)};
    Cloud c = uniformCloud(L);
    ASSERT_TRUE(c.setLight(L));
    const std::uint64_t points = c.receivePoints(), traces = c.receiveTraces(), relights = c.relights(), tables = c.tableBuilds(),
                        restricted = c.restrictedRelights();
    for (float x : {12.0f, 14.0f, 20.0f}) {
        const UniformBox beside({x, 0.0f, -3.0f}, {x + 2.0f, 8.0f, 5.0f}, 2.0f); // x > 8: beside the cloud, under its top
        const UniformBox below({0.0f, 0.0f, -9.0f}, {8.0f, 8.0f, -1.0f}, 2.0f);  // under the cloud: behind it from both lights
        const ShadowCaster* casters[] = {&beside, &below};
        ASSERT_TRUE(c.setLight(L, casters));
    }
    EXPECT_EQ(c.receivePoints(), points);
    EXPECT_EQ(c.receiveTraces(), traces);
    EXPECT_EQ(c.relights(), relights);
    EXPECT_EQ(c.restrictedRelights(), restricted);
    EXPECT_EQ(c.tableBuilds(), tables);
    for (float d : c.receivedDepth(0)) EXPECT_EQ(d, 0.0f);
    // Into the sun's shadow volume over the cloud: traced.
    const UniformBox over({1.0f, 1.0f, 9.0f}, {3.0f, 3.0f, 10.0f}, 2.0f);
    const ShadowCaster* casters[] = {&over};
    ASSERT_TRUE(c.setLight(L, casters));
    EXPECT_GT(c.receivePoints(), points);
    EXPECT_EQ(c.restrictedRelights(), restricted + 1);
    EXPECT_EQ(c.relights(), relights);
}

// Bad input: a null caster, or the cloud's own field among the casters, is
// refused naming the caster; the cloud is left as it was.
TEST(CloudReceive, ANullCasterOrItsOwnFieldIsRefusedNamingIt) {
    CloudLighting L;
    L.model = CloudLightModel::LowAlbedo;
    Cloud c = uniformCloud(L);
    const std::vector<float> before = c.sunTransmittance();
    const UniformBox box({0.0f, 0.0f, 8.0f}, {8.0f, 8.0f, 9.0f}, 1.0f);
    const ShadowCaster* withNull[] = {&box, nullptr};
    Status s = c.setLight(L, withNull);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("casters[1] is null"), std::string::npos) << s.error();
    const ShadowCaster* own[] = {&c.densityField()};
    s = c.setLight(L, own);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("casters[0] is this cloud's own densityField()"), std::string::npos) << s.error();
    EXPECT_EQ(c.sunTransmittance(), before);
    EXPECT_TRUE(c.receivedDepth(0).empty());
}

// In a Scene: a lit plume above a lit low-albedo cloud shadows it (the grid
// points under the plume's interior receive its 4 voxels x 1 log2 unit, as
// above), with the camera on both and turned away from the plume (then
// out of view, advanced for its shadow only): the cloud's light is the same
// bit for bit, and a frame on the same camera leaves nothing traced again.
TEST(CloudReceive, InASceneAPlumeShadowsTheCloudWhetherInViewOrNot) {
    Materials materials{Footprint{}};
    Scene scene;
    const std::uint32_t table = materials.addColorTable(ColorTable::constant({0.8f, 0.8f, 0.8f, 1.0f}));
    Grid g = *Grid::box({4, 4, 4});
    for (Voxel& v : g.voxels) v.opacity = 0.5f;
    g.transform = glm::translate(glm::mat4(1.0f), glm::vec3(2.0f, 17.0f, 2.0f) - g.localPosition({0, 0, 0}));
    EffectDesc desc;
    desc.name = "plume";
    desc.layers = {EffectLayer{.style = {.colorTable = table, .textured = false}}};
    const EffectId plume = scene.add(*Effect::fromGrid(g, desc), {.name = "plume", .lighting = {.enabled = true, .gas = {.albedo = 1.0f}}});
    CloudCreateDesc cd;
    cd.cloud = {.dims = {9, 5, 9}, .seed = 2};
    cd.lighting.model = CloudLightModel::LowAlbedo;
    cd.volume.originWorld = {0.0f, 10.0f, 0.0f};
    cd.transfer.maxExtinctionPerWorld = 1.0f;
    cd.table = {.scalarResolution = 4, .lengthResolution = 8};
    const EffectId cloud = scene.add(*Cloud::create(cd), {.name = "cloud", .lighting = {.enabled = true, .gas = {.albedo = 0.9f}}});
    ASSERT_TRUE(scene.addLight(Light::directional({0.0f, -1.0f, 0.0f})));
    Frame frame;
    const Camera both = Camera::lookAt({4.0f, 14.0f, 60.0f}, {4.0f, 14.0f, 4.0f}, {0, 1, 0}, glm::radians(40.0f), {64, 48}, 0.1f, 200.0f);
    ASSERT_TRUE(scene.prepare(0.0, both, materials, frame));
    EXPECT_TRUE(scene.lightingError().empty()) << scene.lightingError();
    ASSERT_TRUE(scene.status(plume).inView);
    ASSERT_TRUE(scene.status(cloud).lit);
    const Cloud& c = *scene.findCloud(cloud);
    const std::vector<float> seen = c.sunTransmittance();
    std::size_t under = 0;
    for (std::size_t i = 0; i < seen.size(); ++i) {
        const glm::vec3 p = pointOf(c, i);
        if (p.x >= 2.0f && p.x <= 5.0f && p.z >= 2.0f && p.z <= 5.0f) {
            EXPECT_NEAR(c.receivedDepth(0)[i], 4.0f, 4.0f * 6.0f * 4.0f * 0x1p-24f) << i; // as above: <= 6 cells crossed
            ++under;
        }
    }
    EXPECT_EQ(under, 4u * 5u * 4u);
    // Looking at the cloud from below its top, the plume above the view.
    const Camera cloudOnly = Camera::lookAt({4.0f, 8.0f, 30.0f}, {4.0f, 10.0f, 4.0f}, {0, 1, 0}, glm::radians(16.0f), {64, 48}, 0.1f, 200.0f);
    Frame turned;
    ASSERT_TRUE(scene.prepare(0.1, cloudOnly, materials, turned));
    ASSERT_FALSE(scene.status(plume).inView);
    EXPECT_TRUE(scene.status(plume).castsIntoView);
    ASSERT_TRUE(scene.status(cloud).inView);
    EXPECT_EQ(c.sunTransmittance(), seen);
    const std::uint64_t points = c.receivePoints(), relights = c.relights() + c.restrictedRelights();
    ASSERT_TRUE(scene.prepare(0.2, cloudOnly, materials, turned));
    EXPECT_EQ(c.receivePoints(), points);
    EXPECT_EQ(c.relights() + c.restrictedRelights(), relights);
}
