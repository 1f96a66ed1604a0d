// splatfx/lighting.hpp: lights, Henyey-Greenstein phase functions, low-albedo
// gas lighting per voxel, and self-shadowing by tracing or by a shadow table.
//
// Ebert & Parent 1990 ("Illumination of gaseous phenomena", "Shadowing of the
// gas", "Calculation of the shadow table"): a voxel's colour is its emission
// plus, for each light, the light reaching it (attenuated by the gas between
// it and the light) times a phase function of the angle between the light
// and the eye, times the albedo, plus an ambient term for the higher orders of
// scattering. The result is per-voxel RGB that becomes the splat's colour on
// the CPU, so the GL splat pass is unchanged. The density the light sees is
// the same optical depth the splat builder draws (docs/architecture.md,
// "Opacity follows the emission-absorption law"): log2 units throughout,
// transmittance = exp2(-depth).
//
// It does not draw anything, upload textures or shadow host geometry by
// itself: ShadowTable exports its array, dims and world-to-table matrix, and
// shadowGlsl() the GLSL include a host pass compiles (see docs/lighting.md).
//
//   auto field = splatfx::DensityField::fromGrid(grid);            // Result<DensityField>
//   splatfx::ShadowTables shadows;  shadows.update(*field, lights);  // rebuilt only on change
//   splatfx::lightVoxels(grid, eye, lights, &shadows, {}, colors);   // colors[i] per voxel
//
// Threading: plain values and objects; one thread at a time per object.
// const member functions may be called from several threads at once.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/color_table.hpp"
#include "splatfx/grid.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

// ---------------------------------------------------------------- [SECTION] lights

enum class LightType {
    Directional, // parallel rays along `direction` (the sun); irradiance `intensity`
    Point,       // from `position` in every direction; irradiance intensity / distance^2
    Spot,        // a point light limited to a cone around `direction`
};

// A light. Colours are linear RGB. A default Light is valid: a white sun
// shining straight down.
struct Light {
    LightType type = LightType::Directional; // default Directional
    glm::vec3 color{1.0f};                   // linear RGB, each >= 0; default white
    // Directional: irradiance on a surface facing the light. Point and spot:
    // radiant intensity, i.e. irradiance at 1 world unit (inverse-square
    // falloff). >= 0; default 1.
    float intensity = 1.0f;
    glm::vec3 direction{0.0f, -1.0f, 0.0f}; // where the light travels (directional; spot axis); non-zero, need not be unit; default down
    glm::vec3 position{0.0f};               // world position (point, spot); default origin
    float innerConeRad = 0.4f;              // spot: full intensity within this half-angle, [0, outer]; default 0.4
    float outerConeRad = 0.6f;              // spot: no light beyond this half-angle, (0, pi); default 0.6
    // Point and spot: the irradiance of a voxel closer than this (or than half
    // its voxel's size, whichever is larger) is that at this distance, so a
    // light inside the gas stays finite (with both 0, a point exactly at the
    // light takes it at 10^-12 units: huge, finite). >= 0, world units; default 0.
    float radiusWorld = 0.0f;

    static Light directional(glm::vec3 direction, glm::vec3 color = glm::vec3(1.0f), float intensity = 1.0f);
    static Light point(glm::vec3 position, glm::vec3 color = glm::vec3(1.0f), float intensity = 1.0f);
    static Light spot(glm::vec3 position, glm::vec3 direction, float innerConeRad, float outerConeRad, glm::vec3 color = glm::vec3(1.0f),
                      float intensity = 1.0f);
};

// Checks every field that matters for the light's type; the message names
// the field with `name` as prefix ("lights[2].intensity must be ...").
Status validateLight(const Light& light, const std::string& name = "light");

// ---------------------------------------------------------------- [SECTION] phase functions

// One Henyey-Greenstein lobe: g in (-1, 1) (> 0 scatters forward), weight >= 0.
struct HgLobe {
    float g = 0.0f;      // asymmetry, (-1, 1); default 0 (isotropic)
    float weight = 1.0f; // relative weight, >= 0; default 1
};

// A weighted sum of Henyey-Greenstein lobes (Blinn 1982, as used by Ebert &
// Parent 1990), normalized so the weights sum to 1 and the function
// integrates to 1 over the sphere. A default PhaseFunction is isotropic.
// Stored inline (no heap), so it is cheap to copy into descs.
class PhaseFunction {
public:
    static constexpr int kMaxLobes = 4;

    PhaseFunction() = default; // isotropic: one lobe, g = 0
    // Fails on no lobes, more than kMaxLobes, g outside (-1, 1) or not
    // finite, a negative or non-finite weight, or all weights zero; the
    // message names the lobe and field ("lobes[1].g must be in (-1, 1)").
    static Result<PhaseFunction> create(std::span<const HgLobe> lobes);

    // Per steradian. cosTheta is the cosine of the angle between the
    // direction the light travels and the direction towards the eye
    // (1: looking into the light). Clamped to [-1, 1]; NaN reads as 0.
    // Finite for |g| up to 1 - 1e-6: the denominator is evaluated in double
    // as (1 - g)^2 + 2 g (1 - cosTheta), which does not cancel.
    float operator()(float cosTheta) const;
    // The same for unit vectors: the direction the light travels and the
    // direction towards the eye. Near the peaks it keeps full precision,
    // which a float cosine cannot (1 - cos theta of 1e-3 rad is 5e-7, only 8
    // float steps below 1): 1 -+ cos theta are computed as |a -+ b|^2 / 2.
    float operator()(glm::vec3 lightTravel, glm::vec3 toEye) const;

    int lobeCount() const { return mCount; }
    HgLobe lobe(int i) const { return mLobes[std::size_t(i)]; } // weights normalized; expects 0 <= i < lobeCount()

    // One lobe, per steradian.
    static float henyeyGreenstein(float g, float cosTheta);

private:
    std::array<HgLobe, kMaxLobes> mLobes{};
    int mCount = 1;
};

// ---------------------------------------------------------------- [SECTION] shadow casters

// A volume that shadows others and the scene, as the shadow code reads it:
// its extinction (log2 units per world unit, 0 outside its box) and its
// optical depth along a segment, each exact for the caster's own model.
// DensityField is one (an effect's or a cloud's trilinear field); a ground
// fog layer is another (GroundFogCaster, volume.hpp: its continuous layer in
// closed form). ShadowTable::update and the Scene's volume shadows take either.
class ShadowCaster {
public:
    virtual ~ShadowCaster() = default;
    // Extinction at a world point, log2 units per world unit (0 outside).
    virtual float at(glm::vec3 world) const = 0;
    // Optical depth (log2 units) along the segment.
    virtual float opticalDepth(glm::vec3 fromWorld, glm::vec3 toWorld) const = 0;
    // From a world point to the light (to its position, or without end
    // towards a directional light).
    virtual float opticalDepthToLight(glm::vec3 world, const Light& light) const = 0;
    virtual bool empty() const = 0; // no material anywhere
    // World-space box outside which the extinction is zero.
    virtual glm::vec3 boundsMin() const = 0;
    virtual glm::vec3 boundsMax() const = 0;
    // Hash of everything the extinction depends on; equal casters, equal hashes.
    virtual std::uint64_t fingerprint() const = 0;

protected:
    ShadowCaster() = default;
    ShadowCaster(const ShadowCaster&) = default;
    ShadowCaster& operator=(const ShadowCaster&) = default;
};

// ---------------------------------------------------------------- [SECTION] density field

struct DensityFieldDesc {
    float opacityScale = 1.0f;              // as SplatStyle::opacityScale; default 1
    const ColorTable* colorTable = nullptr; // its alpha scales opacity, as in the splat builder; default none
};

// The gas's extinction as the light sees it: each voxel's optical depth
// through its centre, -log2(1 - opacity * tableAlpha) capped at 24 (as the
// splat builder), divided by the cube root of the voxel's world volume, is
// its extinction coefficient (log2 units per world unit); between lattice
// points the field is trilinear, and it falls linearly to zero one cell
// beyond the outermost voxels. A ray through a row of equal voxels thus
// gains the same depth per voxel as the splats drawn for them.
// Voxels sharing a cell add; voxels with non-finite data are skipped.
class DensityField final : public ShadowCaster {
public:
    DensityField() = default; // empty: no material anywhere
    // Fails when the cells' bounding box holds more than kMaxVoxels cells
    // or the transform / spacing is degenerate or not finite.
    static Result<DensityField> fromGrid(const Grid& grid, const DensityFieldDesc& desc = {});

    // Extinction at a world point, log2 units per world unit (0 outside).
    float at(glm::vec3 world) const override;
    // Optical depth (log2 units) along the segment, exact for the trilinear
    // field up to float rounding: the segment is split where it crosses
    // lattice planes, and on each piece the field is a cubic in the ray
    // parameter, which Simpson's rule integrates exactly.
    float opticalDepth(glm::vec3 fromWorld, glm::vec3 toWorld) const override;
    // From a world point to the light (to its position, or out of the
    // field for a directional light). The shadow-tracing reference.
    float opticalDepthToLight(glm::vec3 world, const Light& light) const override;

    bool empty() const override { return mValues.empty(); }
    // World-space box outside which the field is zero (empty: a zero box at the origin).
    glm::vec3 boundsMin() const override { return mBoundsMin; }
    glm::vec3 boundsMax() const override { return mBoundsMax; }
    // Hash of everything the field's values depend on; equal fields, equal hashes.
    std::uint64_t fingerprint() const override { return mFingerprint; }
    // Cube root of a voxel's world volume.
    float voxelSizeWorld() const { return mVoxelSize; }

private:
    float lattice(glm::vec3 cell) const; // trilinear in padded-lattice coordinates, depth per cell
    std::vector<float> mValues;          // per cell of the padded lattice, x fastest, depth per voxel (log2)
    glm::ivec3 mDims{0};                 // padded: one zero cell each side
    glm::vec3 mOrigin{0.0f};             // lattice coordinate of mValues[0]
    glm::mat4 mWorldToLattice{1.0f};
    float mInvVoxelSize = 0.0f, mVoxelSize = 0.0f;
    glm::vec3 mBoundsMin{0.0f}, mBoundsMax{0.0f};
    std::uint64_t mFingerprint = 0;
};

// ---------------------------------------------------------------- [SECTION] shadows

// Gives each voxel's transmittance towards light number `light` (the index
// into the span passed to lightVoxels), in [0, 1].
class ShadowProvider {
public:
    virtual ~ShadowProvider() = default;
    virtual float transmittance(std::size_t light, glm::vec3 world) const = 0;
};

// The reference: traces from each point to each light through the field
// (DensityField::opticalDepthToLight). Keeps a pointer to the field and a
// copy of the lights: the field must outlive it.
class ShadowTracer final : public ShadowProvider {
public:
    ShadowTracer(const DensityField& field, std::span<const Light> lights) : mField(&field), mLights(lights.begin(), lights.end()) {}
    float transmittance(std::size_t light, glm::vec3 world) const override;

private:
    const DensityField* mField;
    std::vector<Light> mLights;
};

struct ShadowTableDesc {
    glm::ivec3 dims{64};                           // entries per axis, each in [1, 1024]; default 64^3
    std::uint64_t memoryBudgetBytes = 64ull << 20; // table plus build scratch (memoryBytes); default 64 MiB
};

// Ebert & Parent 1990's reduced-resolution shadow table: accumulated optical
// depth from each table node to one light, on a world-axis-aligned lattice
// covering the field. Nodes are filled in increasing distance from the light
// (along the light direction for a directional light); each node's value is
// the bilinear interpolation of the already-filled nodes on the face of its
// neighbour cube that the ray to the light pierces, plus the depth of that
// step (trapezoid rule on the sampled density). A light inside the table is
// allowed: nodes within 8 node steps of a point light are traced straight
// to it through the field, where one step spans too wide an angle for the
// face interpolation. For a directional light an axis sweep from the
// light's side replaces the sort (it is already a valid distance order); a
// point light's sorted order is kept while the light and box stay put.
// The error is first order in the node spacing; docs/lighting.md gives it
// against tracing for 16^3 to 128^3 tables.
//
// Lookups are trilinear. A point outside the table is first moved along its
// ray to the light to where the ray meets the table (there is no material in
// between), and one whose ray misses the table is unshadowed; the GLSL in
// shadowGlsl() does the same, so the table shadows host geometry too.
class ShadowTable {
public:
    explicit ShadowTable(const ShadowTableDesc& desc = {}) : mDesc(desc) {}

    // Builds the table, unless the field's fingerprint, the light and the
    // desc equal those of the last successful build (then counts a reuse).
    // Fails on a bad desc (the message names the field), a bad light, or a
    // table whose memoryBytes exceed the budget; the table is then emptied.
    Status update(const DensityField& field, const Light& light);
    // The same for several fields seen as one (their extinctions add; the
    // table covers the union of their supports): one table per light for
    // every effect of a frame, for shadows on the scene. Fails on a null
    // pointer. The fingerprint combines the fields' in order.
    Status update(std::span<const DensityField* const> fields, const Light& light);
    // The same for any shadow casters (a ground fog layer among the fields:
    // GroundFogCaster); the nodes sample each caster's at(), the nodes near a
    // point light trace its opticalDepth(). Fails on a null pointer.
    Status update(std::span<const ShadowCaster* const> casters, const Light& light);

    // Accumulated optical depth towards the light (log2 units), and exp2(-depth).
    float opticalDepth(glm::vec3 world) const;
    float transmittance(glm::vec3 world) const { return std::exp2(-opticalDepth(world)); }

    // ---- What a GL pass uploads (see shadowGlsl()):
    // dims().x * dims().y * dims().z floats, x fastest then y then z: the
    // optical depth at each node, in log2 units. Upload as a GL_R32F 3D
    // texture, GL_LINEAR filtering, GL_CLAMP_TO_EDGE.
    const std::vector<float>& data() const { return mDepth; }
    glm::ivec3 dims() const { return mDims; }
    // World to the table's box [0, 1]^3; node i along an axis of n nodes sits
    // at i / (n - 1) (n = 1: at 0.5), i.e. at texture coordinate
    // (u * (n - 1) + 0.5) / n.
    glm::mat4 worldToTable() const { return mWorldToTable; }
    // The light in table space: xyz = position with w = 1 (point, spot), or
    // xyz = direction the light travels with w = 0 (directional).
    glm::vec4 lightInTable() const { return mLightInTable; }

    // Successful builds and reuses since construction.
    std::uint64_t builds() const { return mBuilds; }
    std::uint64_t reuses() const { return mReuses; }

    // Bytes a build of these dims needs: 4 per node for the table, 4 for the
    // sampled density, 8 for the fill order, 1 for the filled flags.
    static std::uint64_t memoryBytes(glm::ivec3 dims);

private:
    float lookup(glm::vec3 u) const; // trilinear at table coordinates in [0, 1]^3
    ShadowTableDesc mDesc;
    std::vector<float> mDepth, mRho;
    std::vector<std::uint64_t> mOrder;
    std::vector<std::uint8_t> mFilled;
    glm::ivec3 mDims{0};
    glm::mat4 mWorldToTable{1.0f};
    glm::vec4 mLightInTable{0.0f, -1.0f, 0.0f, 0.0f};
    bool mValid = false;
    std::uint64_t mFingerprint = 0;
    Light mLight{};
    glm::ivec3 mBuiltDims{0};
    // What the cached fill order was sorted for: light position or direction, kind, box.
    glm::vec3 mOrderKey{0.0f}, mOrderBoxMin{0.0f}, mOrderBoxMax{0.0f};
    int mOrderType = -1;
    std::uint64_t mBuilds = 0, mReuses = 0, mNearTraced = 0;
};

// One shadow table per light, as a ShadowProvider.
class ShadowTables final : public ShadowProvider {
public:
    explicit ShadowTables(const ShadowTableDesc& desc = {}) : mDesc(desc) {}
    // Updates table i for lights[i] (each rebuilt only on change); tables
    // beyond lights.size() are dropped. The message names the light.
    Status update(const DensityField& field, std::span<const Light> lights);
    // The same, but table i is left as it was (not built, not counted) where
    // reaches[i] is false: a light that cannot reach the field (a spot whose
    // cone misses it) gives it no irradiance, so its transmittance is never
    // used. Expects reaches.size() == lights.size().
    Status update(const DensityField& field, std::span<const Light> lights, const std::vector<bool>& reaches);
    float transmittance(std::size_t light, glm::vec3 world) const override;
    const std::vector<ShadowTable>& tables() const { return mTables; }

private:
    ShadowTableDesc mDesc;
    std::vector<ShadowTable> mTables;
};

// How many lights shadow the scene at once (SceneShadowDesc::maxLights,
// Frame::shadows(), the slots of shadowGlsl()).
inline constexpr int kMaxShadowLights = 4;

// The GLSL include a host's surface shader compiles (GLSL 4.50 core, no
// #version line). Slot 0: uniforms splatfx_shadowTable (sampler3D: data()),
// splatfx_worldToTable (mat4: worldToTable()) and splatfx_shadowLight (vec4:
// lightInTable()); slots 1 to kMaxShadowLights - 1 the same names suffixed
// 1, 2, 3; splatfx_shadowLightIndex[kMaxShadowLights] (int: the scene light
// each slot's table is for, -1 none). And
//   float splatfx_shadow(vec3 worldPos);              // slot 0's table, [0, 1]
//   float splatfx_shadowTo(int light, vec3 worldPos); // towards scene light `light`; 1 without a table
// which match ShadowTable::transmittance up to the texture unit's filtering precision.
// The text is the SDK's GLSL file shadow.glsl, embedded at build time.
std::string shadowGlsl();

// ---------------------------------------------------------------- [SECTION] lighting

struct GasLightingDesc {
    PhaseFunction phase{}; // default isotropic
    float albedo = 0.5f;   // scattered fraction of extinction, [0, 1]; default 0.5
    // Weight of the voxel's own colour as emitted light: fire 1, smoke and
    // steam 0. >= 0; default 0.
    float emission = 0.0f;
    // High-albedo approximation (the paper's ambient term for second and
    // higher order scattering): each light also reaches every voxel
    // unshadowed and isotropically with this fraction of its irradiance.
    // >= 0; default 0 (pure low-albedo single scattering).
    float multipleScattering = 0.0f;
    glm::vec3 ambient{0.0f}; // uniform environment light (linear RGB, >= 0) scattered by the albedo; default black
    // Base colours: the table at each voxel's colour coordinate (as the
    // splat builder). Null: white, so the output is a factor to multiply
    // the splat's colour by. Default null.
    const ColorTable* colorTable = nullptr;
};

// Lit colour of every voxel, seen from eyeWorld:
//   out[v] = base(v) * (emission
//            + albedo * (ambient + sum_i color_i E_i(v) (4 pi phase(cos theta_i) T_i(v) + multipleScattering)))
// where E_i is light i's irradiance at the voxel (inverse-square and cone
// for point and spot lights), T_i the transmittance from `shadows` (1 when
// null) and theta_i the angle between the light's travel and the eye. The
// 4 pi makes an isotropic gas of albedo 1 under a white light of intensity 1
// show exactly its base colour, as engines expect of "intensity".
// A light closer to a voxel than half its size lights it isotropically.
// Linear RGB, not clamped (may exceed 1). out is resized to
// grid.voxels.size(); it allocates only when out's capacity is too small.
// O(voxels x lights). Voxels with non-finite data get 0.
// Fails (out untouched) on a bad light or desc; the message names the field.
Status lightVoxels(const Grid& grid, glm::vec3 eyeWorld, std::span<const Light> lights, const ShadowProvider* shadows, const GasLightingDesc& desc,
                   std::vector<glm::vec3>& out);

// The same model at arbitrary world points (a frame's splat centres): the
// base colour is white (desc.colorTable is ignored), so out[i] is the factor
// to multiply point i's colour by. voxelSizeWorld (>= 0) is the size of the
// voxel each point stands for: a point or spot light closer than half of it
// lights the point isotropically, as in lightVoxels. Scene uses it to light
// the splats of lit effects (scene.hpp, EffectLighting).
Status lightPoints(std::span<const glm::vec3> worldPoints, float voxelSizeWorld, glm::vec3 eyeWorld, std::span<const Light> lights,
                   const ShadowProvider* shadows, const GasLightingDesc& desc, std::vector<glm::vec3>& out);

} // namespace splatfx
