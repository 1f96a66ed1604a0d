// A low-albedo Cloud lit by point and spot lights beside its sun
// (CloudLighting::lights, cloud.hpp): each light's transmittance through a
// uniform cloud against the closed form exp(-sigma L), L the length of the
// ray to the light inside the grid's box; the source each tetrahedron vertex
// draws against the lighting model evaluated in double from those closed
// forms (inverse square, the spot's smoothstep cone, the HG phase per light,
// multiple scattering per light); relights only on change; bad input named.
//
// The cloud: 17x17x9 grid points of spacing 0.5 (box [0, 8] x [0, 8] x [0, 4]),
// density 0.4 everywhere, maxExtinctionPerWorld 1.5: sigma = 0.6 per unit.
//
// Lights of different colours (a white sun and a torch's orange): each
// vertex carries an RGB source s_c = u R_c (LodFrame::rgb), drawn per channel
// as kappa_c(s_c); the same model and tolerance per channel.
//
// Tolerances. Transmittance: the trace is DensityField's segment integral in
// float over at most ~40 lattice pieces, of a depth <= 4 nats whose per-voxel
// value is itself a float conversion (relative ~1e-7): |T - exact| <= 1e-5
// (as cloud_light_test.cpp's sweep). Vertex source: the LOD stores the scalar
// u in 8 bits (rounded: half a code, 0.5 / 255), each vertex draws s = u R
// with R in [0, 1], and kappa(s) = A + B s: so |source - model| <= B (0.5 /
// 255 + 1e-5), the 1e-5 covering T and the float phase and irradiance. With
// an RGB source s_c = u R_c, R_c in [0, 1] likewise (a light's channel is at
// most its largest, w_i): the same bound per channel, B_c (0.5 / 255 + 1e-5).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <gtest/gtest.h>

#include "splatfx/cloud.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

constexpr float kF = 0.4f, kH = 0.5f, kMaxExt = 1.5f;
constexpr double kSigma = double(kMaxExt) * double(kF);
constexpr double kTTol = 1e-5;

std::size_t index(glm::ivec3 n, glm::ivec3 p) { return std::size_t(p.x) + std::size_t(n.x) * (std::size_t(p.y) + std::size_t(n.y) * std::size_t(p.z)); }

CloudCreateDesc uniformDesc() {
    CloudCreateDesc d;
    d.cloud = {.dims = {17, 17, 9}, .seed = 3, .featureCells = 6.0f, .coverage = 0.6f};
    d.table = {.scalarResolution = 8, .lengthResolution = 8};
    d.volume.spacingWorld = kH;
    d.transfer.maxExtinctionPerWorld = kMaxExt;
    d.lighting.model = CloudLightModel::LowAlbedo;
    const HgLobe lobes[] = {{0.6f, 0.7f}, {-0.3f, 0.3f}};
    d.lighting.gas.phase = *PhaseFunction::create(lobes);
    d.lighting.gas.ambient = {0.1f, 0.12f, 0.15f};
    d.lighting.gas.multipleScattering = 0.2f;
    return d;
}

// Lit by `lighting`'s lights and, when withSun, its sun (otherwise a sun of intensity 0).
Cloud uniformCloud(const CloudLighting& lighting, bool withSun = false) {
    CloudCreateDesc d = uniformDesc();
    d.lighting.sun.intensity = 0.0f; // lit by `lighting` once the density is set
    auto c = Cloud::create(d);
    EXPECT_TRUE(c) << c.error();
    EXPECT_TRUE(c->setDensity(std::vector<float>(c->density().size(), kF)));
    CloudLighting L = lighting;
    L.model = CloudLightModel::LowAlbedo;
    L.gas = d.lighting.gas;
    if (!withSun) L.sun.intensity = 0.0f;
    const Status s = c->setLight(L);
    EXPECT_TRUE(s) << s.error();
    return std::move(*c);
}

const glm::dvec3 kBoxLo(0.0), kBoxHi(8.0, 8.0, 4.0);

// exp(-sigma x the length of the segment p -> light inside the box (p inside)).
double closedT(glm::dvec3 p, glm::dvec3 light) {
    const glm::dvec3 d = light - p;
    double t = 1.0;
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 0.0) t = std::min(t, (kBoxHi[a] - p[a]) / d[a]);
        if (d[a] < 0.0) t = std::min(t, (kBoxLo[a] - p[a]) / d[a]);
    }
    return std::exp(-kSigma * t * glm::length(d));
}

double hg(double g, double mu) { return (1.0 - g * g) / (4.0 * std::numbers::pi * std::pow(1.0 + g * g - 2.0 * g * mu, 1.5)); }
double phase(glm::dvec3 travel, glm::dvec3 toEye) {
    const double mu = glm::dot(glm::normalize(travel), glm::normalize(toEye));
    return 0.7 * hg(0.6, mu) + 0.3 * hg(-0.3, mu);
}

double smoothstep(double a, double b, double x) {
    const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// One light's term of the model at p: c I E (4 pi phase T + m), with the
// lighting code's irradiance (1/d^2, d at least max(radiusWorld, spacing/2),
// where the phase is isotropic) and the spot's smoothstep cone.
glm::dvec3 lightTerm(const Light& l, glm::dvec3 p, glm::dvec3 eye, double T) {
    const glm::dvec3 c = glm::dvec3(l.color) * double(l.intensity);
    const double m = 0.2;
    if (l.type == LightType::Directional) return c * (4.0 * std::numbers::pi * phase(glm::dvec3(l.direction), eye - p) * T + m);
    const double minDist = std::max(double(l.radiusWorld), 0.5 * double(kH));
    const glm::dvec3 from = p - glm::dvec3(l.position);
    const double d = glm::length(from);
    double E = 1.0 / std::max(d * d, minDist * minDist);
    if (l.type == LightType::Spot)
        E *= smoothstep(std::cos(double(l.outerConeRad)), std::cos(double(l.innerConeRad)), glm::dot(from / d, glm::normalize(glm::dvec3(l.direction))));
    const double p4 = d >= minDist ? 4.0 * std::numbers::pi * phase(from, eye - p) : 1.0;
    return c * E * (p4 * T + m);
}

// The cloud's source at p: bright x albedo x (ambient + the lights' terms).
glm::dvec3 model(glm::dvec3 terms) { return 0.9 * (glm::dvec3(0.1, 0.12, 0.15) + terms); }

const Camera kCamera = Camera::lookAt({4.0f, -12.0f, 6.0f}, {4.0f, 4.0f, 2.0f}, {0.0f, 0.0f, 1.0f}, 0.8f, {64, 48});

// Every vertex of the fully refined mesh (a grid point) against `want`:
// one scalar per vertex (frame.rgb empty), or with `rgb` an RGB source
// (channel c drawn as kappa_c(rgb_c), the scalar its largest channel).
template <class Want>
void checkVertices(Cloud& cloud, Want want, bool rgb = false) {
    LodFrame frame;
    ASSERT_TRUE(cloud.update(kCamera, {.detailC = 1e6f, .zeroOpacityTest = false, .clipNear = false}, frame));
    ASSERT_FALSE(frame.tets.empty());
    ASSERT_EQ(frame.rgb.size(), rgb ? frame.tets.size() : 0u);
    const glm::dvec3 B = cloud.transfer().color(1.0) - cloud.transfer().color(0.0);
    int checked = 0;
    for (std::size_t i = 0; i < frame.tets.size(); ++i)
        for (int k = 0; k < 4; ++k) {
            const Tetrahedron& t = frame.tets[i];
            const glm::vec3 p = t.position[std::size_t(k)];
            const glm::ivec3 g = glm::ivec3(glm::round(p / kH));
            ASSERT_LT(glm::length(p - glm::vec3(g) * kH), 1e-4f) << "fully refined vertices are grid points";
            const glm::dvec3 w = want(g, glm::dvec3(p));
            glm::dvec3 got = cloud.transfer().color(t.scalar[std::size_t(k)]);
            if (rgb) {
                const glm::vec3 s = frame.rgb[i][std::size_t(k)];
                for (int c = 0; c < 3; ++c) got[c] = cloud.transfer().color(s[c])[c];
                EXPECT_EQ(t.scalar[std::size_t(k)], std::max({s.x, s.y, s.z}));
            }
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], w[c], B[c] * (0.5 / 255.0 + 1e-5)) << g.x << " " << g.y << " " << g.z;
            ++checked;
        }
    EXPECT_GT(checked, 1000);
}

} // namespace

// A point light above the middle of the cloud: every grid point's ray leaves
// through the top face, T = exp(-sigma L) with L its length inside the box.
TEST(CloudLights, PointLightAboveAUniformCloud) {
    const Light lamp = Light::point({4.3f, 3.8f, 12.0f}, {1.0f, 0.8f, 0.6f}, 40.0f);
    Cloud cloud = uniformCloud({.lights = {lamp}});
    const glm::ivec3 n = cloud.dims();
    ASSERT_EQ(cloud.lightTransmittance(0).size(), std::size_t(n.x) * std::size_t(n.y) * std::size_t(n.z));
    EXPECT_EQ(cloud.lightTraces(), std::uint64_t(n.x) * std::uint64_t(n.y) * std::uint64_t(n.z)); // a point light reaches every point
    double lowest = 1.0;
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const double want = closedT(glm::dvec3(x, y, z) * double(kH), glm::dvec3(lamp.position));
                lowest = std::min(lowest, want);
                EXPECT_NEAR(cloud.lightTransmittance(0)[index(n, {x, y, z})], want, kTTol) << x << " " << y << " " << z;
            }
    EXPECT_LT(lowest, 0.1); // the bottom is in the cloud's shadow
    checkVertices(cloud, [&](glm::ivec3, glm::dvec3 p) {
        return model(lightTerm(lamp, p, glm::dvec3(kCamera.eye()), closedT(p, glm::dvec3(lamp.position))));
    });
}

// A point light inside the cloud: each point's ray to it stays inside the
// box, T = exp(-sigma |p - light|). radiusWorld = spacing / 2: the grid point
// 0.15 from the light takes the irradiance at 0.25, isotropically.
TEST(CloudLights, PointLightInsideTheCloud) {
    Light lamp = Light::point({4.1f, 3.9f, 2.05f}, {1.0f, 0.8f, 0.6f}, 0.5f);
    lamp.radiusWorld = 0.5f * kH;
    Cloud cloud = uniformCloud({.lights = {lamp}});
    const glm::ivec3 n = cloud.dims();
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const glm::dvec3 p = glm::dvec3(x, y, z) * double(kH);
                EXPECT_NEAR(cloud.lightTransmittance(0)[index(n, {x, y, z})], std::exp(-kSigma * glm::length(p - glm::dvec3(lamp.position))), kTTol);
            }
    checkVertices(cloud, [&](glm::ivec3, glm::dvec3 p) {
        return model(lightTerm(lamp, p, glm::dvec3(kCamera.eye()), std::exp(-kSigma * glm::length(p - glm::dvec3(lamp.position)))));
    });
}

// A spot above the cloud aimed at its -x edge, its outer cone reaching about
// the middle: the points outside the outer cone are dark and not traced (the
// count of traces is the count of points inside it); inside, T is the closed
// form and the source has the smoothstep cone.
TEST(CloudLights, SpotLightCoveringHalfTheCloud) {
    const glm::vec3 at{4.0f, 4.0f, 12.0f};
    const glm::vec3 axis = glm::vec3(0.0f, 4.0f, 2.0f) - at;
    // Outer half-angle: the angle to (4.02, 4, 2), just past the middle (no grid point on the cone).
    const float outer = std::acos(glm::dot(glm::normalize(axis), glm::normalize(glm::vec3(4.02f, 4.0f, 2.0f) - at)));
    const Light spot = Light::spot(at, axis, 0.6f * outer, outer, {1.0f, 0.8f, 0.6f}, 60.0f);
    Cloud cloud = uniformCloud({.lights = {spot}});
    const glm::ivec3 n = cloud.dims();
    std::uint64_t inside = 0;
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const glm::dvec3 p = glm::dvec3(x, y, z) * double(kH);
                const double c = glm::dot(glm::normalize(p - glm::dvec3(at)), glm::normalize(glm::dvec3(axis)));
                const float T = cloud.lightTransmittance(0)[index(n, {x, y, z})];
                if (c > std::cos(double(outer)) + 1e-6) {
                    ++inside;
                    EXPECT_NEAR(T, closedT(p, glm::dvec3(at)), kTTol);
                } else if (c < std::cos(double(outer)) - 1e-6) {
                    EXPECT_EQ(T, 0.0f) << "dark: not traced";
                }
            }
    const std::uint64_t all = std::uint64_t(n.x) * std::uint64_t(n.y) * std::uint64_t(n.z);
    EXPECT_EQ(cloud.lightTraces(), inside);
    EXPECT_GT(inside, all * 3 / 10);
    EXPECT_LT(inside, all * 7 / 10);
    checkVertices(cloud, [&](glm::ivec3, glm::dvec3 p) { return model(lightTerm(spot, p, glm::dvec3(kCamera.eye()), closedT(p, glm::dvec3(at)))); });
}

// A spot aimed away from the cloud costs no trace and lights nothing.
TEST(CloudLights, SpotMissingTheCloudCostsNothing) {
    const Light spot = Light::spot({4.0f, 4.0f, 12.0f}, {0.0f, 0.0f, 1.0f}, 0.2f, 0.4f, {1.0f, 0.8f, 0.6f}, 60.0f);
    Cloud cloud = uniformCloud({.lights = {spot}});
    EXPECT_EQ(cloud.lightTraces(), 0u);
    EXPECT_EQ(cloud.lightScale(), 0.0f); // no light reaches a point: nothing to scale
}

// The sun straight down (its swept T is exact for it: exp(-sigma h (nz-1-z)))
// and a point light of the same colour: their terms add.
TEST(CloudLights, SunAndPointLightSummed) {
    CloudLighting L;
    L.sun = Light::directional({0.0f, 0.0f, -1.0f}, {1.0f, 0.8f, 0.6f}, 1.5f);
    const Light lamp = Light::point({4.3f, 3.8f, 12.0f}, {2.0f, 1.6f, 1.2f}, 20.0f);
    L.lights = {lamp};
    Cloud cloud = uniformCloud(L, true);
    checkVertices(cloud, [&](glm::ivec3 g, glm::dvec3 p) {
        const double sunT = std::exp(-kSigma * double(kH) * double(8 - g.z));
        return model(lightTerm(L.sun, p, glm::dvec3(kCamera.eye()), sunT) +
                     lightTerm(lamp, p, glm::dvec3(kCamera.eye()), closedT(p, glm::dvec3(lamp.position))));
    });
}

// The typical case of lights of different colours: a torch's orange under a
// white sun. Each vertex's RGB source against the model per channel; the
// cloud's colour is no multiple of either light's (its red-to-blue ratio
// varies over the cloud: the torch's share falls with distance).
TEST(CloudLights, WhiteSunAndOrangeTorchGiveAnRgbSourcePerVertex) {
    CloudLighting L;
    L.sun = Light::directional({0.3f, 0.2f, -1.0f}, glm::vec3(1.0f), 1.2f);
    const Light torch = Light::point({1.5f, 2.0f, 3.0f}, {1.0f, 0.45f, 0.1f}, 6.0f);
    L.lights = {torch};
    Cloud cloud = uniformCloud(L, true);
    checkVertices(
        cloud,
        [&](glm::ivec3, glm::dvec3 p) {
            // The sun's T in closed form: its ray to the box's face, the sun as a light far along -direction.
            const double sunT = closedT(p, p - 1e4 * glm::normalize(glm::dvec3(L.sun.direction)));
            return model(lightTerm(L.sun, p, glm::dvec3(kCamera.eye()), sunT) +
                         lightTerm(torch, p, glm::dvec3(kCamera.eye()), closedT(p, glm::dvec3(torch.position))));
        },
        true);
    // The drawn colour does vary in chromaticity: red over blue near the torch against far from it.
    LodFrame frame;
    ASSERT_TRUE(cloud.update(kCamera, {.detailC = 1e6f, .zeroOpacityTest = false, .clipNear = false}, frame));
    double lo = 1e30, hi = 0.0;
    for (std::size_t i = 0; i < frame.tets.size(); ++i)
        for (std::size_t k = 0; k < 4; ++k) {
            const glm::dvec3 c(cloud.transfer().color(frame.rgb[i][k].r).r, 0.0, cloud.transfer().color(frame.rgb[i][k].b).b);
            lo = std::min(lo, c.x / c.z), hi = std::max(hi, c.x / c.z);
        }
    EXPECT_GT(hi, 1.5 * lo);
}

// The same cloud under lights sharing one colour keeps one scalar per vertex
// (frame.rgb empty: the pass draws it as before, the same records and program).
TEST(CloudLights, LightsOfOneColourKeepOneScalarPerVertex) {
    CloudLighting L;
    L.sun = Light::directional({0.3f, 0.2f, -1.0f}, {1.0f, 0.45f, 0.1f}, 1.2f);
    L.lights = {Light::point({1.5f, 2.0f, 3.0f}, {2.0f, 0.9f, 0.2f}, 3.0f)};
    Cloud cloud = uniformCloud(L, true);
    LodFrame frame;
    ASSERT_TRUE(cloud.update(kCamera, {.detailC = 1e6f, .zeroOpacityTest = false, .clipNear = false}, frame));
    ASSERT_FALSE(frame.tets.empty());
    EXPECT_TRUE(frame.rgb.empty());
    // A new colour for the torch: RGB from the next update on; back to one colour: empty again.
    L.lights[0].color = {0.2f, 0.9f, 1.0f};
    ASSERT_TRUE(cloud.setLight({.model = CloudLightModel::LowAlbedo, .sun = L.sun, .lights = L.lights, .gas = cloud.lighting().gas}));
    ASSERT_TRUE(cloud.update(kCamera, {.detailC = 1e6f, .zeroOpacityTest = false, .clipNear = false}, frame));
    EXPECT_EQ(frame.rgb.size(), frame.tets.size());
    L.lights[0].color = {2.0f, 0.9f, 0.2f};
    ASSERT_TRUE(cloud.setLight({.model = CloudLightModel::LowAlbedo, .sun = L.sun, .lights = L.lights, .gas = cloud.lighting().gas}));
    ASSERT_TRUE(cloud.update(kCamera, {.detailC = 1e6f, .zeroOpacityTest = false, .clipNear = false}, frame));
    EXPECT_TRUE(frame.rgb.empty());
}

// A light that moves relights (and traces again); the same light does
// neither; a new intensity relights (the scale moves) without tracing; a new
// density traces again.
TEST(CloudLights, RelightsOnlyWhenALightOrTheDensityChanges) {
    CloudLighting L;
    L.lights = {Light::point({4.0f, 4.0f, 12.0f}, glm::vec3(1.0f), 40.0f)};
    Cloud cloud = uniformCloud(L);
    const std::uint64_t points = cloud.density().size();
    const std::uint64_t relights = cloud.relights(), traces = cloud.lightTraces(), tables = cloud.tableBuilds();
    CloudLighting same = cloud.lighting();
    ASSERT_TRUE(cloud.setLight(same));
    EXPECT_EQ(cloud.relights(), relights);
    EXPECT_EQ(cloud.lightTraces(), traces);
    EXPECT_EQ(cloud.tableBuilds(), tables);
    same.lights[0].position.x += 1.0f; // moves
    ASSERT_TRUE(cloud.setLight(same));
    EXPECT_EQ(cloud.relights(), relights + 1);
    EXPECT_EQ(cloud.lightTraces(), traces + points);
    EXPECT_EQ(cloud.tableBuilds(), tables + 1);
    same.lights[0].intensity = 80.0f; // brighter: rescaled, not traced
    ASSERT_TRUE(cloud.setLight(same));
    EXPECT_EQ(cloud.relights(), relights + 2);
    EXPECT_EQ(cloud.lightTraces(), traces + points);
    std::vector<float> density = cloud.density();
    density[5] = 0.9f;
    ASSERT_TRUE(cloud.setDensity(density));
    EXPECT_EQ(cloud.relights(), relights + 3);
    EXPECT_EQ(cloud.lightTraces(), traces + 2 * points);
}

TEST(CloudLights, BadLightsAreRefusedNamingTheField) {
    CloudCreateDesc d = uniformDesc();
    auto cloud = Cloud::create(d);
    ASSERT_TRUE(cloud) << cloud.error();
    const std::uint64_t relights = cloud->relights();
    CloudLighting L = cloud->lighting();
    L.lights = {Light::point({0.0f, 0.0f, 10.0f}), Light::point({1.0f, 0.0f, 10.0f}, {1.0f, 0.5f, 0.2f})};
    EXPECT_TRUE(Cloud::validateLighting(L)); // lights of different colours are taken (row 317: no longer refused)
    L.lights[1].position.y = std::numeric_limits<float>::quiet_NaN();
    Status s = cloud->setLight(L);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "CloudLighting.lights[1].position must be finite");
    L.lights.assign(std::size_t(kMaxCloudLights) + 1, Light::point({0.0f, 0.0f, 10.0f}));
    s = cloud->setLight(L);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "CloudLighting.lights holds 5 lights; at most kMaxCloudLights = 4");
    L.lights.resize(1);
    L.model = CloudLightModel::Roettger;
    s = cloud->setLight(L);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "CloudLighting.lights must be empty with CloudLightModel::Roettger (its light is the sun's alone; use LowAlbedo)");
    EXPECT_EQ(cloud->relights(), relights); // nothing changed
    EXPECT_TRUE(cloud->lighting().lights.empty());
}

// In a Scene: a low-albedo cloud takes the scene's sun and its point light;
// a spot aimed away is not taken (it cannot reach the cloud); a light of
// another colour is taken too (an RGB source per vertex), and only lights past
// kMaxCloudLights are left out and counted (SceneCounters::cloudLightsDropped).
TEST(CloudLights, SceneLightsTheCloudWithItsPointLights) {
    CloudCreateDesc d = uniformDesc();
    d.cloud.dims = {9, 9, 5};
    Scene scene;
    const EffectId id = scene.add(*Cloud::create(d), {.name = "cloud", .lighting = {.enabled = true}});
    ASSERT_TRUE(scene.addLight(Light::directional({0.0f, 0.0f, -1.0f})));
    ASSERT_TRUE(scene.addLight(Light::point({2.0f, 2.0f, 6.0f}, glm::vec3(1.0f), 10.0f)));
    ASSERT_TRUE(scene.addLight(Light::spot({2.0f, 2.0f, 6.0f}, {0.0f, 0.0f, 1.0f}, 0.2f, 0.4f)));
    Materials materials{Footprint{}};
    Frame frame;
    const Camera cam = Camera::lookAt({2.0f, -10.0f, 3.0f}, {2.0f, 2.0f, 1.0f}, {0.0f, 0.0f, 1.0f}, 0.8f, {64, 48});
    ASSERT_TRUE(scene.prepare(0.0, cam, materials, frame));
    const Cloud& c = *scene.findCloud(id);
    ASSERT_EQ(c.lighting().lights.size(), 1u);
    EXPECT_EQ(c.lighting().lights[0].type, LightType::Point);
    EXPECT_TRUE(scene.lightingError().empty()) << scene.lightingError();
    EXPECT_EQ(scene.counters().cloudLightsDropped, 0u);
    ASSERT_TRUE(scene.addLight(Light::point({1.0f, 1.0f, 6.0f}, {1.0f, 0.4f, 0.1f}, 10.0f))); // a torch's orange
    ASSERT_TRUE(scene.prepare(0.0, cam, materials, frame));
    EXPECT_EQ(scene.findCloud(id)->lighting().lights.size(), 2u);
    EXPECT_EQ(scene.counters().cloudLightsDropped, 0u);
    EXPECT_TRUE(scene.lightingError().empty()) << scene.lightingError();
    ASSERT_EQ(frame.volumes().size(), 1u);
    EXPECT_EQ(frame.volumes()[0].lod.rgb.size(), frame.volumes()[0].lod.tets.size()); // drawn with an RGB source
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(scene.addLight(Light::point({1.0f + float(k), 3.0f, 6.0f}, {0.2f, 0.4f, 1.0f}, 5.0f)));
    ASSERT_TRUE(scene.prepare(0.0, cam, materials, frame));
    EXPECT_EQ(scene.findCloud(id)->lighting().lights.size(), std::size_t(kMaxCloudLights));
    EXPECT_EQ(scene.counters().cloudLightsDropped, 1u); // the fifth: past the cap
}
