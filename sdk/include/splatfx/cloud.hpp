// splatfx/cloud.hpp: a LOD cloud whose light follows a moving sun.
//
// Roettger & Ertl 2002 (sec. 5) bake the sun's light into the cloud's second
// field once, when the cloud is made. A Cloud keeps the cloud's density and
// relights that field whenever the sun or the density changes (setLight,
// setDensity), and only then: relights() counts it. Two light models:
//  - CloudLightModel::Roettger, the paper's non-physical one (sec. 5.2): the
//    light gamma = ambient + diffuse T scales the segment length (eq. 9) of
//    the density's inverse colour ramp (makeCloudTransfer).
//  - CloudLightModel::LowAlbedo, the model the effects are lit by (Ebert &
//    Parent 1990, lighting.hpp): the cloud absorbs its own extinction
//    sigma = maxExtinctionPerWorld f (f >= threshold, else 0) and emits per
//    unit extinction J = base (albedo (ambient + c I (4 pi phase(theta) T + m))),
//    with Henyey-Greenstein lobes (phase) and multiple scattering m from
//    GasLightingDesc. theta is taken per emitted vertex from the camera
//    (update()), so the phase follows the view without a relight.
// T is the sun's transmittance through the cloud's own density (a plane
// sweep along the sun, exact for density affine across the sweep planes,
// first order in the cell otherwise); LowAlbedo attenuates with the same
// sigma it draws with, Roettger with CloudDesc::lightExtinctionPerCell.
//
// Layout (volume.hpp): Roettger is CloudModel::DensityTableLightLength
// (scalar f, length scale gamma); LowAlbedo is CloudModel::LightTableDensityLength's
// layout (scalar T, length scale sigma / maxExtinctionPerWorld), drawn with
// the transfer kappa(s) = A + B s, rho = maxExtinctionPerWorld, where update()
// writes s = T phase(theta) / max phase at each vertex: pre-integration is
// exact for a colour affine in s, so the per-vertex phase costs no table.
//
// It does NOT: draw (the tetrahedra go to the projected-tetrahedra pass), take
// more than one light (the sun: a directional Light), or receive the shadows
// of other volumes. It casts through densityField(): a Scene puts a lit
// cloud's field into the scene shadow and traces the light of its lit
// effects through it (scene.hpp).
//
//   auto cloud = splatfx::Cloud::create({.cloud = {.dims = {65, 65, 17}}});
//   cloud->setLight(splatfx::Light::directional({-1, -0.2f, -0.3f}));  // relights once
//   cloud->update(camera, {}, frame);                                   // frame.tets
//
// Threading: one thread at a time.
#pragma once

#include <cstdint>
#include <vector>

#include "splatfx/lighting.hpp"
#include "splatfx/volume.hpp"

namespace splatfx {

enum class CloudLightModel {
    Roettger,  // sec. 5.2: gamma = ambient + diffuse T scales the length (default)
    LowAlbedo, // Ebert & Parent 1990 single scattering with HG lobes and self-shadowing
};

// How a cloud is lit. Which fields apply depends on the model.
struct CloudLighting {
    CloudLightModel model = CloudLightModel::Roettger; // default Roettger
    // The sun: a directional light; its direction is where the light travels.
    // Default: travelling down (-z) and a little sideways, the direction
    // CloudDesc's default sunDirection points back to.
    Light sun = Light::directional({-0.3f, -0.2f, -1.0f});
    // Roettger: gamma = ambient + diffuse T, each >= 0, sum <= 1; T through
    // CloudDesc::lightExtinctionPerCell. Defaults as CloudDesc (0.35, 0.65).
    float ambient = 0.35f;
    float diffuse = 0.65f;
    // LowAlbedo: albedo, phase lobes, ambient (RGB), multipleScattering; its
    // emission and colorTable are ignored (the base colour is
    // CloudTransferDesc::bright). Default GasLightingDesc{} with albedo 0.9.
    GasLightingDesc gas{.albedo = 0.9f};
};

struct CloudCreateDesc {
    CloudDesc cloud{};               // the density (and Roettger's lightExtinctionPerCell); its sunDirection, ambient, diffuse and model are unused
    CloudLighting lighting{};        // default Roettger under the default sun
    CloudTransferDesc transfer{};    // extinction, threshold and colours
    LodVolumeDesc volume{};          // origin, spacing, C, budget
    // Its maxLengthWorld is set to the longest tetrahedron edge of a root (sqrt(3) 2^rootLevel spacing);
    // LowAlbedo uses 2 scalar samples (its entries are affine in each scalar: exact).
    PreIntegrationDesc table{};
    // Default false: the generator's up (CloudDesc's z) is world z. True: it
    // is world y (y-up worlds); the grid is then cloud.dims.x x .z x .y
    // points, x fastest, and densities passed to setDensity use that layout.
    bool yUp = false;
};

class Cloud {
public:
    // Fails on a bad field in any desc (the message names it) or a sun that
    // is not a valid directional light.
    static Result<Cloud> create(const CloudCreateDesc& desc = {});

    // Relights when the lighting differs from the current one (any field), and
    // rebuilds the transfer table only when the colour terms changed (not for
    // a new sun direction). Fails, keeping the previous lighting, on a bad
    // lighting field.
    Status setLight(const CloudLighting& lighting);
    // Replaces the density (dims as created, values in [0, 1]) and relights.
    // Fails, changing nothing, on a size mismatch or a bad value.
    Status setDensity(std::vector<float> density);

    // Refines for the camera into out.tets (LodVolume::update); LowAlbedo
    // writes each vertex's scalar s = T phase(theta) / max phase, theta between
    // the sun's travel and the direction to the eye (for an orthographic
    // camera: against its forward). Fails as LodVolume::update.
    Status update(const Camera& camera, const LodRefineDesc& refine, LodFrame& out);

    const LodVolume& volume() const { return mVolume; }
    const TransferFunction& transfer() const { return mTransfer; }
    const PreIntegrationTable& table() const { return mTable; }
    const CloudLighting& lighting() const { return mLighting; }
    const std::vector<float>& density() const { return mDensity; }
    glm::ivec3 dims() const { return mDims; }
    // The sun's transmittance at each grid point from the last relight (x fastest).
    const std::vector<float>& sunTransmittance() const { return mTrans; }
    // The cloud's extinction sigma = maxExtinctionPerWorld f (f >= threshold,
    // else 0) as the field shadow tables read (lighting.hpp): one voxel per
    // grid point, opacity 1 - exp(-sigma spacing), so a ray through it loses
    // exp(-integral of sigma), the field falling to zero half a cell beyond the
    // outermost point with material as an effect's does. For both models (the
    // Roettger model's light-scaled length is not an extinction the scene
    // sees). Rebuilt with the density; empty for a cloud of air.
    const DensityField& densityField() const { return mField; }
    // Relights (sweep + LOD rebuild) and transfer-table builds since creation (create() does one of each).
    std::uint64_t relights() const { return mRelights; }
    std::uint64_t tableBuilds() const { return mTableBuilds; }
    // Bumped whenever the table changes (a GL pass re-uploads it).
    std::uint64_t tableVersion() const { return mTableBuilds; }

    // The lighting model's emission per unit extinction at a point with sun
    // transmittance T, seen along toEye (unit, world): what the tetrahedra
    // draw, as a double-precision reference.
    glm::dvec3 sourceAt(double sunTransmittance, glm::vec3 toEye) const;

private:
    Cloud() = default;
    Status relight();
    Status rebuildTable();
    Status rebuildField();
    CloudCreateDesc mDesc;
    CloudLighting mLighting;
    glm::ivec3 mDims{0};
    std::vector<float> mDensity, mTrans;
    LodVolume mVolume;
    DensityField mField;
    TransferFunction mTransfer;
    PreIntegrationTable mTable;
    float mPhaseMax = 1.0f;
    std::uint64_t mRelights = 0, mTableBuilds = 0;
};

} // namespace splatfx
