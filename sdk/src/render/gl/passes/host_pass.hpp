// The host's own geometry: its hooks run at the plan's HostOpaque and
// HostTransparent steps, with its framebuffer bound and the viewport set.
#pragma once

#include "pass.hpp"

namespace splatfx::gl::detail {

class HostPass final : public Pass {
public:
    void execute(const PlanStep& step, StepContext& context) override; // HostOpaque, HostTransparent
    void report(FrameRenderStats&) const override {}
};

} // namespace splatfx::gl::detail
