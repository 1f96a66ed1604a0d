// splatfx/gl/frame_plan.hpp: what gl::FrameRenderer will run for one frame, as plain data.
//
// planFrame() decides, from the frame, the host's target, the renderer's desc
// and what the host's GL objects are (HostDepth, queried once by the frame
// renderer), every ordering and fallback choice of a frame: which passes run,
// in which order, over which primitives, into which target, and, where a pass
// cannot run as asked, a note that reaches FrameRenderStats. The frame
// renderer then only executes the steps. The plan is GL-free: it runs and is
// tested without a context, and a host or tool can print it
// (FrameRenderer::plan(), describe()) to see why a frame looks as it does.
// It draws nothing and owns nothing: the plan points into the Frame it was
// made from.
//
//   const splatfx::gl::FramePlan plan = splatfx::gl::planFrame(frame, hostTarget, desc, {.texture = depth, .samples = 1});
//   for (const splatfx::gl::PlanStep& s : plan.steps) std::puts(splatfx::gl::describe(s).c_str());
//   // or, after render(): frameRenderer->plan()
//
// Threading: pure functions; any thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "splatfx/frame.hpp"
#include "splatfx/gl/frame_renderer.hpp"

namespace splatfx::gl {

// The host's depth as the passes can read it: the texture behind
// HostTarget::depthTexture, or behind the framebuffer's depth attachment when
// that is a texture, or (copied) the frame renderer's own texture that the
// framebuffer's depth buffer (the default framebuffer's, a renderbuffer) is
// copied into after the host's opaque pass. Looked up once a frame by the
// frame renderer.
// A multisampled one is read one sample at a time: the HostDepthSample steps
// copy sample s into `sampleTexture` (single-sampled) and restrict the
// drawing to sample s (glSampleMaski) before the passes that read it run.
struct HostDepth {
    unsigned texture = 0;       // GL name; 0: none that can be sampled
    int samples = 0;            // its sample count (0 or 1: single-sampled)
    bool copied = false;        // `texture` is filled by the CopyHostDepth step
    std::string missing;        // with no texture: why none could be read or copied (for the notes)
    unsigned sampleTexture = 0; // samples > 1: the single-sample texture the passes read (0: none could be made)
};

enum class StepKind : std::uint8_t {
    UploadShadow,      // the frame's shadow table (when it changed), bound for the hooks
    PrepareTetrahedra, // pre-integration tables that changed; per-tetrahedron data
    HostOpaque,        // HostTarget::drawOpaque
    CopyHostDepth,     // the framebuffer's depth buffer into a texture the passes read (HostDepth::copied)
    HostDepthSample,   // multisampled host: sample `sample` of its depth into the passes' texture, drawing into that sample only
    HostFog,           // the fog of the host's opaque image
    Splats,            // splats of `range`, full resolution
    ReducedSplats,     // every splat, at reduced resolution, composited over the host
    ReducedBegin,      // clear the reduced image (or the full-size volume layer), downsample the host depth into it
    ReducedComposite,  // upsample the reduced image (composite the layer) over the host
    Tetrahedra,        // tetrahedra [begin, end) of Frame::volumes()[volume]
    ListsCollect,      // HostTarget::drawTransparent into the per-pixel lists
    ListsSplit,        // the splats as runs behind / between / in front of the surfaces
    ListsSections,     // the splats between the surfaces, composited per section
    ListsResolve,      // each pixel's surfaces and sections sorted and composited
    HostTransparent,   // HostTarget::drawTransparent, blended over (no lists)
    UnbindShadow,      // the shadow table's unit back as the host had it
};

// Which primitives a step draws. The list runs are known only once the lists
// are collected (ListsSplit reads the surfaces' depth range back).
enum class StepRange : std::uint8_t {
    Explicit,              // [begin, end)
    ListsBehind,           // the splats behind every surface they cover
    ListsBetween,          // the splats that meet a surface
    ListsFront,            // the splats in front of every surface they cover
    ListsBehindAndBetween, // behind and between, as ordinary splats (the between run cannot be sectioned)
};

// Into which image a drawing step goes.
enum class StepTarget : std::uint8_t {
    Host,    // the host's framebuffer
    Reduced, // the reduced image (at resolutionScale 1: the volume layer) between ReducedBegin and ReducedComposite
};

struct PlanStep {
    StepKind kind = StepKind::UploadShadow;
    StepTarget target = StepTarget::Host;
    StepRange range = StepRange::Explicit;
    std::uint32_t volume = 0;       // Tetrahedra: index into Frame::volumes()
    std::size_t begin = 0, end = 0; // StepRange::Explicit: into Frame::splats() or the volume's tetrahedra
    // HostDepthSample: the sample (drawing restricted to it); -1: the nearest
    // sample of each pixel, drawing into every sample again.
    int sample = 0;
    std::string note{};             // empty, or how this step falls back from what was asked
};

struct FramePlan {
    PassTarget target;        // the host's viewport and depth, resolved once
    const Fog* fog = nullptr; // the frame's fog (null: clear air)
    double timeSec = 0.0;     // the frame's time (the fog's)
    // The fog's parameters at timeSec relative to the frame camera's eye
    // (Fog::glslParameters), computed once a frame for every fogged pass.
    std::vector<glm::vec4> fogParameters;
    bool tetrahedra = false;     // the frame has tetrahedra to draw
    bool reduced = false;        // splats at 1/resolutionScale per axis
    bool fogHost = false;        // HostFog is among the steps
    bool lists = false;          // the host's surfaces go through the fragment lists
    bool splatsInLists = false;  // ... and the splats are cut into sections at them
    // A multisampled host depth (HostDepth::samples > 1): the host fog and
    // the volumes run once per sample, each against that sample's depth and
    // drawing into that sample only; the fragment lists read each pixel's
    // nearest sample. 0: a single-sampled host.
    int samples = 0;
    std::string fogNote;         // why the host image is not fogged although the frame has a fog
    std::string listsNote;       // why the splats take the ordered blend in a list frame
    std::vector<PlanStep> steps; // in order
};

// The frame's steps. Expects a frame camera with a positive viewport.
FramePlan planFrame(const Frame& frame, const HostTarget& host, const FrameRendererDesc& desc, const HostDepth& depth);
// One line per step, e.g. "Tetrahedra volume 1 [0, 840) into the reduced image"
// or "HostDepthSample 2".
std::string describe(const PlanStep& step);
const char* toString(StepKind kind);

} // namespace splatfx::gl
