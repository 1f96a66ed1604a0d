// splatfx/frame.hpp: everything one frame draws, as plain data.
//
// A Frame is what a Scene prepares for a camera at a time and what
// gl::FrameRenderer (or the reference renderer) draws: the camera, the time,
// the splats of every needed effect sorted back to front in one list, and
// counters saying what was declared, simulated and drawn. It is GL-free: the
// same Frame can be drawn by the GL backend and integrated by the CPU
// reference, which is how the backend is measured.
// It does not simulate (Scene does), render (gl::FrameRenderer does) or own
// GPU resources. Later passes (fog, lights and shadow tables) join it as
// further plain-data members; LOD volumes already have (volumes(): their
// tetrahedra and tables, and drawOrder(): splats and tetrahedra interleaved
// back to front, made by end()).
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
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/splats.hpp"
#include "splatfx/volume.hpp"

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


// ---- [clouds, issue 17] LOD volumes drawn as projected tetrahedra ----
// One volume's tetrahedra for this frame (LodVolume::update's output) and the
// pre-integration table they are drawn with. Scene::prepare fills these;
// hosts without a Scene push them between begin() and end().
struct FrameVolume {
    const PreIntegrationTable* table = nullptr; // not owned; must outlive the render; null: not drawn
    std::uint64_t tableVersion = 0;            // change it when the table at this address changes (the GL pass re-uploads); default 0
    LodFrame lod;                               // lod.tets back to front, world space
};
// One run of the interleaved back-to-front draw sequence (Frame::drawOrder).
struct DrawBatch {
    enum class Kind : std::uint8_t { Splats, Tetrahedra };
    Kind kind = Kind::Splats;
    std::uint32_t volume = 0;               // index into Frame::volumes() (Tetrahedra only)
    std::uint32_t begin = 0, end = 0;       // [begin, end) into splats() or volumes()[volume].lod.tets
};
// Merges the splats (sorted back to front) and every volume's tetrahedra
// (each list in its own exact visibility order) into one back-to-front
// sequence of batches. Each list keeps its order; between lists, a
// tetrahedron's key is the largest eye distance of a centroid at or after it
// in its list (so the keys never increase along a list) and a splat's key is
// its depth. Exact within each list; across lists it is a centroid order, so a
// splat inside a tetrahedron is drawn wholly before or after it (docs/volume.md).
void interleaveBackToFront(const std::vector<Splat>& splats, const std::vector<FrameVolume>& volumes, const Camera& camera,
                           std::vector<DrawBatch>& out);
// ---- end [clouds] ----

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

    // ---- [clouds, issue 17] ----
    // Volumes to draw as tetrahedra (cleared by begin()).
    std::vector<FrameVolume>& volumes() { return mVolumes; }
    const std::vector<FrameVolume>& volumes() const { return mVolumes; }
    // The interleaved draw sequence of splats and tetrahedra, made by end()
    // (interleaveBackToFront); one Splats batch when there are no volumes.
    const std::vector<DrawBatch>& drawOrder() const { return mDrawOrder; }
    // ---- end [clouds] ----

private:
    SplatBuilder mBuilder;
    FrameCounters mCounters;
    double mTime = 0.0;
    std::vector<FrameVolume> mVolumes;   // [clouds]
    std::vector<DrawBatch> mDrawOrder;   // [clouds]
};

} // namespace splatfx
