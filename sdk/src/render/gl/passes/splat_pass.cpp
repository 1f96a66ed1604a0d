#include "splat_pass.hpp"

#include <cassert>
#include <span>

namespace splatfx::gl::detail {

Result<SplatPass> SplatPass::create(const FrameRendererDesc& desc, Programs programs) {
    SplatPass pass;
    if (desc.resolutionScale == 1) {
        auto r = Renderer::create(desc.splats, std::move(programs));
        if (!r) return makeError(r.error());
        pass.mFull.emplace(std::move(*r));
    } else {
        auto r = ScaledRenderer::create(
            {.scale = desc.resolutionScale, .renderer = desc.splats, .precision = desc.reducedPrecision, .depthThreshold = desc.depthThreshold},
            std::move(programs));
        if (!r) return makeError(r.error());
        pass.mReduced.emplace(std::move(*r));
    }
    return pass;
}

Status SplatPass::upload(const Materials& materials) { return mFull ? mFull->upload(materials) : mReduced->upload(materials); }

void SplatPass::prepare(const FramePlan& plan, const Frame&) {
    mDrawCalls = 0;
    const Status s = active().setFog(plan.fog, plan.timeSec);
    active().setFrameFogParameters(plan.fog ? &plan.fogParameters : nullptr);
    mFogError = s ? std::string() : s.error();
    mFogged = plan.fog && s;
}

void SplatPass::execute(const PlanStep& step, StepContext& context) {
    const Camera& camera = context.frame.camera();
    const std::span<const Splat> all = context.frame.splats();
    switch (step.kind) {
    case StepKind::Splats: {
        if (step.range != StepRange::Explicit && !context.listsReady) return; // the lists failed: the note says why
        const auto [begin, end] = context.range(step);
        if (step.range == StepRange::ListsBehindAndBetween && context.frontBegin > context.behindEnd)
            context.listsNote = "fog: " + std::to_string(end - std::min(context.behindEnd, end)) +
                                " splats that meet a surface take the ordered blend under the surfaces (fogged sections not implemented)";
        if (step.range != StepRange::Explicit && begin >= end) return;
        const std::span<const Splat> run = all.subspan(begin, end - begin);
        if (step.target == StepTarget::Reduced) mReduced->drawSplats(run, camera);
        else mFull->drawResolved(run, camera, context.plan.target);
        break;
    }
    case StepKind::ReducedSplats: mReduced->drawResolved(all, camera, context.plan.target); break;
    case StepKind::ReducedBegin:
        context.reduced = mReduced->beginResolved(context.plan.target, {0, 0, context.plan.target.width, context.plan.target.height}, context.frame.camera().depth);
        return;
    case StepKind::ReducedComposite: mReduced->composite(camera); return;
    default: assert(false && "SplatPass: not a splat step"); return;
    }
    mDrawCalls += active().stats().drawCalls;
}

void SplatPass::report(FrameRenderStats& stats) const {
    stats.drawCalls += mDrawCalls;
    stats.fog.splats = mFogged;
    if (!mFogError.empty()) stats.fog.error = mFogError;
}

} // namespace splatfx::gl::detail
