// splatfx/gl/frame_renderer.hpp: draws a Frame into the host's framebuffer, owning the order of passes.
//
// This is the one place that knows the order in which a frame's passes run.
// The host hands over, once per frame, everything it owns (framebuffer, host
// depth texture, and hooks for its own opaque and transparent geometry), and
// render() runs:
//   0. uploads what changed: the frame's shadow table (Frame::shadow(), a 3D
//      texture bound to FrameRendererDesc::shadowTextureUnit during the hooks;
//      see shadowBinding() and docs/integration.md, "Shadows of the gas")
//   1. the host's opaque pass   (HostTarget::drawOpaque; its depth is what cuts the volumes)
//   1b. the fog of the host's image (Frame::fog; issue 14): each pixel's host
//      depth unprojected, C = f C + (1 - f) C_fog, per pixel or through a
//      reduced fog texture (FrameRendererDesc::fogTextureSize)
//   2. the volumes: the frame's splats, back to front, premultiplied "over",
//      tested against the host depth, at full resolution or at 1/2 or 1/4 per
//      axis with depth-aware upsampling (FrameRendererDesc::resolutionScale);
//      with a fog, every splat fragment is fogged by the medium in front of it
//      with the frame's LOD volumes (Frame::volumes) drawn as pre-integrated
//      projected tetrahedra (the ray segment ended at the host depth, read
//      from HostTarget::depthTexture) interleaved with the splats in
//      Frame::drawOrder (at reduced resolution: all tetrahedra, then splats)
//      and, with a fog, every tetrahedron's segment fogged like a splat fragment
//      (f from the eye to the segment's opacity centroid; docs/fog.md, "Tetrahedra")
//   3. the host's transparent pass (HostTarget::drawTransparent), blended over;
//      or, with HostTarget::transparentToLists (issue 15), the order-exact
//      path: the hook's fragments go into per-pixel lists (transparentGlsl()),
//      the splats (not drawn in step 2 then) are composited per section
//      between those surfaces (Ebert & Parent 1990, Fig. 1), and a resolve
//      sorts each pixel and composites it over the image (fragment_list_pass);
//      splats behind (in front of) every surface they cover take the
//      ordinary splat pass before (after) the resolve instead
// The passes of the systems still being built (fog of the host image, shadow
// tables before the opaque pass, exact ordering among transparent surfaces,
// projected tetrahedra) join this list here, not in callers.
// It never creates a context, never clears, and writes no depth.
//
//   auto fr = splatfx::gl::FrameRenderer::create();       // a GL 4.5 context must be current
//   fr->upload(materials);                                // when materials change
//   scene.prepare(t, camera, materials, frame);           // GL-free (scene.hpp)
//   fr->render(frame, {.framebuffer = fbo, .depthTexture = depth, .drawOpaque = [&] { drawMyScene(); }});
//
// The viewport is the frame camera's (Camera::viewport), at HostTarget's x, y.
// Engines that want the bare splat pass can still use gl::Renderer (or
// gl::ScaledRenderer) with a SplatBuilder directly; FrameRenderer is built
// from them.
//
// GL state: as gl::Renderer / gl::ScaledRenderer (restored with
// RendererDesc::restoreState, the default). The hooks run with the host's
// framebuffer bound and the viewport set; what they change is theirs.
//
// Threading: every call on the thread whose context is current. Move-only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

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
    // [clouds] With resolutionScale 2 or 4: true draws the tetrahedra (clouds,
    // ground fog) into the same reduced image as the splats, in one back-to-front
    // order with them, so their fill cost falls with the splats'; false keeps
    // them at full resolution, all drawn before the splats. Default false.
    bool reduceTetrahedra = false;
    Precision reducedPrecision = Precision::F16; // reduced-resolution colour format; default F16
    float depthThreshold = 0.1f;                 // reduced resolution: relative view depth still one surface; default 0.1
    // ---- lighting (issue 16): the texture unit the frame's shadow table is
    // bound to while the host's hooks run (splatfx_shadowTable of shadowGlsl()).
    int shadowTextureUnit = 15; // [0, 15] (GL 4.5 guarantees 16 per stage); default 15
    // --- Fog (issue 14, docs/fog.md) ---
    // (0, 0): the host image's fog evaluated per pixel; otherwise the size of
    // the reduced fog texture it is evaluated into (the paper's Table 1:
    // 512x512 ... 128x128 for 800x600) and upsampled with depth-aware
    // weights. Default (0, 0).
    glm::ivec2 fogTextureSize{0, 0};
    float fogDepthThreshold = 0.05f; // fog texture: relative distance still one surface; default 0.05
    bool fogHost = true;             // fog the host's opaque image (false: only the splats); default true
    // --- end fog ---
    // ---- (issue 15) order-exact transparency (HostTarget::transparentToLists) ----
    // The fragment budget for the host's transparent surfaces: the node pool
    // holds viewport pixels x this many nodes (16 bytes each, plus 8 bytes of
    // head and count per pixel: at 8 and 640x480, 41.8 MB), and a pixel
    // resolves this many surfaces exactly (more: the farthest are merged,
    // counted in FrameRenderStats). The splats take no nodes: they are
    // composited per section into 2, 4 or 8 RGBA16F targets (8 bytes a pixel
    // each). [1, 128]. Default 8.
    int fragmentsPerPixel = 8;
    // ---- end (issue 15) ----
};

// ---- lighting (issue 16): what a host surface shader with shadowGlsl()
// (lighting.hpp) needs: the table's unit and the two matrices. Without a
// shadow in the frame the unit holds a 1^3 table of zero depth, so
// splatfx_shadow() returns 1 and the host shader needs no variant.
struct ShadowBinding {
    bool valid = false;                              // the frame had a shadow
    int textureUnit = 15;                            // uniform sampler3D splatfx_shadowTable
    unsigned texture = 0;                            // GL name of the 3D texture (GL_R32F)
    glm::mat4 worldToTable{1.0f};                    // uniform mat4 splatfx_worldToTable
    glm::vec4 lightInTable{0.0f, -1.0f, 0.0f, 0.0f}; // uniform vec4 splatfx_shadowLight
};
// Sets shadowGlsl()'s three uniforms on `program` (glProgramUniform: the
// program need not be bound). Call it in the opaque hook, each frame.
void setShadowUniforms(unsigned program, const ShadowBinding& binding);

// What the host owns, handed over for one frame.
struct HostTarget {
    unsigned framebuffer = 0; // the host's framebuffer object (0: the default framebuffer); default 0
    int x = 0, y = 0;         // viewport origin; its size is the frame camera's viewport; default 0, 0
    // The host's depth as a texture (GL name). Reduced resolution reads it
    // (0: the framebuffer's depth attachment when it is a texture); at full
    // resolution the framebuffer's own depth buffer tests the splats. The
    // tetrahedra end each ray segment at this depth (0: the depth attachment
    // if it is a texture; with none, whole fragments are depth-tested, which is
    // not exact inside a cloud). Default 0.
    unsigned depthTexture = 0;
    // The host's opaque geometry, drawn with depth writes before the volumes.
    // Empty: the host drew it before render(). Default empty.
    std::function<void()> drawOpaque{};
    // The host's transparent surfaces, blended after the volumes (ordered
    // blend; exact interleaving with the volumes is issue 15's pass). Default empty.
    std::function<void()> drawTransparent{};
    // ---- (issue 15) ----
    // drawTransparent emits its fragments into per-pixel lists through
    // transparentGlsl()'s splatfx_emitTransparent (transparency.hpp) instead
    // of blending them: the splats are then cut into sections at those
    // surfaces and every pixel is sorted and composited exactly (the
    // order-exact path, docs/integration.md "Transparent surfaces"). The hook
    // runs with the lists bound, premultiplied "over" blending and the depth
    // test on without writes. false (or no hook): today's ordered blend at
    // today's cost. Default false.
    bool transparentToLists = false;
    // ---- end (issue 15) ----
};

struct FrameRenderStats {
    std::uint64_t splats = 0;        // splats drawn
    std::uint64_t drawCalls = 0;     // draw calls of the volume passes
    int resolutionScale = 1;         // the scale the splats were drawn at
    std::uint64_t shadowUploads = 0; // lighting (issue 16): shadow-table uploads (cumulative; only when the frame's changed)
    // --- Fog (issue 14) ---
    bool fogHost = false;       // the host image was fogged (a fog, fogHost and a host depth texture)
    bool fogSplats = false;     // the splats were drawn with per-fragment fog
    bool fogTetrahedra = false; // the tetrahedra were drawn with per-segment fog
    std::string fogError;       // empty, or why the fog could not be drawn (it was then skipped)
    // --- end fog ---
    // ---- [clouds, issue 17] projected tetrahedra ----
    std::uint64_t tetrahedra = 0;            // tetrahedra drawn
    std::uint64_t tetrahedraTransparent = 0; // skipped by the table's zero-opacity test
    std::uint64_t batches = 0;               // runs of the interleaved splat/tetrahedron sequence
    std::size_t tableBytes = 0;              // GPU bytes of the uploaded pre-integration tables
    // ---- (issue 15) order-exact transparency (last frame) ----
    bool transparentLists = false; // the host's surfaces went through the fragment lists
    bool splatsInLists =
        false; // ... and the splats too (false: drawn before them, ordered blend; see transparentNote; with a fog, the splats that meet a surface take the ordered blend, also noted)
    std::string transparentNote;                 // empty, or why the splats took the ordered blend in a list frame
    std::uint64_t transparentNodes = 0;          // surface fragments stored in the lists
    std::uint64_t transparentFallback = 0;       // surface fragments that found the pool full: blended directly by the include, unsorted
    std::uint64_t transparentOverflowPixels = 0; // pixels with more surfaces than fragmentsPerPixel (their farthest merged)
    std::uint64_t transparentMergedNodes = 0;    // surface nodes merged so
    std::uint64_t transparentMaxSurfaces = 0;    // most surfaces stored on one pixel
    int transparentSections = 0;                 // section targets the splats were composited into (2, 4 or 8; 0: none)
    std::uint64_t transparentSectionOverflow =
        0; // pixels with more surfaces than sections - 1 (7 at most): the gas behind the extra ones merged into the last section
    bool transparentCut = false; // sections weighted by the kernel's partial line integral (RendererDesc::depthCut)
    std::uint64_t transparentGeneral =
        0; // sectioned splats whose polygon crosses the eye plane (camera inside a kernel): drawn screen-covering, exact
    // How the splats of a list frame were drawn: behind every surface they
    // cover (the ordinary splat pass, before the resolve), in front of every
    // one (the ordinary pass, after it), or cut into sections (the rest).
    std::uint64_t transparentSplatsBehind = 0;
    std::uint64_t transparentSplatsFront = 0;
    std::uint64_t transparentSplatsSectioned = 0;
    std::size_t transparentBytes = 0; // GPU bytes of the lists (pool, heads, counts, counters, section targets)
    // ---- end (issue 15) ----
};

class FrameRenderer {
public:
    // Compiles the passes. Fails when no GL 4.5 context is current,
    // desc.resolutionScale is not 1, 2 or 4, or desc.fogTextureSize is
    // negative or above 8192 (the message names the field).
    static Result<FrameRenderer> create(const FrameRendererDesc& desc = {});
    FrameRenderer(FrameRenderer&&) noexcept;
    FrameRenderer& operator=(FrameRenderer&&) noexcept;
    ~FrameRenderer();

    // Uploads texture layers and colour rows when materials changed (cheap otherwise).
    Status upload(const Materials& materials);
    // Runs the frame's passes into the host target. Expects upload() first and
    // a frame camera with a positive viewport.
    void render(const Frame& frame, const HostTarget& target);

    const FrameRendererDesc& desc() const;
    const FrameRenderStats& stats() const;
    // The splat pass's renderer: what texture sampling upload() chose, its
    // layer texture (for tools and debug views).
    const Renderer& splatRenderer() const;
    // lighting (issue 16): the shadow table of the last render(), for the
    // host's shaders (bound to its unit only while render()'s hooks run).
    ShadowBinding shadowBinding() const;

private:
    struct Impl;
    explicit FrameRenderer(std::unique_ptr<Impl> impl);
    void drawInterleaved(const Frame& frame, const HostTarget& target); // [clouds]
    std::unique_ptr<Impl> mImpl;
};

} // namespace splatfx::gl
