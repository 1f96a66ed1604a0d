#include "host_pass.hpp"

#include <cassert>

#include <epoxy/gl.h>

namespace splatfx::gl::detail {

void HostPass::execute(const PlanStep& step, StepContext& context) {
    assert(step.kind == StepKind::HostOpaque || step.kind == StepKind::HostTransparent);
    const PassTarget& t = context.plan.target;
    glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
    glViewport(t.x, t.y, t.width, t.height);
    if (step.kind == StepKind::HostOpaque) context.host.drawOpaque();
    else context.host.drawTransparent();
}

} // namespace splatfx::gl::detail
