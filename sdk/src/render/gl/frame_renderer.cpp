// The frame's passes in the order of its plan (frame_plan.hpp).
#include "splatfx/gl/frame_renderer.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "context_check.hpp"
#include "passes/fog_pass.hpp"
#include "passes/fragment_list_pass.hpp"
#include "host_depth.hpp"
#include "passes/host_pass.hpp"
#include "passes/splat_pass.hpp"
#include "passes/shadow_pass.hpp"
#include "splatfx/gl/frame_plan.hpp"
#include "passes/tetra_pass.hpp"

namespace splatfx::gl {

namespace {

// The host's colour buffer (its draw buffer 0): floating point or not, and
// its red channel's bits. One of 32-bit floats takes the volumes straight:
// blending into it rounds no more than the volume layer would. RGBA16F rounds
// each blend to 11 bits: that one takes the layer.
struct HostColor {
    bool isFloat = false;
    int redBits = 0;
};

HostColor hostColor(unsigned framebuffer) {
    GLint bound = 0, buffer = GL_NONE;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
    if (GLuint(bound) != framebuffer) glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer);
    glGetIntegerv(GL_DRAW_BUFFER0, &buffer);
    if (GLuint(bound) != framebuffer) glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(bound));
    if (framebuffer == 0) buffer = buffer == GL_FRONT ? GL_FRONT_LEFT : buffer == GL_BACK ? GL_BACK_LEFT : buffer;
    if (buffer == GL_NONE) return {};
    GLint object = GL_NONE, type = GL_NONE;
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, GLenum(buffer), GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &object);
    // A context without a default framebuffer (surfaceless) answers with an
    // error: the layer is used, and the error must not reach a later pass's own check.
    if (framebuffer == 0)
        while (glGetError() != GL_NO_ERROR) {}
    if (object == GL_NONE) return {}; // asking more of an empty attachment is an error
    GLint red = 0;
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, GLenum(buffer), GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &type);
    glGetNamedFramebufferAttachmentParameteriv(framebuffer, GLenum(buffer), GL_FRAMEBUFFER_ATTACHMENT_RED_SIZE, &red);
    return {.isFloat = type == GL_FLOAT, .redBits = red};
}

// An 8-bit intermediate image the volumes go through on a floating-point host
// clamps their colours at 1 (HDR lit colour, emission above 1): said, not done
// silently, since the host asked for that precision.
std::string clampingLayerNote(const FramePlan& plan, const FrameRendererDesc& desc, bool volumeLayer, HostColor host) {
    if (!host.isFloat) return {};
    if (plan.reduced && desc.reducedPrecision == Precision::U8)
        return "reducedPrecision U8 on a floating-point host: the reduced layer clamps the volumes' colours to [0, 1] and rounds them to 8 bits";
    if (!plan.reduced && plan.tetrahedra && volumeLayer && desc.volumeLayerPrecision == Precision::U8)
        return "volumeLayerPrecision U8 on a floating-point host: the volume layer clamps the volumes' colours to [0, 1] and rounds them to 8 bits";
    return {};
}

// The per-sample runs of a multisampled host that draw the volumes into the
// full-resolution layer: that layer is single-sampled, so each run draws it
// with the image shifted by (pixel centre - sample position), putting its
// pixel centres on the sample's positions, and composites it into that sample
// only: each sample gets what a single-sampled frame with a pixel centre
// there gets. One camera per sample; none when no run goes through the layer.
std::vector<Camera> layerCameras(const Camera& camera, unsigned framebuffer, const FramePlan& plan) {
    std::vector<Camera> out;
    const bool layer = !plan.reduced && std::any_of(plan.steps.begin(), plan.steps.end(), [](const PlanStep& step) { return step.kind == StepKind::ReducedBegin; });
    const bool perSample = std::any_of(plan.steps.begin(), plan.steps.end(), [](const PlanStep& step) { return step.kind == StepKind::HostDepthSample && step.sample >= 0; });
    if (plan.samples <= 1 || !layer || !perSample || plan.target.width <= 0 || plan.target.height <= 0) return out;
    GLint bound = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer);
    for (int i = 0; i < plan.samples; ++i) {
        glm::vec2 o(0.5f);
        glGetMultisamplefv(GL_SAMPLE_POSITION, GLuint(i), &o.x);
        // ndc spans the layer's width (height) in 2: a shift of one pixel is 2 / width.
        glm::mat4 shift(1.0f);
        shift[3][0] = 2.0f * (0.5f - o.x) / float(plan.target.width);
        shift[3][1] = 2.0f * (0.5f - o.y) / float(plan.target.height);
        Camera c = camera;
        c.proj = shift * camera.proj;
        out.push_back(c);
    }
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(bound));
    return out;
}

} // namespace

struct FrameRenderer::Impl {
    Impl(const FrameRendererDesc& d, const detail::Programs& programs, detail::SplatPass s, detail::TetraPass t, detail::FragmentListPass l)
        : desc(d),
          shadow(d.shadowTextureUnit),
          host(programs),
          fog(d.fogTextureSize, d.fogDepthThreshold, programs),
          splats(std::move(s)),
          tetra(std::move(t)),
          lists(std::move(l)) {}

    FrameRendererDesc desc;
    const void* context = nullptr; // the context create() ran in: its GL objects are names in that context only
    FramePlan plan;
    FrameRenderStats stats;
    std::string depthNote;     // the camera's depth convention against the context and its projection
    std::string clampingNote;  // an 8-bit layer on a floating-point host (clampingLayerNote)
    bool layerPerSample = false; // the last frame's per-sample runs drew the volume layer per sample (layerCameras)
    detail::ShadowPass shadow;
    detail::HostPass host;
    detail::FogPass fog;
    detail::SplatPass splats;
    detail::TetraPass tetra;
    detail::FragmentListPass lists;

    std::array<detail::Pass*, 6> passes() { return {&shadow, &host, &fog, &splats, &tetra, &lists}; }
    detail::Pass& passFor(StepKind kind) {
        switch (kind) {
        case StepKind::UploadShadow:
        case StepKind::UnbindShadow: return shadow;
        case StepKind::HostOpaque:
        case StepKind::CopyHostDepth:
        case StepKind::HostDepthSample:
        case StepKind::HostTransparent: return host;
        case StepKind::HostFog: return fog;
        case StepKind::Splats:
        case StepKind::ReducedSplats:
        case StepKind::ReducedBegin:
        case StepKind::ReducedComposite: return splats;
        case StepKind::PrepareTetrahedra:
        case StepKind::Tetrahedra: return tetra;
        case StepKind::ListsCollect:
        case StepKind::ListsSplit:
        case StepKind::ListsSections:
        case StepKind::ListsResolve: return lists;
        }
        return host;
    }
    void report(const Frame& frame, const detail::StepContext& context);
};

Result<FrameRenderer> FrameRenderer::create(const FrameRendererDesc& desc) {
    if (desc.resolutionScale != 1 && desc.resolutionScale != 2 && desc.resolutionScale != 4)
        return makeError("FrameRendererDesc::resolutionScale must be 1, 2 or 4, got " + std::to_string(desc.resolutionScale));
    if (desc.shadowTextureUnit < kMaxShadowLights - 1 || desc.shadowTextureUnit > 15)
        return makeError("FrameRendererDesc::shadowTextureUnit must be in [" + std::to_string(kMaxShadowLights - 1) +
                         ", 15] (the other shadow slots take the units below it), got " + std::to_string(desc.shadowTextureUnit));
    if (desc.fogTextureSize.x < 0 || desc.fogTextureSize.y < 0 || desc.fogTextureSize.x > 8192 || desc.fogTextureSize.y > 8192 ||
        (desc.fogTextureSize.x == 0) != (desc.fogTextureSize.y == 0))
        return makeError("FrameRendererDesc::fogTextureSize must be (0, 0) (per pixel) or between 1 and 8192 on each side, got " +
                         std::to_string(desc.fogTextureSize.x) + "x" + std::to_string(desc.fogTextureSize.y));
    if (desc.fragmentsPerPixel < 1 || desc.fragmentsPerPixel > detail::FragmentListPass::kMaxFragmentsPerPixel)
        return makeError("FrameRendererDesc::fragmentsPerPixel must be in [1, " + std::to_string(detail::FragmentListPass::kMaxFragmentsPerPixel) +
                         "], got " + std::to_string(desc.fragmentsPerPixel));
    // One program library for every pass (each releases only its own programs).
    const auto programs = std::make_shared<detail::ProgramLibrary>();
    auto splats = detail::SplatPass::create(desc, programs);
    if (!splats) return makeError(splats.error());
    auto tetra = detail::TetraPass::create(programs);
    if (!tetra) return makeError(tetra.error());
    auto lists = detail::FragmentListPass::create(desc.fragmentsPerPixel, desc.splats, programs);
    if (!lists) return makeError(lists.error());
    auto impl = std::make_unique<Impl>(desc, programs, std::move(*splats), std::move(*tetra), std::move(*lists));
    impl->stats.resolutionScale = desc.resolutionScale;
    impl->context = detail::currentContext();
    return FrameRenderer(std::move(impl));
}

FrameRenderer::FrameRenderer(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
FrameRenderer::FrameRenderer(FrameRenderer&&) noexcept = default;
FrameRenderer& FrameRenderer::operator=(FrameRenderer&&) noexcept = default;
FrameRenderer::~FrameRenderer() = default;

Status FrameRenderer::checkContext() const {
    const void* current = detail::currentContext();
    if (current == mImpl->context) return {};
    return makeError(current ? "splatfx::gl::FrameRenderer: the OpenGL context current on this thread is not the one it was created in "
                               "(its GL objects are names in that context only); make that context current"
                             : "splatfx::gl::FrameRenderer: no OpenGL context is current on this thread; make the one it was created in current");
}

Status FrameRenderer::upload(const Materials& materials) {
    if (Status s = checkContext(); !s) return s;
    for (detail::Pass* p : mImpl->passes())
        if (Status s = p->upload(materials); !s) return s;
    return {};
}

const FrameRendererDesc& FrameRenderer::desc() const { return mImpl->desc; }
const FrameRenderStats& FrameRenderer::stats() const { return mImpl->stats; }
const FramePlan& FrameRenderer::plan() const { return mImpl->plan; }
ShadowBinding FrameRenderer::shadowBinding() const { return mImpl->shadow.binding(); }
const Renderer& FrameRenderer::splatRenderer() const { return mImpl->splats.renderer(); }

void FrameRenderer::render(const Frame& frame, const HostTarget& target) {
    Impl& r = *mImpl;
    if (Status s = checkContext(); !s) {
        // Any GL call here would reach another context's objects (or abort in the loader): nothing is drawn, and the stats say why.
        r.plan = {};
        r.stats = {};
        r.stats.resolutionScale = r.desc.resolutionScale;
        r.stats.notes.push_back("frame not drawn: " + s.error());
        return;
    }
    r.depthNote = detail::depthConventionNote(frame.camera());
    HostDepth depth = detail::queryHostDepth(target.framebuffer, target.depthTexture);
    if (!depth.texture)
        depth = r.desc.copyHostDepth
                    ? r.host.depthCopy(target.framebuffer, target.x + frame.camera().viewport.x, target.y + frame.camera().viewport.y)
                    : HostDepth{.missing = "FrameRendererDesc::copyHostDepth is off and neither HostTarget::depthTexture nor a texture depth "
                                           "attachment is given"};
    r.host.addSampleTexture(depth, target.x + frame.camera().viewport.x, target.y + frame.camera().viewport.y);
    FrameRendererDesc planDesc = r.desc;
    if (!r.splats.layerError().empty()) planDesc.volumeLayer = false; // noted in report()
    // The host's colour format matters to the volume layer's choice and to an 8-bit layer's clamp; asked only then.
    const bool readsHostColor = (planDesc.volumeLayer && planDesc.resolutionScale == 1) || planDesc.reducedPrecision == Precision::U8 ||
                                planDesc.volumeLayerPrecision == Precision::U8;
    const HostColor hostColorBuffer = readsHostColor ? hostColor(target.framebuffer) : HostColor{};
    if (planDesc.volumeLayer && planDesc.resolutionScale == 1 && hostColorBuffer.isFloat && hostColorBuffer.redBits >= 32) planDesc.volumeLayer = false;
    r.plan = planFrame(frame, target, planDesc, depth);
    r.clampingNote = clampingLayerNote(r.plan, planDesc, planDesc.volumeLayer, hostColorBuffer);
    for (detail::Pass* p : r.passes()) p->prepare(r.plan, frame);
    detail::StepContext context{.frame = frame, .host = target, .plan = r.plan, .splatLayers = r.splats.renderer().layerTexture()};
    const std::vector<Camera> sampleCameras = layerCameras(frame.camera(), target.framebuffer, r.plan);
    r.layerPerSample = !sampleCameras.empty();
    for (const PlanStep& step : r.plan.steps) {
        if (step.kind == StepKind::HostDepthSample)
            context.layerCamera = step.sample >= 0 && std::size_t(step.sample) < sampleCameras.size() ? &sampleCameras[std::size_t(step.sample)] : nullptr;
        r.passFor(step.kind).execute(step, context);
        // A hook that made another context current (or none): the next GL call would reach that one's objects, or abort.
        if (step.kind == StepKind::HostOpaque || step.kind == StepKind::HostTransparent)
            if (Status s = checkContext(); !s) {
                r.report(frame, context);
                r.stats.notes.push_back("frame cut short after the host's " +
                                        std::string(step.kind == StepKind::HostOpaque ? "opaque" : "transparent") + " hook: " + s.error());
                return;
            }
    }
    r.report(frame, context);
}

void FrameRenderer::Impl::report(const Frame& frame, const detail::StepContext& context) {
    FrameRenderStats& s = stats;
    s = {};
    s.splats = frame.splats().size();
    s.resolutionScale = desc.resolutionScale;
    s.depthConvention = describe(frame.camera().depth);
    for (detail::Pass* p : passes()) p->report(s);
    if (plan.tetrahedra)
        s.tetrahedra.batches = std::uint64_t(std::count_if(plan.steps.begin(), plan.steps.end(), [](const PlanStep& step) {
            return step.kind == StepKind::Tetrahedra || step.kind == StepKind::Splats || step.kind == StepKind::ReducedSplats;
        }));
    s.msaa.samples = plan.samples;
    s.msaa.perSample = std::any_of(plan.steps.begin(), plan.steps.end(), [](const PlanStep& step) { return step.kind == StepKind::HostDepthSample && step.sample >= 0; });
    s.msaa.listsNearest = plan.samples > 1 && plan.lists;
    s.msaa.layerPerSample = layerPerSample;
    s.lists.used = plan.lists;
    s.lists.splats = plan.splatsInLists;
    s.lists.note = plan.listsNote.empty() ? context.listsNote : plan.listsNote;
    if (s.fog.error.empty()) s.fog.error = plan.fogNote;

    // Every fallback, once.
    auto note = [&](const std::string& line) {
        if (!line.empty() && std::find(s.notes.begin(), s.notes.end(), line) == s.notes.end()) s.notes.push_back(line);
    };
    note(depthNote);
    note(clampingNote);
    note(s.fog.error);
    note(s.tetrahedra.error);
    for (const PlanStep& step : plan.steps)
        if (step.range != StepRange::ListsBehindAndBetween) note(step.note); // that one is noted with its count, when it applies
    note(s.lists.note);
    if (plan.tetrahedra && !plan.reduced && desc.volumeLayer) note(splats.layerError());
}

} // namespace splatfx::gl
