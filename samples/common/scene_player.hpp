// samples/common/scene_player.hpp: plays a scene file (host side).
//
// Loads a scene file (splatfx::loadSceneFile), its geometry (GeometryRenderer)
// and a splat renderer, and draws one frame at a time: clear, geometry (with
// depth writes), then the effects the Scene finds needed for the camera,
// sorted back to front and composited against that depth. The render tool,
// the viewer and the sample tests share it, so they draw exactly alike.
// Not part of the SDK: it is an example host.
//
//   auto player = scenehost::ScenePlayer::load("samples/05-teapot-steam/scene.json", {});
//   player->renderFrame(timeSec, player->cameraAt(timeSec, size), {.framebuffer = fbo, .width = w, .height = h});
//
// Time passed to renderFrame must not decrease (solver effects simulate
// forward); reload to start over.
// Threading: the GL thread only. Move-only.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry_renderer.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/scene_file.hpp"
#include "splatfx/splats.hpp"

namespace scenehost {

struct PlayerOptions {
    std::optional<std::uint32_t> seed; // replaces the file's seed; default the file's
    splatfx::gl::RendererDesc renderer{}; // the splat renderer's settings; default the SDK's
};

struct FrameOptions {
    bool traditional = false;   // every effect untextured (Fig. 1a); default false
    float opacityScale = 1.0f;  // multiplies every splat's opacity; default 1
    bool drawGeometry = true;   // default true
    bool clear = true;          // clear colour (scene background) and depth first; default true
};

struct FrameStats {
    std::size_t declared = 0;   // effects in the scene
    std::size_t visible = 0;    // needed this frame (in view, in range, alive, enabled)
    std::size_t simulated = 0;  // effects that did dynamics work this frame
    std::size_t drawn = 0;      // effects that emitted at least one splat
    std::uint64_t voxels = 0;   // voxels of the needed effects
    std::uint64_t splats = 0;   // splats drawn
    std::vector<std::uint64_t> splatsPerEffect; // in SceneFile::effects order (0 when skipped)
    double updateMs = 0.0, buildMs = 0.0, drawMs = 0.0; // CPU time of each stage (the draw is GL submission)
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
    splatfx::Camera cameraAt(double timeSec, glm::ivec2 viewport) const;
    // Draws the frame at timeSec (>= the previous call's) into target.
    void renderFrame(double timeSec, const splatfx::Camera& camera, const splatfx::gl::Target& target, const FrameOptions& options = {});

    splatfx::SceneFile& file();
    const splatfx::SceneFile& file() const;
    const splatfx::Materials& materials() const;
    const FrameStats& stats() const;
    GeometryRenderer& geometry();
    // The splat renderer, and a new one with other settings (materials re-uploaded).
    const splatfx::gl::Renderer& renderer() const;
    splatfx::Status setRenderer(const splatfx::gl::RendererDesc& desc);

private:
    struct Impl;
    explicit ScenePlayer(std::unique_ptr<Impl> impl);
    static splatfx::Status setupGl(Impl& impl, const std::string& path, const splatfx::gl::RendererDesc& desc);
    static splatfx::Status installRenderer(Impl& impl, const splatfx::gl::RendererDesc& desc);
    std::unique_ptr<Impl> mImpl;
};

} // namespace scenehost
