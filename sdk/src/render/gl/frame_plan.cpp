// Every ordering and fallback decision of a frame (frame_plan.hpp). GL-free:
// the frame renderer queries the host's depth once and executes the steps.
#include "splatfx/gl/frame_plan.hpp"

#include <algorithm>
#include <cassert>
#include <string>

namespace splatfx::gl {

namespace {

PlanStep step(StepKind kind, StepTarget target = StepTarget::Host) { return {.kind = kind, .target = target}; }

PlanStep splatRange(std::size_t begin, std::size_t end, StepTarget target = StepTarget::Host) {
    return {.kind = StepKind::Splats, .target = target, .begin = begin, .end = end};
}

PlanStep listRun(StepKind kind, StepRange range) { return {.kind = kind, .range = range}; }

// The volumes when the frame has tetrahedra: splats and tetrahedra interleaved
// by Frame::drawOrder (frame.hpp).
void planInterleaved(const Frame& frame, const FrameRendererDesc& desc, bool reduced, FramePlan& plan) {
    if (reduced && !desc.reduceTetrahedra) {
        // Reduced-resolution splats are composited in one pass, so the order
        // is per pass: every tetrahedron (full resolution), then the splats.
        for (const DrawBatch& b : frame.drawOrder())
            if (b.kind == DrawBatch::Kind::Tetrahedra)
                plan.steps.push_back({.kind = StepKind::Tetrahedra, .volume = b.volume, .begin = b.begin, .end = b.end});
        plan.steps.push_back(step(StepKind::ReducedSplats));
        return;
    }
    // Every batch in draw order: into the host target, or (reduceTetrahedra;
    // volumeLayer at full resolution) all into one layer composited once (an
    // "over" sequence drawn into a cleared layer and then over the host is
    // the same sequence, rounded once by the host's format).
    const bool layer = reduced || desc.volumeLayer;
    const StepTarget into = layer ? StepTarget::Reduced : StepTarget::Host;
    if (layer) plan.steps.push_back(step(StepKind::ReducedBegin));
    for (const DrawBatch& b : frame.drawOrder()) {
        if (b.kind == DrawBatch::Kind::Tetrahedra)
            plan.steps.push_back({.kind = StepKind::Tetrahedra, .target = into, .volume = b.volume, .begin = b.begin, .end = b.end});
        else plan.steps.push_back(splatRange(b.begin, b.end, into));
    }
    if (layer) plan.steps.push_back(step(StepKind::ReducedComposite));
}

// A multisampled host depth whose per-sample texture could not be made (HostDepth::missing says why).
std::string multisampledNote(const char* what, int samples) {
    return std::string(what) + ": the host depth is multisampled (" + std::to_string(samples) +
           " samples) and the texture its samples are read into could not be made";
}

} // namespace

FramePlan planFrame(const Frame& frame, const HostTarget& host, const FrameRendererDesc& desc, const HostDepth& depth) {
    const Camera& camera = frame.camera();
    assert(camera.viewport.x > 0 && camera.viewport.y > 0 && "planFrame: the frame camera's viewport must be positive");
    FramePlan plan;
    // A multisampled depth is read through the single-sample texture each sample is copied into.
    const bool multisampled = depth.texture != 0 && depth.samples > 1;
    plan.target = {.framebuffer = host.framebuffer,
                   .x = host.x,
                   .y = host.y,
                   .width = camera.viewport.x,
                   .height = camera.viewport.y,
                   .depthTexture = multisampled ? depth.sampleTexture : depth.texture};
    plan.fog = frame.fog() && !frame.fog()->empty() ? frame.fog() : nullptr;
    plan.timeSec = frame.time();
    if (plan.fog) plan.fogParameters = plan.fog->glslParameters(plan.timeSec, glm::dvec3(camera.eye()));
    plan.tetrahedra =
        std::any_of(frame.volumes().begin(), frame.volumes().end(), [](const FrameVolume& v) { return v.table && !v.lod.tets.empty(); });
    plan.reduced = desc.resolutionScale != 1;
    const bool hasDepth = plan.target.depthTexture != 0;
    plan.samples = multisampled && hasDepth ? depth.samples : 0;

    // 0. Uploads: the frame's shadow table (bound while the hooks run), the tetrahedra's tables.
    plan.steps.push_back(step(StepKind::UploadShadow));
    if (plan.tetrahedra) plan.steps.push_back(step(StepKind::PrepareTetrahedra));

    // 1. The host's opaque pass: its depth is what the volumes are tested against.
    if (host.drawOpaque) plan.steps.push_back(step(StepKind::HostOpaque));
    // 1a. A depth buffer that cannot be sampled, copied once it is complete (before anything reads it).
    if (depth.copied && depth.texture) plan.steps.push_back(step(StepKind::CopyHostDepth));

    const std::string noDepth = "no host depth to read (" +
                                (depth.missing.empty() ? std::string("HostTarget::depthTexture, a texture depth attachment or a depth buffer to copy")
                                                       : depth.missing) +
                                ")";
    const bool fogHost = plan.fog && desc.fogHost;
    if (fogHost) {
        if (hasDepth) plan.fogHost = true;
        else if (multisampled) plan.fogNote = multisampledNote("fog of the host image skipped", depth.samples);
        else plan.fogNote = "fog of the host image skipped: " + noDepth;
    }

    // The order-exact path: the splats go into the fragment lists with the
    // host's transparent surfaces (step 3) when nothing the lists cannot draw
    // is in the frame; otherwise they are drawn in step 2 as usual and only
    // the surfaces are sorted (among themselves) in step 3.
    plan.lists = host.transparentToLists && bool(host.drawTransparent);
    plan.splatsInLists = plan.lists && !plan.reduced && !plan.tetrahedra && hasDepth && !multisampled;
    if (plan.lists && !plan.splatsInLists)
        plan.listsNote = plan.reduced      ? "reduced resolution: the splats take the ordered blend under the surfaces"
                         : plan.tetrahedra ? "tetrahedra in the frame: the volumes take the ordered blend under the surfaces"
                         : multisampled && hasDepth
                             ? "multisampled host (" + std::to_string(depth.samples) +
                                   " samples): the splats take the ordered blend under the surfaces (drawn per sample; the list sections are per pixel)"
                         : multisampled ? multisampledNote("the splats take the ordered blend under the surfaces", depth.samples)
                                           : noDepth + ": the splats take the ordered blend under the surfaces";

    // 1b. The fog of the host's opaque image, read from its depth, and
    // 2. the volumes, back to front: once, or (multisampled) once per sample,
    // each run reading that sample's depth and drawing into that sample only.
    const std::size_t splats = frame.splats().size();
    auto fogAndVolumes = [&] {
        if (plan.fogHost) plan.steps.push_back(step(StepKind::HostFog));
        if (plan.splatsInLists) {
            // drawn in step 3
        } else if (plan.tetrahedra) {
            planInterleaved(frame, desc, plan.reduced, plan);
        } else if (!plan.reduced) {
            plan.steps.push_back(splatRange(0, splats));
        } else {
            plan.steps.push_back(step(StepKind::ReducedSplats));
        }
        if (multisampled && !hasDepth && desc.splats.depthCut && splats > 0 && !plan.splatsInLists)
            plan.steps.back().note = multisampledNote("depth cut off (the plain depth test at each splat's plane)", depth.samples);
    };
    if (plan.samples > 1) {
        // (Nothing per sample when the splats go into the lists and no fog is drawn.)
        const int perSample = plan.fogHost || !plan.splatsInLists ? plan.samples : 0;
        for (int s = 0; s < perSample; ++s) {
            plan.steps.push_back({.kind = StepKind::HostDepthSample, .sample = s});
            fogAndVolumes();
        }
        // Unlike the full-resolution layer (shifted onto each sample's positions), the reduced
        // one is drawn at its own texel centres in every sample's run: said once, on the first.
        if (plan.reduced && perSample > 0 && (splats > 0 || plan.tetrahedra)) {
            const auto first = std::find_if(plan.steps.begin(), plan.steps.end(), [](const PlanStep& st) {
                return st.kind == StepKind::ReducedSplats || st.kind == StepKind::ReducedBegin;
            });
            if (first != plan.steps.end() && first->note.empty())
                first->note = "reduced resolution (resolutionScale " + std::to_string(desc.resolutionScale) + ") on a multisampled host (" +
                              std::to_string(plan.samples) +
                              " samples): the reduced layer is drawn at its own texel centres in every sample's run, not shifted onto the "
                              "sample positions";
        }
        plan.steps.push_back({.kind = StepKind::HostDepthSample, .sample = -1});
        if (plan.lists)
            plan.steps.back().note = "fragment lists on a multisampled host (" + std::to_string(plan.samples) +
                                     " samples): each pixel resolved once, against its nearest sample's depth";
    } else {
        fogAndVolumes();
    }

    // 3. The host's transparent surfaces, over the volumes: into the lists,
    // the splats cut into sections at them, every pixel sorted and
    // composited; or blended in the host's own order.
    if (plan.lists) {
        plan.steps.push_back(step(StepKind::ListsCollect));
        if (plan.splatsInLists) {
            // The splats behind every surface they cover, and those in front
            // of every one, take the ordinary splat pass before and after the
            // resolve; the rest are sectioned, except with a fog (fogged
            // sections are not implemented): then they take the ordered blend.
            plan.steps.push_back(step(StepKind::ListsSplit));
            if (plan.fog) {
                plan.steps.push_back(listRun(StepKind::Splats, StepRange::ListsBehindAndBetween));
                plan.steps.back().note = "fog: the splats that meet a surface take the ordered blend under the surfaces "
                                         "(fogged sections not implemented)";
            } else {
                plan.steps.push_back(listRun(StepKind::Splats, StepRange::ListsBehind));
                plan.steps.push_back(listRun(StepKind::ListsSections, StepRange::ListsBetween));
            }
        }
        plan.steps.push_back(step(StepKind::ListsResolve));
        if (plan.splatsInLists) plan.steps.push_back(listRun(StepKind::Splats, StepRange::ListsFront));
    } else if (host.drawTransparent) {
        plan.steps.push_back(step(StepKind::HostTransparent));
    }
    plan.steps.push_back(step(StepKind::UnbindShadow));
    return plan;
}

const char* toString(StepKind kind) {
    switch (kind) {
    case StepKind::UploadShadow: return "UploadShadow";
    case StepKind::PrepareTetrahedra: return "PrepareTetrahedra";
    case StepKind::HostOpaque: return "HostOpaque";
    case StepKind::CopyHostDepth: return "CopyHostDepth";
    case StepKind::HostDepthSample: return "HostDepthSample";
    case StepKind::HostFog: return "HostFog";
    case StepKind::Splats: return "Splats";
    case StepKind::ReducedSplats: return "ReducedSplats";
    case StepKind::ReducedBegin: return "ReducedBegin";
    case StepKind::ReducedComposite: return "ReducedComposite";
    case StepKind::Tetrahedra: return "Tetrahedra";
    case StepKind::ListsCollect: return "ListsCollect";
    case StepKind::ListsSplit: return "ListsSplit";
    case StepKind::ListsSections: return "ListsSections";
    case StepKind::ListsResolve: return "ListsResolve";
    case StepKind::HostTransparent: return "HostTransparent";
    case StepKind::UnbindShadow: return "UnbindShadow";
    }
    return "?";
}

std::string describe(const PlanStep& s) {
    std::string line = toString(s.kind);
    if (s.kind == StepKind::Tetrahedra) line += " volume " + std::to_string(s.volume);
    if (s.kind == StepKind::HostDepthSample) line.append(" ").append(s.sample >= 0 ? std::to_string(s.sample) : std::string("nearest"));
    switch (s.range) {
    case StepRange::Explicit:
        if (s.kind == StepKind::Splats || s.kind == StepKind::Tetrahedra) line += " [" + std::to_string(s.begin) + ", " + std::to_string(s.end) + ")";
        break;
    case StepRange::ListsBehind: line += " (behind every surface)"; break;
    case StepRange::ListsBetween: line += " (meeting a surface)"; break;
    case StepRange::ListsFront: line += " (in front of every surface)"; break;
    case StepRange::ListsBehindAndBetween: line += " (behind or meeting a surface)"; break;
    }
    if (s.target == StepTarget::Reduced) line += " into the reduced image";
    if (!s.note.empty()) line += ": " + s.note;
    return line;
}

} // namespace splatfx::gl
