// splatfx/gl/frame_renderer.hpp: draws a Frame into the host's framebuffer, owning the order of passes.
//
// This is the one place that knows the order in which a frame's passes run.
// The host hands over, once per frame, everything it owns (framebuffer, host
// depth texture, and hooks for its own opaque and transparent geometry).
// render() makes the frame's plan (frame_plan.hpp: every ordering and
// fallback decision, as data) and runs its steps:
//   0. uploads what changed: the frame's shadow tables (Frame::shadows(), 3D
//      textures bound to FrameRendererDesc::shadowTextureUnit and below during the hooks;
//      see shadowBinding() and docs/integration.md, "Shadows of the gas"), the
//      LOD volumes' pre-integration tables
//   1. the host's opaque pass (HostTarget::drawOpaque; its depth is what cuts the volumes)
//   1b. the fog of the host's image (Frame::fog): each pixel's host depth
//      unprojected, C = f C + (1 - f) C_fog, per pixel or through a reduced
//      fog texture (FrameRendererDesc::fogTextureSize)
//   2. the volumes, back to front, premultiplied "over", cut at the host
//      depth: the frame's splats, at full resolution or at 1/2 or 1/4 per axis
//      with depth-aware upsampling (FrameRendererDesc::resolutionScale),
//      interleaved (Frame::drawOrder) with the LOD volumes' pre-integrated
//      projected tetrahedra (Frame::volumes; at reduced resolution either all
//      tetrahedra then the splats, or both in one order in the reduced image:
//      FrameRendererDesc::reduceTetrahedra; at full resolution both in one
//      float layer composited once: FrameRendererDesc::volumeLayer); with a fog, every splat fragment
//      and every tetrahedron segment is fogged by the medium in front of it
//   3. the host's transparent pass (HostTarget::drawTransparent), blended
//      over; or, with HostTarget::transparentToLists, the order-exact path:
//      the hook's fragments go into per-pixel lists (transparentGlsl()), the
//      splats that meet a surface are composited per section between those
//      surfaces (Ebert & Parent 1990, Fig. 1) and a resolve sorts each pixel
//      and composites it over the image; the splats behind (in front of)
//      every surface they cover take the ordinary splat pass before (after)
//      the resolve.
// Where a pass cannot run as asked (no host depth, a fog with splat
// sections, tetrahedra in a list frame, the lists of a multisampled host)
// the frame says so in stats().notes and the pass's own block; nothing falls
// back silently. A multisampled host target (MSAA) gets the host fog and the
// volumes once per sample (stats().msaa).
// The host depth is read in the frame camera's depth convention
// (Camera::depth, depth_convention.hpp); a context whose glClipControl or a
// projection that disagrees with it is a note too.
// It never creates a context, never clears, and writes no depth.
//
//   auto fr = splatfx::gl::FrameRenderer::create();       // a GL 4.5 context must be current
//   fr->upload(materials);                                // when materials change
//   scene.prepare(t, camera, materials, frame);           // GL-free (scene.hpp)
//   fr->render(frame, {.framebuffer = fbo, .depthTexture = depth, .drawOpaque = [&] { drawMyScene(); }});
//
// The viewport is the frame camera's (Camera::viewport), at HostTarget's x, y.
// Engines that want the bare splat pass can still use gl::Renderer (or
// gl::ScaledRenderer) with a SplatBuilder directly.
//
// GL state: as gl::Renderer / gl::ScaledRenderer (restored with
// RendererDesc::restoreState, the default). The hooks run with the host's
// framebuffer bound and the viewport set; what they change is theirs.
//
// Threading: every call on the thread whose context is current. Move-only.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/frame.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/result.hpp"

namespace splatfx::gl {

struct FrameRendererDesc {
    RendererDesc splats{}; // the splat pass's settings; default RendererDesc{}
    // 1: splats at full resolution; 2 or 4: at 1/scale per axis, composited
    // with depth-aware upsampling (gl::ScaledRenderer). Default 1.
    int resolutionScale = 1;
    // With resolutionScale 2 or 4: true draws the tetrahedra (clouds,
    // ground fog) into the same reduced image as the splats, in one back-to-front
    // order with them, so their fill cost falls with the splats'; false keeps
    // them at full resolution, all drawn before the splats. Default false.
    bool reduceTetrahedra = false;
    // With resolutionScale 1 and tetrahedra in the frame: true draws the
    // volumes (tetrahedra and splats, in their one back-to-front order) into a
    // layer of the viewport's size (volumeLayerPrecision), composited once
    // over the host, so an 8-bit host target rounds the volumes once instead
    // of once per tetrahedron (which leaves faint straight steps along the
    // tetrahedra's faces inside a cloud); false: straight into the host
    // target. A host colour buffer of 32-bit floats is drawn into straight
    // (it rounds no more than the layer; RGBA16F does). Where the layer cannot be
    // made, FrameRenderStats::notes says so and the volumes go straight into
    // the host target. Default true.
    bool volumeLayer = true;
    // The volume layer's colour format. F16 rounds each of the dozens of
    // blends inside a cloud to 11 bits, which adds up to about half an 8-bit
    // level (docs/BENCHMARKS.md, "Clouds"); default F32.
    Precision volumeLayerPrecision = Precision::F32;
    Precision reducedPrecision = Precision::F16; // reduced-resolution colour format; default F16
    float depthThreshold = 0.1f;                 // reduced resolution: relative view depth still one surface; default 0.1
    // The texture unit the frame's shadow table of slot 0 is bound to while
    // the host's hooks run (splatfx_shadowTable of shadowGlsl()); slot k's
    // (Frame::shadows(), splatfx_shadowTable<k>) takes the unit
    // shadowTextureUnit - k, so units 15, 14, 13, 12 by default.
    int shadowTextureUnit = 15; // [kMaxShadowLights - 1, 15] (GL 4.5 guarantees 16 per stage); default 15
    // Fog (docs/fog.md).
    // (0, 0): the host image's fog evaluated per pixel; otherwise the size of
    // the reduced fog texture it is evaluated into (the paper's Table 1:
    // 512x512 ... 128x128 for 800x600) and upsampled with depth-aware
    // weights. Default (0, 0).
    glm::ivec2 fogTextureSize{0, 0};
    float fogDepthThreshold = 0.05f; // fog texture: relative distance still one surface; default 0.05
    bool fogHost = true;             // fog the host's opaque image (false: only the splats); default true
    // A host depth that is not a texture (the default framebuffer's, a
    // renderbuffer) is copied, after the opaque pass, into a texture of the
    // same format that every pass then reads (one depth blit a frame,
    // FrameRenderStats::hostDepthCopied); false: those passes fall back
    // (FrameRenderStats::notes says how). Default true.
    bool copyHostDepth = true;
    // Order-exact transparency (HostTarget::transparentToLists).
    // The fragment budget for the host's transparent surfaces: the node pool
    // holds viewport pixels x this many nodes (16 bytes each, plus 8 bytes of
    // head and count per pixel: at 8 and 640x480, 41.8 MB), and a pixel
    // resolves this many surfaces exactly (more: the farthest are merged,
    // counted in FrameRenderStats). The splats take no nodes: they are
    // composited per section into 2, 4 or 8 RGBA16F targets (8 bytes a pixel
    // each). [1, 128]. Default 8.
    int fragmentsPerPixel = 8;
};

// One of slots 1 to kMaxShadowLights - 1 of a ShadowBinding (uniforms
// suffixed with the slot's number: splatfx_shadowTable1, ...).
struct ShadowSlotBinding {
    bool valid = false;                              // the frame had a shadow in this slot
    int light = -1;                                  // splatfx_shadowLightIndex[k]: the scene light; -1 none
    int textureUnit = 0;                             // uniform sampler3D splatfx_shadowTable<k>
    unsigned texture = 0;                            // GL name of the 3D texture (GL_R32F)
    glm::mat4 worldToTable{1.0f};                    // uniform mat4 splatfx_worldToTable<k>
    glm::vec4 lightInTable{0.0f, -1.0f, 0.0f, 0.0f}; // uniform vec4 splatfx_shadowLight<k>
};

// What a host surface shader with shadowGlsl()
// (lighting.hpp) needs: each table's unit and the two matrices. Without a
// shadow in a slot its unit holds a 1^3 table of zero depth, so
// splatfx_shadow() / splatfx_shadowTo() return 1 and the host shader needs no variant.
struct ShadowBinding {
    bool valid = false;                              // the frame had a shadow in slot 0
    int textureUnit = 15;                            // uniform sampler3D splatfx_shadowTable
    unsigned texture = 0;                            // GL name of the 3D texture (GL_R32F)
    glm::mat4 worldToTable{1.0f};                    // uniform mat4 splatfx_worldToTable
    glm::vec4 lightInTable{0.0f, -1.0f, 0.0f, 0.0f}; // uniform vec4 splatfx_shadowLight
    int light = 0;                                   // splatfx_shadowLightIndex[0]: slot 0's scene light; default 0
    // Slots 1 to 3 (Frame::shadows()[1...]); by default no light, on units 14, 13, 12.
    std::array<ShadowSlotBinding, kMaxShadowLights - 1> slots{ShadowSlotBinding{.textureUnit = 14}, ShadowSlotBinding{.textureUnit = 13},
                                                               ShadowSlotBinding{.textureUnit = 12}};
    // The frame's emitted lights (Frame::emittedLights): splatfx_emittedIrradiance's uniforms.
    std::vector<EmittedLight> emittedLights{};
    // An irradiance grid (fitEmittedGrid; dims 0: none): splatfx_emittedGridIrradiance's uniforms.
    EmittedGrid emittedGrid{};
};
// Sets shadowGlsl()'s uniforms on `program` (glProgramUniform: the
// program need not be bound): the table's three and the emitted lights'.
// Call it in the opaque hook, each frame.
void setShadowUniforms(unsigned program, const ShadowBinding& binding);

// What the host owns, handed over for one frame.
struct HostTarget {
    unsigned framebuffer = 0; // the host's framebuffer object (0: the default framebuffer); default 0
    int x = 0, y = 0;         // viewport origin; its size is the frame camera's viewport; default 0, 0
    // The host's depth as a texture (GL name, the framebuffer's size,
    // single-sampled or multisampled like the framebuffer); 0: the
    // framebuffer's depth attachment when it is a texture, else a copy of its
    // depth buffer (FrameRendererDesc::copyHostDepth), in the frame camera's
    // depth convention (Camera::depth). Every pass that reads the host depth
    // reads this one (the depth cut of the splats, the reduced-resolution
    // upsampling, the host fog, the tetrahedra's ray end, the list
    // sections); a multisampled one one sample at a time
    // (FrameRenderStats::msaa). Without any (no depth buffer, copyHostDepth
    // off) the splats and tetrahedra are only depth-tested at their fragments
    // (not exact inside a volume), the host image gets no fog and the splats
    // take the ordered blend in a list frame; FrameRenderStats::notes says
    // so. Default 0.
    unsigned depthTexture = 0;
    // The host's opaque geometry, drawn with depth writes before the volumes.
    // Empty: the host drew it before render(). Default empty.
    std::function<void()> drawOpaque{};
    // The host's transparent surfaces, blended after the volumes in the
    // order the hook draws them (see transparentToLists). Default empty.
    std::function<void()> drawTransparent{};
    // drawTransparent emits its fragments into per-pixel lists through
    // transparentGlsl()'s splatfx_emitTransparent (transparency.hpp) instead
    // of blending them: the splats are then cut into sections at those
    // surfaces and every pixel is sorted and composited exactly (the
    // order-exact path, docs/integration.md "Transparent surfaces"). The hook
    // runs with the lists bound, premultiplied "over" blending and the depth
    // test on without writes. false (or no hook): the ordered blend. Default false.
    bool transparentToLists = false;
};

// What the last render() did, one nested block a pass. Every fallback (a pass
// that could not run as asked) is also a line of `notes`.
struct FrameRenderStats {
    std::uint64_t splats = 0;       // splats in the frame
    std::uint64_t drawCalls = 0;    // draw calls of the volume passes
    int resolutionScale = 1;        // the scale the splats were drawn at
    std::vector<std::string> notes; // every fallback of the frame, one line each (the plan's and the passes'); empty: all ran as asked
    std::string depthConvention;    // the frame camera's (describe(Camera::depth)): how the host depth was read
    bool hostDepthCopied = false;   // the host depth was copied from a depth buffer that is not a texture (FrameRendererDesc::copyHostDepth)
    // A multisampled host depth (MSAA): what ran on it. The host fog and the
    // volumes (splats, reduced splats, tetrahedra) run once per sample, each
    // reading that sample's depth and drawing into that sample only (the
    // resolved image is the mean of the per-sample images: exact at every
    // sample, at `samples` times the cost of those passes); the fragment
    // lists run once, against each pixel's nearest sample (a note says so).
    struct Msaa {
        int samples = 0;       // the host depth's sample count; 0: single-sampled
        bool perSample = false; // the fog and volume passes ran per sample as above (false: a list frame without them)
        int sampleCopies = 0;  // samples copied out of the host depth (samples, + 1 for the nearest)
        bool listsNearest = false; // the fragment lists read each pixel's nearest sample
        // The volumes went through the full-resolution volume layer (single-sampled):
        // each sample's run drew it with the image shifted onto that sample's
        // positions (glGetMultisamplefv) and composited it into that sample.
        bool layerPerSample = false;
    } msaa;
    struct Shadow {
        std::uint64_t uploads = 0; // shadow-table uploads, every slot (cumulative; only when the frame's changed)
        int tables = 0;            // slots with a valid table at the last render (Frame::shadows())
    } shadow;
    struct Fog {
        bool host = false;       // the host image was fogged (a fog, fogHost and a host depth to read)
        bool splats = false;     // the splats were drawn with per-fragment fog
        bool tetrahedra = false; // the tetrahedra were drawn with per-segment fog
        std::string error;       // empty, or why a fog that was asked for was not drawn
    } fog;
    struct Tetrahedra {
        std::uint64_t drawn = 0;       // tetrahedra drawn
        std::uint64_t transparent = 0; // skipped by the table's zero-opacity test
        std::uint64_t batches = 0;     // runs of the interleaved splat/tetrahedron sequence
        std::size_t tableBytes = 0;    // GPU bytes of the uploaded pre-integration tables
        std::uint64_t rgb = 0;         // of those drawn, with an RGB source per vertex (LodFrame::rgb: 3 table lookups a segment)
        std::string error;             // empty, or why an RGB source was not drawn as given (its program failed to build: not drawn; LodFrame::rgb's length not the tetrahedra's: drawn with the scalar)
    } tetrahedra;
    // Order-exact transparency (HostTarget::transparentToLists).
    struct Lists {
        bool used = false;                // the host's surfaces went through the fragment lists
        bool splats = false;              // ... and the splats too (false: drawn before them, ordered blend; see note)
        std::string note;                 // empty, or why (some of) the splats took the ordered blend in a list frame
        std::uint64_t nodes = 0;          // surface fragments stored in the lists
        std::uint64_t fallback = 0;       // surface fragments that found the pool full: blended directly by the include, unsorted
        std::uint64_t overflowPixels = 0; // pixels with more surfaces than fragmentsPerPixel (their farthest merged)
        std::uint64_t mergedNodes = 0;    // surface nodes merged so
        std::uint64_t maxSurfaces = 0;    // most surfaces stored on one pixel
        int sections = 0;                 // section targets the splats were composited into (2, 4 or 8; 0: none)
        std::uint64_t sectionOverflow =
            0;            // pixels with more surfaces than sections - 1 (7 at most): the gas behind the extra ones merged into the last section
        bool cut = false; // sections weighted by the kernel's partial line integral (RendererDesc::depthCut)
        std::uint64_t general = 0; // sectioned splats whose polygon crosses the eye plane (camera inside a kernel): drawn screen-covering, exact
        // How the splats were drawn: behind every surface they cover (the
        // ordinary splat pass, before the resolve), in front of every one (the
        // ordinary pass, after it), or cut into sections (the rest).
        std::uint64_t splatsBehind = 0, splatsFront = 0, splatsSectioned = 0;
        std::size_t bytes = 0; // GPU bytes of the lists (pool, heads, counts, counters, section targets)
    } lists;
};

// Camera::depth for a host drawing with `proj` in the current context: the
// clip range from glClipControl's depth mode (GL_CLIP_DEPTH_MODE), reversed
// and infinite far from the projection (conventionOfProjection). Fails when
// no context is current or the clip origin is GL_UPPER_LEFT (not supported:
// flip y in the projection instead, docs/integration.md).
Result<DepthConvention> depthConventionOfContext(const glm::mat4& proj);

struct FramePlan; // frame_plan.hpp

class FrameRenderer {
public:
    // Compiles the passes. Fails when no GL 4.5 context is current,
    // desc.resolutionScale is not 1, 2 or 4, or desc.fogTextureSize is
    // negative or above 8192 (the message names the field).
    static Result<FrameRenderer> create(const FrameRendererDesc& desc = {});
    FrameRenderer(FrameRenderer&&) noexcept;
    FrameRenderer& operator=(FrameRenderer&&) noexcept;
    ~FrameRenderer();

    // Uploads texture layers and colour rows when materials changed (cheap
    // otherwise). Fails, uploading nothing, when checkContext() does.
    Status upload(const Materials& materials);
    // Runs the frame's passes into the host target. Expects upload() first and
    // a frame camera with a positive viewport. When checkContext() fails it
    // makes no GL call and draws nothing; stats().notes says so.
    void render(const Frame& frame, const HostTarget& target);
    // OK when the context current on this thread is the one create() ran in
    // (its GL objects are names in that context only); otherwise an error
    // saying whether none or another one is current.
    Status checkContext() const;

    const FrameRendererDesc& desc() const;
    const FrameRenderStats& stats() const;
    // The splat pass's renderer: what texture sampling upload() chose, its
    // layer texture (for tools and debug views).
    const Renderer& splatRenderer() const;
    // The shadow table of the last render(), for the host's shaders (bound
    // to its unit only while render()'s hooks run).
    ShadowBinding shadowBinding() const;
    // The plan the last render() ran (frame_plan.hpp), for tools and debugging.
    const FramePlan& plan() const;

private:
    struct Impl;
    explicit FrameRenderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

} // namespace splatfx::gl
