// The one shape every pass of gl::FrameRenderer has: upload what materials
// changed, prepare once a frame, execute the plan's steps it owns, report
// its share of FrameRenderStats. The frame renderer owns the order (the plan,
// frame_plan.hpp); a pass never decides what runs next.
#pragma once

#include <cstddef>
#include <utility>
#include <string>
#include <vector>

#include "splatfx/frame.hpp"
#include "splatfx/gl/frame_plan.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/result.hpp"

namespace splatfx::gl::detail {

// What the steps of one frame share, beyond the plan.
struct StepContext {
    const Frame& frame;
    const HostTarget& host; // the hooks
    const FramePlan& plan;
    PassTarget reduced{}; // the reduced image, between ReducedBegin and ReducedComposite
    // ListsSplit's runs of the sorted splats: [0, behindEnd) behind every
    // surface, [frontBegin, size) in front of every one, the rest between.
    std::size_t behindEnd = 0, frontBegin = 0;
    bool listsReady = false;  // ListsCollect succeeded (the later list steps run only then)
    unsigned splatLayers = 0; // the splat pass's texture array (the list sections sample it)
    std::string listsNote{};  // why (some) splats took the ordered blend, found while executing
    // A multisampled host's per-sample run through the full-resolution volume
    // layer (single-sampled): the frame's camera with its image shifted so the
    // layer's pixel centres lie on that sample's positions, what the volume
    // steps into the layer project with; null otherwise (frame.camera()).
    const Camera* layerCamera = nullptr;

    // The splats a step draws: [begin, end) of Frame::splats().
    std::pair<std::size_t, std::size_t> range(const PlanStep& step) const;
};

class Pass {
public:
    virtual ~Pass() = default;
    // Materials changed (texture layers, colour rows, the footprint's tables).
    virtual Status upload(const Materials&) { return {}; }
    // Once a frame, before its first step: per-frame state (the fog variant, tables).
    virtual void prepare(const FramePlan&, const Frame&) {}
    virtual void execute(const PlanStep& step, StepContext& context) = 0;
    // Writes this pass's share of the last frame's statistics.
    virtual void report(FrameRenderStats& stats) const = 0;
};

} // namespace splatfx::gl::detail
