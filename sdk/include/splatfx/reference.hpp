// splatfx/reference.hpp: the CPU reference renderer (double precision), two modes.
//
// Every accuracy figure splatfx publishes is "GL output vs this reference on
// the same input". It consumes exactly what the GL renderer consumes (the
// splat list, the camera, the Materials) and follows GL's rasterization
// conventions: pixel (x, y) of the output (top row first) is sampled at its
// centre, x + 0.5, and GL row height - 1 - y + 0.5, through camera.proj * view
// over a viewport of camera.viewport pixels; fragments outside [near, far]
// are clipped and a host depth image is tested with LEQUAL (or, with
// SplatExactDesc::depthCut, the default, every splat is cut exactly there).
//
//  * Splat-exact (renderSplatExact): the splat model with every approximation
//    of the real-time path removed. Each splat's footprint is evaluated
//    analytically (Footprint::exact, no table, no 8-bit texture); textured
//    detail is sampled like the GPU (bilinear, clamp to edge, texel centres)
//    in double and multiplied by the exact window; the splats overlapping a
//    pixel are composited in the order of the depth at which that pixel's ray
//    meets each splat plane (not the per-splat sort key); accumulation is in
//    double. Alpha and colour follow the GPU: alpha = 1 - 2^(-density * detail),
//    colour = colourRow(colorCoord).rgb * texel.rgb, premultiplied "over".
//  * Volume-exact (VolumeField + renderVolumeExact): untextured splatting's
//    continuous field, i.e. the sum of the voxel kernels h(|M^-1 (x - c)|)
//    with the extinction each voxel's splat implies, colour from the same
//    colour table (extinction-weighted where kernels overlap), integrated
//    along every pixel ray with the emission-absorption model, halving the
//    step until two successive results agree to VolumeExactDesc::tolerance.
//    It measures what splatting itself costs against true volume rendering.
//    With VolumeExactDesc::lighting (LitVolumeDesc) the field is lit as
//    lighting.hpp's low-albedo model defines it, but at every sample point
//    of the view ray rather than at voxel centres: the phase function in
//    double (or an exact phase the HG lobes approximate), the transmittance
//    to each light (directional, point, spot; inside the field too) through
//    this continuous field. VolumeField::add can instead take each voxel's
//    colour as lit per voxel (what a Scene puts in its splats), so the two
//    differ by the per-voxel lighting alone (docs/lighting.md, "The lit
//    reference").
//    A VolumeField can also hold continuous media (ContinuousMedium), through
//    the same integrator: a procedural gas's turbulence density
//    (proceduralGasMedium) or a VDB file's voxels at full resolution
//    (denseMedium), the truths its sampled or resampled grid is measured against.
//
//  * Tetrahedra with fog (renderTetraExact, integrateRayWithFog): a LOD
//    volume's emitted tetrahedra and a Biri fog as one medium, integrated
//    numerically; what gl::FrameRenderer's tetrahedra pass with per-segment
//    fog is measured against.
//
//  * Ground fog (renderGroundFogExact, integrateGroundFogRay): the layer of
//    Roettger & Ertl sec. 6 between the terrain and the fog top as a
//    continuous field, not its tetrahedra, so the prisms' split, the LOD and
//    the sort-free mode each show their error against it.
//
// It does NOT: draw anything with GL, apply the splat builder's near-plane
// fade in volume mode (rays simply start at the near plane), model textured
// detail in volume mode (the field is the traditional, untextured one), or
// run fast: it is for tests and benchmarks (seconds per frame).
//
//   splatfx::Image ref = *splatfx::renderSplatExact(builder.splats(), camera, materials, {.host = {.background = bg}});
//   splatfx::VolumeField field(materials);
//   field.add(grid, {.colorTable = lut});
//   splatfx::Image vol = *splatfx::renderVolumeExact(field, camera, {.host = {.background = bg}});
//   splatfx::LitVolumeDesc lit{.lights = lights, .gas = gas};      // the lit volume: the model at every sample
//   splatfx::Image litRef = *splatfx::renderVolumeExact(field, camera, {.lighting = &lit});
//
// Threading: the render functions split rows over `threads` worker threads
// they own; inputs are read-only during the call. A VolumeField is a plain
// value (one writer at a time; evaluate() is const and thread-safe).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/camera.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/grid.hpp"
#include "splatfx/image.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/procedural_gas.hpp"
#include "splatfx/result.hpp"
#include "splatfx/splats.hpp"
#include "splatfx/volume.hpp"

namespace splatfx {

// How a textured layer's footprint window is evaluated.
enum class ReferenceWindow {
    // The detail is recovered from the stored layer (alpha / the sampled
    // window it was multiplied by at layerSize) and multiplied by the exact
    // window F(r) / F(0). Exact when the set was windowed at layerSize (a set
    // whose size equals MaterialsDesc::layerSize); default.
    Exact,
    // The layer's alpha as stored (sampled window included), in double: the
    // GPU's texture, without 8-bit storage or fixed-point filtering.
    Stored,
};

// What the GL frame was drawn over: a constant colour, or the host's image.
struct ReferenceHost {
    glm::vec4 background{0.0f};             // premultiplied RGBA under the splats; default transparent black
    const Image* backgroundImage = nullptr; // optional RGBA, top row first, viewport size; replaces `background`
    const Image* depth = nullptr;           // optional host depth, window units [0, 1], one channel, top row first
                                            // (as gl::Framebuffer::readDepth returns); fragments behind it are dropped
};

// A transparent surface the reference composites exactly
// among the splats (what a host sends through transparentGlsl()): triangles,
// each crossing of a pixel ray one layer of the premultiplied colour (both
// faces of a box count, like glass drawn without culling). Hidden behind the
// host depth like the splats.
struct ReferenceSurface {
    std::vector<glm::dvec3> triangles; // three world points per triangle
    glm::dvec4 premultiplied{0.0};     // premultiplied RGBA of one crossing; default zero (invisible)
    // The quad a, b, c, d (in order around its edge) as two triangles.
    static ReferenceSurface quad(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d, glm::dvec4 premultiplied);
    // An axis-aligned box's six faces (12 triangles).
    static ReferenceSurface box(glm::dvec3 lo, glm::dvec3 hi, glm::dvec4 premultiplied);
};

struct SplatExactDesc {
    ReferenceHost host{};                            // default: transparent black, no depth
    ReferenceWindow window = ReferenceWindow::Exact; // default Exact
    bool trimCorners = false;                        // match RendererDesc::trimCorners (octagon vs square quad); default false, as the renderer's
    int threads = 0;                                 // worker threads; 0 = std::thread::hardware_concurrency(); default 0
    // Lighting: false reads each splat's colour table exactly at its
    // colour coordinate (unlit splats); true uses the splat's RGBA8 colour
    // times its HDR scale (splatColor), which is what the GL pass draws and
    // where a Scene puts lit colours (docs/lighting.md, "In a Scene"). Default false.
    bool packedColor = false;
    // Fog: the medium the splats and the host are seen through,
    // integrated numerically (integrateFogNumerically, never the closed
    // forms) along each pixel ray from the eye: every fragment at world
    // point X becomes f c + (1 - f) alpha C_fog (premultiplied), f = exp(-tau(eye, X))
    // (0 beyond farDistanceWorld), and the host background is fogged to the
    // host depth's point as gl::FrameRenderer's fog pass does, in the camera's
    // depth convention: the far plane's depth (sky: 1, 0 reversed; or no depth
    // image) to the far plane (none under an infinite far plane: fully
    // fogged), NaN or outside [0, 1] fully fogged.
    const Fog* fog = nullptr;   // default none
    double fogTimeSec = 0.0;    // the fog's time; default 0
    double fogTolerance = 1e-9; // absolute tolerance on each optical depth; default 1e-9
    bool fogHost = true;        // fog the background too (false: as a frame drawn without the host fog pass); default true
    // The depth cut (as gl::RendererDesc::depthCut): each fragment
    // keeps the share of its kernel's line integral between the near plane
    // and the host depth (or the far plane) on its pixel ray, exactly
    // (Footprint::exactFractionBefore), r = R |(u, v)|, s = (t - t_plane) / l
    // with l = splatRayScale(splat); the splat plane is met by the pixel's
    // line, so planes just behind the eye or the near plane still give the
    // tail in front. false: the plain test at the splat plane (fragments
    // outside [near, min(far, host depth)] are dropped whole). Default true.
    bool depthCut = true;
    // Transparent surfaces, composited per pixel in exact
    // depth order with the splats; each splat fragment is cut at the surface
    // crossings of its pixel ray into sections (Ebert & Parent 1990, Fig. 1),
    // each with its exact share of the kernel's line integral (depthCut; false:
    // the whole fragment at its plane). With a fog a surface layer is fogged
    // like a splat fragment at its crossing. Default none.
    std::vector<ReferenceSurface> surfaces{};
};

struct SplatExactStats {
    std::uint64_t fragments = 0;      // (pixel, splat) pairs composited
    std::uint64_t maxOverlap = 0;     // most fragments on one pixel
    std::uint64_t skippedSplats = 0;  // non-finite or degenerate splats, or layer/row out of range
    double fogMaxOpticalDepth = 0.0;  // largest finite tau from the eye to a fragment or the host point
    double fogMaxErrorEstimate = 0.0; // largest quadrature error estimate of one pixel's optical depths (summed)
    std::uint64_t fogUnconverged = 0; // quadratures that missed fogTolerance
};

// Expects camera.viewport > 0 and materials holding every splat's layer and
// colour row (others are skipped and counted). Fails with a message on a
// host image whose size or channel count does not match the viewport.
Result<Image> renderSplatExact(const std::vector<Splat>& splats, const Camera& camera, const Materials& materials, const SplatExactDesc& desc = {},
                               SplatExactStats* stats = nullptr);

// The exact irradiance the splats' emission gives a surface point with unit
// normal `normal` (emitted_light.hpp): the radiance renderSplatExact composites
// along every ray from the point (every splat's occlusion of the others
// included), times the cosine, integrated over the sphere as six cube faces of
// faceSize^2 pixels, each weighted by its exact solid angle. `splats` must be
// built with the point as the eye (a SplatBuilder with frustumCull off and a
// camera at the point: the ellipses face it). errorEstimate: the difference
// from the same integral at half the resolution (the quadrature's error is
// below it when the pixel rule converges at first order or better).
struct IrradianceExactDesc {
    int faceSize = 64;          // pixels per cube-face side, [2, 4096]; default 64
    bool packedColor = false;   // as SplatExactDesc::packedColor; default false
    double nearDistance = 1e-4; // the faces' near plane, world units; default 1e-4
    int threads = 0;            // as SplatExactDesc::threads; default 0
};
struct IrradianceExact {
    glm::dvec3 irradiance{0.0};
    double errorEstimate = 0.0; // max channel |E(faceSize) - E(faceSize / 2)|
};
Result<IrradianceExact> emittedIrradianceExact(const std::vector<Splat>& splats, const Materials& materials, glm::dvec3 point, glm::dvec3 normal,
                                               const IrradianceExactDesc& desc = {});

// A continuous medium the volume-exact reference integrates beside (or
// instead of) the voxel kernels: extinction and colour as a function of the
// world point, through the same quadrature (so a gas's turbulence or a VDB
// file's own voxels are the truth a sampled grid is measured against).
struct ContinuousMedium {
    struct Sample {
        double extinction = 0.0; // natural log, per world unit, >= 0
        glm::dvec3 color{0.0};   // emitted colour per unit extinction
    };
    // Called only inside the box, from several threads at once (const state only).
    std::function<Sample(glm::dvec3 world)> sample{};
    glm::dvec3 boxMin{0.0}, boxMax{0.0}; // world box outside which the medium is empty
    // World length of its finest detail (a voxel, a noise octave): the first
    // quadrature step is a quarter of it. > 0.
    double featureSize = 1.0;
    // Optional: appends the t in (t0, t1) where origin + t dir crosses a kink
    // or jump of the medium (voxel faces or centre planes), so each quadrature
    // piece is smooth. Default none.
    std::function<void(glm::dvec3 origin, glm::dvec3 dir, double t0, double t1, std::vector<double>& out)> breaks{};
};

// How a dense voxel array is read between voxel centres.
enum class DenseFilter {
    Nearest,   // each voxel a cube of its value (a box-filtered grid's own meaning); jumps at voxel faces
    Trilinear, // between the 8 nearest voxel centres (OpenVDB's BoxSampler); kinks at voxel-centre planes
};

// Axis-aligned cubic voxels (e.g. an OpenVDB grid at full resolution, tiles filled): value 0 outside.
struct DenseVoxels {
    glm::ivec3 dims{0};          // voxels along x, y, z
    glm::dvec3 origin{0.0};      // world centre of voxel (0, 0, 0)
    double voxelSize = 1.0;      // world edge of a voxel, > 0
    std::vector<float> values{}; // x fastest, then y, then z; dims.x * dims.y * dims.z entries
};

// The voxels as a medium: extinction = extinctionPerValue * value(x) read
// with `filter`, colour = color(world point) (default white). Breaks at every
// voxel face (Nearest) or centre plane (Trilinear): between them the
// extinction along a ray is a polynomial of degree <= 3, which the
// reference's 4-point Gauss-Legendre integrates exactly. Shares the voxels.
ContinuousMedium denseMedium(std::shared_ptr<const DenseVoxels> voxels, DenseFilter filter, double extinctionPerValue,
                             std::function<glm::dvec3(glm::dvec3 world)> color = {});

// What a procedural gas's sampled grid stands for, as a continuous medium.
struct GasMediumDesc {
    SplatStyle style{}; // the layer's colour table and opacityScale (as drawn); default as SplatStyle
    // World length over which a density d has opacity d (a voxel's opacity is
    // that of a ray through one cell): sigma(x) = -ln(1 - alpha(x)) / cellLength
    // with alpha = clamp(d(x) * opacityScale, 0, 1) * table alpha. 0: the
    // lattice's cell, cbrt of its spacings' product. Default 0.
    double cellLength = 0.0;
    // Densities at most this are empty (the sampler's threshold); the
    // continuous gas has none, so its error is measured. Its jumps are not
    // break points: there the quadrature converges at first order and may
    // stop at up to about twice its tolerance. Default 0.
    double threshold = 0.0;
    // Lattice rows (cell y) mapped to colour coordinate 0 and 1, linear in
    // between and clamped, as Grid::colorByHeight does for the cells present.
    // Both 0: the lattice's full height, 0 to dims.y - 1. Default 0, 0.
    double rowLow = 0.0, rowHigh = 0.0;
};

// proceduralGasDensity (in double, not the float sampled value) at every
// point of the lattice's box (its cells' extent, half a cell beyond the
// outer cell centres, under its transform) at timeSec. Expects a valid desc
// and a lattice with dims >= 1.
ContinuousMedium proceduralGasMedium(const ProceduralGasDesc& gas, const Grid& lattice, double timeSec, const Materials& materials,
                                     const GasMediumDesc& desc = {});

// The continuous field that untextured splatting reconstructs.
//
// Voxel j, with kernel matrix M_j (grid rotation and scale, lattice spacing,
// stretch, as SplatBuilder builds it), centre c_j and log2 optical depth
// tau_j = -log2(1 - opacity * opacityScale * table alpha) (clamped like the
// builder, at most 24), contributes extinction (natural log, per world unit)
//   sigma_j(x) = ln 2 * tau_j / (F(0) * |det M_j|^(1/3)) * h(|M_j^-1 (x - c_j)|)
// with h = Footprint::kernel and F(0) = Footprint::exact(0). Its line
// integral along any direction d is then ln 2 * tau_j * chord * F(q) / F(0),
// the splat's own optical depth (splats.cpp), so a lone voxel seen head-on
// renders identically as a splat and as a volume.
class VolumeField {
public:
    struct Sample {
        double extinction = 0.0; // sum of sigma_j(x), per world unit
        glm::dvec3 color{0.0};   // extinction-weighted mean colour (0 where extinction is 0)
    };
    struct VoxelKernel {
        glm::dvec3 center{0.0};
        glm::dmat3 inverse{1.0};  // M^-1
        double scale = 0.0;       // ln 2 * tau / (F(0) |det M|^(1/3))
        double boundRadius = 0.0; // world radius of a sphere holding the support
        glm::dvec3 color{1.0};    // colour row at colorCoord (texel.rgb = 1 for the plain footprint)
    };

    explicit VolumeField(const Materials& materials);

    // Adds a continuous medium beside the kernels (evaluate(),
    // renderVolumeExact, segmentOpticalDepth and opticalDepthToLight include
    // it, so a lit field's light is shadowed by it; lineOpticalDepth does not).
    void addMedium(ContinuousMedium medium) { mMedia.push_back(std::move(medium)); }
    const std::vector<ContinuousMedium>& media() const { return mMedia; }

    // Appends the grid's voxels with the splat builder's rules: opacities
    // clamped to [0, 1], non-finite voxels or singular kernels dropped and
    // counted in rejected(), zero-opacity voxels left out. style.textured is
    // ignored (the field is the untextured one). voxelColors, when not
    // empty, gives voxel i's colour in place of the colour table's (a lit
    // colour, as a Scene writes into the splat); the table's alpha still
    // scales the opacity. Expects voxelColors empty or of grid.voxels.size().
    void add(const Grid& grid, const SplatStyle& style = {}, std::span<const glm::vec3> voxelColors = {});

    Sample evaluate(glm::dvec3 worldPoint) const;
    // Exact optical depth (natural log) along the whole line origin + t dir,
    // t in (-inf, inf): the sum of each kernel's footprint (closed form up to
    // Footprint::exact's quadrature). For tests.
    double lineOpticalDepth(glm::dvec3 origin, glm::dvec3 dir) const;
    // Optical depth (natural log) along the segment from `from` to `to`:
    // each kernel integrated over its own chord of the segment by 6-point
    // Gauss-Legendre on panels doubled until two results agree to
    // `tolerance` (relative to the kernel's whole-line depth). Along a line
    // the Crawfis-Max kernel is a polynomial of degree 10 in the line
    // parameter, which 6 points integrate exactly, so it converges at once;
    // the Gaussian kernel needs a few doublings. Each medium: clipped to its
    // box, cut at its breaks, each piece doubled until two results agree to
    // `tolerance` in absolute optical depth (a trilinear medium at once).
    double segmentOpticalDepth(glm::dvec3 from, glm::dvec3 to, double tolerance = 1e-10) const;
    // From a world point to the light: to its position (point, spot), or out
    // of the field against the direction a directional light travels.
    double opticalDepthToLight(glm::dvec3 world, const Light& light, double tolerance = 1e-10) const;

    const Materials& materials() const { return *mMaterials; }
    const std::vector<VoxelKernel>& kernels() const { return mKernels; }
    std::uint64_t rejected() const { return mRejected; }

private:
    const Materials* mMaterials;
    std::vector<VoxelKernel> mKernels;
    std::uint64_t mRejected = 0;
    double mCentreFootprint = 1.0; // F(0)
    double mSupportRadius = 1.0;   // where the kernel ends, in double (Footprint::radius() is a float: 1.6 is not one)
    std::vector<ContinuousMedium> mMedia;
};

// The lit volume (lighting.hpp's model, evaluated exactly): at a point x of
// colour c(x) (the field's extinction-weighted colour) the source is
//   c(x) * (emission + albedo * (ambient + sum_i color_i E_i(x) (4 pi p(cos theta_i) T_i(x) + multipleScattering)))
// with E_i the irradiance (intensity; point and spot: intensity / d^2 with d
// at least the light's radiusWorld, spot cone by the same smoothstep), T_i =
// exp(-VolumeField::opticalDepthToLight) and theta_i between the light's
// travel and the direction to the eye. Unlike lightVoxels there is no voxel
// size: only the light's own radiusWorld (inside it the phase is isotropic,
// as in the model).
struct LitVolumeDesc {
    std::vector<Light> lights{}; // default none (then emission and ambient only)
    GasLightingDesc gas{};       // phase, albedo, emission, multipleScattering, ambient; colorTable ignored (the field's colour is the base)
    // The phase function p(cos theta) per steradian, when it is not gas.phase:
    // e.g. the exact phase a few HG lobes are fitted to. Empty: gas.phase's
    // lobes evaluated in double. Default empty.
    std::function<double(double)> phase{};
    double shadowTolerance = 1e-10; // VolumeField::opticalDepthToLight's; default 1e-10
};

// The lit factor (the bracket above, without c(x)) at a world point seen from
// eyeWorld, in double. Expects valid lights (validateLight).
glm::dvec3 litFactor(const VolumeField& field, glm::dvec3 world, glm::dvec3 eyeWorld, const LitVolumeDesc& desc);
// The phase the lit reference uses at cos theta (desc.phase, or the lobes in
// double with 1 -+ cos theta as given, so a g near +-1 keeps its peak).
double litPhase(const LitVolumeDesc& desc, double cosTheta, double oneMinusCos, double onePlusCos);

// Transmittance towards each light through a VolumeField (opticalDepthToLight,
// in double), as a ShadowProvider: lightVoxels / lightPoints with it light
// each voxel at its centre with the reference's own shadows, which isolates
// the per-voxel lighting from the shadow table and the light's field.
// Keeps a pointer to the field and a copy of the lights.
class VolumeFieldShadows final : public ShadowProvider {
public:
    VolumeFieldShadows(const VolumeField& field, std::span<const Light> lights, double tolerance = 1e-10)
        : mField(&field), mLights(lights.begin(), lights.end()), mTolerance(tolerance) {}
    float transmittance(std::size_t light, glm::vec3 world) const override;

private:
    const VolumeField* mField;
    std::vector<Light> mLights;
    double mTolerance;
};

struct VolumeExactDesc {
    ReferenceHost host{};     // default: transparent black, no depth
    double tolerance = 1e-5;  // stop halving when two results differ by less (max over RGBA); default 1e-5
    double initialStep = 0.0; // world units; 0 = a quarter of the smallest kernel support radius; default 0
    int maxHalvings = 10;     // at most this many halvings per pixel; default 10
    int minHalvings = 1;      // at least this many (so every pixel has an error estimate); default 1
    // Fixed step (no refinement) when > 0: for convergence studies. Default 0.
    double fixedStep = 0.0;
    int threads = 0; // 0 = std::thread::hardware_concurrency(); default 0
    // Lit: the source at each sample point is c(x) times litFactor(x), the
    // eye at camera.eye(). Default none (the field's colours as they are).
    const LitVolumeDesc* lighting = nullptr;
};

struct VolumeExactStats {
    double maxErrorEstimate = 0.0; // largest |C(h) - C(h/2)| over pixels at the final step
    int maxHalvingsUsed = 0;
    std::uint64_t unconverged = 0; // pixels that hit maxHalvings above tolerance
    std::uint64_t kernelEvaluations = 0;
};

// Emission-absorption: C = integral T(t) sigma(t) c(t) dt, T = exp(-integral sigma),
// from the near plane to the far plane (or the host depth), then
// C + T * background. The ray is cut at every kernel's support boundary;
// inside each piece, steps of at most h each contribute
// (1 - exp(-dtau)) * (extinction-weighted colour) with dtau by 4-point
// Gauss-Legendre: exact for a constant colour, second order in h otherwise.
// Lit (desc.lighting), each Gauss point's extinction-weighted source is the
// lit one. Fails on a bad host image or tolerance, or (lit) a bad light or
// gas desc, the message naming the field.
// A medium's box is a piece of its own, cut at its breaks, and sampled at the
// same Gauss points.
Result<Image> renderVolumeExact(const VolumeField& field, const Camera& camera, const VolumeExactDesc& desc = {}, VolumeExactStats* stats = nullptr);

// ---- Tetrahedra (LOD volumes) and fog in one medium ----

struct RayFogDesc {
    const Fog* fog = nullptr; // default none (then the cloud alone, like integrateRay)
    double timeSec = 0.0;     // the fog's time; default 0
    // true: the fog is integrated to the ray's end (the host point) and counts
    // in alpha, as a frame with gl::FrameRenderer's host fog pass; false: as a
    // frame drawn without it (fog only in front of cloud matter, alpha the
    // cloud's). Default true.
    bool fogHost = true;
    double tolerance = 1e-6; // per tetrahedron piece: halve the step until two results differ by less; default 1e-6
    int maxHalvings = 12;    // at most this many halvings per piece; default 12
};
struct RayFogStats {
    double errorEstimate = 0.0;      // sum of the pieces' last differences and the fog quadratures' estimates
    bool converged = true;           // every piece and quadrature met the tolerance
    double cloudTransmittance = 1.0; // the cloud's own, through the whole ray
    double fogTransmittance = 1.0;   // the fog's, from the eye to the ray's end (0 beyond farDistanceWorld)
};

// The emission-absorption integral of a tetrahedron list (e.g. LodFrame::tets)
// and a fog together along eye + t dir, t in [tNear, tFar] (multiples of
// |dir|): extinction sigma_cloud + K_t, emission sigma_cloud kappa + K_t
// C_fog, the cloud as integrateRay sees it (linear scalar and length scale
// in each tetrahedron, pieces in ray order), the fog numerically
// (integrateFogNumerically between tetrahedra, Gauss-Legendre on the density
// inside them; never the closed forms) and starting at the eye. Beyond the
// fog's farDistanceWorld the fog's transmittance is 0 (its colour at the cut-off),
// as the GL passes do. Premultiplied RGBA. Brute force: for tests and benches.
glm::dvec4 integrateRayWithFog(const std::vector<Tetrahedron>& tets, const TransferFunction& transfer, glm::dvec3 eye, glm::dvec3 dir, double tNear,
                               double tFar, const RayFogDesc& desc = {}, RayFogStats* stats = nullptr);

struct TetraExactDesc {
    ReferenceHost host{};     // default: transparent black, no depth (a depth that is NaN or < 0 is ignored)
    const Fog* fog = nullptr; // default none
    double fogTimeSec = 0.0;  // default 0
    bool fogHost = true;      // RayFogDesc::fogHost; default true
    double tolerance = 1e-6;  // RayFogDesc::tolerance; default 1e-6
    int maxHalvings = 12;     // in [1, 20]; default 12
    int threads = 0;          // 0 = std::thread::hardware_concurrency(); default 0
};
struct TetraExactStats {
    double maxErrorEstimate = 0.0; // largest RayFogStats::errorEstimate of a pixel
    std::uint64_t unconverged = 0; // pixels whose integral missed the tolerance somewhere
};

// integrateRayWithFog through every pixel centre (GL's conventions, as the
// other modes) from the eye, the near plane to the far plane or the host
// depth, then C + T * background. Needs a perspective camera (the fog is
// integrated from the eye along the pixel ray). Fails on a bad host image,
// tolerance or maxHalvings, or an orthographic camera.
Result<Image> renderTetraExact(const std::vector<Tetrahedron>& tets, const TransferFunction& transfer, const Camera& camera,
                               const TetraExactDesc& desc = {}, TetraExactStats* stats = nullptr);

// ---- Ground fog (Roettger & Ertl 2002, sec. 6): the layer's continuous field ----

struct GroundFogRayStats {
    double errorEstimate = 0.0; // sum of the pieces' last step-halving differences
    bool converged = true;      // every piece met the tolerance
    std::uint64_t pieces = 0;   // stretches integrated (per triangle, cut at the transfer's control points)
    double transmittance = 1.0; // through the whole ray
};

// The emission-absorption integral of a ground fog layer along origin + t dir,
// t in [tNear, tFar] (multiples of |dir|), through the field the prisms stand
// for, not through any tetrahedra: over each triangle of the full-resolution
// triangulation (cell (i, j) split along (i, j)-(i+1, j+1) when i + j is even,
// else along (i+1, j)-(i, j+1), as GroundFog builds it) the terrain and the
// thickness max(fogTop - terrain, 0) are linear (in double from the desc's
// floats); between the terrain and top = terrain + thickness the scalar is
// density (top - y) / thickness (the paper's: density at the terrain, 0 at
// the top, linear along every vertical) or, with densityDepthWorld D > 0,
// min(density (top - y) / D, 1); transfer's extinction and colour of it. Outside the grid there is no fog. Each stretch
// (per triangle, cut where the scalar crosses a control point of `transfer`)
// is integrated by 4-point Gauss-Legendre steps, halved until two results
// differ by less than `tolerance` (at most maxHalvings times).
// Premultiplied RGBA, front to back. Expects a desc GroundFog::create accepts
// (desc.lod and desc.sortFree are ignored: the field is the same); gives 0 for
// a bad one or a non-finite ray.
glm::dvec4 integrateGroundFogRay(const GroundFogDesc& desc, const TransferFunction& transfer, glm::dvec3 origin, glm::dvec3 dir, double tNear,
                                 double tFar, double tolerance = 1e-7, int maxHalvings = 14, GroundFogRayStats* stats = nullptr);

struct GroundFogExactDesc {
    ReferenceHost host{};    // default: transparent black, no depth (a depth that is NaN or < 0 is ignored)
    double tolerance = 1e-7; // per stretch, as integrateGroundFogRay; default 1e-7
    int maxHalvings = 14;    // in [1, 20]; default 14
    int threads = 0;         // 0 = std::thread::hardware_concurrency(); default 0
};
struct GroundFogExactStats {
    double maxErrorEstimate = 0.0; // largest GroundFogRayStats::errorEstimate of a pixel
    std::uint64_t unconverged = 0; // pixels whose integral missed the tolerance somewhere
    std::uint64_t pieces = 0;      // stretches integrated over all pixels
};

// integrateGroundFogRay through every pixel centre (GL's conventions, as the
// other modes) from the near plane to the far plane or the host depth, then
// C + T * background: what GroundFog's tetrahedra, at full resolution or LOD,
// sorted or sort-free, drawn by gl::FrameRenderer are measured against.
// Perspective or orthographic. Fails on a bad host image, tolerance or
// maxHalvings, or a fog desc GroundFog::create rejects (its message).
Result<Image> renderGroundFogExact(const GroundFogDesc& fog, const TransferFunction& transfer, const Camera& camera,
                                   const GroundFogExactDesc& desc = {}, GroundFogExactStats* stats = nullptr);

} // namespace splatfx
