// tools/scenehost/scene_player.hpp: plays a scene file through the SDK's frame (host side).
//
// Loads a scene file (splatfx::loadSceneFile), its geometry (GeometryRenderer)
// and a gl::FrameRenderer, and draws one frame at a time: Scene::prepare for
// the camera, then FrameRenderer::render with this host's opaque pass (clear
// and geometry, with depth writes) as its hook, so the SDK owns the order of
// the passes. The render tool, the viewer and the sample tests share it, so
// they draw exactly alike.
// Not part of the SDK: it is an example host.
//
//   auto player = scenehost::ScenePlayer::load("samples/05-teapot-steam/scene.json", {});
//   player->renderFrame(timeSec, player->cameraAt(timeSec, size), fbo);
//
// Time passed to renderFrame / advance must not decrease (solver effects simulate
// forward); reload to start over.
// Threading: the GL thread only. Move-only.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry_renderer.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/scene_file.hpp"

namespace scenehost {

struct PlayerOptions {
    std::optional<std::uint32_t> seed;         // replaces the file's seed; default the file's
    splatfx::gl::FrameRendererDesc renderer{}; // the frame renderer's settings; default the SDK's
    splatfx::Budgets budgets{};                // what the file and its meshes may ask for (budget.hpp); default the SDK's
};

struct FrameOptions {
    bool traditional = false;  // every effect untextured (Fig. 1a); default false
    float opacityScale = 1.0f; // multiplies every splat's opacity; default 1
    bool drawGeometry = true;  // default true
    bool clear = true;         // clear colour (scene background) and depth first; default true
    // Biri et al.'s buffer method (sec. 4.3): the geometry fogs itself per
    // vertex (GeometryLighting::vertexFog) with the scene's fog. Needs a
    // renderer with fogHost off (else the geometry would be fogged twice:
    // renderFrame refuses). The background is not fogged. Default false.
    bool fogPerVertex = false;
};

struct FrameStats {
    splatfx::FrameCounters counters;            // declared / needed / simulated / drawn, voxels, splats
    std::vector<std::uint64_t> splatsPerEffect; // in SceneFile::effects order (0 when skipped)
    double prepareMs = 0.0;                     // CPU: Scene::prepare (decide, simulate, build, sort)
    double renderMs = 0.0;                      // CPU: FrameRenderer::render (GL submission, geometry included)
};

class ScenePlayer {
public:
    // Needs a current GL 4.5 context. Errors carry the scene file's message.
    static splatfx::Result<ScenePlayer> load(const std::string& path, const PlayerOptions& options = {});
    // Same from text (the viewer's editor); `path` anchors relative paths.
    static splatfx::Result<ScenePlayer> fromText(const std::string& text, const std::string& path, const PlayerOptions& options = {});
    ScenePlayer(ScenePlayer&&) noexcept;
    ScenePlayer& operator=(ScenePlayer&&) noexcept;
    ~ScenePlayer();

    // The scene file's camera path at t for a viewport.
    // `depth`: the host's depth convention (its clear value and depth test follow the camera's).
    splatfx::Camera cameraAt(double timeSec, glm::ivec2 viewport, const splatfx::DepthConvention& depth = {}) const;
    // Draws the frame at timeSec (>= the previous call's) into the host
    // framebuffer (0: the default one) over camera.viewport. Fails, drawing
    // nothing, as Scene::prepare does (a time past splatfx::kMaxTimeSec).
    splatfx::Status renderFrame(double timeSec, const splatfx::Camera& camera, unsigned framebuffer, const FrameOptions& options = {});
    // Everything renderFrame does except drawing: Scene::prepare (decide,
    // simulate, emit, sort) for this time and camera, stats() updated. A
    // render-farm task replays the frames before its range with it, so the
    // scene's state (solver effects, catch-ups, shadow tables) at its first
    // frame is the state a full run has there; the GL side caches only by
    // content version, so skipping its draws changes nothing drawn later.
    splatfx::Status advance(double timeSec, const splatfx::Camera& camera, const FrameOptions& options = {});
    // What the last advance() or renderFrame() could not do, or empty: a
    // lighting or shadow failure (Scene::lightingError: effects drawn unlit,
    // no scene shadow), or a terrain mesh the GL could not store. The frame
    // was drawn without it; a tool must not pass it off as complete.
    const std::string& problem() const;

    splatfx::SceneFile& file();
    const splatfx::SceneFile& file() const;
    const splatfx::Materials& materials() const;
    const FrameStats& stats() const;
    GeometryRenderer& geometry();
    // The frame renderer, and a new one with other settings (materials re-uploaded).
    const splatfx::gl::FrameRenderer& renderer() const;
    splatfx::Status setRenderer(const splatfx::gl::FrameRendererDesc& desc);

private:
    struct Impl;
    explicit ScenePlayer(std::unique_ptr<Impl> impl);
    static splatfx::Status setupGl(Impl& impl, const std::string& path, const PlayerOptions& options);
    static splatfx::Status installRenderer(Impl& impl, const splatfx::gl::FrameRendererDesc& desc);
    std::unique_ptr<Impl> mImpl;
};

} // namespace scenehost
