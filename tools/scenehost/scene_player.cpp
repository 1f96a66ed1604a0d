#include "scene_player.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>
#include <vector>

#include <epoxy/gl.h>

#include "camera_path.hpp"

namespace scenehost {

struct ScenePlayer::Impl {
    splatfx::Materials materials{splatfx::Footprint{}};
    std::optional<splatfx::SceneFile> file;
    std::optional<GeometryRenderer> geometry;
    std::optional<splatfx::gl::FrameRenderer> renderer;
    splatfx::Frame frame;
    FrameStats stats;
    // Heightmap objects drawn from a LOD ground fog's terrain mesh (groundFog "terrainGeometry").
    struct LodTerrain {
        std::size_t object = 0;
        splatfx::EffectId fog = 0;
        bool meshSet = false; // the object's mesh is a LOD terrain, no longer the heightmap's own
    };
    std::vector<LodTerrain> lodTerrain;
    splatfx::LodFrame scratch;
    std::vector<glm::vec3> terrain;
    std::string problem; // problem()
};

namespace {

using Clock = std::chrono::steady_clock;

// The geometry's lights: the scene's, each darkened by its own shadow
// (splatfx_shadowTo; 1 for a light without a table). Slot 0's light first,
// so a one-light scene looks as it did.
GeometryLighting geometryLighting(const splatfx::Scene& scene, const splatfx::gl::FrameRenderer& renderer) {
    GeometryLighting g;
    g.shadow = renderer.shadowBinding();
    const std::span<const splatfx::Light> lights = scene.lights();
    if (lights.empty()) return g; // the default sun, unshadowed by any table
    std::vector<std::size_t> order;
    const std::size_t first = scene.sceneShadow().light;
    if (first < lights.size()) order.push_back(first);
    for (std::size_t i = 0; i < lights.size(); ++i)
        if (i != first) order.push_back(i);
    g.lightCount = int(std::min<std::size_t>(order.size(), scenehost::kMaxGeometryLights));
    for (int k = 0; k < g.lightCount; ++k) {
        const std::size_t i = order[std::size_t(k)];
        const splatfx::Light& l = lights[i];
        GeometryLight& h = g.lights[std::size_t(k)];
        h.light = l.type == splatfx::LightType::Directional ? glm::vec4(-glm::normalize(l.direction), 0.0f) : glm::vec4(l.position, 1.0f);
        h.color = l.color * std::min(l.type == splatfx::LightType::Directional ? l.intensity : 1.0f, 1.0f);
        h.shadowLight = int(i);
        if (l.type == splatfx::LightType::Spot) {
            h.spotAxis = glm::normalize(l.direction);
            h.cosInner = std::max(std::cos(l.innerConeRad), std::cos(l.outerConeRad) + 1e-4f); // smoothstep needs inner > outer
            h.cosOuter = std::cos(l.outerConeRad);
        }
    }
    return g;
}
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

} // namespace

// Geometry and the splat renderer, once the scene file is read.
splatfx::Status ScenePlayer::setupGl(Impl& impl, const std::string& path, const PlayerOptions& options) {
    auto geo = GeometryRenderer::create(impl.file->geometry, options.budgets);
    if (!geo) return splatfx::makeError(path + ": " + geo.error());
    impl.geometry.emplace(std::move(*geo));
    for (const splatfx::GroundFogTerrain& link : impl.file->groundFogTerrain) {
        const long i = impl.geometry->find(link.geometry); // the scene file checked it names a heightmap
        if (i < 0) return splatfx::makeError(path + ": groundFog terrainGeometry '" + link.geometry + "' not found");
        impl.lodTerrain.push_back({std::size_t(i), link.fog});
    }
    // A scene of geometry only still needs one row for the renderer to upload.
    if (impl.materials.colorTableCount() == 0) impl.materials.addColorTable(splatfx::ColorTable::constant(glm::vec4(1.0f)));
    return installRenderer(impl, options.renderer);
}

// A splat renderer with these settings and the materials uploaded; on failure
// the previous renderer stays.
splatfx::Status ScenePlayer::installRenderer(Impl& impl, const splatfx::gl::FrameRendererDesc& desc) {
    auto r = splatfx::gl::FrameRenderer::create(desc);
    if (!r) return splatfx::makeError(r.error());
    if (auto s = r->upload(impl.materials); !s) return s;
    impl.renderer.emplace(std::move(*r));
    return {};
}

splatfx::Status ScenePlayer::setRenderer(const splatfx::gl::FrameRendererDesc& desc) { return installRenderer(*mImpl, desc); }
const splatfx::gl::FrameRenderer& ScenePlayer::renderer() const { return *mImpl->renderer; }

splatfx::Result<ScenePlayer> ScenePlayer::load(const std::string& path, const PlayerOptions& options) {
    auto impl = std::make_unique<Impl>();
    splatfx::SceneFileOptions so;
    so.seed = options.seed;
    so.budgets = options.budgets;
    auto file = splatfx::loadSceneFile(path, impl->materials, so);
    if (!file) return splatfx::makeError(file.error());
    impl->file.emplace(std::move(*file));
    if (auto s = setupGl(*impl, path, options); !s) return splatfx::makeError(s.error());
    return ScenePlayer(std::move(impl));
}

splatfx::Result<ScenePlayer> ScenePlayer::fromText(const std::string& text, const std::string& path, const PlayerOptions& options) {
    auto impl = std::make_unique<Impl>();
    splatfx::SceneFileOptions so;
    so.seed = options.seed;
    so.budgets = options.budgets;
    auto file = splatfx::parseSceneFile(text, path, impl->materials, so);
    if (!file) return splatfx::makeError(file.error());
    impl->file.emplace(std::move(*file));
    if (auto s = setupGl(*impl, path, options); !s) return splatfx::makeError(s.error());
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
const std::string& ScenePlayer::problem() const { return mImpl->problem; }
GeometryRenderer& ScenePlayer::geometry() { return *mImpl->geometry; }

splatfx::Camera ScenePlayer::cameraAt(double t, glm::ivec2 viewport, const splatfx::DepthConvention& depth) const {
    return evaluate(mImpl->file->camera, t, viewport, depth);
}

splatfx::Status ScenePlayer::advance(double t, const splatfx::Camera& camera, const FrameOptions& options) {
    Impl& p = *mImpl;
    splatfx::SceneFile& f = *p.file;
    FrameStats& s = p.stats;
    const auto t0 = Clock::now();
    // Moving lights (scene file "directionEnd"/"moveSec"): set before the frame, so lit clouds relight.
    for (const splatfx::LightMotion& m : f.lightMotions)
        if (m.light < f.scene.lights().size())
            if (splatfx::Status st = f.scene.setLight(m.light, m.at(f.scene.lights()[m.light], t)); !st) return st;
    if (splatfx::Status st =
            f.scene.prepare(t, camera, p.materials, p.frame, {.textured = !options.traditional, .opacityScale = options.opacityScale});
        !st)
        return st;
    s.prepareMs = msSince(t0);
    p.problem = f.scene.lightingError();
    s.renderMs = 0.0;
    s.counters = p.frame.counters();
    s.splatsPerEffect.assign(f.effects.size(), 0);
    for (std::size_t i = 0; i < f.effects.size(); ++i) s.splatsPerEffect[i] = f.scene.status(f.effects[i].id).splatsDrawn;
    return {};
}

splatfx::Status ScenePlayer::renderFrame(double t, const splatfx::Camera& camera, unsigned framebuffer, const FrameOptions& options) {
    if (splatfx::Status st = advance(t, camera, options); !st) return st;
    Impl& p = *mImpl;
    splatfx::SceneFile& f = *p.file;
    FrameStats& s = p.stats;

    // The LOD terrain of ground-fog layers replaces their heightmap objects'
    // meshes (the same morphed triangulation as the fog's bottom): the one
    // prepare() refined (EffectOptions::keepTerrain, set by the scene file),
    // or, for a layer switched off, refined here for the terrain alone. A
    // layer the Scene culled has its whole terrain out of view too, so its
    // mesh may stay as it was, once it is a LOD terrain at all.
    for (Impl::LodTerrain& t : p.lodTerrain) {
        if (!options.drawGeometry) continue;
        const splatfx::GroundFog* layer = f.scene.findGroundFog(t.fog);
        const std::vector<glm::vec3>& kept = f.scene.groundFogTerrain(t.fog);
        splatfx::Status set;
        if (f.scene.options(t.fog).enabled && !kept.empty()) {
            set = p.geometry->setWorldTriangles(t.object, kept);
            t.meshSet = true;
        } else if ((!f.scene.options(t.fog).enabled || !t.meshSet) && layer &&
                   layer->update(camera, f.scene.options(t.fog).refine, p.scratch, &p.terrain)) {
            set = p.geometry->setWorldTriangles(t.object, p.terrain);
            t.meshSet = true;
        }
        if (!set && p.problem.empty()) p.problem = set.error();
    }

    // This host's opaque pass: background, then geometry with depth writes.
    auto drawOpaque = [&] {
        if (options.clear) {
            glClearColor(f.output.background.r, f.output.background.g, f.output.background.b, 1.0f);
            glClearDepth(camera.depth.farWindow()); // 0 under reverse-Z
            glDepthMask(GL_TRUE);
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            glClearDepth(1.0);
        }
        if (options.drawGeometry) {
            GeometryLighting g = geometryLighting(f.scene, *p.renderer);
            if (options.fogPerVertex) g.vertexFog = f.scene.fog();
            p.geometry->draw(t, camera, g);
        }
    };
    if (options.fogPerVertex && p.renderer->desc().fogHost)
        return splatfx::makeError("fog per vertex needs a frame renderer with fogHost off (the host image would be fogged twice)");
    const auto t0 = Clock::now();
    splatfx::gl::HostTarget target{.framebuffer = framebuffer, .drawOpaque = drawOpaque};
    // (issue 15) Glass: sorted per pixel with the gas through the fragment lists.
    if (options.drawGeometry && p.geometry->hasTransparent()) {
        target.drawTransparent = [&] { p.geometry->drawTransparent(t, camera, geometryLighting(f.scene, *p.renderer)); };
        target.transparentToLists = true;
    }
    p.renderer->render(p.frame, target);
    s.renderMs = msSince(t0);
    if (options.fogPerVertex && options.drawGeometry && !p.geometry->vertexFogError().empty())
        return splatfx::makeError(p.geometry->vertexFogError());
    return {};
}

} // namespace scenehost
