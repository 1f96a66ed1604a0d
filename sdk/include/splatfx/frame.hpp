// splatfx/frame.hpp: everything one frame draws, as plain data.
//
// A Frame is what a Scene prepares for a camera at a time and what
// gl::FrameRenderer (or the reference renderer) draws: the camera, the time,
// the splats of every needed effect sorted back to front in one list, and
// counters saying what was declared, simulated and drawn. It is GL-free: the
// same Frame can be drawn by the GL backend and integrated by the CPU
// reference, which is how the backend is measured.
// It does not simulate (Scene does), render (gl::FrameRenderer does) or own
// GPU resources. Besides the splats it holds the gas's shadows on the scene
// (shadows(), one FrameShadow per shadowing light), the fog (fog()), LOD volumes (volumes(): their
// tetrahedra and tables) and drawOrder(): splats and tetrahedra interleaved
// back to front, made by end().
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

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/camera.hpp"
#include "splatfx/emitted_light.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/lighting.hpp"
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
    // Lighting (Scene fills them).
    std::size_t litEffects = 0;          // needed effects lit by the scene's lights
    std::uint64_t shadowTableBuilds = 0; // shadow tables (self-shadowing and the scene's) rebuilt for this frame
    std::uint64_t shadowTableReuses = 0; // ... and reused because density and light had not changed
    std::size_t shadowLights = 0;        // lights with a table in shadows() (SceneShadowDesc::maxLights)
    // Lights that cast onto the view but got no table: past maxLights, or
    // over SceneShadowDesc::memoryBudgetBytes / Budgets::lightingBytes (the
    // least influential are dropped first). SceneCounters says which.
    std::size_t shadowLightsDropped = 0;
};

// The shadow the frame's gas casts on the scene towards one light.
// One shadow table (lighting.hpp, ShadowTable) for one light, covering every
// needed effect that casts shadows, as plain data: what gl::FrameRenderer
// uploads as a 3D texture before the host's opaque pass, and what the GLSL
// of shadowGlsl() samples. Empty (valid = false): nothing is shadowed.
struct FrameShadow {
    bool valid = false;       // default false: no shadow this frame
    std::vector<float> depth; // dims.x * dims.y * dims.z optical depths (log2), x fastest
    glm::ivec3 dims{0};
    glm::mat4 worldToTable{1.0f};                    // world to the table's [0, 1]^3 (ShadowTable::worldToTable)
    glm::vec4 lightInTable{0.0f, -1.0f, 0.0f, 0.0f}; // ShadowTable::lightInTable
    int light = 0;                                   // the scene light (index into Scene::lights()) it is cast by; default 0
    // Changes whenever the contents do (a renderer re-uploads only then); 0 when never filled.
    std::uint64_t version = 0;
};

// LOD volumes drawn as projected tetrahedra: one volume's tetrahedra for this frame (LodVolume::update's output) and the
// pre-integration table they are drawn with. Scene::prepare fills these;
// hosts without a Scene push them between begin() and end().
struct FrameVolume {
    const PreIntegrationTable* table = nullptr; // not owned; must outlive the render; null: not drawn
    std::uint64_t tableVersion = 0;             // change it when the table at this address changes (the GL pass re-uploads); default 0
    LodFrame lod;                               // lod.tets back to front, world space
};
// One run of the interleaved back-to-front draw sequence (Frame::drawOrder).
struct DrawBatch {
    enum class Kind : std::uint8_t { Splats, Tetrahedra };
    Kind kind = Kind::Splats;
    std::uint32_t volume = 0;         // index into Frame::volumes() (Tetrahedra only)
    std::uint32_t begin = 0, end = 0; // [begin, end) into splats() or volumes()[volume].lod.tets
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
    // The gas's shadow on the scene, one slot per shadowing light: kept
    // across begin() (each version says when it changed). Slot 0 is
    // SceneShadowDesc::light's (splatfx_shadow() of shadowGlsl()); the others
    // hold the next lights by influence, in light order; unused slots are invalid.
    const std::array<FrameShadow, kMaxShadowLights>& shadows() const { return mShadows; }
    std::array<FrameShadow, kMaxShadowLights>& shadows() { return mShadows; }
    const FrameShadow& shadow() const { return mShadows[0]; }
    FrameShadow& shadow() { return mShadows[0]; }

    // The one medium the frame is seen through: gl::FrameRenderer fogs the
    // host's opaque image with it and applies it per fragment to every
    // splat, at time(). Not cleared by begin() (a setting, not content);
    // Scene::prepare sets it from Scene::setFog. nullptr: clear air (default).
    // docs/fog.md.
    void setFog(std::shared_ptr<const Fog> fog) { mFog = std::move(fog); }
    const Fog* fog() const { return mFog.get(); }
    const std::shared_ptr<const Fog>& sharedFog() const { return mFog; }

    // Light the frame's emissive volumes give the host's surfaces (cleared by
    // begin()): what splatfx_emittedIrradiance of shadowGlsl() adds, through
    // gl::ShadowBinding. Scene::prepare fills it (EffectOptions::emitsLight),
    // brightest first, at most kMaxEmittedLights. emitted_light.hpp.
    std::vector<EmittedLight>& emittedLights() { return mEmittedLights; }
    const std::vector<EmittedLight>& emittedLights() const { return mEmittedLights; }
    // The frame's irradiance grid (cleared by begin()): what
    // splatfx_emittedGridIrradiance adds. Scene::prepare fills it from the
    // first effect in EmittedLightMode::Grid (the GLSL holds one grid).
    EmittedGrid& emittedGrid() { return mEmittedGrid; }
    const EmittedGrid& emittedGrid() const { return mEmittedGrid; }

    // Volumes to draw as tetrahedra (cleared by begin()).
    std::vector<FrameVolume>& volumes() { return mVolumes; }
    const std::vector<FrameVolume>& volumes() const { return mVolumes; }
    // The interleaved draw sequence of splats and tetrahedra, made by end()
    // (interleaveBackToFront); one Splats batch when there are no volumes.
    const std::vector<DrawBatch>& drawOrder() const { return mDrawOrder; }

private:
    SplatBuilder mBuilder;
    FrameCounters mCounters;
    std::array<FrameShadow, kMaxShadowLights> mShadows{};
    double mTime = 0.0;
    std::shared_ptr<const Fog> mFog; // default none
    std::vector<FrameVolume> mVolumes;
    std::vector<EmittedLight> mEmittedLights;
    EmittedGrid mEmittedGrid;
    std::vector<DrawBatch> mDrawOrder;
};

} // namespace splatfx
