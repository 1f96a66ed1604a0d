#include "splatfx/gl/renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cassert>
#include <cstddef>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

#include "context_check.hpp"
#include "fog_state.hpp"
#include "host_depth.hpp"
#include "partial_texture.hpp"
#include "saved_state.hpp"
#include "over_state.hpp"
#include "program_library.hpp"
#include "splat_vertex.hpp"

namespace splatfx::gl {
namespace {

// The host depth tiles' size (glsl/depth_tiles.frag reads 16 x 16 pixels per tile).
constexpr int kCutTile = 16;

// An n x n RGBA layer resampled to (factor n)^2 with GL's bilinear rule
// (texel centres at (i + 0.5) / size, clamped at the edges), so that
// nearest sampling of the result reproduces bilinear sampling of the
// original to within half a new texel.
const float* upsampleBilinear(const float* src, int n, int factor, std::vector<float>& out) {
    const int m = n * factor;
    out.resize(std::size_t(m) * m * 4);
    for (int y = 0; y < m; ++y) {
        const float fy = std::clamp((float(y) + 0.5f) / float(factor) - 0.5f, 0.0f, float(n - 1));
        const int y0 = std::min(int(fy), n - 1), y1 = std::min(y0 + 1, n - 1);
        const float ay = fy - float(y0);
        for (int x = 0; x < m; ++x) {
            const float fx = std::clamp((float(x) + 0.5f) / float(factor) - 0.5f, 0.0f, float(n - 1));
            const int x0 = std::min(int(fx), n - 1), x1 = std::min(x0 + 1, n - 1);
            const float ax = fx - float(x0);
            const float* a = src + (std::size_t(y0) * n + x0) * 4;
            const float* b = src + (std::size_t(y0) * n + x1) * 4;
            const float* c = src + (std::size_t(y1) * n + x0) * 4;
            const float* d = src + (std::size_t(y1) * n + x1) * 4;
            float* o = out.data() + (std::size_t(y) * m + x) * 4;
            for (int k = 0; k < 4; ++k) o[k] = (1.0f - ay) * ((1.0f - ax) * a[k] + ax * b[k]) + ay * ((1.0f - ax) * c[k] + ax * d[k]);
        }
    }
    return out.data();
}

} // namespace

struct Renderer::Impl {
    RendererDesc desc;
    DrawStats stats;
    // Programs by variant (kCrossfade | kFog | ...), compiled on first use
    // (the program library's key: these bits as the splat program's defines):
    // each draw run picks the cheapest variant that is exact for its splats.
    enum Variant : unsigned { kCrossfade = 1, kFog = 2, kCut = 4, kHostDepth = 8, kNear = 16, kGeneral = 32 };
    using Program = detail::ProgramLibrary::Program;
    detail::Programs library;
    std::string programError; // the last variant that failed to build (never expected: a shader bug)
    std::string fogSource;    // fogGlsl() the fog programs are built from (empty: none)
    std::uint64_t fogKey = 0; // its Fog::glslKey()
    const Fog* fog = nullptr;
    double fogTimeSec = 0.0;
    std::vector<glm::vec4> fogParams;
    const std::vector<glm::vec4>* frameFogParams = nullptr; // the frame renderer's, for this frame (setFrameFogParameters)
    // Depth cut (issue 15): the partial table, its GLSL, per-splat classes.
    detail::PartialTexture partial;
    std::string partialSource;
    std::uint64_t partialKey = 0; // a hash of partialSource (the cut programs' key)
    float kernelRadius = 1.6f;
    std::array<float, 256> rho{}; // rayScaleRho by code
    std::vector<std::uint8_t> classes;
    // The host depth as view depth (R32F, the target's size), its framebuffer and program.
    // The host view-depth range per kCutTile tile (RG32F), read back per draw.
    GLuint tiles = 0, tilesFbo = 0, tilesVao = 0;
    const Program* tilesProgram = nullptr;
    std::vector<float> tileRange;
    int tilesW = 0, tilesH = 0;
    GLuint vao = 0, instances = 0, layers = 0;
    // Instance data streams through a persistently mapped ring of kRing
    // regions: the CPU writes region i while the GPU may still read the
    // others; a fence per region says when it is free again. No per-frame
    // allocation and no implicit synchronisation inside the driver.
    static constexpr int kRing = 3;
    std::size_t regionSplats = 0; // capacity of one region, in splats
    Splat* mapped = nullptr;
    GLsync fences[kRing] = {};
    int region = 0;
    std::uint64_t uploadedVersion = 0;
    TextureSampling sampling = TextureSampling::Bilinear; // resolved at upload
    int upsample = 1;

    const Program* program(unsigned variant);
    // Drops the splat programs with any of the variant bits of `mask`.
    void dropPrograms(unsigned mask) {
        library->release(glsl::ProgramId::Splat, [mask](const glsl::ProgramKey& k) {
            using namespace glsl::splat;
            return ((mask & kFog) && k.values[FOG]) || ((mask & kCut) && k.values[CUT]);
        });
    }

    void grow(std::size_t splats) {
        for (GLsync& f : fences)
            if (f) {
                glClientWaitSync(f, GL_SYNC_FLUSH_COMMANDS_BIT, GLuint64(-1));
                glDeleteSync(f);
                f = nullptr;
            }
        if (instances) glDeleteBuffers(1, &instances);
        regionSplats = std::max<std::size_t>(splats + splats / 2, 1024);
        const GLsizeiptr bytes = GLsizeiptr(regionSplats * sizeof(Splat) * kRing);
        const GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
        glCreateBuffers(1, &instances);
        glNamedBufferStorage(instances, bytes, nullptr, flags);
        mapped = static_cast<Splat*>(glMapNamedBufferRange(instances, 0, bytes, flags));
        glVertexArrayVertexBuffer(vao, 0, instances, 0, sizeof(Splat));
        region = 0;
    }

    ~Impl() {
        // The context may already be gone at exit; its objects died with it then.
        if (!detail::contextIsCurrent()) return;
        for (GLsync f : fences)
            if (f) glDeleteSync(f);
        if (vao) glDeleteVertexArrays(1, &vao);
        if (tilesVao) glDeleteVertexArrays(1, &tilesVao);
        if (tiles) glDeleteTextures(1, &tiles);
        if (tilesFbo) glDeleteFramebuffers(1, &tilesFbo);
        if (instances) glDeleteBuffers(1, &instances);
        if (layers) glDeleteTextures(1, &layers);
    }
};

const Renderer::Impl::Program* Renderer::Impl::program(unsigned v) {
    using namespace glsl::splat;
    const bool cut = v & kCut, fogged = v & kFog;
    glsl::ProgramKey key{glsl::ProgramId::Splat};
    key.values[FOG] = fogged ? 1 : 0;
    key.values[FOG_PER_SPLAT] = fogged && desc.fogPerSplat ? 1 : 0;
    key.values[CUT] = cut ? 1 : 0;
    key.values[HOST_DEPTH] = cut && (v & kHostDepth) ? 1 : 0;
    key.values[NEAR_CUT] = cut && (v & (kNear | kGeneral)) ? 1 : 0;
    key.values[GENERAL] = cut && (v & kGeneral) ? 1 : 0;
    key.values[CROSSFADE] = (v & kCrossfade) ? 1 : 0;
    key.dataKey = (fogged ? fogKey : 0u) * 1099511628211ull + (cut ? partialKey : 0u);
    auto p = library->get(key, {.fog = fogged ? std::string_view(fogSource) : std::string_view(),
                                .partial = cut ? std::string_view(partialSource) : std::string_view()});
    if (!p) {
        programError = p.error();
        return nullptr;
    }
    return *p;
}

Renderer::Renderer(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;
Renderer::~Renderer() = default;
const DrawStats& Renderer::stats() const { return mImpl->stats; }
const RendererDesc& Renderer::desc() const { return mImpl->desc; }
unsigned Renderer::layerTexture() const { return mImpl->layers; }
TextureSampling Renderer::sampling() const { return mImpl->sampling; }
int Renderer::upsampleFactor() const { return mImpl->upsample; }

Result<Renderer> Renderer::create(const RendererDesc& desc) { return create(desc, std::make_shared<detail::ProgramLibrary>()); }

Result<Renderer> Renderer::create(const RendererDesc& desc, detail::Programs programs) {
    if (!detail::contextIsCurrent()) return makeError("splatfx::gl::Renderer::create: no OpenGL context is current on this thread");
    if (epoxy_gl_version() < 45)
        return makeError("splatfx::gl::Renderer::create: OpenGL 4.5 is required, the current context has " + std::to_string(epoxy_gl_version() / 10) +
                         "." + std::to_string(epoxy_gl_version() % 10));
    auto impl = std::make_unique<Impl>();
    impl->desc = desc;
    impl->library = std::move(programs);
    for (int c = 0; c < 256; ++c) impl->rho[size_t(c)] = rayScaleRho(std::uint8_t(c));
    // The plain program now, so a broken build of the shaders fails here
    // (the cut variants need the materials' footprint: built at upload).
    if (!impl->program(0)) return makeError(impl->programError);

    glCreateVertexArrays(1, &impl->vao);
    impl->grow(0);
    if (!impl->mapped) return makeError("splatfx::gl::Renderer::create: cannot map a persistent instance buffer");
    detail::setSplatVertexLayout(impl->vao);
    return Renderer(std::move(impl));
}

Status Renderer::upload(const Materials& materials) {
    Impl& r = *mImpl;
    if (materials.version() == r.uploadedVersion) return {};
    const int n = materials.layerSize();
    const std::uint32_t count = materials.layerCount();
    GLint maxLayers = 0;
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
    if (Status s = materials.checkLayerLimit(std::uint32_t(std::max(maxLayers, 0))); !s)
        return makeError("splatfx::gl::Renderer::upload (limit: this GL's GL_MAX_ARRAY_TEXTURE_LAYERS): " + s.error());
    // Resolve Auto and the automatic factor for these layers.
    TextureSampling mode = r.desc.sampling;
    if (mode == TextureSampling::Auto) mode = detail::softwareRasterizer() ? TextureSampling::Upsampled : TextureSampling::Bilinear;
    int factor = 1;
    if (mode == TextureSampling::Upsampled) {
        factor = std::clamp(r.desc.upsample, 0, 16);
        const auto bytes = [&](int f) { return std::size_t(count) * std::size_t(n * f) * std::size_t(n * f) * 4; };
        if (factor == 0) factor = bytes(4) <= kUpsampleBudgetBytes ? 4 : bytes(2) <= kUpsampleBudgetBytes ? 2 : 1;
        if (factor < 2) {
            mode = TextureSampling::Bilinear;
            factor = 1;
        }
    }
    GLint maxSize = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
    if (n * factor > maxSize)
        return makeError("texture layers of " + std::to_string(n) + "^2 upsampled " + std::to_string(factor) + "x exceed this GL's " +
                         std::to_string(maxSize) + " texels; use a smaller RendererDesc::upsample");
    if (r.layers) glDeleteTextures(1, &r.layers);
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &r.layers);
    glTextureStorage3D(r.layers, 1, GL_RGBA8, n * factor, n * factor, GLsizei(count));
    std::vector<float> resampled;
    for (std::uint32_t i = 0; i < count; ++i) {
        const float* texels = materials.layer(i).data();
        if (factor > 1) texels = upsampleBilinear(texels, n, factor, resampled);
        glTextureSubImage3D(r.layers, 0, 0, 0, GLint(i), n * factor, n * factor, 1, GL_RGBA, GL_FLOAT, texels);
    }
    const GLint filter = mode == TextureSampling::Bilinear ? GL_LINEAR : GL_NEAREST;
    glTextureParameteri(r.layers, GL_TEXTURE_MIN_FILTER, filter);
    glTextureParameteri(r.layers, GL_TEXTURE_MAG_FILTER, filter);
    // Clamp to the border texels, which the footprint window has brought to zero.
    glTextureParameteri(r.layers, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(r.layers, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

    r.sampling = mode;
    r.upsample = factor;
    r.uploadedVersion = materials.version();

    // Depth cut (issue 15): the footprint's partial table and its lookup.
    r.partial.update(materials.footprint());
    r.kernelRadius = materials.footprint().radius();
    std::string partial = partialGlsl(materials.footprint(), 2);
    if (partial != r.partialSource) {
        r.dropPrograms(Impl::kCut);
        r.partialKey = std::hash<std::string>{}(partial);
        r.partialSource = std::move(partial);
    }
    if (r.desc.depthCut && !r.program(Impl::kCut)) return makeError("splatfx::gl::Renderer::upload: " + r.programError);
    if (r.desc.depthCut && !r.tilesProgram) {
        auto tiles = r.library->get({glsl::ProgramId::DepthTiles});
        if (!tiles) return makeError("splatfx::gl::Renderer::upload: " + tiles.error());
        r.tilesProgram = *tiles;
        glCreateVertexArrays(1, &r.tilesVao);
    }
    return {};
}

void Renderer::setFrameFogParameters(const std::vector<glm::vec4>* params) { mImpl->frameFogParams = params; }

Status Renderer::setFog(const Fog* fog, double timeSec) {
    Impl& r = *mImpl;
    r.fogTimeSec = timeSec;
    auto change = detail::fogChange(fog, r.fogKey);
    r.fog = change ? change->fog : nullptr;
    if (!change) return makeError("splatfx::gl::Renderer::setFog: " + change.error());
    if (!change->rebuild) return {};
    r.dropPrograms(Impl::kFog);
    r.fogSource = std::move(*change->rebuild);
    r.fogKey = r.fog->glslKey();
    if (!r.program(Impl::kFog | (r.desc.depthCut && !r.partialSource.empty() ? Impl::kCut : 0u))) {
        r.fog = nullptr;
        r.fogSource.clear();
        r.fogKey = 0;
        return makeError(r.programError);
    }
    return {};
}

namespace {} // namespace

void Renderer::draw(std::span<const Splat> splats, const Camera& camera, const PassTarget& target) {
    drawResolved(splats, camera, detail::resolveTarget(target));
}

void Renderer::drawResolved(std::span<const Splat> splats, const Camera& camera, const PassTarget& target) {
    Impl& r = *mImpl;
    // No splats need no materials (a frame of only a shadow, fog or volumes).
    assert((splats.empty() || r.layers) && "splatfx::gl::Renderer::draw: call upload(materials) first");
    r.stats.splats = splats.size();
    r.stats.drawCalls = 0;
    r.stats.cutNear = r.stats.cutGeneral = r.stats.cutHost = r.stats.cutHidden = 0;
    r.stats.cutHostDepth = false;
    if (splats.empty() || !r.layers) return;

    if (splats.size() > r.regionSplats) r.grow(splats.size());
    r.region = (r.region + 1) % Impl::kRing;
    if (GLsync& f = r.fences[r.region]) {
        // Three frames back: normally long finished, so this does not wait.
        glClientWaitSync(f, GL_SYNC_FLUSH_COMMANDS_BIT, GLuint64(-1));
        glDeleteSync(f);
        f = nullptr;
    }
    const std::size_t first = std::size_t(r.region) * r.regionSplats;
    const bool cut = r.desc.depthCut && !r.partialSource.empty();
    const bool persp = camera.perspective();
    const glm::vec3 eye = camera.eye(), fwd = camera.forward();
    const float nearZ = camera.nearPlane();
    const float cutExtent = std::clamp(r.desc.footprintCut, 0.05f, 1.0f);

    // draw() binds unit 0's texture array and, with the cut, 2D textures on units 1 and 2.
    detail::SavedState saved;
    if (r.desc.restoreState) saved.save({.texture2DUnits = cut ? 3 : 0, .scissor = false});

    // The cut reads the host depth where it can sample it (single-sampled):
    // first as view depth per pixel and its range per tile (read back).
    // (A multisampled host depth was resolved to none: the plain test at the splat plane.)
    const GLuint depthTex = cut && r.desc.depthTest && r.tilesProgram ? target.depthTexture : 0;
    r.stats.cutHostDepth = depthTex != 0;
    const glm::vec3 depthMap = detail::hostDepthMap(camera);
    const glm::vec2 ndcZ = detail::generalNdcZ(camera);
    const int tile = kCutTile;
    const int tilesX = (target.width + tile - 1) / tile, tilesY = (target.height + tile - 1) / tile;
    if (depthTex) {
        if (r.tilesW != tilesX || r.tilesH != tilesY) {
            if (r.tiles) glDeleteTextures(1, &r.tiles);
            if (!r.tilesFbo) glCreateFramebuffers(1, &r.tilesFbo);
            glCreateTextures(GL_TEXTURE_2D, 1, &r.tiles);
            glTextureStorage2D(r.tiles, 1, GL_RG32F, std::max(tilesX, 1), std::max(tilesY, 1));
            glNamedFramebufferTexture(r.tilesFbo, GL_COLOR_ATTACHMENT0, r.tiles, 0);
            r.tilesW = tilesX;
            r.tilesH = tilesY;
        }
        glDisable(GL_BLEND);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_CULL_FACE);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glBindVertexArray(r.tilesVao);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r.tilesFbo);
        glViewport(0, 0, tilesX, tilesY);
        glUseProgram(r.tilesProgram->id);
        glUniform3fv(r.tilesProgram->uniform(glsl::depth_tiles::HostDepthMap), 1, glm::value_ptr(depthMap));
        glUniform4i(r.tilesProgram->uniform(glsl::depth_tiles::Target), target.x, target.y, target.width, target.height);
        glBindTextureUnit(1, depthTex);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        r.tileRange.resize(std::size_t(tilesX) * std::size_t(tilesY) * 2);
        glGetTextureImage(r.tiles, 0, GL_RG, GL_FLOAT, GLsizei(r.tileRange.size() * sizeof(float)), r.tileRange.data());
    }

    // One pass over the splats: classify (cut), copy the drawn ones into the
    // ring in order, note whether any cross-fades. Needs per splat: the near
    // cut (its support meets the near plane), the host cut (its support
    // meets the range of host depths over the tiles it covers), the general
    // variant (perspective: its polygon nearly crosses the eye plane, drawn
    // as a screen-covering quad), or none; a support wholly behind the host
    // surface is not drawn (its share is 0 everywhere). Thresholds carry 1 %
    // margin against the shaders' float arithmetic (the vertex shader drops
    // a polygon only below 0.25 near, the CPU routes below 0.5 near).
    Splat* dst = r.mapped + first;
    bool anyCrossfade = false;
    std::size_t drawn = 0;
    if (cut) r.classes.resize(splats.size());
    const glm::mat4 vp = camera.proj * camera.view;
    const float focalY = std::abs(camera.proj[1][1]) * 0.5f * float(target.height), focalX = std::abs(camera.proj[0][0]) * 0.5f * float(target.width);
    for (std::size_t i = 0; i < splats.size(); ++i) {
        const Splat& sp = splats[i];
        if (cut) {
            const float a = std::abs(glm::dot(sp.axisU, fwd)), b = std::abs(glm::dot(sp.axisV, fwd));
            const float reach = cutExtent * (r.desc.trimCorners ? std::max(a + 0.41421356f * b, 0.41421356f * a + b) : a + b);
            const float zc = glm::dot(sp.center - eye, fwd);
            const float minZ = zc - reach, maxZ = zc + reach;
            const float area = glm::length(glm::cross(sp.axisU, sp.axisV));
            // The support's reach along the rays, R l (l = rho sqrt(area) / R), with 1 % margin.
            const float depthReach = 1.01f * r.rho[sp.color >> 24] * std::sqrt(area);
            std::uint8_t c = minZ - depthReach < nearZ * 1.01f + 1e-6f ? std::uint8_t(Impl::kNear) : std::uint8_t(0);
            if (persp && !(minZ >= 0.5f * nearZ)) c = std::uint8_t(Impl::kGeneral); // also NaN
            if (depthTex) {
                // The host depths over the splat's screen rectangle (centre
                // projected, half-size from its largest in-plane extent).
                float lo = 0.0f, hi = 3.4e38f;
                if (!(c & Impl::kGeneral)) {
                    const glm::vec4 cc = vp * glm::vec4(sp.center, 1.0f);
                    const float ext = cutExtent * (glm::length(sp.axisU) + glm::length(sp.axisV)) * 1.01f;
                    const float px = (cc.x / cc.w * 0.5f + 0.5f) * float(target.width), py = (cc.y / cc.w * 0.5f + 0.5f) * float(target.height);
                    const float hx = persp ? ext * focalX / minZ : ext * focalX, hy = persp ? ext * focalY / minZ : ext * focalY;
                    const int x0 = std::clamp(int(std::floor((px - hx) / float(tile))), 0, tilesX - 1),
                              x1 = std::clamp(int(std::floor((px + hx) / float(tile))), 0, tilesX - 1);
                    const int y0 = std::clamp(int(std::floor((py - hy) / float(tile))), 0, tilesY - 1),
                              y1 = std::clamp(int(std::floor((py + hy) / float(tile))), 0, tilesY - 1);
                    if (std::isfinite(px) && std::isfinite(py) && std::isfinite(hx) && std::isfinite(hy)) {
                        lo = 3.4e38f, hi = 0.0f;
                        for (int ty = y0; ty <= y1; ++ty)
                            for (int tx = x0; tx <= x1; ++tx) {
                                const float* t = &r.tileRange[(std::size_t(ty) * std::size_t(tilesX) + std::size_t(tx)) * 2];
                                lo = std::min(lo, t[0]);
                                hi = std::max(hi, t[1]);
                            }
                    }
                }
                if (minZ - depthReach > hi * 1.01f + 1e-6f) { // wholly behind the surface
                    ++r.stats.cutHidden;
                    continue;
                }
                if (!(maxZ + depthReach < lo * 0.99f)) c |= std::uint8_t(Impl::kHostDepth); // the surface may meet the support
            }
            r.classes[drawn] = c;
        }
        dst[drawn++] = sp;
        anyCrossfade |= sp.blend > 0.0f;
    }

    // With the host depth read, the cut replaces the hardware test (the
    // depth texture is read, never written: the test and writes are off).
    detail::setOverState(target.framebuffer, target, r.desc.depthTest && !depthTex ? detail::nearerOrEqual(camera) : detail::DepthTest::Off);
    glDisable(GL_CULL_FACE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);

    const bool fogged = r.fog && !r.fogSource.empty();
    const unsigned base = (anyCrossfade ? Impl::kCrossfade : 0u) | (fogged ? Impl::kFog : 0u) | (cut ? Impl::kCut : 0u);
    const glm::mat4 invVp = glm::inverse(vp);
    // The frame renderer hands over the frame's parameters (computed once a frame); alone, compute them here.
    if (fogged && !r.frameFogParams) r.fogParams = r.fog->glslParameters(r.fogTimeSec, glm::dvec3(eye));
    const std::span<const glm::vec4> fogParams = r.frameFogParams ? std::span<const glm::vec4>(*r.frameFogParams) : r.fogParams;
    glBindTextureUnit(0, r.layers);
    if (cut) {
        glBindTextureUnit(1, depthTex);
        glBindTextureUnit(2, r.partial.texture());
    }
    glBindVertexArray(r.vao);
    const GLsizei corners = r.desc.trimCorners ? 8 : 4;

    auto drawRange = [&](unsigned variant, std::size_t begin, std::size_t end) {
        if (end <= begin) return;
        const Impl::Program* p = r.program(variant);
        assert(p && "splatfx::gl::Renderer: a shader variant failed to build");
        if (!p) return;
        glUseProgram(p->id);
        if (variant & Impl::kFog) {
            // Parameters in double relative to the eye, rounded to float once (docs/fog.md, GLSL).
            glUniform3f(p->uniform(glsl::splat::FogEye), eye.x, eye.y, eye.z);
            detail::setFogUniforms(
                p->id,
                {.params = p->uniform(glsl::splat::FogParams), .colour = p->uniform(glsl::splat::FogColour), .far = p->uniform(glsl::splat::FogFar)},
                *r.fog, fogParams);
        }
        glUniformMatrix4fv(p->uniform(glsl::splat::ViewProj), 1, GL_FALSE, glm::value_ptr(vp));
        glUniform1i(p->uniform(glsl::splat::Octagon), r.desc.trimCorners ? 1 : 0);
        glUniform1f(p->uniform(glsl::splat::Cut), cutExtent);
        if (variant & Impl::kCut) {
            glUniform3f(p->uniform(glsl::splat::Eye), eye.x, eye.y, eye.z);
            glUniform3f(p->uniform(glsl::splat::Forward), fwd.x, fwd.y, fwd.z);
            glUniform1f(p->uniform(glsl::splat::NearZ), nearZ);
            glUniform1i(p->uniform(glsl::splat::Persp), persp ? 1 : 0);
            glUniform1f(p->uniform(glsl::splat::KernelRadius), r.kernelRadius);
            glUniform3fv(p->uniform(glsl::splat::HostDepthMap), 1, glm::value_ptr(depthMap));
            glUniform2fv(p->uniform(glsl::splat::NdcZ), 1, glm::value_ptr(ndcZ));
            glUniformMatrix4fv(p->uniform(glsl::splat::InvViewProj), 1, GL_FALSE, glm::value_ptr(invVp));
            glUniform4f(p->uniform(glsl::splat::Viewport), float(target.x), float(target.y), float(target.width), float(target.height));
        }
        glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, corners, GLsizei(end - begin), GLuint(first + begin));
        ++r.stats.drawCalls;
    };

    if (!cut) {
        drawRange(base, 0, drawn);
    } else {
        // Runs in back-to-front order, each with the variant its splats need.
        // A short run (< kMerge splats) that needs no more than its
        // predecessor joins it (drawn with a costlier but exact variant)
        // rather than costing a draw call; the general variant covers the
        // screen, so only general splats get it.
        constexpr std::size_t kMerge = 24;
        std::size_t i = 0;
        while (i < drawn) {
            unsigned need = r.classes[i];
            std::size_t j = i + 1;
            for (;;) {
                while (j < drawn && r.classes[j] == need) ++j;
                if (j >= drawn || (need & Impl::kGeneral) || (r.classes[j] & Impl::kGeneral)) break;
                const unsigned c = r.classes[j];
                if (j - i < kMerge) { // a short run takes on the next one's needs (or its splat, if it needs less)
                    if ((c & ~need) == 0) ++j;
                    else need |= c;
                    continue;
                }
                if ((c & ~need) != 0) break;
                // Cheaper splats inside a long run: absorbed if only a few.
                std::size_t k = j;
                while (k < drawn && k - j < kMerge && r.classes[k] != need && (r.classes[k] & ~need) == 0) ++k;
                if (k - j >= kMerge) break;
                j = k;
            }
            drawRange(base | need, i, j);
            for (std::size_t q = i; q < j; ++q) {
                if (need & Impl::kGeneral) ++r.stats.cutGeneral;
                else if (need & Impl::kNear) ++r.stats.cutNear;
                if (need & Impl::kHostDepth) ++r.stats.cutHost;
            }
            i = j;
        }
    }
    r.fences[r.region] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);

    if (r.desc.restoreState) saved.restore();
}

} // namespace splatfx::gl
