// The splats, back to front: at full resolution (gl::Renderer) or at 1/2 or
// 1/4 per axis with depth-aware upsampling (gl::ScaledRenderer), over the
// ranges the plan gives (all of them, a run of the interleaved order, or a
// run of the fragment lists' split).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "pass.hpp"
#include "render/gl/program_library.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/gl/scaled_renderer.hpp"

namespace splatfx::gl::detail {

class SplatPass final : public Pass {
public:
    static Result<SplatPass> create(const FrameRendererDesc& desc, Programs programs);

    Status upload(const Materials& materials) override;
    void prepare(const FramePlan& plan, const Frame& frame) override; // the fog variant
    // Splats, ReducedSplats, ReducedBegin, ReducedComposite.
    void execute(const PlanStep& step, StepContext& context) override;
    void report(FrameRenderStats& stats) const override;

    // The full-resolution renderer (at reduced resolution, the one inside).
    const Renderer& renderer() const { return mFull ? *mFull : mReduced->renderer(); }
    // Empty, or why the full-size volume layer (FrameRendererDesc::volumeLayer)
    // could not be made: the frame renderer then plans without it and notes this.
    const std::string& layerError() const { return mLayerError; }

private:
    SplatPass() = default;
    Status makeLayer(const FrameRendererDesc& desc, const Programs& programs);
    Renderer& active() { return mFull ? *mFull : mReduced->renderer(); }
    std::optional<Renderer> mFull;          // resolutionScale 1
    std::optional<ScaledRenderer> mReduced; // resolutionScale 2 or 4
    // resolutionScale 1 with volumeLayer: a scale-1 ScaledRenderer for its
    // begin (clear, host depth copy) and composite; mFull draws into it.
    std::optional<ScaledRenderer> mLayer;
    std::string mLayerError;
    ScaledRenderer& layered() { return mReduced ? *mReduced : *mLayer; }
    std::uint64_t mDrawCalls = 0;
    bool mFogged = false;
    std::string mFogError;
};

} // namespace splatfx::gl::detail
