// splatfx/volume.hpp: view-dependent LOD volumes as tetrahedra, after
// Roettger & Ertl 2002, "Fast Volumetric Display of Natural Gaseous Phenomena".
//
// A regular scalar field is held as an implicit octree (sec. 2.1). Every frame
// LodVolume::update refines it top-down where the screen-space error asks
// (eq. 1), morphs the new vertices between levels (sec. 3, eqs. 6-8) and emits
// a flat list of tetrahedra in back-to-front order, frustum-culled, with
// transparent nodes dropped by the zero-opacity test (sec. 4.1) and the
// tetrahedra cut by the near plane clipped as volumes (sec. 4.3). The
// pre-integration table (sec. 4, [35]) for a 1D transfer function is built
// here for upload as a 3D texture; exact double-precision integrators (one
// segment, one ray through the finest mesh) are the references. GroundFog
// (sec. 6) is a fog layer of prisms over a terrain height field, at full
// resolution or over the paper's view-dependent LOD terrain with the fog top
// geomorphed (GroundFogDesc::lod).
//
// It does NOT: draw anything (no GL here; the projected-tetrahedra pass reads
// LodFrame::tets and PreIntegrationTable::data()), or model anisotropic scattering (the light field is precomputed, sec. 5).
//
//   auto vol = splatfx::LodVolume::create(*splatfx::makeCloudVolume({}), {});
//   splatfx::LodFrame frame;
//   vol->update(camera, {.detailC = 10}, &transfer, frame); // frame.tets back to front
//
// Threading: TransferFunction, PreIntegrationTable and ScalarVolume are plain
// values (const methods thread-safe). A LodVolume is used by one thread at a
// time: update() writes its per-frame morph state; the const functions
// (integrateRay, sampleFinest) may run concurrently with each other but not
// with update().
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <span>

#include "splatfx/camera.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/motion.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

// -----------------------------------------------------------------------------
// [SECTION] Transfer function and pre-integration
// -----------------------------------------------------------------------------

// One control point of a piecewise-linear 1D transfer function.
struct TransferPoint {
    float scalar = 0.0f;             // in [0, 1]; points sorted ascending; two points at one scalar make a step
    glm::vec3 color{1.0f};           // chromaticity kappa (emission per unit extinction), linear RGB
    float extinctionPerWorld = 0.0f; // optical density rho, per world unit, >= 0
};

// Colour and extinction as piecewise-linear functions of the scalar, clamped
// to the end points outside [first, last]. The volume-density optical model
// (Williams & Max 1992, [46]): emission = color * extinction.
class TransferFunction {
public:
    // Fails on no points, non-finite values, scalars outside [0, 1] or not
    // ascending, or negative extinction; the message names the point.
    static Result<TransferFunction> create(std::vector<TransferPoint> points);

    // A NaN scalar has no material: colour and extinction 0.
    glm::dvec3 color(double scalar) const;
    double extinction(double scalar) const;
    // Exact: is extinction zero everywhere on [lo, hi]? (the zero-opacity
    // test, sec. 4.1, done on the function itself so it is conservative).
    bool zeroOpacity(double lo, double hi) const;
    const std::vector<TransferPoint>& points() const { return mPoints; }

private:
    std::vector<TransferPoint> mPoints;
};

// The exact integral of one ray segment through a tetrahedron (Williams & Max
// 1992): the scalar goes linearly from `frontScalar` (eye side) to
// `backScalar` over `lengthWorld`, the extinction is multiplied by a length
// scale going linearly from `frontLengthScale` to `backLengthScale` (the
// modified PT, eq. 9: l' = l f / f_max). Returns premultiplied RGBA (alpha =
// 1 - transmittance), composited with "over". Double precision, numerical:
// the segment is split at the transfer function's control points and into
// sub-steps of optical depth <= 1/4, each integrated by 5-point Gauss-Legendre
// (relative error ~1e-12); it stops once transmittance < 1e-18.
// Non-finite or negative lengths count as 0; +inf as 1e30 (fully saturated).
glm::dvec4 integrateSegment(const TransferFunction& transfer, double frontScalar, double backScalar, double lengthWorld,
                            double frontLengthScale = 1.0, double backLengthScale = 1.0);

struct PreIntegrationDesc {
    int scalarResolution = 64;   // default 64 (the paper's 64x64x128): samples along front and back scalar
    int lengthResolution = 128;  // default 128: samples along the segment length
    float maxLengthWorld = 1.0f; // default 1: the length of the last slice; set it to the longest segment drawn
};

// A 3D table of RGBA over (front scalar, back scalar, segment length) (Roettger
// et al. 2000 [35]; sec. 4 of the paper). Texel (i, j, k) holds
// integrateSegment(s_i, s_j, l_k) with s_i = i / (scalarResolution - 1) and
// l_k = k / (lengthResolution - 1) * maxLengthWorld, so a GL sampler reads it
// at texture coordinate (s * (n - 1) + 0.5) / n along each axis.
class PreIntegrationTable {
public:
    // Fails on resolutions < 2 or > 1024, or a non-positive/non-finite maxLengthWorld.
    static Result<PreIntegrationTable> create(const TransferFunction& transfer, const PreIntegrationDesc& desc = {});

    // RGBA floats, front scalar fastest, then back scalar, then length.
    const std::vector<float>& data() const { return mData; }
    glm::ivec3 dims() const { return mDims; }
    float maxLengthWorld() const { return mMaxLength; }
    std::size_t bytes() const { return mData.size() * sizeof(float); }

    // Trilinear lookup (scalars clamped to [0, 1]). Lengths beyond
    // maxLengthWorld are split into equal pieces (the scalar is linear, so
    // each piece is a segment too) composited front to back, up to 2^16 pieces.
    glm::vec4 lookup(float frontScalar, float backScalar, float lengthWorld) const;
    // The paper's table form of the zero-opacity test: the entry at
    // (floor((n-1) lo), ceil((n-1) hi), m-1) is zero. (The paper floors both;
    // ceil on hi keeps the test conservative.)
    bool zeroOpacity(float lo, float hi) const;

private:
    glm::vec4 texel(int i, int j, int k) const;
    glm::vec4 lookupInRange(float sf, float sb, float l) const;
    std::vector<float> mData;
    glm::ivec3 mDims{0};
    float mMaxLength = 1.0f;
};

// -----------------------------------------------------------------------------
// [SECTION] Input field
// -----------------------------------------------------------------------------

// A regular grid of scalars in [0, 1] (x fastest, then y, then z), with an
// optional second field that scales the segment length (eq. 9; for clouds the
// light intensity gamma of sec. 5.2, or f / f_max for sec. 5.1). Both drive
// the simplification (sec. 5: "the maximum deviation of both scalar fields").
struct ScalarVolume {
    glm::ivec3 dims{0};
    std::vector<float> scalar;      // dims.x * dims.y * dims.z values, the transfer function's coordinate
    std::vector<float> lengthScale; // empty (= 1 everywhere) or the same size, in [0, 1]
};

// -----------------------------------------------------------------------------
// [SECTION] The LOD volume
// -----------------------------------------------------------------------------

enum class DeltaMode {
    Max,     // the paper's recommendation against popping (sec. 3)
    Average, // the definition of sec. 2.2
};

struct LodVolumeDesc {
    glm::vec3 originWorld{0.0f};                          // default (0,0,0): world position of grid point (0,0,0)
    float spacingWorld = 1.0f;                            // default 1: world distance between grid points
    int rootLevel = 0;                                    // default 0 = auto: roots are cubes of 2^rootLevel cells (see LodVolume)
    float minAccuracyC = 4.0f;                            // default 4: C of eq. 1 (> sqrt(3), as eq. 4 needs); fixes K_max of eq. 4 at build time
    DeltaMode delta = DeltaMode::Max;                     // default Max
    float padValue = 0.0f;                                // default 0: value of the points added by padding (both fields)
    std::size_t memoryBudgetBytes = std::size_t(1) << 30; // default 1 GiB: create() fails beyond it
};

// Per-frame refinement settings.
struct LodRefineDesc {
    float detailC = 10.0f;       // default 10: c of eq. 1 (per unit scalar deviation); higher is finer (docs/volume.md: count vs error)
    bool morph = true;           // default true: volumetric morphing (sec. 3); false pops between levels
    bool frustumCull = true;     // default true: hierarchical view-frustum culling (sec. 4.2)
    bool zeroOpacityTest = true; // default true: drop nodes and tetrahedra of zero opacity (sec. 4.1); needs a transfer function
    bool clipNear = true;        // default true: volumetric clipping at the near plane (sec. 4.3)
};

// One emitted tetrahedron: world positions, scalars and length scales at its
// four vertices, positively oriented (dot(p1-p0, cross(p2-p0, p3-p0)) > 0).
struct Tetrahedron {
    std::array<glm::vec3, 4> position{};
    std::array<float, 4> scalar{};
    std::array<float, 4> lengthScale{};
};

struct LodFrameStats {
    std::uint64_t emitted = 0;          // tetrahedra in LodFrame::tets
    std::uint64_t fullResolution = 0;   // 5 per cell of the finest level
    std::uint64_t clippedInput = 0;     // tetrahedra cut by the near plane
    std::uint64_t clippedExtra = 0;     // tetrahedra added by clipping (prisms are three)
    std::uint64_t nodesRefined = 0;     // octree nodes split this frame
    std::uint64_t nodesCulled = 0;      // subtrees dropped by the frustum
    std::uint64_t nodesTransparent = 0; // subtrees dropped by the zero-opacity test
    std::uint64_t tetsTransparent = 0;  // single tetrahedra dropped by the zero-opacity test
};

struct LodFrame {
    std::vector<Tetrahedron> tets; // back to front for the camera of the update
    LodFrameStats stats;
    // A source colour per vertex, for a transfer kappa(s) = A + B s whose
    // extinction does not depend on s (a LowAlbedo Cloud lit by lights of
    // different colours, cloud.hpp): empty (one scalar, the default), or one
    // entry per tets entry, channel c of vertex k drawn as kappa_c(rgb[i][k][c])
    // (pre-integration stays exact: affine per channel). 48 bytes a
    // tetrahedron beside its 80; tets[i].scalar then holds each vertex's
    // largest channel. Producers that write one scalar clear it.
    std::vector<std::array<glm::vec3, 4>> rgb;
};

// The octree over a grid of (R.x 2^n + 1) x (R.y 2^n + 1) x (R.z 2^n + 1)
// points: R roots (a forest, so a 513x513x65 field is 8x8x1 roots of n = 6)
// each an implicit octree of (2^n + 1)^3 points (sec. 2.1). Other sizes are
// padded with padValue up to the next such size (never resampled). Nodes are
// never stored as objects: a node of level L (2^L cells wide) at node
// coordinates X is the cube [X 2^L, (X+1) 2^L]; its centre grid point keys
// its error Delta (16 bits) and morph state e' (8 bits), as in the paper.
// Leaves are split in five tetrahedra, the centre one on the corners of even
// (X + corner) parity, so neighbours alternate (Fig. 1) and every face
// diagonal of every level runs between even-parity corners (conforming).
//
// Storage: 1 byte per grid point per field (8-bit scalars) plus, per node of
// level >= 1 (about 1/7 of the points), 2 bytes Delta + 1 byte e' + 2 bytes
// scalar range (for the zero-opacity test): ~1.71 bytes per point with one
// field, ~2.71 with two (the paper: 4). memoryBytes() is exact.
class LodVolume {
public:
    // Fails on empty or non-finite data, values outside [0, 1], a dims/data
    // size mismatch, fewer than 2 points along an axis, a bad desc field, or
    // a volume above desc.memoryBudgetBytes (the message gives both numbers).
    static Result<LodVolume> create(const ScalarVolume& field, const LodVolumeDesc& desc = {});
    // The bytes create() would keep for a field of `dims` (after padding).
    static std::size_t bytesFor(glm::ivec3 dims, bool hasLengthScale, int rootLevel = 0);

    // Refine for `camera`, morph, and emit the frame's tetrahedra into `out`
    // (cleared first). `transfer` may be null when refine.zeroOpacityTest is
    // false. Fails on a non-finite camera or a bad refine field.
    Status update(const Camera& camera, const LodRefineDesc& refine, const TransferFunction* transfer, LodFrame& out);

    // K_max of eq. 4 for this volume's C.
    double kMax() const { return mKMax; }
    int rootLevel() const { return mRootLevel; }
    glm::ivec3 roots() const { return mRoots; }
    glm::ivec3 pointDims() const { return mDims; } // after padding
    glm::vec3 originWorld() const { return mOrigin; }
    float spacingWorld() const { return mSpacing; }
    float minAccuracyC() const { return mC; }
    // The world box of the (padded) grid: every tetrahedron update() emits lies in it.
    Aabb boundsWorld() const { return {mOrigin, mOrigin + glm::vec3(mDims - 1) * mSpacing}; }
    bool hasLengthScale() const { return !mLength.empty(); }
    std::size_t memoryBytes() const;
    std::uint64_t fullResolutionTets() const;

    // Stored (8-bit) values at a grid point.
    float scalarAt(glm::ivec3 p) const;
    float lengthScaleAt(glm::ivec3 p) const;
    // The propagated error Delta (eq. 5, dequantized) of the node of `level`
    // (>= 1) at node coordinates `node`, and the same before propagation.
    double deltaAt(int level, glm::ivec3 node) const;
    double localDeltaAt(int level, glm::ivec3 node) const;
    // e of eq. 1 for that node and an eye.
    double errorMetric(int level, glm::ivec3 node, glm::vec3 eyeWorld, float detailC) const;
    // Which corners (bit i: corner (i&1, i>>1&1, i>>2&1)) carry the centre
    // tetrahedron of a node, by the alternating rule.
    static unsigned centreTetCorners(glm::ivec3 node);

    // The finest-level piecewise-linear field at a world point: (scalar,
    // length scale); points outside the grid are clamped onto it; a
    // non-finite point gives (0, 0).
    glm::dvec2 sampleFinest(glm::dvec3 pointWorld) const;
    // Emission-absorption integral along origin + t dir, t in [tNear, tFar],
    // through the finest tetrahedral mesh (no LOD, no table: every linear piece
    // is integrated by integrateSegment). Premultiplied RGBA, front to back.
    // `dir` need not be unit; lengths are world lengths. Non-finite origin or
    // direction give 0.
    glm::dvec4 integrateRay(const TransferFunction& transfer, glm::dvec3 originWorld, glm::dvec3 dir, double tNear, double tFar) const;

private:
    struct Level {
        glm::ivec3 nodes{0};
        std::vector<std::uint16_t> delta;
        std::vector<std::uint8_t> morph, rangeLo, rangeHi;
    };
    std::size_t pointIndex(glm::ivec3 p) const {
        return std::size_t(p.x) + std::size_t(mDims.x) * (std::size_t(p.y) + std::size_t(mDims.y) * std::size_t(p.z));
    }
    std::size_t nodeIndex(int level, glm::ivec3 n) const {
        const glm::ivec3 d = mLevels[std::size_t(level)].nodes;
        return std::size_t(n.x) + std::size_t(d.x) * (std::size_t(n.y) + std::size_t(d.y) * std::size_t(n.z));
    }
    void build();
    friend struct LodTraversal;

    glm::ivec3 mDims{0}, mRoots{0};
    int mRootLevel = 0;
    glm::vec3 mOrigin{0.0f};
    float mSpacing = 1.0f, mC = 4.0f;
    double mKMax = 1.0;
    DeltaMode mDeltaMode = DeltaMode::Max;
    std::vector<std::uint8_t> mScalar, mLength;
    std::vector<Level> mLevels;                             // index = level; level 0 (unit cells) has no node storage
    std::vector<std::pair<int, std::size_t>> mMorphWritten; // nodes whose e' was set last frame
};

// The same emission-absorption integral through an emitted (LOD) mesh, e.g.
// LodFrame::tets: every tetrahedron the ray crosses gives one linear piece,
// integrated by integrateSegment, composited front to back in ray order (not
// list order). Brute force, O(tets) per ray: for references and tests.
glm::dvec4 integrateRay(const std::vector<Tetrahedron>& tets, const TransferFunction& transfer, glm::dvec3 originWorld, glm::dvec3 dir, double tNear,
                        double tFar);

// Clip a tetrahedron to the visible side of a plane (dot(normal, x) >= offset)
// as a volume (sec. 4.3): 0 (all outside), 1 (a tetrahedron: untouched, or the
// tip left by three outside vertices) or 3 (a prism) tetrahedra are appended
// to `out`; pieces of zero volume are dropped. Values are interpolated along
// the cut edges. Returns how many were appended.
int clipTetrahedron(const Tetrahedron& tet, glm::vec3 normal, float offset, std::vector<Tetrahedron>& out);

// -----------------------------------------------------------------------------
// [SECTION] Clouds (sec. 5)
// -----------------------------------------------------------------------------

// Which field indexes the transfer function and which scales the length.
enum class CloudModel {
    DensityTableLightLength, // sec. 5.2 (default): kappa, rho of density f; l' = l * gamma
    LightTableDensityLength, // sec. 5.1: kappa of light gamma, rho = Id; l' = l * f / f_max (eq. 9)
};

struct CloudDesc {
    glm::ivec3 dims{129, 129, 33};                          // default 129x129x33 grid points
    std::uint32_t seed = 1;                                 // default 1
    float featureCells = 24.0f;                             // default 24: cells per period of the lowest noise octave
    int octaves = 4;                                        // default 4: Perlin octaves (fBm, gain 1/2, lacunarity 2)
    float coverage = 0.45f;                                 // default 0.45: fraction of the noise range turned into cloud
    float sharpness = 3.0f;                                 // default 3: gain from noise above the coverage cut to density
    glm::vec3 sunDirection{0.3f, 0.2f, 1.0f};               // default (0.3,0.2,1): toward the sun (need not be unit), +z up
    float ambient = 0.35f;                                  // default 0.35: ambient light
    float diffuse = 0.65f;                                  // default 0.65: direct sun light before attenuation
    float lightExtinctionPerCell = 0.6f;                    // default 0.6: extinction per cell of density 1 toward the sun
    CloudModel model = CloudModel::DensityTableLightLength; // default sec. 5.2
};

// Density f from 3D Perlin noise (Perlin 1985 [33]) shaped by a vertical
// profile that is zero at the bottom and top layers (cumulus), and the
// isotropic light gamma = ambient + diffuse * transmittance toward the sun
// (attenuated through the density by a plane sweep along the sun's main
// axis). Deterministic by seed. Fails on bad desc fields.
Result<ScalarVolume> makeCloudVolume(const CloudDesc& desc = {});

struct CloudTransferDesc {
    float threshold = 0.08f;             // default 0.08: densities below it get zero extinction (ZOT discards them)
    float maxExtinctionPerWorld = 2.0f;  // default 2: extinction at density 1
    glm::vec3 bright{1.0f, 1.0f, 1.0f};  // default white: kappa at low density
    glm::vec3 dark{0.35f, 0.38f, 0.45f}; // default blue-grey: kappa at density 1 (inverse colour ramp)
};
// The non-physical transfer functions of sec. 5.2: an inverse colour ramp
// (bright thin edges, dark cores) and a linear optical density set to zero
// below a threshold. For CloudModel::LightTableDensityLength pass the light
// field as scalar: then rho = Id * max extinction and kappa is a ramp in gamma.
Result<TransferFunction> makeCloudTransfer(const CloudTransferDesc& desc = {}, CloudModel model = CloudModel::DensityTableLightLength);

// -----------------------------------------------------------------------------
// [SECTION] Ground fog (sec. 6)
// -----------------------------------------------------------------------------

struct GroundFogDesc {
    glm::ivec2 dims{0};               // height-field points along x and z (>= 2 each), y is up
    glm::vec3 originWorld{0.0f};      // default (0,0,0): world x, z of point (0, 0) (y unused: heights are absolute)
    float spacingWorld = 1.0f;        // default 1: world distance between points
    std::vector<float> terrainHeight; // dims.x * dims.y world heights (x fastest)
    std::vector<float> fogTop;        // same size: world height of the fog's top; <= terrain: no fog there
    float density = 1.0f;             // default 1: the scalar at the terrain (the top boundary has 0, sec. 6)
    // Default 0: the scalar is `density` on the terrain and 0 at the top
    // (sec. 6), linear within each tetrahedron, so inside a prism of varying
    // thickness it depends on how the prism is split: refining the LOD
    // re-splits prisms and the fog changes there even when the geometry is
    // morphed (docs/volume.md measures it). > 0: the scalar is
    // density * (fog top - y) / densityDepthWorld, affine in every prism, the
    // same for any split: with morphing a refinement changes nothing at all.
    // The fog then thins where it is shallow. create() fails if a thickness
    // exceeds it (the scalar would pass 1).
    float densityDepthWorld = 0.0f;
    // The paper's sort-free emissive model (sec. 6, eq. 10): true
    // emits the tetrahedra in grid order with no back-to-front sorting. With
    // one fog colour C (makeGroundFogTransfer) every segment blends as
    // I' = eps C + (1 - eps) I, and two such blends commute (the result is
    // C (1 - (1-e1)(1-e2)) + (1-e1)(1-e2) I either way), so the image is the
    // sorted one up to rounding. Not so with a transfer function whose colour
    // varies, with Biri fog applied per segment, or where splats or other
    // volumes interleave with the layer (their order then is per batch only).
    // Default false (sorted).
    bool sortFree = false;
    // The paper's LOD terrain (sec. 6, see GroundFog): true refines a 4-8
    // mesh per frame by the deviations of both the terrain and the fog top,
    // geomorphed; false draws every grid cell. Default false.
    bool lod = false;
    // C of the LOD metric (like eq. 1, see GroundFog), > 0; only with lod. Default 4.
    float minAccuracyC = 4.0f;
};

// How a lit ground fog layer is lit (GroundFog::setLighting; opt-in: a
// layer never given one draws its transfer function's colour, unlit). The
// low-albedo model the effects and LowAlbedo clouds are lit by (Ebert &
// Parent 1990, lighting.hpp): the layer absorbs sigma = extinctionPerWorld s
// (s the fog's scalar, as makeGroundFogTransfer's transfer) and emits per
// unit extinction J = color (albedo (ambient + c I (4 pi phase(theta) T + m))),
// T the sun's transmittance through the layer's own field and the casters.
struct GroundFogLighting {
    // The sun: a directional light (y is up); default travelling down and a little sideways.
    Light sun = Light::directional({-0.3f, -1.0f, -0.2f});
    // Albedo, phase lobes, ambient (RGB), multipleScattering; emission and
    // colorTable are ignored (the base colour is `color`). Default albedo 0.9.
    GasLightingDesc gas{.albedo = 0.9f};
    glm::vec3 color{1.0f};           // default white: the fog's own colour (kappa before the light), each >= 0
    float extinctionPerWorld = 1.0f; // default 1: extinction at scalar 1 (sigma = extinctionPerWorld s), >= 0
    // The pre-integration table's length samples (its scalars need 2: exact). Default 128.
    int lengthResolution = 128;
};

namespace detail {
struct FogFieldView;
} // namespace detail

// A fog layer over a terrain height field as vertical prisms of three
// tetrahedra (sec. 6): every triangle a prism from the terrain to the fog
// top, split into three tetrahedra by the global vertex order so neighbouring
// prisms share their split faces (conforming). Prisms of zero height are
// dropped; the scalar is `density` on the terrain and 0 on the top, linear in
// between. update() emits them back to front for a camera, clipped at the
// near plane (MPVO order of the pieces), or in grid order (sortFree, eq. 10).
//
// Full resolution (desc.lod false): every grid cell is two triangles
// (diagonals alternating), ordered by a BSP over the grid.
//
// LOD (desc.lod true, sec. 6 with the metric of sec. 2.2 and the morphing of
// sec. 3): the grid is padded to (2^n+1)^2 points (terrain clamped to the
// edge, no fog in the padding) and triangulated as a right-triangle bintree
// (a 4-8 mesh) from two root triangles. Every vertex but the four corners is
// the hypotenuse midpoint of its diamond; its local error Delta is the larger
// deviation, in world units, of the terrain and of the fog top from the
// average of the hypotenuse's ends, saturated upward (Delta >= Delta of its
// children, bounding radius r >= r(child) + |v - child|) so the metric never
// grows toward finer levels: a child active means its parents are, and the
// mesh is conforming (no T-vertices). Per frame, top down, a triangle splits
// where e = l C max(c Delta, 1) / (|eye - v| - r) > 1 (l its hypotenuse
// length, C = desc.minAccuracyC, c = LodRefineDesc::detailC per world unit;
// e is infinite within r). A split vertex is geomorphed with w = clamp(e - 1,
// 0, 1): its terrain height and fog thickness (so the fog top with the
// terrain) are lerp(average of the hypotenuse ends' displayed values, true
// value, w), computed top down, so a new vertex starts on the coarse edge.
// The bintree is the BSP: the two children of a triangle are separated by the
// vertical plane through its apex and hypotenuse midpoint, far child first
// (exact for vertical prisms); subtrees outside the view frustum emit no
// prisms (LodRefineDesc::frustumCull). Fully refined (e >= 2 everywhere, e.g. huge
// detailC and C) the mesh is the alternating-diagonal grid and the output is
// the full-resolution one. Coarse triangles that reach into the padding carry
// fog tapering to 0 beyond the grid's edge (within one such triangle).
//
// Memory: full resolution keeps the desc (8 bytes per grid point). LOD keeps
// 16 bytes per padded point (terrain, thickness, Delta, r as floats) and not
// the desc's arrays; bytesFor() is exact.
// In a Scene: Scene::add(GroundFog, ...) (EffectOptions::refine is the refine desc);
// in scene files: volumes kind "groundFog" (keys "lod", "detailC", "minAccuracyC", "morph",
// "terrainGeometry", "densityDepthWorld").
class GroundFog {
public:
    // Fails on dims < 2, size mismatches, non-finite heights or a bad field.
    static Result<GroundFog> create(const GroundFogDesc& desc);
    // update(camera, LodRefineDesc{}, out).
    Status update(const Camera& camera, LodFrame& out) const;
    // Emits into out.tets (cleared first), back to front, with out.stats
    // (emitted, fullResolution = 3 x the prisms of the full grid with fog,
    // nodesRefined = LOD splits, nodesCulled = LOD subtrees outside the
    // frustum, clipping). refine.detailC, refine.morph and refine.frustumCull
    // drive the LOD (ignored at full resolution), refine.clipNear the
    // near-plane clipping; zeroOpacityTest is ignored. If terrainTriangles is
    // not null it receives (cleared first) the terrain the prisms stand on,
    // 3 positions per triangle, counter-clockwise seen from above (+y), the
    // LOD mesh morphed exactly as the fog's bottom (draw the host's terrain
    // with it so the two agree); triangles wholly in the padding are left out.
    // Fails on a non-finite camera or a bad refine field.
    Status update(const Camera& camera, const LodRefineDesc& refine, LodFrame& out, std::vector<glm::vec3>* terrainTriangles = nullptr) const;
    // The world box every prism and terrain triangle update() emits lies in:
    // x and z over the grid (the LOD's padded grid, where fog tapers off),
    // y from the lowest terrain to the highest fog top (morphing only
    // interpolates between heights, so it stays inside).
    Aabb boundsWorld() const { return mBounds; }
    // Prisms with fog at full resolution (the LOD emits fewer).
    std::uint64_t prismCount() const { return mPrisms; }
    bool lod() const { return mDesc.lod; }
    // Points per side of the LOD's padded grid (2^n + 1); 0 at full resolution.
    int lodPointsPerSide() const { return mN; }
    // The bytes create() keeps for a layer of `dims` points (exact; the vectors' payload).
    static std::size_t bytesFor(glm::ivec2 dims, bool lod);
    std::size_t memoryBytes() const;

    // ---- Lighting (GroundFogLighting; docs/lighting.md, "Ground fog") ----
    // Lights the layer from now on: update() then writes each vertex's
    // scalar s = T phase(theta) / max phase (theta between the sun's travel
    // and the direction to the eye) and its length scale = the fog's scalar,
    // to be drawn with litTransfer() / litTable(): kappa(s) = A + B s, rho =
    // extinctionPerWorld, so the extinction is the unlit layer's and
    // pre-integration stays exact. T at each grid point's terrain and fog top
    // is exp(-optical depth toward the sun) through the layer's own
    // continuous field (reference.hpp's integrateGroundFogRay field: in each
    // triangle terrain and thickness linear; integrated in closed form per
    // triangle stretch) times exp2(-DensityField::opticalDepthToLight)
    // through each caster (a lit cloud's or effect's field: smoke shadowing
    // the fog); vertices between grid points (LOD clipping at the grid's
    // edge, near-plane clipping) interpolate it. Relights (O(points x cells
    // crossed toward the sun)) only when the sun's direction or a caster's
    // fingerprint changed; rebuilds the table only when a colour term did.
    // Fails, changing nothing, on a bad field (the message names it) or a
    // null caster.
    Status setLighting(const GroundFogLighting& lighting, std::span<const DensityField* const> casters = {});
    // The same with any shadow casters (another layer's GroundFogCaster among
    // them; not this layer's own: its self-shadowing is already in T).
    Status setLighting(const GroundFogLighting& lighting, std::span<const ShadowCaster* const> casters);
    // Back to the unlit layer (the transfer function's colour).
    void clearLighting() { mLit = false; }
    bool lit() const { return mLit; }
    const GroundFogLighting& lighting() const { return mLighting; }
    const TransferFunction& litTransfer() const { return mLitTransfer; }
    const PreIntegrationTable& litTable() const { return mLitTable; }
    // Relights (transmittance recomputed) and lit-table builds since creation.
    std::uint64_t relights() const { return mRelights; }
    std::uint64_t litTableBuilds() const { return mLitTableBuilds; }
    // The sun's transmittance at the terrain (even entries) and fog top (odd)
    // of each point of the field's grid (x fastest: dims, or the LOD's
    // padded grid), from the last relight.
    const std::vector<float>& sunTransmittance() const { return mSunT; }
    // The layer's own optical depth (natural log) from a world point toward
    // the sun (`towardSun` need not be unit) under the current lighting's
    // extinctionPerWorld: the self-shadowing the relight uses. Double.
    double opticalDepthToSun(glm::dvec3 pointWorld, glm::dvec3 towardSun) const;
    // The model's emission per unit extinction at sun transmittance T seen
    // along toEye (unit, world): what the lit tetrahedra draw, in double.
    glm::dvec3 sourceAt(double sunTransmittance, glm::vec3 toEye) const;

private:
    friend class GroundFogCaster;
    detail::FogFieldView fieldView() const;
    Status relightFog(std::span<const ShadowCaster* const> casters);
    Status rebuildLitTable();
    GroundFogDesc mDesc;
    std::uint64_t mPrisms = 0;
    Aabb mBounds;
    // LOD (desc.lod): padded mN x mN grid, x fastest.
    int mN = 0, mMaxDepth = 0;
    double mMaxThickness = 0.0;
    std::vector<float> mHeight, mThickness, mDelta, mRadius;
    // Lighting (setLighting).
    bool mLit = false;
    GroundFogLighting mLighting;
    std::vector<float> mSunT;                   // 2 per field-grid point: terrain, top
    std::vector<std::uint64_t> mCasterPrints;   // the casters' fingerprints at the last relight
    TransferFunction mLitTransfer;
    PreIntegrationTable mLitTable;
    float mPhaseMax = 1.0f;
    std::uint64_t mRelights = 0, mLitTableBuilds = 0;
};

// A ground fog layer as a shadow caster (lighting.hpp, ShadowCaster): what
// the layer casts on effects, on other layers and, through the scene shadow
// table, on the host's surfaces (docs/lighting.md, "Ground fog casts"). Its
// extinction is extinctionPerWorld x the fog's scalar over the layer's
// continuous field (integrateGroundFogRay's: terrain and thickness linear in
// each triangle of the grid, the scalar linear in height or the paper's
// ratio), in log2 units; optical depths along a segment are integrated in
// closed form per triangle stretch (exact up to double rounding, returned in
// float), the same integral the layer's own self-shadowing uses. It does not
// depend on the camera: the LOD's refinement is not involved.
//
//   auto caster = splatfx::GroundFogCaster::create(fog, 0.8f);   // Result<GroundFogCaster>
//   float depth = caster->opticalDepthToLight(p, sun);           // log2 units
//
// Refers to `fog`, which must outlive it and stay where it is (a Scene keeps
// its layers on the heap). Threading: const members may be called from
// several threads at once.
class GroundFogCaster final : public ShadowCaster {
public:
    GroundFogCaster() = default; // empty: casts nothing
    // extinctionPerWorld: natural-log extinction at scalar 1 (the transfer's,
    // makeGroundFogTransfer), finite and >= 0; fails otherwise, naming it.
    // O(grid points): the fingerprint hashes the layer's field.
    static Result<GroundFogCaster> create(const GroundFog& fog, float extinctionPerWorld);

    float at(glm::vec3 world) const override;
    float opticalDepth(glm::vec3 fromWorld, glm::vec3 toWorld) const override;
    float opticalDepthToLight(glm::vec3 world, const Light& light) const override;
    bool empty() const override { return mFog == nullptr; }
    glm::vec3 boundsMin() const override { return mBounds.lo; }
    glm::vec3 boundsMax() const override { return mBounds.hi; }
    std::uint64_t fingerprint() const override { return mFingerprint; }
    float extinctionPerWorld() const { return mExtinction; }
    const GroundFog* fog() const { return mFog; }

private:
    const GroundFog* mFog = nullptr; // null: empty (no fog, or extinction 0)
    float mExtinction = 0.0f;
    Aabb mBounds{glm::vec3(0.0f), glm::vec3(0.0f)}; // empty: a zero box at the origin, as DensityField
    std::uint64_t mFingerprint = 0;
};

// A fog transfer function: constant colour, extinction linear in the scalar
// (0 at 0, extinctionPerWorld at 1).
Result<TransferFunction> makeGroundFogTransfer(glm::vec3 color, float extinctionPerWorld);

} // namespace splatfx
