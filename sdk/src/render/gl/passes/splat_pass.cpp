#include "splat_pass.hpp"

#include <cassert>
#include <cstdio>
#include <span>
#include <string>

#include <epoxy/gl.h>

#include "render/gl/formats.hpp"

namespace splatfx::gl::detail {

Result<SplatPass> SplatPass::create(const FrameRendererDesc& desc, Programs programs) {
    SplatPass pass;
    if (desc.resolutionScale == 1) {
        auto r = Renderer::create(desc.splats, programs);
        if (!r) return makeError(r.error());
        pass.mFull.emplace(std::move(*r));
        if (desc.volumeLayer) {
            if (Status st = pass.makeLayer(desc, programs); !st) pass.mLayerError = st.error();
        }
    } else {
        auto r = ScaledRenderer::create(
            {.scale = desc.resolutionScale, .renderer = desc.splats, .precision = desc.reducedPrecision, .depthThreshold = desc.depthThreshold},
            std::move(programs));
        if (!r) return makeError(r.error());
        pass.mReduced.emplace(std::move(*r));
    }
    return pass;
}

Status SplatPass::makeLayer(const FrameRendererDesc& desc, const Programs& programs) {
    // Its colour and depth formats must make a complete framebuffer here, or
    // the layer would draw nothing: tried once on a 1x1 framebuffer.
    GLuint color = 0, depth = 0, fbo = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &color);
    glTextureStorage2D(color, 1, colorFormat(desc.volumeLayerPrecision), 1, 1);
    glCreateTextures(GL_TEXTURE_2D, 1, &depth);
    glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT32F, 1, 1);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
    const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_DRAW_FRAMEBUFFER);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &color);
    glDeleteTextures(1, &depth);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        const char* format = desc.volumeLayerPrecision == Precision::F32 ? "RGBA32F" : desc.volumeLayerPrecision == Precision::F16 ? "RGBA16F" : "RGBA8";
        char code[16];
        std::snprintf(code, sizeof code, "0x%04x", unsigned(status));
        return makeError(std::string("volume layer not available (FrameRendererDesc::volumeLayer): a framebuffer of ") + format +
                         " colour and 32-bit float depth is incomplete here (status " + code +
                         "); the tetrahedra are blended straight into the host target, rounded by its format once per tetrahedron");
    }
    auto r = ScaledRenderer::create({.scale = 1, .renderer = desc.splats, .precision = desc.volumeLayerPrecision, .depthThreshold = desc.depthThreshold},
                                    programs);
    if (!r) return makeError("volume layer not available (FrameRendererDesc::volumeLayer): " + r.error());
    mLayer.emplace(std::move(*r));
    return {};
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
    // Into the layer of a per-sample run: the image shifted onto the sample (StepContext::layerCamera).
    const Camera& camera = step.target == StepTarget::Reduced && context.layerCamera ? *context.layerCamera : context.frame.camera();
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
        if (step.target == StepTarget::Reduced && mReduced) mReduced->drawSplats(run, camera);
        else if (step.target == StepTarget::Reduced) mFull->drawResolved(run, camera, context.reduced);
        else mFull->drawResolved(run, camera, context.plan.target);
        break;
    }
    case StepKind::ReducedSplats: mReduced->drawResolved(all, camera, context.plan.target); break;
    case StepKind::ReducedBegin:
        context.reduced = layered().beginResolved(context.plan.target, {0, 0, context.plan.target.width, context.plan.target.height},
                                                  context.frame.camera().depth);
        return;
    case StepKind::ReducedComposite: layered().composite(camera); return;
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
