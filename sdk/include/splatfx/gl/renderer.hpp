// splatfx/gl/renderer.hpp: the OpenGL 4.5 backend that draws a SplatList.
//
// Draws sorted splats as instanced quads into a framebuffer the host owns,
// with premultiplied-alpha "over" compositing, cutting every splat exactly
// at the host's depth and the near plane (RendererDesc::depthCut; or testing,
// not writing, the host's depth buffer at each splat's plane) so scene
// geometry drawn first occludes and cuts through the effect. It never
// creates a context or a window, and never clears.
//
//   auto r = splatfx::gl::Renderer::create();   // a GL 4.5 context must be current
//   r->upload(materials);                       // when materials change
//   r->draw(builder.splats(), camera, {.framebuffer = hostFbo, .width = w, .height = h});
//
// GL state: draw() saves and restores everything it changes: bound draw
// framebuffer, viewport, program, vertex array, array buffer, texture
// bindings on units 0 and 1 (and the active unit), blend enable/func/equation,
// depth test/func/mask, cull face enable, colour mask. With
// RendererDesc::restoreState = false it skips the queries (faster on drivers
// where glGet stalls) and leaves: blend on (ONE, ONE_MINUS_SRC_ALPHA, ADD),
// depth test on (LEQUAL), depth writes off, culling off, its own program,
// vertex array and texture array (unit 0) bound.
//
// Threading: every call on the thread whose context is current. Move-only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/result.hpp"
#include "splatfx/splats.hpp"

namespace splatfx::gl {

// How splats sample their texture layers.
enum class TextureSampling {
    // Upsampled on software rasterizers (Mesa's llvmpipe, softpipe), where
    // filtering dominates a splat fragment; Bilinear on GPUs, where it is free.
    Auto,
    Bilinear, // the layers as stored, bilinear filtering
    Nearest,  // the layers as stored, nearest texel: blocky where splats magnify their textures
    // The layers resampled bilinearly on upload by an integer factor, then
    // sampled nearest: within half a new texel of bilinear, at nearest's cost
    // per fragment. On llvmpipe: 1.5x the fill rate of Bilinear, for an RMSE
    // against the exact reference 0.0004 above Bilinear's at 2x and 0.0001
    // at 4x (docs/BENCHMARKS.md). Costs factor^2 the texture memory, so with
    // RendererDesc::upsample = 0 the factor is 4 or 2, whichever keeps all
    // layers within kUpsampleBudgetBytes (larger layers thrash a CPU's
    // caches where splats are small); Bilinear where neither fits.
    Upsampled,
};

// Texture memory Upsampled may use with an automatic factor: half the L2
// cache of a typical desktop core, leaving room for framebuffer tiles.
inline constexpr std::size_t kUpsampleBudgetBytes = 512 * 1024;

struct RendererDesc {
    bool restoreState = true;                         // save and restore host GL state around draw(); default true
    bool depthTest = true;                            // test against the host's depth buffer; default true
    TextureSampling sampling = TextureSampling::Auto; // default Auto
    int upsample = 0;                                 // Upsampled's factor, 2 to 16 (1: Bilinear); 0 (default): automatic (see Upsampled)
    // Draw octagons (6 triangles) that skip the square's empty corners, or
    // squares (2 triangles). Octagons save ~17 % of the fragments but cost 3x
    // the triangles; on Mesa's llvmpipe squares are 1.3-2x faster per frame
    // (docs/BENCHMARKS.md, Table I), so the default is squares. Fill-bound
    // GPUs with large splats may prefer octagons. Default false.
    bool trimCorners = false;
    // Fraction of the footprint's support radius actually drawn. The kernel's
    // outer ring carries little weight (Crawfis-Max: 1.25 % of the centre at
    // 0.8125 of the radius, below one 8-bit step of a typical splat) but 34 %
    // of the area. Measured (docs/BENCHMARKS.md, "Accuracy vs time"): 0.8125
    // costs 0.77x the time of 1.0 at the same error against the exact
    // reference. Default 0.8125; 1 draws the whole support.
    float footprintCut = 0.8125f;
    // With a fog (setFog): evaluate the transmittance once per splat, at its
    // centre, instead of per fragment. Cheaper where fragments dominate; its
    // error grows with the fog's variation across a splat (for a constant fog
    // k, |df| <= k times the splat's drawn radius). Default false (per fragment).
    bool fogPerSplat = false;
    // The depth cut (docs/architecture.md "The depth cut"): each
    // fragment keeps the share of its kernel's line integral that lies
    // between the near plane and the host's opaque depth on its pixel ray
    // (Footprint::fractionBefore), instead of the all-or-nothing depth test
    // at the splat plane, so geometry inside an effect and a camera inside
    // one show no popping (pair it with SplatBuilderDesc::nearFade = false,
    // the default). The host depth is read from PassTarget::depthTexture or the
    // target framebuffer's depth attachment when it is a single-sampled
    // texture; without one only the near plane is cut exactly and the host
    // surface is tested at the splat plane. false: that plain test
    // everywhere (pair it with SplatBuilderDesc::nearFade = true). Default true.
    bool depthCut = true;
};

// Where a pass draws: the host's framebuffer object (0 = the default
// framebuffer), the viewport, and the host's depth as a GL texture (depth
// format, single-sampled, the framebuffer's size) for RendererDesc::depthCut
// and the reduced-resolution upsampling. depthTexture 0: Renderer::draw and
// ScaledRenderer::draw / begin use the framebuffer's depth attachment when it
// is a single-sampled texture, else none. A FramePlan's target
// (frame_plan.hpp) has that lookup done: there 0 means none the passes can
// read. The one other target is the frame renderer's HostTarget, which adds
// the host's hooks and takes its size from the camera.
struct PassTarget {
    unsigned framebuffer = 0;
    int x = 0, y = 0, width = 0, height = 0;
    unsigned depthTexture = 0;
};

namespace detail {
class SplatPass;
class ProgramLibrary;
} // namespace detail

struct DrawStats {
    std::uint64_t splats = 0;
    std::uint64_t drawCalls = 0;
    // Depth cut: splats drawn with the near-plane cut, those whose
    // polygon crosses the eye plane (drawn as a screen-covering quad), those
    // drawn with the host-depth cut, and those skipped as wholly behind the
    // host surface; whether the host depth was read.
    std::uint64_t cutNear = 0, cutGeneral = 0, cutHost = 0, cutHidden = 0;
    bool cutHostDepth = false;
};

class Renderer {
public:
    // Compiles shaders and allocates buffers. Fails when no GL 4.5 context is current.
    static Result<Renderer> create(const RendererDesc& desc = {});
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;
    ~Renderer();

    // Uploads texture layers and colour rows when materials.version() differs
    // from the last upload (cheap otherwise).
    Status upload(const Materials& materials);
    // Draws splats (already sorted back to front) with camera's matrices.
    // Expects upload() to have been called.
    void draw(std::span<const Splat> splats, const Camera& camera, const PassTarget& target);

    // Per-fragment fog (docs/fog.md): from the next draw() on,
    // every splat fragment becomes f c + (1 - f) alpha C_fog (premultiplied,
    // alpha unchanged), f the transmittance from the camera's eye to the
    // fragment's world position at timeSec. Compiles the fog variant of the
    // shaders the first time a fog of this structure is seen (its generated
    // GLSL is the cache key; only the uniforms change per frame), so draws
    // without a fog run the plain shaders and cost nothing more. The Fog
    // must outlive the draws that use it. nullptr: no fog (default). Fails
    // only if the generated GLSL does not compile (the message says why).
    Status setFog(const Fog* fog, double timeSec = 0.0);

    const DrawStats& stats() const;
    const RendererDesc& desc() const;
    // The GL texture array holding the uploaded layers (0 before upload), for
    // tools and debug views; the renderer owns it.
    unsigned layerTexture() const;
    // What the last upload() chose: never Auto; Upsampled with its factor
    // (1 for the other modes).
    TextureSampling sampling() const;
    int upsampleFactor() const;

private:
    friend class detail::SplatPass;
    friend class ScaledRenderer;
    // create() with the program library of the frame renderer it draws for.
    static Result<Renderer> create(const RendererDesc& desc, std::shared_ptr<detail::ProgramLibrary> programs);
    // draw() with the host depth already resolved (no framebuffer query).
    void drawResolved(std::span<const Splat> splats, const Camera& camera, const PassTarget& target);
    // The fog parameters of the frame being drawn (computed once a frame by
    // the frame renderer; null: draw() computes them from setFog's fog and time).
    void setFrameFogParameters(const std::vector<glm::vec4>* params);
    struct Impl;
    explicit Renderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

} // namespace splatfx::gl
