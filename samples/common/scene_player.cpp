#include "scene_player.hpp"

#include <chrono>

#include <epoxy/gl.h>

#include "camera_path.hpp"

namespace scenehost {

struct ScenePlayer::Impl {
    splatfx::Materials materials{splatfx::Footprint{}};
    std::optional<splatfx::SceneFile> file;
    std::optional<GeometryRenderer> geometry;
    std::optional<splatfx::gl::Renderer> splats;
    splatfx::SplatBuilder builder;
    FrameStats stats;
};

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

} // namespace

// Geometry and the splat renderer, once the scene file is read.
splatfx::Status ScenePlayer::setupGl(Impl& impl, const std::string& path, const splatfx::gl::RendererDesc& desc) {
    auto geo = GeometryRenderer::create(impl.file->geometry);
    if (!geo) return splatfx::makeError(path + ": " + geo.error());
    impl.geometry.emplace(std::move(*geo));
    // A scene of geometry only still needs one row for the renderer to upload.
    if (impl.materials.colorTableCount() == 0) impl.materials.addColorTable(splatfx::ColorTable::constant(glm::vec4(1.0f)));
    return installRenderer(impl, desc);
}

// A splat renderer with these settings and the materials uploaded; on failure
// the previous renderer stays.
splatfx::Status ScenePlayer::installRenderer(Impl& impl, const splatfx::gl::RendererDesc& desc) {
    auto r = splatfx::gl::Renderer::create(desc);
    if (!r) return splatfx::makeError(r.error());
    if (auto s = r->upload(impl.materials); !s) return s;
    impl.splats.emplace(std::move(*r));
    return {};
}

splatfx::Status ScenePlayer::setRenderer(const splatfx::gl::RendererDesc& desc) { return installRenderer(*mImpl, desc); }
const splatfx::gl::Renderer& ScenePlayer::renderer() const { return *mImpl->splats; }

splatfx::Result<ScenePlayer> ScenePlayer::load(const std::string& path, const PlayerOptions& options) {
    auto impl = std::make_unique<Impl>();
    splatfx::SceneFileOptions so;
    so.seed = options.seed;
    auto file = splatfx::loadSceneFile(path, impl->materials, so);
    if (!file) return splatfx::makeError(file.error());
    impl->file.emplace(std::move(*file));
    if (auto s = setupGl(*impl, path, options.renderer); !s) return splatfx::makeError(s.error());
    return ScenePlayer(std::move(impl));
}

splatfx::Result<ScenePlayer> ScenePlayer::fromText(const std::string& text, const std::string& path, const PlayerOptions& options) {
    auto impl = std::make_unique<Impl>();
    splatfx::SceneFileOptions so;
    so.seed = options.seed;
    auto file = splatfx::parseSceneFile(text, path, impl->materials, so);
    if (!file) return splatfx::makeError(file.error());
    impl->file.emplace(std::move(*file));
    if (auto s = setupGl(*impl, path, options.renderer); !s) return splatfx::makeError(s.error());
    return ScenePlayer(std::move(impl));
}

ScenePlayer::ScenePlayer(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
ScenePlayer::ScenePlayer(ScenePlayer&&) noexcept = default;
ScenePlayer& ScenePlayer::operator=(ScenePlayer&&) noexcept = default;
ScenePlayer::~ScenePlayer() = default;

splatfx::SceneFile& ScenePlayer::file() { return *mImpl->file; }
const splatfx::SceneFile& ScenePlayer::file() const { return *mImpl->file; }
const splatfx::Materials& ScenePlayer::materials() const { return mImpl->materials; }
const FrameStats& ScenePlayer::stats() const { return mImpl->stats; }
GeometryRenderer& ScenePlayer::geometry() { return *mImpl->geometry; }

splatfx::Camera ScenePlayer::cameraAt(double t, glm::ivec2 viewport) const { return evaluate(mImpl->file->camera, t, viewport); }

void ScenePlayer::renderFrame(double t, const splatfx::Camera& camera, const splatfx::gl::Target& target, const FrameOptions& options) {
    Impl& p = *mImpl;
    splatfx::SceneFile& f = *p.file;
    FrameStats& s = p.stats;
    s = {};
    glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
    glViewport(target.x, target.y, target.width, target.height);
    if (options.clear) {
        glClearColor(f.output.background.r, f.output.background.g, f.output.background.b, 1.0f);
        glClearDepth(1.0);
        glDepthMask(GL_TRUE);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }
    // Opaque geometry first: its depth is what the splats are tested against.
    if (options.drawGeometry) p.geometry->draw(t, camera);

    auto t0 = Clock::now();
    f.scene.update(t, camera);
    s.updateMs = msSince(t0);

    t0 = Clock::now();
    p.builder.begin(camera);
    s.splatsPerEffect.assign(f.effects.size(), 0);
    for (std::size_t i = 0; i < f.effects.size(); ++i) {
        const splatfx::SceneEffectInfo& info = f.effects[i];
        if (!f.scene.status(info.id).needed) continue;
        const splatfx::Effect& e = f.scene.effect(info.id);
        s.voxels += e.grid().voxels.size();
        const std::size_t n = e.emit(p.builder, p.materials,
                                     {.textured = !(options.traditional || info.traditional), .opacityScale = options.opacityScale});
        s.splatsPerEffect[i] = n;
        s.drawn += n > 0 ? 1 : 0;
    }
    p.builder.sort();
    s.buildMs = msSince(t0);
    s.splats = p.builder.splats().size();
    const splatfx::SceneCounters& c = f.scene.counters();
    s.declared = c.declared;
    s.visible = c.needed;
    s.simulated = c.simulated;

    t0 = Clock::now();
    p.splats->draw(p.builder.splats(), camera, target);
    s.drawMs = msSince(t0);
}

} // namespace scenehost
