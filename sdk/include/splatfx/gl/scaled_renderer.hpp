// splatfx/gl/scaled_renderer.hpp: draw splats at reduced resolution, composite with depth-aware upsampling.
//
// The splat pass is fill-limited (King et al. 1999, sec. 5), so drawing it at
// half or quarter resolution cuts its cost by about 4x or 16x. This wraps a
// gl::Renderer: it draws the splats into an internal target of
// ceil(width / scale) x ceil(height / scale) pixels, depth-tested against a
// copy of the host depth downsampled by taking the farthest depth of each
// scale x scale block (so thin foreground geometry cannot hide the effect
// behind it), then composites that image over the host target with
// premultiplied "over". Upsampling is depth-aware: each full-resolution
// pixel interpolates those of the four nearest low-resolution texels whose
// downsampled depths lie within depthThreshold (relative, in view depth) of
// its own host depth, their bilinear weights renormalized (all four: plain
// bilinear), and takes the single texel whose depth is nearest its own when
// none does (so effects do not bleed onto geometry edges).
// Without a host depth texture it upsamples bilinearly and tests no depth.
// The full-resolution passes are scissored to the splats' screen rectangle,
// and the host depth is copied once per draw (sampling the attached texture
// while drawing into its framebuffer would be a feedback loop).
// It does not anti-alias, blur or sharpen, and it never clears the host target.
// With scale 1 it is exactly the wrapped Renderer drawing into the target.
//
//   auto sr = splatfx::gl::ScaledRenderer::create({.scale = 2});
//   sr->upload(materials);
//   sr->draw(builder.splats(), camera, {.framebuffer = fbo, .width = w, .height = h, .depthTexture = depthTex});
//
// GL state: with renderer.restoreState (the default) draw() saves and
// restores what it and the wrapped renderer change (the renderer.hpp list
// plus texture unit 2's 2D binding and the scissor test and box); otherwise it leaves blending on
// (ONE, ONE_MINUS_SRC_ALPHA), depth test and writes off, its own program,
// vertex array and textures bound.
//
// Threading: every call on the thread whose context is current. Move-only.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/result.hpp"
#include "splatfx/splats.hpp"

namespace splatfx::gl {

struct ScaledRendererDesc {
    int scale = 2;                        // 1, 2 or 4: internal resolution = viewport / scale per axis; default 2
    RendererDesc renderer{};              // the wrapped Renderer's settings; default RendererDesc{}
    Precision precision = Precision::F16; // internal colour format (U8 quantizes before the composite); default F16
    float depthThreshold = 0.1f;          // relative view-depth difference that still counts as one surface; default 0.1
};

class ScaledRenderer {
public:
    // Fails when no GL 4.5 context is current or scale is not 1, 2 or 4 (the message names desc.scale).
    static Result<ScaledRenderer> create(const ScaledRendererDesc& desc = {});
    ScaledRenderer(ScaledRenderer&&) noexcept;
    ScaledRenderer& operator=(ScaledRenderer&&) noexcept;
    ~ScaledRenderer();

    Status upload(const Materials& materials);
    // Expects upload() first and a target of positive size.
    // The target's depthTexture (0: the framebuffer's depth attachment when it
    // is a texture) is downsampled for the test and the upsampling; with none,
    // no depth test and plain bilinear upsampling.
    void draw(std::span<const Splat> splats, const Camera& camera, const PassTarget& target);

    // draw() in steps, for more than one pass into the reduced image (gl::FrameRenderer
    // draws a frame's tetrahedra and splats into it in one back-to-front order):
    // begin() clears the reduced image and downsamples the host depth into it; draw
    // into the layer it returns (premultiplied "over", back to front; drawSplats for
    // splats); composite() upsamples it over the target once. `box` is the
    // full-resolution rectangle (x0, y0, x1, y1, viewport-relative) the passes can
    // touch: the composite is scissored to it. Expects begin and composite
    // paired (at scale 1 the layer is full size and the composite copies it texel for texel); GL state as draw() (saved at begin, restored at composite).
    // The layer is a framebuffer of ceil(width / scale) x ceil(height / scale)
    // pixels, premultiplied RGBA cleared to 0, whose depth attachment
    // (depthTexture) holds the host depth downsampled (farthest of each
    // block; the far plane's depth without a host depth). `depth`: the
    // frame camera's convention (Camera::depth), which the downsampling
    // and the reduced image's depth follow.
    PassTarget begin(const PassTarget& target, glm::ivec4 box, const DepthConvention& depth = {});
    void drawSplats(std::span<const Splat> splats, const Camera& camera);
    void composite(const Camera& camera);

    const ScaledRendererDesc& desc() const;
    const Renderer& renderer() const;
    Renderer& renderer(); // e.g. Renderer::setFog

private:
    friend class detail::SplatPass;
    // create() with the program library of the frame renderer it draws for.
    static Result<ScaledRenderer> create(const ScaledRendererDesc& desc, std::shared_ptr<detail::ProgramLibrary> programs);
    // draw() and begin() with the host depth already resolved.
    void drawResolved(std::span<const Splat> splats, const Camera& camera, const PassTarget& target);
    PassTarget beginResolved(const PassTarget& target, glm::ivec4 box, const DepthConvention& depth);
    struct Impl;
    explicit ScaledRenderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

} // namespace splatfx::gl
