// The order-exact transparency pass (private to the GL backend, a pass of
// gl::FrameRenderer): per-pixel linked fragment lists.
//
// Method (Ebert & Parent 1990, "Combining A-buffer and Volume Rendering",
// Fig. 1: "the volume to be rendered must be broken into sections that lie
// between, in front of, and behind the a-buffer fragments"):
//  1. the host's transparent fragments are appended to one linked list per
//     pixel (head image + node pool, transparentGlsl()); a survey of the
//     lists then finds, per 16 x 16 tile, the surfaces' depth range, the
//     nearest host depth and the most surfaces on a pixel (read back);
//  1b. split(): the splats behind every surface they cover, and those in
//     front of every one, need no sections (the frame renderer draws them
//     with the ordinary splat pass before and after the resolve);
//  2. every other splat fragment walks its pixel's surface list: the surfaces
//     wholly in front of it give its section index, the ones that cut it
//     split it into consecutive sections, each weighted by the fraction of
//     the kernel's line integral it holds (sectionFraction in the shader:
//     one function); section k is composited "over" into colour target k.
//     The splats arrive back to front, so each section is the ordered blend
//     of the gas between two surfaces: one A-buffer fragment per volume
//     section, as in the paper, and no per-splat node;
//  3. a resolve pass sorts each pixel's surfaces, interleaves them with its
//     sections (section 0, surface 0, section 1, ...) and composites the
//     result "over" the image already in the framebuffer (the host's opaque
//     image).
//
// Memory: a pool of width * height * fragmentsPerPixel surface nodes (16
// bytes) shared by all pixels, 4 bytes of list head per pixel, 16 per tile
// for the survey, and one RGBA16F target per section in use (none when no
// splat needs sections, else 2, 4 or 8, from the most surfaces on a pixel:
// 1 pane takes 2). A surface fragment that finds the pool full is
// blended by the host directly (the include returns its colour) and counted;
// a pixel with more surfaces than fragmentsPerPixel keeps the nearest ones
// and merges the farthest into its last slot (counted); splat fragments
// behind more than 7 surfaces go into the last section (counted).
//
// A splat whose polygon crosses the eye plane (the camera inside its
// kernel) takes the general variant, as in the splat pass.
//
// It does not draw tetrahedra, work at reduced resolution or fog the splat
// sections (the frame renderer takes the ordered blend then and says why;
// with a fog, only for the splats that would need sections).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/result.hpp"
#include "splatfx/splats.hpp"
#include "pass.hpp"
#include "render/gl/program_library.hpp"
#include "render/gl/saved_state.hpp"
#include "splatfx/gl/renderer.hpp"

namespace splatfx::gl::detail {

struct FragmentListStats {
    std::uint64_t nodes = 0;           // surface nodes stored
    std::uint64_t fallback = 0;        // surface fragments that found the pool full (blended directly instead)
    std::uint64_t maxSurfaces = 0;     // most surfaces stored on one pixel
    int sections = 0;                  // section targets the splats were drawn into (0: no splats in the lists)
    std::uint64_t sectionOverflow = 0; // pixels with more surfaces than sections - 1 (the gas behind the extra ones merged into the last section)
    std::uint64_t overflowPixels = 0;  // pixels with more nodes than fragmentsPerPixel
    std::uint64_t mergedNodes = 0;     // nodes merged into a pixel's farthest slot
    bool cut = false;                  // the sections were weighted by the kernel's partial line integral
    std::uint64_t generalSplats = 0;   // sectioned splats whose polygon crosses the eye plane: drawn with the general (screen-covering) variant
    std::uint64_t splatsBehind = 0;    // split(): splats behind every surface they cover (ordinary pass, before the resolve)
    std::uint64_t splatsFront = 0;     // split(): splats in front of every surface they cover (ordinary pass, after it)
    std::uint64_t splatsSectioned = 0; // splats drawn into the section targets
    std::size_t bytes = 0;             // GPU bytes of the pool, heads, counts, counters and the section targets in use
    std::size_t poolNodes = 0;         // capacity of the pool
};

class FragmentListPass final : public Pass {
public:
    // fragmentsPerPixel in [1, kMaxFragmentsPerPixel] (checked by the caller).
    static constexpr int kMaxFragmentsPerPixel = 128;
    // splats: the splat pass's settings (the sections cut and trim as it does).
    static Result<FragmentListPass> create(int fragmentsPerPixel, const RendererDesc& splats, Programs programs);
    FragmentListPass(FragmentListPass&&) noexcept;
    FragmentListPass& operator=(FragmentListPass&&) noexcept;
    ~FragmentListPass();

    // The footprint's partial-integral table and the cut programs (when it changed).
    Status upload(const Materials& materials) override;
    // Sizes the lists to the target, empties them and binds them where
    // transparentGlsl() expects them; then runs drawSurfaces with the
    // target's framebuffer bound, premultiplied "over" blending, depth test
    // LEQUAL without writes.
    // `camera`: its depth convention (the lists' key and the hook's depth test).
    Status collectSurfaces(const PassTarget& target, const Camera& camera, const std::function<void()>& drawSurfaces);
    // After collectSurfaces: the sorted splats (back to front) as three runs.
    // [0, behindEnd) lie behind every surface stored on every pixel they may
    // cover, [frontBegin, size) in front of every one, the rest between.
    // On every pixel the first run falls into the last section and the last
    // run into the first, so drawing the first run over the opaque image
    // before the resolve and the last run over the result after it gives
    // what the sections give ("over" is associative, the runs keep the
    // back-to-front order): the frame renderer draws both with the ordinary
    // splat pass, and only the middle run needs the section pass. Conservative
    // (per 16 x 16 tile and with the kernel's whole reach along the rays, 1 %
    // margin). One GPU sync: the tiles' surface depth range is read back.
    struct Split {
        std::size_t behindEnd = 0, frontBegin = 0;
    };
    Split split(const std::vector<Splat>& splats, const Camera& camera, float cut, bool trimCorners, bool depthCut, const PassTarget& target);
    // Composites the splats [begin, end) (sorted back to front) into their sections.
    // layerTexture: the splat pass's GL_TEXTURE_2D_ARRAY; cut, trimCorners:
    // RendererDesc's. Reads the surface counters back first (one GPU sync)
    // to choose how many section targets the frame needs.
    // depthCut (RendererDesc::depthCut): sections weighted by the kernel's
    // partial line integral and cut at the near plane and the host depth;
    // false: the kernel as a step at its plane.
    void insertSplats(const std::vector<Splat>& splats, std::size_t begin, std::size_t end, const Camera& camera, unsigned layerTexture, float cut,
                      bool trimCorners, bool depthCut, const PassTarget& target);
    // Sorts every pixel's surfaces, interleaves the sections, composites
    // over the framebuffer, unbinds the lists, reads the counters back.
    void resolve(const PassTarget& target);

    const FragmentListStats& stats() const;

    void prepare(const FramePlan& plan, const Frame& frame) override;
    void execute(const PlanStep& step, StepContext& context) override; // ListsCollect, ListsSplit, ListsSections, ListsResolve
    void report(FrameRenderStats& stats) const override;

private:
    struct Impl;
    explicit FragmentListPass(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
    RendererDesc mSplatDesc;
    SavedState mSaved; // the host's state, from ListsCollect to ListsResolve
    bool mUsed = false;
    std::uint64_t mSectioned = 0; // section draws this frame
};

} // namespace splatfx::gl::detail
