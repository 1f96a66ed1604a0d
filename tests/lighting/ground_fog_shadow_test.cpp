// Smoke shadows the ground fog in a Scene (scene.hpp, GroundFog::setLighting):
// a lit fog layer under a lit plume, the sun straight down. At every terrain
// vertex the lit tetrahedra's scalar (T, the phase being isotropic) is the
// fog's own transmittance (the reference's continuous layer,
// integrateGroundFogRay) times the plume's (the lit-volume reference: a
// VolumeField holding the plume's density as a trilinear medium, one voxel
// per cell of log2 depth -log2(1 - opacity), zero one cell beyond, as the
// scene's DensityField reads an effect's density; VolumeField::
// opticalDepthToLight in double).
//
// Tolerance: T is stored in float (6e-8 at 1); the scene traces the plume's
// field in float, a few float epsilons per lattice cell crossed, relative to
// the depth (<= 4 ln 2 nats over <= 6 cells: < 1e-5 in T); the fog's
// reference adds its own error estimate (halving 4-point Gauss-Legendre to
// 1e-11 per stretch: < 1e-9 over this layer's stretches).
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/scene.hpp"

using namespace splatfx;

namespace {

constexpr double kTolerance = 6e-8 + 1e-5 + 1e-9;

struct FogUnderSmoke {
    Materials materials{Footprint{}};
    Scene scene;
    EffectId plume = 0, fog = 0;
    Frame frame;
    GroundFogDesc fogDesc;
    TransferFunction fogTransfer = *makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, 0.8f);
    glm::vec3 plumeAt{3.0f, 4.0f, 3.0f}; // world centre of the plume's voxel (0, 0, 0)
    Camera camera = Camera::lookAt({4.0f, 9.0f, 22.0f}, {4.0f, 1.0f, 4.0f}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.1f, 200.0f);

    FogUnderSmoke() {
        // The fog: a flat layer 1.5 thick over 9x9 points, spacing 1, at the origin.
        fogDesc.dims = {9, 9};
        fogDesc.terrainHeight.assign(81, 0.0f);
        fogDesc.fogTop.assign(81, 1.5f);
        auto table = PreIntegrationTable::create(fogTransfer, {.scalarResolution = 4, .lengthResolution = 4});
        fog = scene.add(*GroundFog::create(fogDesc), fogTransfer, *table, {.name = "fog", .lighting = {.enabled = true, .gas = {.albedo = 0.9f}}});
        // The smoke: a 4x4x4 plume of opacity 0.5 (log2 depth 1 per voxel), lit, casting.
        const std::uint32_t lut = materials.addColorTable(ColorTable::constant({0.5f, 0.5f, 0.5f, 1.0f}));
        Grid g = *Grid::box({4, 4, 4});
        for (Voxel& v : g.voxels) v.opacity = 0.5f;
        g.transform = glm::translate(glm::mat4(1.0f), plumeAt - g.localPosition({0, 0, 0}));
        EffectDesc desc;
        desc.name = "plume";
        desc.layers = {EffectLayer{.style = {.colorTable = lut, .textured = false}}};
        plume = scene.add(*Effect::fromGrid(g, desc), {.name = "plume", .lighting = {.enabled = true, .selfShadow = SelfShadow::Off}});
        EXPECT_TRUE(scene.addLight(Light::directional({0.0f, -1.0f, 0.0f})));
    }

    const LodFrame* fogTets() const {
        const GroundFog* f = scene.findGroundFog(fog);
        for (const FrameVolume& v : frame.volumes())
            if (v.table == &f->litTable()) return &v.lod;
        return nullptr;
    }

    // The plume's optical depth (natural log) toward the sun through the reference medium.
    double plumeDepth(glm::vec3 p) const {
        auto voxels = std::make_shared<DenseVoxels>();
        voxels->dims = {4, 4, 4};
        voxels->origin = glm::dvec3(plumeAt);
        voxels->voxelSize = 1.0;
        voxels->values.assign(64, 1.0f); // log2 depth 1 per unit length
        VolumeField field(materials);
        field.addMedium(denseMedium(voxels, DenseFilter::Trilinear, std::log(2.0)));
        return field.opticalDepthToLight(glm::dvec3(p), Light::directional({0.0f, -1.0f, 0.0f}));
    }
};

} // namespace

TEST(GroundFogShadow, SmokeDarkensTheFogUnderIt) {
    FogUnderSmoke s;
    ASSERT_TRUE(s.scene.prepare(0.0, s.camera, s.materials, s.frame));
    EXPECT_TRUE(s.scene.status(s.fog).lit);
    EXPECT_TRUE(s.scene.status(s.plume).lit);
    const LodFrame* tets = s.fogTets();
    ASSERT_NE(tets, nullptr);
    ASSERT_FALSE(tets->tets.empty());
    EXPECT_EQ(tets->stats.clippedInput, 0u);
    double under = 1.0, away = 0.0;
    std::size_t checked = 0;
    for (const Tetrahedron& t : tets->tets)
        for (int k = 0; k < 4; ++k) {
            const glm::vec3 p = t.position[std::size_t(k)];
            if (p.y != 0.0f) continue; // terrain vertices
            GroundFogRayStats st;
            integrateGroundFogRay(s.fogDesc, s.fogTransfer, glm::dvec3(p), {0.0, 1.0, 0.0}, 0.0, 1e4, 1e-11, 20, &st);
            const double want = st.transmittance * std::exp(-s.plumeDepth(p));
            EXPECT_NEAR(t.scalar[std::size_t(k)], want, kTolerance + 2.0 * st.errorEstimate) << p.x << ", " << p.z;
            if (p.x >= 4.0f && p.x <= 5.0f && p.z >= 4.0f && p.z <= 5.0f) under = std::min(under, double(t.scalar[std::size_t(k)]));
            if (p.x == 0.0f || p.z == 0.0f) away = std::max(away, double(t.scalar[std::size_t(k)]));
            ++checked;
        }
    EXPECT_GT(checked, 100u);
    EXPECT_LT(under, 0.1 * away); // the darker patch of fog under the plume
    // Nothing changed: no relight; the fog's own table is not rebuilt either.
    const GroundFog* f = s.scene.findGroundFog(s.fog);
    const auto relights = f->relights(), builds = f->litTableBuilds();
    ASSERT_TRUE(s.scene.prepare(0.1, s.camera, s.materials, s.frame));
    EXPECT_EQ(f->relights(), relights);
    EXPECT_EQ(f->litTableBuilds(), builds);
    // The sun moves: one relight.
    ASSERT_TRUE(s.scene.setLight(0, Light::directional({0.2f, -1.0f, 0.0f})));
    ASSERT_TRUE(s.scene.prepare(0.2, s.camera, s.materials, s.frame));
    EXPECT_EQ(f->relights(), relights + 1);
}

// Lighting off (the default): the layer draws its own transfer function, unlit, as before.
TEST(GroundFogShadow, UnlitByDefault) {
    Materials materials{Footprint{}};
    Scene scene;
    GroundFogDesc d;
    d.dims = {4, 4};
    d.terrainHeight.assign(16, 0.0f);
    d.fogTop.assign(16, 1.0f);
    const TransferFunction tf = *makeGroundFogTransfer(glm::vec3(1.0f), 1.0f);
    const EffectId id = scene.add(*GroundFog::create(d), tf, *PreIntegrationTable::create(tf, {.scalarResolution = 4, .lengthResolution = 4}));
    ASSERT_TRUE(scene.addLight(Light::directional({0.0f, -1.0f, 0.0f})));
    Frame frame;
    const Camera cam = Camera::lookAt({1.5f, 5.0f, 9.0f}, {1.5f, 0.5f, 1.5f}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.1f, 100.0f);
    ASSERT_TRUE(scene.prepare(0.0, cam, materials, frame));
    EXPECT_FALSE(scene.status(id).lit);
    EXPECT_FALSE(scene.findGroundFog(id)->lit());
    ASSERT_EQ(frame.volumes().size(), 1u);
    for (const Tetrahedron& t : frame.volumes()[0].lod.tets)
        for (float l : t.lengthScale) EXPECT_EQ(l, 1.0f);
}

// A lit layer needs sigma = rho s in one colour (makeGroundFogTransfer's
// form): another transfer function is refused by name and drawn unlit.
TEST(GroundFogShadow, ATransferOfAnotherFormIsRefusedAndDrawnUnlit) {
    Materials materials{Footprint{}};
    Scene scene;
    GroundFogDesc d;
    d.dims = {4, 4};
    d.terrainHeight.assign(16, 0.0f);
    d.fogTop.assign(16, 1.0f);
    const TransferFunction ramp = *TransferFunction::create({{0.0f, glm::vec3(1.0f), 0.0f}, {1.0f, glm::vec3(0.2f), 1.0f}});
    const EffectId id = scene.add(*GroundFog::create(d), ramp, *PreIntegrationTable::create(ramp, {.scalarResolution = 4, .lengthResolution = 4}),
                                  {.name = "mist", .lighting = {.enabled = true}});
    ASSERT_TRUE(scene.addLight(Light::directional({0.0f, -1.0f, 0.0f})));
    Frame frame;
    const Camera cam = Camera::lookAt({1.5f, 5.0f, 9.0f}, {1.5f, 0.5f, 1.5f}, {0, 1, 0}, glm::radians(50.0f), {64, 48}, 0.1f, 100.0f);
    ASSERT_TRUE(scene.prepare(0.0, cam, materials, frame));
    EXPECT_NE(scene.lightingError().find("effect 'mist': lighting: a lit ground fog needs a transfer function of makeGroundFogTransfer's form"),
              std::string::npos)
        << scene.lightingError();
    EXPECT_FALSE(scene.status(id).lit);
    ASSERT_EQ(frame.volumes().size(), 1u);
    EXPECT_FALSE(frame.volumes()[0].lod.tets.empty()); // drawn, unlit
}
