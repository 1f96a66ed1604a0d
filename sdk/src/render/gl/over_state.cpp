#include "over_state.hpp"

#include <epoxy/gl.h>

namespace splatfx::gl::detail {

void setOverState(unsigned framebuffer, const PassTarget& target, DepthTest test) {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer);
    glViewport(target.x, target.y, target.width, target.height);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glBlendEquationSeparate(GL_FUNC_ADD, GL_FUNC_ADD);
    glDepthMask(GL_FALSE);
    if (test != DepthTest::Off) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(test == DepthTest::GreaterEqual ? GL_GEQUAL : GL_LEQUAL);
    } else {
        glDisable(GL_DEPTH_TEST);
    }
}

} // namespace splatfx::gl::detail
