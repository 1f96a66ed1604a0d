// The frame's passes in their order (frame_renderer.hpp lists them).
#include "splatfx/gl/frame_renderer.hpp"

#include <algorithm>
#include <cassert>
#include <optional>
#include <string>

#include <epoxy/gl.h>

#include "shadow_pass.hpp"
#include "fog_pass.hpp"
#include "splatfx/gl/scaled_renderer.hpp"
#include "tetra_pass.hpp"
#include "fragment_list_pass.hpp"
#include "saved_state.hpp"

namespace splatfx::gl {

struct FrameRenderer::Impl {
    FrameRendererDesc desc;
    // Exactly one of the two splat passes: the reduced-resolution one wraps its own Renderer.
    std::optional<Renderer> full;
    std::optional<ScaledRenderer> reduced;
    FrameRenderStats stats;
    std::optional<ShadowPass> shadow; // lighting (issue 16): pass 0, the frame's shadow table
    detail::FogPass fog;              // fog of the host image (issue 14)
    // [clouds] Projected tetrahedra, and the splats of one interleaved batch.
    std::optional<detail::TetraPass> tetra;
    std::vector<Splat> batch;
    std::optional<detail::FragmentListPass> lists; // (issue 15) order-exact transparency
};

Result<FrameRenderer> FrameRenderer::create(const FrameRendererDesc& desc) {
    if (desc.resolutionScale != 1 && desc.resolutionScale != 2 && desc.resolutionScale != 4)
        return makeError("FrameRendererDesc::resolutionScale must be 1, 2 or 4, got " + std::to_string(desc.resolutionScale));
    if (desc.shadowTextureUnit < 0 || desc.shadowTextureUnit > 15)
        return makeError("FrameRendererDesc::shadowTextureUnit must be in [0, 15], got " + std::to_string(desc.shadowTextureUnit));
    if (desc.fogTextureSize.x < 0 || desc.fogTextureSize.y < 0 || desc.fogTextureSize.x > 8192 || desc.fogTextureSize.y > 8192 ||
        (desc.fogTextureSize.x == 0) != (desc.fogTextureSize.y == 0))
        return makeError("FrameRendererDesc::fogTextureSize must be (0, 0) (per pixel) or between 1 and 8192 on each side, got " +
                         std::to_string(desc.fogTextureSize.x) + "x" + std::to_string(desc.fogTextureSize.y));
    auto impl = std::make_unique<Impl>();
    impl->shadow.emplace(desc.shadowTextureUnit); // lighting (issue 16)
    impl->desc = desc;
    impl->stats.resolutionScale = desc.resolutionScale;
    if (desc.resolutionScale == 1) {
        auto r = Renderer::create(desc.splats);
        if (!r) return makeError(r.error());
        impl->full.emplace(std::move(*r));
    } else {
        auto r = ScaledRenderer::create(
            {.scale = desc.resolutionScale, .renderer = desc.splats, .precision = desc.reducedPrecision, .depthThreshold = desc.depthThreshold});
        if (!r) return makeError(r.error());
        impl->reduced.emplace(std::move(*r));
    }
    { // [clouds]
        auto t = detail::TetraPass::create();
        if (!t) return makeError(t.error());
        impl->tetra.emplace(std::move(*t));
    }
    { // (issue 15)
        if (desc.fragmentsPerPixel < 1 || desc.fragmentsPerPixel > detail::FragmentListPass::kMaxFragmentsPerPixel)
            return makeError("FrameRendererDesc::fragmentsPerPixel must be in [1, " +
                             std::to_string(detail::FragmentListPass::kMaxFragmentsPerPixel) + "], got " + std::to_string(desc.fragmentsPerPixel));
        auto l = detail::FragmentListPass::create(desc.fragmentsPerPixel);
        if (!l) return makeError(l.error());
        impl->lists.emplace(std::move(*l));
    }
    return FrameRenderer(std::move(impl));
}

FrameRenderer::FrameRenderer(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
FrameRenderer::FrameRenderer(FrameRenderer&&) noexcept = default;
FrameRenderer& FrameRenderer::operator=(FrameRenderer&&) noexcept = default;
FrameRenderer::~FrameRenderer() = default;

Status FrameRenderer::upload(const Materials& materials) {
    Status s = mImpl->full ? mImpl->full->upload(materials) : mImpl->reduced->upload(materials);
    if (s && mImpl->lists) s = mImpl->lists->upload(materials); // the sections' partial-integral table
    return s;
}

const FrameRendererDesc& FrameRenderer::desc() const { return mImpl->desc; }
const FrameRenderStats& FrameRenderer::stats() const { return mImpl->stats; }
ShadowBinding FrameRenderer::shadowBinding() const { return mImpl->shadow->binding(); }
const Renderer& FrameRenderer::splatRenderer() const { return mImpl->full ? *mImpl->full : mImpl->reduced->renderer(); }

void FrameRenderer::render(const Frame& frame, const HostTarget& target) {
    Impl& r = *mImpl;
    const Camera& camera = frame.camera();
    assert(camera.viewport.x > 0 && camera.viewport.y > 0 && "FrameRenderer::render: the frame camera's viewport must be positive");
    const int w = camera.viewport.x, h = camera.viewport.y;

    // 0. Uploads (lighting, issue 16): the frame's shadow table, bound for the hooks.
    if (r.shadow->upload(frame.shadow())) ++r.stats.shadowUploads;
    r.shadow->bind();
    // 0. [clouds] Upload the pre-integration tables that changed; per-tetrahedron data.
    const bool anyTets =
        std::any_of(frame.volumes().begin(), frame.volumes().end(), [](const FrameVolume& v) { return v.table && !v.lod.tets.empty(); });
    if (anyTets) r.tetra->prepare(frame);

    // 1. The host's opaque pass: its depth is what the volumes are tested against.
    if (target.drawOpaque) {
        glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
        glViewport(target.x, target.y, w, h);
        target.drawOpaque();
    }

    // 1b. Fog of the host's opaque image (issue 14): read from its depth texture.
    r.stats.fogHost = r.stats.fogSplats = false;
    r.stats.fogError.clear();
    const Fog* fog = frame.fog() && !frame.fog()->empty() ? frame.fog() : nullptr;
    if (fog && r.desc.fogHost) {
        unsigned depth = target.depthTexture;
        if (!depth && target.framebuffer != 0) { // the default framebuffer's depth is never a texture
            GLint type = GL_NONE, name = 0;
            glGetNamedFramebufferAttachmentParameteriv(target.framebuffer, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
            if (type == GL_TEXTURE)
                glGetNamedFramebufferAttachmentParameteriv(target.framebuffer, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &name);
            depth = unsigned(name);
        }
        if (depth) {
            const Status s =
                r.fog.draw(*fog, frame.time(), camera,
                           {.framebuffer = target.framebuffer, .x = target.x, .y = target.y, .width = w, .height = h, .depthTexture = depth},
                           r.desc.fogTextureSize, r.desc.fogDepthThreshold);
            if (s) r.stats.fogHost = true;
            else r.stats.fogError = s.error();
        }
    }
    {
        Renderer& splatPass = r.full ? *r.full : r.reduced->renderer();
        const Status s = splatPass.setFog(fog, frame.time());
        if (!s) r.stats.fogError = s.error();
        r.stats.fogSplats = fog && s;
    }

    // (issue 14) The tetrahedra in the same medium as the splats.
    r.stats.fogTetrahedra = false;
    if (anyTets) {
        const Status s = r.tetra->setFog(fog, frame.time());
        if (!s) r.stats.fogError = s.error();
        r.stats.fogTetrahedra = fog && s;
    }
    // ---- (issue 15) The order-exact path: the splats go into the fragment
    // lists with the host's transparent surfaces (step 3) when nothing this
    // pass cannot draw is in the frame; otherwise they are drawn here as
    // usual and only the surfaces are sorted (among themselves) in step 3.
    const bool lists = target.transparentToLists && bool(target.drawTransparent);
    unsigned listDepth = target.depthTexture; // the section targets are depth-tested against the host's depth
    if (lists && !listDepth && target.framebuffer != 0) {
        GLint type = GL_NONE, name = 0;
        glGetNamedFramebufferAttachmentParameteriv(target.framebuffer, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
        if (type == GL_TEXTURE)
            glGetNamedFramebufferAttachmentParameteriv(target.framebuffer, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &name);
        listDepth = unsigned(name);
    }
    // With a fog the splats still go through the split (the ordinary pass
    // fogs each fragment); only the ones that meet a surface cannot be
    // sectioned (fogged sections are not implemented): they take the
    // ordered blend under the surfaces, and the frame says so.
    const bool splatsInLists = lists && r.full && !anyTets && listDepth != 0;
    r.stats.transparentLists = lists;
    r.stats.splatsInLists = splatsInLists;
    r.stats.transparentNote = !lists || splatsInLists ? std::string()
                              : !r.full               ? "reduced resolution: the splats take the ordered blend under the surfaces"
                              : anyTets               ? "tetrahedra in the frame: the volumes take the ordered blend under the surfaces"
                                                      : "no host depth texture (HostTarget::depthTexture or a texture depth attachment): "
                                                        "the splats take the ordered blend under the surfaces";
    // ---- end (issue 15) ----

    // 2. The volumes, back to front.
    if (splatsInLists) {
        // drawn in step 3
    } else if (anyTets) {
        // [clouds] Splats and tetrahedra interleaved by Frame::drawOrder (frame.hpp).
        drawInterleaved(frame, target);
    } else if (r.full) {
        r.full->draw(frame.splats(), camera,
                     {.framebuffer = target.framebuffer,
                      .x = target.x,
                      .y = target.y,
                      .width = w,
                      .height = h,
                      .depthTexture = target.depthTexture}); // the host depth the splats are cut by (issue 15)
        r.stats.drawCalls = r.full->stats().drawCalls;
    } else {
        r.reduced->draw(
            frame.splats(), camera,
            {.framebuffer = target.framebuffer, .x = target.x, .y = target.y, .width = w, .height = h, .depthTexture = target.depthTexture});
        r.stats.drawCalls = r.reduced->renderer().stats().drawCalls;
    }
    r.stats.splats = frame.splats().size();
    if (!anyTets) r.stats.tetrahedra = r.stats.tetrahedraTransparent = r.stats.batches = 0;

    // 3. The host's transparent surfaces, over the volumes.
    if (lists) {
        // (issue 15) Surfaces into the lists, the splats cut into
        // sections at them, every pixel sorted and composited.
        detail::SavedState saved;
        if (r.desc.splats.restoreState) saved.save({.texture2DUnits = 0, .scissor = false});
        const detail::FragmentListTarget lt{
            .framebuffer = target.framebuffer, .x = target.x, .y = target.y, .width = w, .height = h, .depthTexture = listDepth};
        const Status s = r.lists->collectSurfaces(lt, target.drawTransparent);
        if (s) {
            detail::FragmentListPass::Split split{};
            const std::vector<Splat>& all = frame.splats();
            // The splats behind every surface they cover, and those in front
            // of every one, take the ordinary splat pass (before and after
            // the resolve: FragmentListPass::split); the rest, sections.
            auto ordinary = [&](std::size_t begin, std::size_t end) {
                if (begin >= end) return;
                r.batch.assign(all.begin() + std::ptrdiff_t(begin), all.begin() + std::ptrdiff_t(end));
                r.full->draw(
                    r.batch, camera,
                    {.framebuffer = target.framebuffer, .x = target.x, .y = target.y, .width = w, .height = h, .depthTexture = target.depthTexture});
                r.stats.drawCalls += r.full->stats().drawCalls;
            };
            if (splatsInLists) {
                r.stats.drawCalls = 0;
                split = r.lists->split(all, camera, r.desc.splats.footprintCut, r.desc.splats.trimCorners, r.desc.splats.depthCut, lt);
                if (fog && split.frontBegin > split.behindEnd) {
                    ordinary(0, split.frontBegin);
                    r.stats.transparentNote =
                        "fog: " + std::to_string(split.frontBegin - split.behindEnd) +
                        " splats that meet a surface take the ordered blend under the surfaces (fogged sections not implemented)";
                } else {
                    ordinary(0, split.behindEnd);
                    r.lists->insertSplats(all, split.behindEnd, split.frontBegin, camera, r.full->layerTexture(), r.desc.splats.footprintCut,
                                          r.desc.splats.trimCorners, r.desc.splats.depthCut, lt);
                    if (split.frontBegin > split.behindEnd) ++r.stats.drawCalls;
                }
            }
            r.lists->resolve(lt);
            if (splatsInLists) ordinary(split.frontBegin, all.size());
        } else {
            r.stats.transparentNote = s.error();
        }
        const detail::FragmentListStats& ls = r.lists->stats();
        r.stats.transparentNodes = ls.nodes;
        r.stats.transparentFallback = ls.fallback;
        r.stats.transparentOverflowPixels = ls.overflowPixels;
        r.stats.transparentMergedNodes = ls.mergedNodes;
        r.stats.transparentSectionOverflow = ls.sectionOverflow;
        r.stats.transparentMaxSurfaces = ls.maxSurfaces;
        r.stats.transparentSections = ls.sections;
        r.stats.transparentCut = ls.cut;
        r.stats.transparentGeneral = ls.generalSplats;
        r.stats.transparentSplatsBehind = ls.splatsBehind;
        r.stats.transparentSplatsFront = ls.splatsFront;
        r.stats.transparentSplatsSectioned = ls.splatsSectioned;
        r.stats.transparentBytes = ls.bytes;
        if (r.desc.splats.restoreState) saved.restore();
    } else if (target.drawTransparent) {
        glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
        glViewport(target.x, target.y, w, h);
        target.drawTransparent();
    }
    r.shadow->unbind(); // lighting (issue 16): the unit's previous binding back
}

// ---- [clouds, issue 17] ----
void FrameRenderer::drawInterleaved(const Frame& frame, const HostTarget& target) {
    Impl& r = *mImpl;
    const Camera& camera = frame.camera();
    const int w = camera.viewport.x, h = camera.viewport.y;
    const detail::TetraTarget tt{
        .framebuffer = target.framebuffer, .x = target.x, .y = target.y, .width = w, .height = h, .depthTexture = target.depthTexture};
    std::uint64_t calls = 0, batches = 0;
    if (r.reduced && !r.desc.reduceTetrahedra) {
        // Reduced-resolution splats are composited in one pass, so the order
        // is per pass: every tetrahedron (full resolution), then the splats.
        for (const DrawBatch& b : frame.drawOrder())
            if (b.kind == DrawBatch::Kind::Tetrahedra) r.tetra->draw(frame, b.volume, b.begin, b.end, tt), ++batches;
        r.reduced->draw(
            frame.splats(), camera,
            {.framebuffer = target.framebuffer, .x = target.x, .y = target.y, .width = w, .height = h, .depthTexture = target.depthTexture});
        calls += r.reduced->renderer().stats().drawCalls;
        ++batches;
    } else {
        // Every batch in draw order: into the host target, or (reduceTetrahedra)
        // all into one reduced image composited once (an "over" sequence drawn
        // into a cleared layer and then over the host is the same sequence).
        detail::TetraTarget tets = tt;
        if (r.reduced) {
            const ReducedLayer layer = r.reduced->begin(
                {.framebuffer = target.framebuffer, .x = target.x, .y = target.y, .width = w, .height = h, .depthTexture = target.depthTexture},
                {0, 0, w, h});
            // The tetrahedra cut at the downsampled depth, as the splats are tested against it.
            tets = {.framebuffer = layer.framebuffer, .width = layer.width, .height = layer.height, .depthTexture = layer.depthTexture};
        }
        for (const DrawBatch& b : frame.drawOrder()) {
            ++batches;
            if (b.kind == DrawBatch::Kind::Tetrahedra) {
                r.tetra->draw(frame, b.volume, b.begin, b.end, tets);
                continue;
            }
            const auto& all = frame.splats();
            r.batch.assign(all.begin() + std::ptrdiff_t(b.begin), all.begin() + std::ptrdiff_t(b.end));
            if (r.reduced) {
                r.reduced->drawSplats(r.batch, camera);
                calls += r.reduced->renderer().stats().drawCalls;
            } else {
                r.full->draw(
                    r.batch, camera,
                    {.framebuffer = target.framebuffer, .x = target.x, .y = target.y, .width = w, .height = h, .depthTexture = target.depthTexture});
                calls += r.full->stats().drawCalls;
            }
        }
        if (r.reduced) r.reduced->composite(camera);
    }
    const detail::TetraStats& ts = r.tetra->stats();
    r.stats.drawCalls = calls + ts.drawCalls;
    r.stats.tetrahedra = ts.tetrahedra;
    r.stats.tetrahedraTransparent = ts.transparent;
    r.stats.batches = batches;
    r.stats.tableBytes = ts.tableBytes;
}

} // namespace splatfx::gl
