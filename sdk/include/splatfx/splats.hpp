// splatfx/splats.hpp: voxels to camera-facing splats, sorted back to front.
//
// For each voxel the builder computes the ellipse its (possibly anisotropic)
// kernel projects to for this camera, the optical depth along the ray
// through its centre, its texture layer(s) and colour coordinate, and the
// kernel's along-ray scale for the depth cut (or, with
// SplatBuilderDesc::nearFade, a fade towards the near plane). The list is then sorted back to front for composite-every-sample
// splatting (King et al. 1999, sec. 2 step 4). The resulting SplatList is
// exactly what the GL renderer draws and the reference renderer integrates.
// It does no GL and no animation.
//
//   splatfx::SplatBuilder builder;
//   builder.begin(camera);
//   builder.add(grid, materials, {.textureSet = fireSet, .colorTable = fireLut});
//   builder.sort();
//   renderer.draw(builder.splats(), camera, target);
//
// Threading: one thread at a time per builder; builders are independent.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/grid.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/particles.hpp"

namespace splatfx {

// One splat, laid out as the GPU reads it (64 bytes).
// A fragment at ellipse coordinates (u, v) in [-1, 1]^2, i.e. world position
// center + u * axisU + v * axisV, gets
//   texel  = mix(layer[layer](u, v), layer[nextLayer](u, v), blend)
//   alpha  = 1 - exp2(-density * texel.a)
//   colour = color.rgb * texel.rgb
// composited with premultiplied "over". `color` is the colour table's entry
// at colorCoord in row colorRow, quantized to 8 bits per channel by the
// builder, so the GPU needs no colour lookup; colorCoord and colorRow stay for
// the reference renderer, which reads the table exactly.
// A Scene's HDR lit colour (Scene::setHdrLit, docs/lighting.md "HDR lit
// colour") is the one exception: colorCoord < 0 marks a lit colour whose
// largest channel exceeds 1, color.rgb holds its chroma (the colour divided
// by that channel) and -colorCoord that channel, so
//   colour = -colorCoord * color.rgb    (splatColor)
// The vertex fetch already reads that float: the scale costs no bytes.
struct Splat {
    glm::vec3 center{0.0f};
    float density = 0.0f;  // optical depth scale, log2 units (includes the near-plane fade when SplatBuilderDesc::nearFade)
    glm::vec3 axisU{0.0f}; // ellipse half-axis reaching the footprint's support radius
    float colorCoord = 0.0f;
    glm::vec3 axisV{0.0f};
    float colorRow = 0.0f;
    std::uint16_t layer = 0;     // texture-array layer (Materials)
    std::uint16_t nextLayer = 0; // layer cross-faded towards
    float blend = 0.0f;          // cross-fade weight towards nextLayer
    // RGB8 colour, R in the lowest byte; the top byte is the kernel's
    // along-ray scale code (rayScaleCode; 255, the default, is 1).
    std::uint32_t color = 0xffffffffu;
    float depth = 0.0f; // distance from the eye (perspective) or along forward (ortho); sort key
};
static_assert(sizeof(Splat) == 64, "Splat must match the GPU layout");

// The depth cut (docs/architecture.md "The depth cut") needs the
// kernel's extent along the ray, which the ellipse alone does not give for an
// anisotropic kernel: the world length of one kernel unit along the ray d
// through the centre is l = 1 / |M^-1 d|. With the ellipse's half-axes
// reaching the footprint radius R, |axisU x axisV| = R^2 |det M| |M^-1 d|,
// so l = rho * sqrt(|axisU x axisV|) / R with rho = (|det M|^(1/3) |M^-1 d|)^(-3/2),
// 1 for any isotropic kernel. rho is stored in the top byte of Splat::color
// as code = 127 + round(32 log2 rho) in [0, 254] (1.1 % steps, rho in
// [2^-3.97, 2^3.97], clamped), 255 meaning exactly 1.
std::uint8_t rayScaleCode(float rho);
// The linear colour the GL pass draws a splat with: color.rgb / 255, times
// -colorCoord when colorCoord < 0 (an HDR lit colour, see Splat).
glm::vec3 splatColor(const Splat& splat);
float rayScaleRho(std::uint8_t code);
// World length per kernel unit along the splat's centre ray (see above);
// 0 for a degenerate ellipse.
float splatRayScale(const Splat& splat, float footprintRadius);

// Per-splat variation that hides the voxel lattice. King et al. 1999 (sec. 2)
// stamp every voxel's texture at the same orientation and scale at a
// position fixed to the grid, and the overlapping stamps then read as a
// regular weave. Each option is a pure function of (voxel cell, seed), so it
// is stable over time (the three scales of motion still read) and is the
// same for the GL renderer and the reference, which both draw the Splat list.
// Untextured splats (SplatStyle::textured false, Fig. 1a) ignore it: plain
// footprints on the lattice reconstruct the field best and show no stamp.
// The zero value is the paper's lattice; presets use recommended().
struct SplatVariation {
    // The splat centre moves by up to +-jitter cells along each lattice axis
    // (uniform, per voxel). [0, kMaxJitter]; default 0. At 0.5 the centres
    // are uniform over their cells, and the expected lattice sum has no
    // component at the lattice's frequencies (nor at 1: uniform over two).
    float jitter = 0.0f;
    static constexpr float kMaxJitter = 1.0f;
    // The texture turns about the splat's centre by an angle uniform in
    // +-rotationRad (the footprint is radial, so only the texture turns).
    // [0, pi]; default 0. pi: any orientation (isotropic turbulence); small
    // angles for textures with an up (flames photographed, faces).
    float rotationRad = 0.0f;
    // Half of the splats show their texture mirrored left-right (up stays
    // up). Default false.
    bool mirror = false;
    // The splat's size is multiplied by 2^u, u uniform in +-scaleLog2, with
    // its optical depth divided by the square of that factor so each splat
    // carries the same material. [0, 1]; default 0.
    float scaleLog2 = 0.0f;
    std::uint32_t seed = 0; // hashed with the voxel's cell; default 0

    bool any() const { return jitter > 0.0f || rotationRad > 0.0f || mirror || scaleLog2 > 0.0f; }
    // What the presets and scene files use (docs/BENCHMARKS.md, "The voxel
    // lattice"): centres uniform over their cells, any orientation, mirrored
    // half the time, no scale variation.
    static SplatVariation recommended(std::uint32_t seed) { return {.jitter = 0.5f, .rotationRad = 3.14159265f, .mirror = true, .scaleLog2 = 0.0f, .seed = seed}; }
};

// How a grid's voxels become splats.
struct SplatStyle {
    std::uint32_t textureSet = 0; // id from Materials::addTextureSet; default 0
    std::uint32_t colorTable = 0; // id from Materials::addColorTable; default 0
    bool textured = true;         // false: traditional splatting with the plain footprint (Fig. 1a); default true
    bool crossfade = false;       // blend towards the next texture by the voxel's phase; default false
    float opacityScale = 1.0f;    // multiplies every voxel's opacity; default 1
    SplatVariation variation{};   // per-splat jitter, rotation, mirroring, scale; default none (the paper's lattice)
};
// How particles become splats: the grid's SplatStyle (texture set, colour
// table, cross-fade, opacity scale; its variation's rotation, mirroring and
// scale are drawn per particle id, its jitter is ignored) plus the stretch.
struct ParticleStyle {
    SplatStyle splat{};
    // The kernel is stretched by 1 + min(|v| * stretchPerSpeed, maxStretch)
    // along the velocity v (Voxel::stretch): sparks streak along their flight.
    float stretchPerSpeed = 0.0f; // seconds, >= 0; default 0 (round)
    float maxStretch = 4.0f;      // >= 0; default 4
};

// The message naming the first out-of-range field of v ("jitter must be in
// [0, 1], got 1.2"), or empty when v is valid. `field` prefixes the name.
std::string checkSplatVariation(const SplatVariation& v, const std::string& field = "variation.");

enum class SortMode {
    Exact,    // radix sort on the exact depth key (default)
    Bucketed, // radix sort on a coarse key (SplatBuilderDesc::buckets bins over the depth range)
    None,     // grid order: wrong compositing order, cheapest
};

struct SplatBuilderDesc {
    // The near-plane fade of the splats' density. Off by default: the GL
    // renderer and the reference cut every splat exactly at the near plane
    // (RendererDesc::depthCut, docs/architecture.md "The depth cut"). Turn it
    // on with RendererDesc::depthCut = false: the all-or-nothing test at the
    // splat plane then shows no popping at the near plane.
    bool nearFade = false;       // default false
    float nearFadeStart = 0.25f; // with nearFade: fade begins at near + nearFadeStart * splat extent; default 0.25
    float nearFadeEnd = 1.5f;    // ... and is complete (full opacity) at near + nearFadeEnd * extent; default 1.5
    bool frustumCull = true;     // drop splats wholly outside the view frustum; default true
    std::uint32_t buckets = 64;  // depth bins for SortMode::Bucketed; default 64
    // Threads add() may use on a large grid (one per 8192 voxels at most);
    // the output is identical for any count. 0: one per hardware thread.
    // Default 1: the SDK starts no threads unless asked.
    unsigned threads = 1;
};

struct SplatStats {
    std::uint64_t voxelsIn = 0; // voxels offered
    std::uint64_t culled = 0;   // outside the frustum, behind the eye or fully faded
    std::uint64_t rejected = 0; // non-finite voxel data or a degenerate transform
};

// Memory the back-to-front sort reuses between frames (keys, indices, a copy
// of the splats). Each builder owns one; pass your own to sortBackToFront to
// keep a host-side sort free of allocation too.
struct SortScratch {
    std::vector<std::uint32_t> keys, keys2, index, index2;
    std::vector<Splat> splats;
};

class SplatBuilder {
public:
    explicit SplatBuilder(const SplatBuilderDesc& desc = {}) : mDesc(desc) {}

    // Starts a frame: clears the list (keeping its memory) and the stats.
    void begin(const Camera& camera);
    // Appends the grid's voxels. Opacities are clamped to [0, 1]; voxels with
    // non-finite data are dropped and counted in stats().rejected.
    void add(const Grid& grid, const Materials& materials, const SplatStyle& style = {});
    // Appends particles (particles.hpp; King et al. 1999, sec. 6) to the same
    // list, so they sort and cut with the grids' splats. A particle with a
    // non-finite field or a size <= 0 is dropped and counted in
    // stats().rejected; stats().voxelsIn counts the particles offered.
    void add(std::span<const Particle> particles, const Materials& materials, const ParticleStyle& style = {});
    // Orders the list back to front (largest depth first).
    void sort(SortMode mode = SortMode::Exact);

    const std::vector<Splat>& splats() const { return mSplats; }
    std::vector<Splat>& splats() { return mSplats; }
    const SplatStats& stats() const { return mStats; }
    const Camera& camera() const { return mCamera; }

private:
    SplatBuilderDesc mDesc;
    Camera mCamera;
    std::vector<Splat> mSplats;
    SplatStats mStats;
    SortScratch mScratch;
};

// Back-to-front radix sort of splats by their depth field, stable, O(n).
// Exposed for tests and for hosts that merge lists from several builders.
void sortBackToFront(std::vector<Splat>& splats, SortScratch& scratch, SortMode mode = SortMode::Exact, std::uint32_t buckets = 64);
// Same, with scratch memory allocated for this call.
void sortBackToFront(std::vector<Splat>& splats, SortMode mode = SortMode::Exact, std::uint32_t buckets = 64);

} // namespace splatfx
