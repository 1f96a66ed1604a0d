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
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/grid.hpp"
#include "splatfx/materials.hpp"

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
float rayScaleRho(std::uint8_t code);
// World length per kernel unit along the splat's centre ray (see above);
// 0 for a degenerate ellipse.
float splatRayScale(const Splat& splat, float footprintRadius);

// How a grid's voxels become splats.
struct SplatStyle {
    std::uint32_t textureSet = 0; // id from Materials::addTextureSet; default 0
    std::uint32_t colorTable = 0; // id from Materials::addColorTable; default 0
    bool textured = true;         // false: traditional splatting with the plain footprint (Fig. 1a); default true
    bool crossfade = false;       // blend towards the next texture by the voxel's phase; default false
    float opacityScale = 1.0f;    // multiplies every voxel's opacity; default 1
};

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
