// splatfx/frame.hpp: everything one frame draws, as plain data.
//
// A Frame is what a Scene prepares for a camera at a time and what
// gl::FrameRenderer (or the reference renderer) draws: the camera, the time,
// the splats of every needed effect sorted back to front in one list, and
// counters saying what was declared, simulated and drawn. It is GL-free: the
// same Frame can be drawn by the GL backend and integrated by the CPU
// reference, which is how the backend is measured.
// It does not simulate (Scene does), render (gl::FrameRenderer does) or own
// GPU resources. Later passes (fog, lights and shadow tables, volume
// primitives) join it as further plain-data members.
//
//   splatfx::Frame frame;                          // keep it: it reuses its memory
//   scene.prepare(timeSec, camera, materials, frame);
//   frameRenderer->render(frame, {.framebuffer = fbo, .depthTexture = depth});
//
// Hand-made content without a Scene goes through the same object:
//   frame.begin(timeSec, camera); frame.builder().add(grid, materials, style); frame.end();
//
// Threading: a plain value; one thread at a time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/splats.hpp"

namespace splatfx {

// What a frame holds and what it cost to decide (Scene fills the effect counts).
struct FrameCounters {
    std::size_t declared = 0;  // effects in the scene
    std::size_t needed = 0;    // in view, in range, alive and enabled (= simulated and drawn)
    std::size_t simulated = 0; // effects that did dynamics work for this frame
    std::size_t drawn = 0;     // effects that emitted at least one splat
    std::uint64_t voxels = 0;  // voxels offered to the splat builder
    std::uint64_t splats = 0;  // splats in the frame
};

class Frame {
public:
    explicit Frame(const SplatBuilderDesc& builder = {}) : mBuilder(builder) {}

    // Starts a frame for this camera at timeSec: clears the splats (keeping
    // their memory) and the counters.
    void begin(double timeSec, const Camera& camera);
    // Where content is added between begin() and end().
    SplatBuilder& builder() { return mBuilder; }
    // Sorts the splats back to front (one order across every effect).
    void end(SortMode mode = SortMode::Exact);

    double time() const { return mTime; }
    const Camera& camera() const { return mBuilder.camera(); }
    // Sorted back to front after end().
    const std::vector<Splat>& splats() const { return mBuilder.splats(); }
    const SplatStats& splatStats() const { return mBuilder.stats(); }
    const FrameCounters& counters() const { return mCounters; }
    FrameCounters& counters() { return mCounters; }

    // --- Fog (issue 14, docs/fog.md) -------------------------------------
    // The one medium the frame is seen through: gl::FrameRenderer fogs the
    // host's opaque image with it and applies it per fragment to every
    // splat, at time(). Not cleared by begin() (a setting, not content);
    // Scene::prepare sets it from Scene::setFog. nullptr: clear air (default).
    void setFog(std::shared_ptr<const Fog> fog) { mFog = std::move(fog); }
    const Fog* fog() const { return mFog.get(); }
    const std::shared_ptr<const Fog>& sharedFog() const { return mFog; }
    // --- end fog ---------------------------------------------------------

private:
    SplatBuilder mBuilder;
    FrameCounters mCounters;
    double mTime = 0.0;
    std::shared_ptr<const Fog> mFog; // fog (issue 14); default none
};

} // namespace splatfx
