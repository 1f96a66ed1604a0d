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
// More lights (LowAlbedo only: CloudLighting::lights, up to kMaxCloudLights
// directional, point or spot lights beside the sun): each has its own
// transmittance at every grid point (a directional one swept as the sun; a
// point or spot light's rays converge, so each grid point is traced toward it
// through the cloud's trilinear extinction, DensityField's exact segment
// integral, inside the grid's box: light enters at the grid's faces as the
// sun's does), and the source sums them as lightPoints does (irradiance
// 1/d^2 capped at max(radiusWorld, spacing / 2), the spot's cone, the HG
// phase per light, multipleScattering per light). When every lit light (the
// sun included; one of zero colour or intensity is left out) shares one
// chromaticity the tetrahedra carry one scalar per vertex; lights of
// different colours (a torch's orange under a white sun) give each vertex an
// RGB source instead (LodFrame::rgb, drawn per channel by the tetrahedra
// pass: 48 more bytes per tetrahedron, three table lookups a segment). Points
// a spot's cone leaves dark are not traced, and a light of zero intensity not
// at all (lightTraces() counts the traced points).
//
// Layout (volume.hpp): Roettger is CloudModel::DensityTableLightLength
// (scalar f, length scale gamma); LowAlbedo is CloudModel::LightTableDensityLength's
// layout (scalar T, length scale sigma / maxExtinctionPerWorld), drawn with
// the transfer kappa(s) = A + B s, rho = maxExtinctionPerWorld, where update()
// writes s = T phase(theta) / max phase at each vertex: pre-integration is
// exact for a colour affine in s, so the per-vertex phase costs no table.
//
// Shadows of other volumes (setLight's casters: effects' DensityFields,
// other clouds' fields, GroundFogCasters): each grid point's transmittance
// towards each light, the sun's included, is its own one times
// exp2(-depth), depth the sum of the casters' opticalDepthToLight from the
// point (to the light's position, or without end toward a directional one),
// summed over the casters whose box the point's ray to the light meets; a
// caster whose box cannot shadow the grid for a light (Scene::shadowFallsOn)
// is never traced for it. When only the casters change (a plume simulated,
// moved), only the grid points whose ray meets a changed caster's old or new
// box are traced again (receivePoints(), receiveTraces() count them), with
// the same sum, so the result equals a full relight bit for bit; the LOD
// fields are then rebuilt whole (LodVolume has no partial rebuild; see
// docs/BENCHMARKS.md "Cloud relighting" for what that costs). The Roettger
// model receives through its T as well (gamma = ambient + diffuse T).
//
// It does NOT: draw (the tetrahedra go to the projected-tetrahedra pass), or
// light the Roettger model with anything but the sun (its gamma = ambient +
// diffuse T is a bounded sun term, not an irradiance). It casts through
// densityField(): a Scene puts a lit cloud's field into the scene shadow and
// traces the light of its lit effects and other lit clouds through it (scene.hpp).
//
//   auto cloud = splatfx::Cloud::create({.cloud = {.dims = {65, 65, 17}}});
//   splatfx::CloudLighting L = cloud->lighting();
//   L.sun = splatfx::Light::directional({-1, -0.2f, -0.3f});
//   cloud->setLight(L);                                                 // relights once
//   cloud->update(camera, {}, frame);                                   // frame.tets
//
// Threading: one thread at a time.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "splatfx/lighting.hpp"
#include "splatfx/volume.hpp"

namespace splatfx {

enum class CloudLightModel {
    Roettger,  // sec. 5.2: gamma = ambient + diffuse T scales the length (default)
    LowAlbedo, // Ebert & Parent 1990 single scattering with HG lobes and self-shadowing
};

// How a cloud is lit. Which fields apply depends on the model.
// How many lights a cloud takes beside its sun (CloudLighting::lights).
inline constexpr int kMaxCloudLights = 4;

struct CloudLighting {
    CloudLightModel model = CloudLightModel::Roettger; // default Roettger
    // The sun: a directional light; its direction is where the light travels.
    // Default: travelling down (-z) and a little sideways, the direction
    // CloudDesc's default sunDirection points back to.
    Light sun = Light::directional({-0.3f, -0.2f, -1.0f});
    // LowAlbedo only: up to kMaxCloudLights more lights (directional, point,
    // spot), summed with the sun, of any colours (set the sun's intensity to
    // 0 to light by these alone). Lights whose colours are multiples of one
    // another draw one scalar per vertex; others an RGB source per vertex
    // (update()). Default none (the sun alone, as before).
    std::vector<Light> lights{};
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
    // What setLight checks, without a cloud: every field, and the lights' count
    // and kind for the model. The message names the field.
    static Status validateLighting(const CloudLighting& lighting);

    // Relights when the lighting differs from the current one (any field), and
    // rebuilds the transfer table only when the colour terms changed (not for
    // a new sun direction). With lights beside the sun, any change of a light
    // relights and rebuilds the table (the scalar's scale is the largest
    // source over the grid); a light's transmittance is traced again only when
    // its position, direction, type, cone or radius, or the density, changed.
    // `casters` are the other volumes that shadow the cloud (not its own
    // densityField(): its self-shadowing is its own); the cloud keeps their
    // fingerprints and boxes, not the pointers, so every call names them all
    // (none: the cloud receives no shadow). When only the casters changed,
    // only the grid points under a changed caster's old or new box are traced
    // again (restrictedRelights(), receivePoints()); a changed caster whose
    // box cannot shadow the cloud costs nothing.
    // Fails, keeping the previous lighting, on a bad lighting field (the
    // message names it: "CloudLighting.lights[1].color ..."), a null caster
    // or the cloud's own field among the casters ("Cloud::setLight: casters[0] ...").
    // A failure after the checks (none is known) forgets the casters: the
    // next call traces them all again.
    Status setLight(const CloudLighting& lighting, std::span<const ShadowCaster* const> casters = {});
    // Replaces the density (dims as created, values in [0, 1]) and relights.
    // The casters' shadows of the last setLight are kept (they do not depend
    // on the cloud's density). Fails, changing nothing, on a size mismatch or a bad value.
    Status setDensity(std::vector<float> density);

    // Refines for the camera into out.tets (LodVolume::update); LowAlbedo
    // writes each vertex's scalar s = T phase(theta) / max phase, theta between
    // the sun's travel and the direction to the eye (for an orthographic
    // camera: against its forward). With lights beside the sun the stored
    // field is u = sum_i w_i E_i (4 pi maxPhase T_i + m) / scale (w_i the
    // light's share of the common colour, E_i its irradiance factor) and each
    // vertex gets s = u R, R = sum_i w_i E_i (4 pi phase_i T_i + m) / sum_i
    // w_i E_i (4 pi maxPhase T_i + m) at the vertex (lightPoints, T_i
    // trilinear between grid points): O(vertices x lights) per frame. With
    // lights of different colours (w_i then the light's largest channel) it
    // also writes out.rgb, s_c = u R_c with R_c = sum_i c_i,c E_i (4 pi
    // phase_i T_i + m) / the same denominator (c_i the light's colour x
    // intensity), drawn per channel as kappa_c(s_c), and the scalar max_c s_c;
    // otherwise out.rgb is left empty. Fails as LodVolume::update.
    Status update(const Camera& camera, const LodRefineDesc& refine, LodFrame& out);

    const LodVolume& volume() const { return mVolume; }
    const TransferFunction& transfer() const { return mTransfer; }
    const PreIntegrationTable& table() const { return mTable; }
    const CloudLighting& lighting() const { return mLighting; }
    const std::vector<float>& density() const { return mDensity; }
    glm::ivec3 dims() const { return mDims; }
    // The sun's transmittance at each grid point from the last relight (x
    // fastest): through the cloud's own density times exp2(-receivedDepth(0)).
    const std::vector<float>& sunTransmittance() const { return mTrans; }
    // Towards lighting().lights[i] at each grid point (x fastest), from the
    // last relight (times exp2(-receivedDepth(i + 1))); empty for a light that
    // lights nothing (zero colour or intensity); 0 where a spot's cone leaves
    // a point dark (not traced). Expects i < lighting().lights.size().
    const std::vector<float>& lightTransmittance(std::size_t i) const { return mLightT[i].trans; }
    // The casters' optical depth (log2 units) at each grid point (x fastest)
    // towards light `slot` (0 the sun, 1 + i lighting().lights[i]); empty for
    // a light that lights nothing or a slot beyond the lights.
    const std::vector<float>& receivedDepth(std::size_t slot) const;
    // Grid points whose received depth was computed again, per light, since
    // creation (a light's first or new depths with no caster able to shadow
    // the cloud count none: they are zero); and the casters'
    // opticalDepthToLight calls those made (only casters whose box the
    // point's ray meets are traced).
    std::uint64_t receivePoints() const { return mReceivePoints; }
    std::uint64_t receiveTraces() const { return mReceiveTraces; }
    // setLight calls that only the casters changed and that traced at least
    // one point again (each rebuilds the LOD fields, not the sweep).
    std::uint64_t restrictedRelights() const { return mRestrictedRelights; }
    // With lights beside the sun: the largest source over the grid that the
    // scalar's 1 stands for (sum_i w_i E_i (4 pi maxPhase T_i + m)); 0 without.
    // w_i: the light's share of the common colour, or its largest channel
    // when the lights' colours differ (the colour scale is then white).
    float lightScale() const { return mLightScale; }
    // Grid points traced toward point and spot lights since creation.
    std::uint64_t lightTraces() const { return mLightTraces; }
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
    // For the sun alone (lighting().lights empty).
    glm::dvec3 sourceAt(double sunTransmittance, glm::vec3 toEye) const;

private:
    // One of CloudLighting::lights: its transmittance and what it was traced for.
    struct LightState {
        std::vector<float> own, trans; // through the cloud alone; times the casters' shadow
        Light tracedFor{};
        bool valid = false;
    };
    // The casters' depth towards one light (Cloud::receive), and what it was traced for.
    struct Received {
        std::vector<float> depth;
        Light tracedFor{};
        bool valid = false;
    };
    // What the received depths were traced for: one per caster of the last setLight.
    struct CasterRecord {
        std::uint64_t print = 0;
        glm::vec3 lo{0.0f}, hi{0.0f};
        bool empty = true;
        bool operator==(const CasterRecord&) const = default;
    };
    Cloud() = default;
    // own: the cloud's own transmittances again (the sweep, traceLights);
    // casters: the received depths for them (null: kept as they are).
    Status relight(bool own = true, const std::span<const ShadowCaster* const>* casters = nullptr);
    bool receive(std::span<const ShadowCaster* const> casters, std::vector<std::uint8_t>& changed);
    void compose(const std::vector<std::uint8_t>* changed);
    Status buildField(const std::vector<std::uint8_t>* changed);
    bool sameCasters(std::span<const ShadowCaster* const> casters) const;
    void forgetCasters();
    Status traceLights();
    std::vector<Light> unitLights(float scale, std::vector<const std::vector<float>*>* trans = nullptr, bool coloured = false) const;
    Status applyLightPhases(const Camera& camera, LodFrame& out);
    glm::vec3 gridPoint(glm::ivec3 p) const;
    Status rebuildTable();
    Status rebuildField();
    CloudCreateDesc mDesc;
    CloudLighting mLighting;
    glm::ivec3 mDims{0};
    std::vector<float> mDensity, mTrans, mSunOwn; // mTrans = mSunOwn x the casters' shadow
    std::vector<Received> mRecv;                  // 0 the sun, 1 + i lights[i]
    std::vector<CasterRecord> mCasters;
    std::vector<float> mSource;                   // with lights beside the sun: the source per grid point before scaling
    LodVolume mVolume;
    DensityField mField;
    TransferFunction mTransfer;
    PreIntegrationTable mTable;
    float mPhaseMax = 1.0f;
    std::vector<LightState> mLightT;
    glm::vec3 mLightColour{0.0f}; // the common colour x intensity the weights are shares of
    float mLightScale = 0.0f;
    bool mRgb = false; // lights of different colours: an RGB source per vertex (LodFrame::rgb)
    std::vector<glm::vec3> mVertexScratch, mSeenScratch, mBoundScratch; // update(): reused per frame
    std::uint64_t mRelights = 0, mTableBuilds = 0, mLightTraces = 0;
    std::uint64_t mReceivePoints = 0, mReceiveTraces = 0, mRestrictedRelights = 0;
};

} // namespace splatfx
