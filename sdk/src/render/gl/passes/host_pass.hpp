// The host's own geometry: its hooks run at the plan's HostOpaque and
// HostTransparent steps, with its framebuffer bound and the viewport set.
// A host depth buffer that cannot be sampled (the default framebuffer's, a
// renderbuffer) is copied into a texture of the same format at the plan's
// CopyHostDepth step, once the opaque pass has written it.
#pragma once

#include <string>

#include "pass.hpp"

namespace splatfx::gl::detail {

class HostPass final : public Pass {
public:
    HostPass() = default;
    HostPass(const HostPass&) = delete;
    HostPass& operator=(const HostPass&) = delete;
    ~HostPass() override;

    // The texture `framebuffer`'s depth buffer will be copied into (covering
    // [0, width) x [0, height)), made or resized to match its format; none,
    // with the reason in HostDepth::missing, when there is no depth buffer,
    // it is multisampled or no texture format matches it.
    HostDepth depthCopy(unsigned framebuffer, int width, int height);
    void prepare(const FramePlan& plan, const Frame& frame) override;
    void execute(const PlanStep& step, StepContext& context) override; // HostOpaque, CopyHostDepth, HostTransparent
    void report(FrameRenderStats& stats) const override;

private:
    unsigned mTexture = 0, mFbo = 0;
    unsigned mFormat = 0;
    int mWidth = 0, mHeight = 0;
    bool mCopied = false;     // this frame's CopyHostDepth ran
    std::string mCopyError{}; // ... and failed
};

} // namespace splatfx::gl::detail
