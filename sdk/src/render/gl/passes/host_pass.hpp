// The host's own geometry: its hooks run at the plan's HostOpaque and
// HostTransparent steps, with its framebuffer bound and the viewport set.
// A host depth buffer that cannot be sampled (the default framebuffer's, a
// renderbuffer) is copied into a texture of the same format at the plan's
// CopyHostDepth step, once the opaque pass has written it. A multisampled
// one (copied into a multisampled texture when it is not one) is read one
// sample at a time: each HostDepthSample step copies sample s into a
// single-sample depth texture the passes read and restricts the drawing to
// sample s (GL_SAMPLE_MASK), shaded at its position (GL_SAMPLE_SHADING), until the last (sample -1) copies each pixel's
// nearest sample and puts the host's multisample state back.
#pragma once

#include <string>
#include <utility>

#include "pass.hpp"
#include "render/gl/program_library.hpp"

namespace splatfx::gl::detail {

class HostPass final : public Pass {
public:
    explicit HostPass(Programs programs) : mPrograms(std::move(programs)) {}
    HostPass(const HostPass&) = delete;
    HostPass& operator=(const HostPass&) = delete;
    ~HostPass() override;

    // The texture `framebuffer`'s depth buffer will be copied into (covering
    // [0, width) x [0, height)), made or resized to match its format; none,
    // with the reason in HostDepth::missing, when there is no depth buffer,
    // no texture format matches it (multisampled: a multisampled texture of
    // the same sample count).
    HostDepth depthCopy(unsigned framebuffer, int width, int height);
    // A multisampled `depth`: its sampleTexture, the single-sample texture
    // (covering [0, width) x [0, height)) its samples are copied into, made
    // or resized; 0 with the reason in `missing` when it cannot be.
    void addSampleTexture(HostDepth& depth, int width, int height);
    void prepare(const FramePlan& plan, const Frame& frame) override;
    void execute(const PlanStep& step, StepContext& context) override; // HostOpaque, CopyHostDepth, HostDepthSample, HostTransparent
    void report(FrameRenderStats& stats) const override;

private:
    void copySample(const PlanStep& step, StepContext& context);

    Programs mPrograms;
    unsigned mTexture = 0, mFbo = 0; // the copy of a depth buffer that is not a texture
    unsigned mFormat = 0;
    int mWidth = 0, mHeight = 0, mSamples = 0;
    unsigned mSampleTexture = 0, mSampleFbo = 0, mVao = 0; // a multisampled host depth's current sample (DEPTH_COMPONENT32F)
    int mSampleWidth = 0, mSampleHeight = 0;
    unsigned mSource = 0;      // this frame's multisampled depth texture
    int mSourceSamples = 0;    // ... and its sample count
    bool mReversed = false;    // the frame's depth convention is reversed (the nearest sample is the largest)
    // The host's multisample state, saved by the first HostDepthSample step of a frame and put back by the last.
    bool mMaskSaved = false;
    bool mHostSampleMask = false, mHostMultisample = true;
    unsigned mHostMaskWord = ~0u;
    bool mHostSampleShading = false;
    float mHostMinSampleShading = 0.0f;
    int mSampleSteps = 0;     // HostDepthSample steps this frame
    bool mCopied = false;     // this frame's CopyHostDepth ran
    std::string mCopyError{}; // ... and failed
};

} // namespace splatfx::gl::detail
