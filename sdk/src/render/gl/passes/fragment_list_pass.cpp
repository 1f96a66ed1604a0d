// (issue 15) Per-pixel fragment lists: surfaces, splat sections, resolve
// (fragment_list_pass.hpp). The node layout is transparentGlsl()'s.
#include "fragment_list_pass.hpp"

#include <algorithm>
#include <cassert>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <span>
#include <string>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

#include "render/gl/context_check.hpp"
#include "render/gl/host_depth.hpp"
#include "render/gl/partial_texture.hpp"
#include "render/gl/over_state.hpp"
#include "render/gl/program_library.hpp"
#include "render/gl/splat_vertex.hpp"
#include "splatfx/footprint.hpp"
#include "splatfx/transparency.hpp"
#include "render/gl/transparent_bindings.hpp"

namespace splatfx::gl::detail {
namespace {

constexpr GLuint kEnd = 0xffffffffu;
constexpr int kCounterWords = 12;
constexpr GLsizeiptr kCounterBytes = kCounterWords * 4;
// The surface depth range tiles (glsl/list_tile_range.comp: 16 x 16 pixels per tile).
constexpr int kRangeTile = 16;

// A per-tile texture of `tiles` texels in `format`, (re)made when the target's tile grid changes.
void fitTileTexture(GLuint& texture, glm::ivec2& size, glm::ivec2 tiles, GLenum format) {
    if (texture && size == tiles) return;
    if (texture) glDeleteTextures(1, &texture);
    glCreateTextures(GL_TEXTURE_2D, 1, &texture);
    glTextureStorage2D(texture, 1, format, tiles.x, tiles.y);
    size = tiles;
}

} // namespace

struct FragmentListPass::Impl {
    int perPixel = 8;
    struct SectionProgram {
        int sections = 0;
        GLuint id = 0; // program->id; 0: not built
        const ProgramLibrary::Program* program = nullptr;
    };
    using Program = ProgramLibrary::Program;
    Programs library;
    // [kind][2, 4, 8 sections]; kinds: 0 plain; cut with 1 near and host
    // cuts, 2 the same general (the polygon crosses the eye plane), 3 no
    // near or host cut, 4 near only, 5 host only (3-5 built on first use).
    static constexpr int kKinds = 6;
    SectionProgram sectionPrograms[kKinds][3];
    static int cutKind(unsigned needs) { return needs == 3 ? 1 : needs == 0 ? 3 : needs == 1 ? 4 : 5; }
    PartialTexture partial;       // the footprint's partial-integral table (cut programs)
    std::string partialSource;    // partialGlsl() the cut programs were built from
    std::uint64_t partialKey = 0; // its hash (the cut programs' key)
    float kernelRadius = 1.0f;
    std::string programError;

    // Builds the three section programs of one kind (kind 0: plain; 1: cut
    // with the partial integral; 2: cut, general: the polygon crosses the eye plane).
    bool buildSections(int kind) {
        using namespace glsl::section;
        const bool cut = kind > 0;
        const int counts[3] = {2, 4, kTransparentMaxSections};
        const bool nearCut = kind == 1 || kind == 2 || kind == 4, hostCut = kind == 1 || kind == 2 || kind == 5;
        glsl::ProgramKey key{glsl::ProgramId::ListSection};
        key.values[CUT] = cut ? 1 : 0;
        key.values[HOST_DEPTH] = hostCut ? 1 : 0;
        key.values[NEAR_CUT] = nearCut ? 1 : 0;
        key.values[GENERAL] = kind == 2 ? 1 : 0;
        key.values[CROSSFADE] = 1;
        key.dataKey = cut ? partialKey : 0;
        for (int v = 0; v < 3; ++v) {
            SectionProgram& p = sectionPrograms[kind][v];
            p = {};
            key.values[SECTIONS] = counts[v];
            auto linked = library->get(key, {.partial = cut ? std::string_view(partialSource) : std::string_view()});
            if (!linked) {
                programError = linked.error();
                return false;
            }
            p.sections = counts[v];
            p.program = *linked;
            p.id = p.program->id;
        }
        return true;
    }
    std::vector<std::pair<int, const Program*>> resolvePrograms; // (K, program), K ascending
    // The fragment resolve by K (built on first use), reading the pool
    // through a texture buffer view when it fits GL_MAX_TEXTURE_BUFFER_SIZE.
    std::vector<std::pair<int, const Program*>> fragmentResolvePrograms;
    GLuint poolView = 0;
    bool poolViewed = false;
    const Program* fragmentResolve(int k) {
        for (const auto& fp : fragmentResolvePrograms)
            if (fp.first == k) return fp.second;
        auto prog = library->get({glsl::ProgramId::ListResolveFrag, {k}});
        const Program* p = prog ? *prog : nullptr; // null: this GL cannot build it; the compute resolve is used
        fragmentResolvePrograms.push_back({k, p});
        return p;
    }
    const Program *compositeProgram = nullptr, *prepareProgram = nullptr, *rangeProgram = nullptr, *hostTileProgram = nullptr;
    GLuint hostTiles = 0; // R32F per tile: the nearest host depth (split(), frames with sections only)
    glm::ivec2 hostTileSize{0};
    std::vector<float> hostTileDepth;
    // The surface depth range per kRangeTile tile (RG32UI float bits), read back by split().
    GLuint tileRange = 0;
    glm::ivec2 tileSize{0};
    std::vector<GLuint> tileBits;
    std::vector<float> tileView;       // tileBits' surface depth range as view depth
    std::vector<float> tileHost;       // tileBits' nearest host depth as view depth
    std::vector<std::uint8_t> classes; // insertSplats(): per splat, its variant
    std::vector<std::uint8_t> needs;   // split(): per splat of the middle run, the cuts its section variant needs (1 near, 2 host)
    std::array<float, 256> rho{};      // rayScaleRho by code (the kernel's reach along the rays)
    GLuint depths = 0;                 // R32F array: each pixel's nearest surface depths
    int depthLayers = 0;
    glm::ivec2 depthSize{0};
    GLuint resolved = 0; // RGBA16F, the lists' viewport
    GLuint vao = 0, instances = 0, emptyVao = 0;
    std::size_t instanceCapacity = 0;
    GLuint heads = 0, pool = 0, counters = 0;
    GLuint sections = 0, sectionFbo = 0, attachedDepth = 0;
    glm::ivec2 sectionSize{0};
    int sectionLayers = 0;
    int width = 0, height = 0;
    std::size_t poolNodes = 0;
    int sectionsThisFrame = 0;
    FragmentListStats stats;

    ~Impl() {
        if (!contextIsCurrent()) return;
        if (poolView) glDeleteTextures(1, &poolView);
        if (hostTiles) glDeleteTextures(1, &hostTiles);
        if (tileRange) glDeleteTextures(1, &tileRange);
        if (depths) glDeleteTextures(1, &depths);
        GLuint vaos[2] = {vao, emptyVao};
        glDeleteVertexArrays(2, vaos);
        GLuint bufs[3] = {instances, pool, counters};
        glDeleteBuffers(3, bufs);
        GLuint tex[3] = {heads, sections, resolved};
        glDeleteTextures(3, tex);
        if (sectionFbo) glDeleteFramebuffers(1, &sectionFbo);
    }

    void resize(int w, int h) {
        if (w == width && h == height && pool) return;
        GLuint tex[2] = {heads, resolved};
        glDeleteTextures(2, tex);
        glCreateTextures(GL_TEXTURE_2D, 1, &resolved);
        glTextureStorage2D(resolved, 1, GL_RGBA16F, w, h);
        glTextureParameteri(resolved, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(resolved, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glCreateTextures(GL_TEXTURE_2D, 1, &heads);
        glTextureStorage2D(heads, 1, GL_R32UI, w, h);
        // Integer textures are complete only with nearest filtering.
        glTextureParameteri(heads, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(heads, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        if (pool) glDeleteBuffers(1, &pool);
        poolNodes = std::size_t(w) * std::size_t(h) * std::size_t(perPixel);
        glCreateBuffers(1, &pool);
        glNamedBufferStorage(pool, GLsizeiptr(poolNodes * kTransparentNodeBytes), nullptr, 0);
        if (poolView) glDeleteTextures(1, &poolView);
        poolView = 0;
        GLint maxTexels = 0;
        glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &maxTexels);
        poolViewed = poolNodes <= std::size_t(std::max(maxTexels, 0));
        if (poolViewed) {
            glCreateTextures(GL_TEXTURE_BUFFER, 1, &poolView);
            glTextureBuffer(poolView, GL_RGBA32UI, pool); // one node per texel (kTransparentNodeBytes = 16)
        }
        width = w;
        height = h;
        stats.poolNodes = poolNodes;
    }

    // Section targets covering [0, x + w) x [0, y + h), so that the host's
    // viewport and depth texture coordinates apply unchanged.
    // Grows only (layers: the sections this frame needs).
    void sizeSections(glm::ivec2 size, int layers, GLuint depth) {
        if (size != sectionSize || !sections || layers > sectionLayers) {
            if (sections) glDeleteTextures(1, &sections);
            glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &sections);
            glTextureStorage3D(sections, 1, GL_RGBA16F, size.x, size.y, layers);
            glTextureParameteri(sections, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTextureParameteri(sections, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            if (!sectionFbo) glCreateFramebuffers(1, &sectionFbo);
            for (int k = 0; k < kTransparentMaxSections; ++k)
                if (k < layers) glNamedFramebufferTextureLayer(sectionFbo, GL_COLOR_ATTACHMENT0 + GLenum(k), sections, 0, k);
                else glNamedFramebufferTexture(sectionFbo, GL_COLOR_ATTACHMENT0 + GLenum(k), 0, 0);
            sectionSize = size;
            sectionLayers = layers;
        }
        if (depth != attachedDepth) {
            glNamedFramebufferTexture(sectionFbo, GL_DEPTH_ATTACHMENT, depth, 0);
            attachedDepth = depth;
        }
    }
};

FragmentListPass::FragmentListPass(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
FragmentListPass::FragmentListPass(FragmentListPass&&) noexcept = default;
FragmentListPass& FragmentListPass::operator=(FragmentListPass&&) noexcept = default;
FragmentListPass::~FragmentListPass() = default;
const FragmentListStats& FragmentListPass::stats() const { return mImpl->stats; }

Result<FragmentListPass> FragmentListPass::create(int fragmentsPerPixel, const RendererDesc& splats, Programs programs) {
    auto impl = std::make_unique<Impl>();
    impl->library = std::move(programs);
    impl->perPixel = std::clamp(fragmentsPerPixel, 1, kMaxFragmentsPerPixel);
    if (!impl->buildSections(0)) return makeError(impl->programError);
    // Resolve variants for K = 1, 2, 4, ... below the budget and the budget
    // itself: a frame with few surfaces per pixel runs the smallest that holds
    // them (the per-pixel arrays cost in proportion to K on a CPU rasterizer).
    for (int k = 1;; k = std::min(2 * k, impl->perPixel)) {
        auto resolve = impl->library->get({glsl::ProgramId::ListResolve, {k}});
        if (!resolve) return makeError(resolve.error());
        impl->resolvePrograms.push_back({k, *resolve});
        if (k == impl->perPixel) break;
    }
    auto prepare = impl->library->get({glsl::ProgramId::ListPrepare});
    if (!prepare) return makeError(prepare.error());
    impl->prepareProgram = *prepare;
    auto range = impl->library->get({glsl::ProgramId::ListTileRange});
    if (!range) return makeError(range.error());
    impl->rangeProgram = *range;
    auto hostTile = impl->library->get({glsl::ProgramId::ListHostTiles});
    if (!hostTile) return makeError(hostTile.error());
    impl->hostTileProgram = *hostTile;
    for (int c = 0; c < 256; ++c) impl->rho[std::size_t(c)] = rayScaleRho(std::uint8_t(c));
    auto composite = impl->library->get({glsl::ProgramId::ListComposite});
    if (!composite) return makeError(composite.error());
    impl->compositeProgram = *composite;

    glCreateVertexArrays(1, &impl->vao);
    glCreateVertexArrays(1, &impl->emptyVao);
    setSplatVertexLayout(impl->vao);
    glCreateBuffers(1, &impl->counters);
    glNamedBufferStorage(impl->counters, kCounterBytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
    FragmentListPass pass(std::move(impl));
    pass.mSplatDesc = splats;
    return pass;
}

Status FragmentListPass::upload(const Materials& materials) {
    Impl& r = *mImpl;
    r.partial.update(materials.footprint());
    r.kernelRadius = materials.footprint().radius();
    std::string partial = partialGlsl(materials.footprint(), 3);
    if (partial == r.partialSource) return {};
    r.library->release(glsl::ProgramId::ListSection, [](const glsl::ProgramKey& k) { return k.values[glsl::section::CUT] != 0; });
    r.partialKey = std::hash<std::string>{}(partial);
    r.partialSource = std::move(partial);
    for (int kind = 1; kind < Impl::kKinds; ++kind)
        for (Impl::SectionProgram& p : r.sectionPrograms[kind]) p = {};
    if (!r.buildSections(1) || !r.buildSections(2)) {
        r.partialSource.clear();
        return makeError("fragment lists: " + r.programError);
    }
    return {};
}

Status FragmentListPass::collectSurfaces(const PassTarget& target, const Camera& camera, const std::function<void()>& drawSurfaces) {
    Impl& r = *mImpl;
    if (target.width <= 0 || target.height <= 0) return makeError("fragment lists: the viewport must be positive");
    r.resize(target.width, target.height);
    r.sectionsThisFrame = 0;
    r.stats.generalSplats = 0;
    r.stats.cut = false;
    r.stats.splatsBehind = r.stats.splatsFront = r.stats.splatsSectioned = 0;
    const GLuint end = kEnd;
    glClearTexImage(r.heads, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &end);
    // Word 10: splatfx_depthReversed (transparent_lists.glsl: the nodes' depth key).
    const GLint header[kCounterWords] = {0, 0, target.x, target.y, target.width, target.height, 0, 0, 0, 0, camera.depth.reversed ? 1 : 0, 0};
    glNamedBufferSubData(r.counters, 0, sizeof(header), header);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kTransparentNodeBinding, r.pool, 0, GLsizeiptr(r.poolNodes * kTransparentNodeBytes));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTransparentCounterBinding, r.counters);
    glBindImageTexture(kTransparentHeadImageUnit, r.heads, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    if (drawSurfaces) {
        setOverState(target.framebuffer, target, nearerOrEqual(camera));
        drawSurfaces();
    }
    // The survey of the lists (kTileRangeCompute).
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    const int tilesX = (target.width + kRangeTile - 1) / kRangeTile, tilesY = (target.height + kRangeTile - 1) / kRangeTile;
    fitTileTexture(r.tileRange, r.tileSize, {tilesX, tilesY}, GL_RGBA32UI);
    glUseProgram(r.rangeProgram->id);
    glUniform2i(r.rangeProgram->uniform(glsl::lists::Size), target.width, target.height);
    glUniform2i(r.rangeProgram->uniform(glsl::lists::Tiles), tilesX, tilesY);
    glBindTextureUnit(2, r.heads);
    glBindImageTexture(5, r.tileRange, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32UI);
    glDispatchCompute(GLuint((tilesX + 7) / 8), GLuint(tilesY), 1);
    glBindImageTexture(5, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32UI);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    return {};
}

FragmentListPass::Split FragmentListPass::split(const std::vector<Splat>& splats, const Camera& camera, float cut, bool trimCorners, bool depthCut,
                                                const PassTarget& target) {
    Impl& r = *mImpl;
    r.stats.splatsBehind = r.stats.splatsFront = r.stats.splatsSectioned = 0;
    r.needs.clear();
    const std::size_t n = splats.size();
    if (n == 0) return {};
    const int tile = kRangeTile;
    const int tilesX = r.tileSize.x, tilesY = r.tileSize.y;
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    r.tileBits.resize(std::size_t(tilesX) * std::size_t(tilesY) * 4);
    glGetTextureImage(r.tileRange, 0, GL_RGBA_INTEGER, GL_UNSIGNED_INT, GLsizei(r.tileBits.size() * sizeof(GLuint)), r.tileBits.data());
    // A list key (window depth, or 1 - it reversed) to view depth, as the
    // shaders do (monotonic: the range maps to the range).
    const DepthUnprojection unproject = depthUnprojection(camera);
    auto viewDepth = [&](GLuint bits) {
        float key;
        std::memcpy(&key, &bits, 4);
        return float(unproject.viewDepth(camera.depth.reversed ? 1.0 - double(key) : double(key)));
    };
    std::vector<float>& range = r.tileView;
    const std::size_t tiles = std::size_t(tilesX) * std::size_t(tilesY);
    range.resize(tiles * 2);
    bool any = false;
    for (std::size_t t = 0; t < tiles; ++t) {
        const bool empty = r.tileBits[4 * t] > r.tileBits[4 * t + 1];
        any |= !empty;
        range[2 * t] = empty ? 3.4e38f : viewDepth(r.tileBits[4 * t]);
        range[2 * t + 1] = empty ? -3.4e38f : viewDepth(r.tileBits[4 * t + 1]);
    }
    if (!any) { // no surface stored: every splat is in the only section
        r.stats.splatsBehind = n;
        return {n, n};
    }
    // Per splat: the view-depth interval its contribution can come from (the
    // polygon's, widened by the kernel's reach along the rays with the cut),
    // and the surfaces' depth range over the tiles its screen rectangle meets
    // (the same bound as the splat pass's tile test, renderer.cpp).
    const bool persp = camera.perspective();
    const glm::vec3 eye = camera.eye(), fwd = camera.forward();
    const float nearZ = camera.nearPlane(), extent = std::clamp(cut, 0.05f, 1.0f);
    const glm::mat4 vp = camera.proj * camera.view;
    const float focalY = std::abs(camera.proj[1][1]) * 0.5f * float(target.height), focalX = std::abs(camera.proj[0][0]) * 0.5f * float(target.width);
    // 0: between (sections), 1: behind every surface it covers, 2: in front of every one, 3: no surface on its tiles.
    int needs = 3;
    auto classify = [&](const Splat& sp) -> int {
        const float a = std::abs(glm::dot(sp.axisU, fwd)), b = std::abs(glm::dot(sp.axisV, fwd));
        const float reach = extent * (trimCorners ? std::max(a + 0.41421356f * b, 0.41421356f * a + b) : a + b);
        const float zc = glm::dot(sp.center - eye, fwd);
        const float minZ = zc - reach, maxZ = zc + reach;
        const float depthReach = depthCut ? 1.01f * r.rho[sp.color >> 24] * std::sqrt(glm::length(glm::cross(sp.axisU, sp.axisV))) : 0.0f;
        float lo = 3.4e38f, hi = -3.4e38f;
        const glm::vec4 cc = vp * glm::vec4(sp.center, 1.0f);
        const float ext = extent * (glm::length(sp.axisU) + glm::length(sp.axisV)) * 1.01f;
        const float px = (cc.x / cc.w * 0.5f + 0.5f) * float(target.width), py = (cc.y / cc.w * 0.5f + 0.5f) * float(target.height);
        const float hx = persp ? ext * focalX / minZ : ext * focalX, hy = persp ? ext * focalY / minZ : ext * focalY;
        int x0 = 0, x1 = tilesX - 1, y0 = 0, y1 = tilesY - 1; // near or across the eye plane, or not finite: every tile
        if ((!persp || minZ >= 0.5f * nearZ) && std::isfinite(px) && std::isfinite(py) && std::isfinite(hx) && std::isfinite(hy)) {
            x0 = std::clamp(int(std::floor((px - hx) / float(tile))), 0, tilesX - 1),
            x1 = std::clamp(int(std::floor((px + hx) / float(tile))), 0, tilesX - 1);
            y0 = std::clamp(int(std::floor((py - hy) / float(tile))), 0, tilesY - 1),
            y1 = std::clamp(int(std::floor((py + hy) / float(tile))), 0, tilesY - 1);
        }
        float host = 3.4e38f;
        for (int ty = y0; ty <= y1; ++ty)
            for (int tx = x0; tx <= x1; ++tx) {
                const std::size_t at = std::size_t(ty) * std::size_t(tilesX) + std::size_t(tx);
                lo = std::min(lo, range[2 * at]);
                hi = std::max(hi, range[2 * at + 1]);
                if (!r.tileHost.empty()) host = std::min(host, r.tileHost[at]);
                else host = 0.0f; // not surveyed: assume the host cut may be needed
            }
        // The section program's variant: the near cut where the support may
        // reach the near plane, the host cut where it may reach the nearest
        // host depth on its tiles (the splat pass's tests, renderer.cpp).
        needs = (minZ - depthReach < nearZ * 1.01f + 1e-6f ? 1 : 0) | (maxZ + depthReach < host * 0.99f ? 0 : 2);
        if (lo > hi) return 3; // no surface on its tiles: its only section is the first and the last
        if (minZ - depthReach > hi * 1.01f + 1e-6f) return 1;
        if (maxZ + depthReach < lo * 0.99f) return 2;
        return 0;
    };
    Split s;
    while (s.behindEnd < n && (classify(splats[s.behindEnd]) & 1)) ++s.behindEnd;
    s.frontBegin = n;
    while (s.frontBegin > s.behindEnd && (classify(splats[s.frontBegin - 1]) & 2)) --s.frontBegin;
    r.stats.splatsBehind = s.behindEnd;
    r.stats.splatsFront = n - s.frontBegin;
    // The middle run's section variants (bit 0: near cut, bit 1: host cut),
    // from the nearest host depth per tile (surveyed only now: frames with
    // no splat to section do not pay for it).
    r.tileHost.clear();
    if (s.frontBegin > s.behindEnd && depthCut && target.depthTexture) {
        fitTileTexture(r.hostTiles, r.hostTileSize, {tilesX, tilesY}, GL_R32F);
        glUseProgram(r.hostTileProgram->id);
        glUniform2i(r.hostTileProgram->uniform(glsl::lists::Size), target.width, target.height);
        glUniform2i(r.hostTileProgram->uniform(glsl::lists::Tiles), tilesX, tilesY);
        glUniform2i(r.hostTileProgram->uniform(glsl::lists::Origin), target.x, target.y);
        glUniform1i(r.hostTileProgram->uniform(glsl::lists::Reversed), camera.depth.reversed ? 1 : 0);
        glBindTextureUnit(3, target.depthTexture);
        glBindImageTexture(5, r.hostTiles, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
        glDispatchCompute(GLuint((tilesX + 7) / 8), GLuint(tilesY), 1);
        glBindImageTexture(5, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
        glBindTextureUnit(3, 0);
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        r.hostTileDepth.resize(std::size_t(tilesX) * std::size_t(tilesY));
        glGetTextureImage(r.hostTiles, 0, GL_RED, GL_FLOAT, GLsizei(r.hostTileDepth.size() * sizeof(float)), r.hostTileDepth.data());
        r.tileHost.resize(r.hostTileDepth.size());
        for (std::size_t t = 0; t < r.tileHost.size(); ++t) {
            GLuint bits;
            std::memcpy(&bits, &r.hostTileDepth[t], 4);
            r.tileHost[t] = viewDepth(bits);
        }
    }
    r.needs.resize(s.frontBegin - s.behindEnd);
    for (std::size_t i = s.behindEnd; i < s.frontBegin; ++i) {
        classify(splats[i]);
        r.needs[i - s.behindEnd] = std::uint8_t(needs);
    }
    return s;
}

void FragmentListPass::insertSplats(const std::vector<Splat>& all, std::size_t begin, std::size_t end, const Camera& camera, unsigned layerTexture,
                                    float cut, bool trimCorners, bool depthCut, const PassTarget& target) {
    Impl& r = *mImpl;
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    end = std::min(end, all.size());
    if (begin >= end || !layerTexture || !target.depthTexture) return;
    const Splat* splats = all.data() + begin;
    const std::size_t count = end - begin;
    r.stats.splatsSectioned = count;
    // How many sections the frame needs: one more than the most surfaces on a pixel.
    GLuint maxSurfaces = 0;
    glGetNamedBufferSubData(r.counters, 6 * 4, 4, &maxSurfaces);
    const bool partial = depthCut && !r.partialSource.empty();
    r.stats.cut = partial;
    const Impl::SectionProgram* prog = &r.sectionPrograms[partial][2];
    for (const Impl::SectionProgram& p : r.sectionPrograms[partial])
        if (GLuint(p.sections) >= maxSurfaces + 1) {
            prog = &p;
            break;
        }
    r.sectionsThisFrame = prog->sections;
    // The sorted depths the section shader reads (grown only).
    const int layers = prog->sections - 1;
    if (!r.depths || layers > r.depthLayers || r.depthSize != glm::ivec2(target.width, target.height)) {
        if (r.depths) glDeleteTextures(1, &r.depths);
        glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &r.depths);
        glTextureStorage3D(r.depths, 1, GL_R32F, target.width, target.height, layers);
        glTextureParameteri(r.depths, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(r.depths, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        r.depthLayers = layers;
        r.depthSize = {target.width, target.height};
    }
    glUseProgram(r.prepareProgram->id);
    glUniform2i(r.prepareProgram->uniform(glsl::lists::Size), target.width, target.height);
    glUniform1i(r.prepareProgram->uniform(glsl::lists::Layers), layers);
    glBindTextureUnit(2, r.heads);
    glBindImageTexture(5, r.depths, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glDispatchCompute(GLuint((target.width + 7) / 8), GLuint((target.height + 7) / 8), 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindImageTexture(5, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    r.sizeSections({target.x + target.width, target.y + target.height}, prog->sections, target.depthTexture);

    if (count > r.instanceCapacity) {
        if (r.instances) glDeleteBuffers(1, &r.instances);
        r.instanceCapacity = std::max<std::size_t>(count + count / 2, 1024);
        glCreateBuffers(1, &r.instances);
        glNamedBufferStorage(r.instances, GLsizeiptr(r.instanceCapacity * sizeof(Splat)), nullptr, GL_DYNAMIC_STORAGE_BIT);
        glVertexArrayVertexBuffer(r.vao, 0, r.instances, 0, sizeof(Splat));
    }
    glNamedBufferSubData(r.instances, 0, GLsizeiptr(count * sizeof(Splat)), splats);

    GLenum bufs[kTransparentMaxSections];
    for (int k = 0; k < kTransparentMaxSections; ++k) bufs[k] = k < prog->sections ? GL_COLOR_ATTACHMENT0 + GLenum(k) : GL_NONE;
    glNamedFramebufferDrawBuffers(r.sectionFbo, kTransparentMaxSections, bufs);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    const GLfloat clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int k = 0; k < prog->sections; ++k) glClearNamedFramebufferfv(r.sectionFbo, GL_COLOR, k, clear);
    // With the cut the shader keeps each fragment's share in front of the
    // host depth it reads, so the hardware test is off (as in the splat
    // pass): at the drawn polygon it would drop whole the splats whose plane
    // lies behind the host surface (or was moved there past the near plane)
    // but whose kernel reaches in front of it. Without the cut, the plain
    // test at the splat plane is the model.
    setOverState(r.sectionFbo, target, partial ? DepthTest::Off : nearerOrEqual(camera));
    glDisable(GL_CULL_FACE);
    // Perspective with the cut: a polygon that crosses (or nearly) the eye
    // plane takes the general variant (screen-covering, each fragment meets
    // its ray with the splat plane), as in the splat pass: the vertex stage
    // of the other variant drops it below 0.25 near, the CPU routes below
    // 0.5 near (margin against float arithmetic).
    const glm::vec3 eye = camera.eye(), fwd = camera.forward();
    const float nearZ = camera.nearPlane(), extent = std::clamp(cut, 0.05f, 1.0f);
    auto crossesEyePlane = [&](const Splat& sp) {
        const float a = std::abs(glm::dot(sp.axisU, fwd)), b = std::abs(glm::dot(sp.axisV, fwd));
        const float reach = trimCorners ? std::max(a + 0.41421356f * b, 0.41421356f * a + b) : a + b;
        return !(glm::dot(sp.center - eye, fwd) - extent * reach >= 0.5f * nearZ); // also NaN
    };
    const bool general = partial && camera.perspective();
    const glm::mat4 vp = camera.proj * camera.view;
    const glm::mat4 invVp = glm::inverse(vp);
    const glm::vec3 depthMap = hostDepthMap(camera);
    const glm::vec2 ndcZ = generalNdcZ(camera);
    const std::size_t variant = std::size_t(prog - &r.sectionPrograms[partial][0]);
    const Impl::SectionProgram* generalProg = &r.sectionPrograms[2][variant];
    auto setUniforms = [&](const Impl::SectionProgram& p) {
        glUseProgram(p.id);
        glUniformMatrix4fv(p.program->uniform(glsl::section::ViewProj), 1, GL_FALSE, glm::value_ptr(vp));
        glUniform1i(p.program->uniform(glsl::section::Octagon), trimCorners ? 1 : 0);
        glUniform1f(p.program->uniform(glsl::section::Cut), extent);
        glUniform2i(p.program->uniform(glsl::section::Origin), target.x, target.y);
        glUniform1i(p.program->uniform(glsl::section::Reversed), camera.depth.reversed ? 1 : 0);
        if (!partial) return;
        glUniform3f(p.program->uniform(glsl::section::Eye), eye.x, eye.y, eye.z);
        glUniform3f(p.program->uniform(glsl::section::Forward), fwd.x, fwd.y, fwd.z);
        glUniform1f(p.program->uniform(glsl::section::NearZ), nearZ);
        glUniform1i(p.program->uniform(glsl::section::Persp), camera.perspective() ? 1 : 0);
        glUniform1f(p.program->uniform(glsl::section::KernelRadius), r.kernelRadius);
        glUniform3fv(p.program->uniform(glsl::section::HostDepthMap), 1, glm::value_ptr(depthMap));
        glUniform2fv(p.program->uniform(glsl::section::NdcZ), 1, glm::value_ptr(ndcZ));
        glUniformMatrix4fv(p.program->uniform(glsl::section::InvViewProj), 1, GL_FALSE, glm::value_ptr(invVp));
        glUniform4f(p.program->uniform(glsl::section::Viewport), float(target.x), float(target.y), float(target.width), float(target.height));
    };
    if (partial) {
        glBindTextureUnit(1, target.depthTexture);
        glBindTextureUnit(3, r.partial.texture());
    }
    glBindTextureUnit(0, layerTexture);
    glBindTextureUnit(2, r.depths);
    glBindVertexArray(r.vao);
    // Runs in back-to-front order, each with its variant.
    const GLsizei corners = trimCorners ? 8 : 4;
    const Impl::SectionProgram* bound = nullptr;
    std::uint64_t crossing = 0;
    // Per splat: 4 general, else the cuts it needs (split(): 1 near, 2 host).
    std::vector<std::uint8_t>& cls = r.classes;
    cls.resize(count);
    const bool planned = r.needs.size() == count;
    for (std::size_t i = 0; i < count; ++i) cls[i] = general && crossesEyePlane(splats[i]) ? 4 : planned ? r.needs[i] : 3;
    constexpr std::size_t kMerge = 24; // a shorter run takes the next one's cuts too rather than a draw of its own
    for (std::size_t i = 0; i < count;) {
        unsigned need = cls[i];
        std::size_t j = i + 1;
        for (;;) {
            while (j < count && cls[j] == need) ++j;
            if (j >= count || need == 4 || cls[j] == 4) break;
            if (j - i < kMerge) { // a short run takes on the next splat's cuts, and the splat
                need |= cls[j];
                ++j;
                continue;
            }
            // A long run absorbs a short run of splats that need less.
            std::size_t k = j;
            while (k < count && cls[k] == cls[j]) ++k;
            if ((cls[j] & ~need) != 0 || k - j >= kMerge) break;
            j = k;
        }
        const bool g = need == 4;
        const Impl::SectionProgram* p = g ? generalProg : partial ? &r.sectionPrograms[Impl::cutKind(need)][variant] : prog;
        if (!p->id) {
            if (!r.buildSections(Impl::cutKind(need))) p = prog; // never expected: the full cut program is exact for any splat
        }
        if (p != bound) setUniforms(*p), bound = p;
        glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, corners, GLsizei(j - i), GLuint(i));
        if (g) crossing += j - i;
        i = j;
    }
    r.stats.generalSplats = crossing;
}

void FragmentListPass::resolve(const PassTarget& target) {
    Impl& r = *mImpl;
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    GLuint maxSurfaces = 0;
    glGetNamedBufferSubData(r.counters, 6 * 4, 4, &maxSurfaces);
    const Impl::Program* program = r.resolvePrograms.back().second;
    int programK = r.resolvePrograms.back().first;
    for (const auto& rp : r.resolvePrograms)
        if (GLuint(rp.first) >= maxSurfaces) {
            program = rp.second;
            programK = rp.first;
            break;
        }
    // Every pixel's list fits the variant (nothing to merge, so nothing to
    // count): one full-screen draw resolves and composites at once. A
    // compute dispatch costs llvmpipe several times a draw per pixel, and
    // the RGBA16F image between the two goes.
    const Impl::Program* fragmentProgram = GLuint(programK) >= maxSurfaces && r.poolViewed ? r.fragmentResolve(programK) : nullptr;
    // Both resolves read the lists and the sections the same way.
    auto useResolve = [&](const Impl::Program& p) {
        glUseProgram(p.id);
        glUniform1i(p.uniform(glsl::lists::SectionCount), r.sectionsThisFrame);
        glUniform2i(p.uniform(glsl::lists::Origin), target.x, target.y);
        glUniform2i(p.uniform(glsl::lists::Size), target.width, target.height);
        if (r.sectionsThisFrame > 0) glBindTextureUnit(1, r.sections);
        glBindTextureUnit(2, r.heads);
    };
    if (fragmentProgram) {
        setOverState(target.framebuffer, target, DepthTest::Off);
        useResolve(*fragmentProgram);
        glBindTextureUnit(4, r.poolView);
        glBindVertexArray(r.emptyVao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindTextureUnit(4, 0);
    } else {
        useResolve(*program);
        glBindImageTexture(5, r.resolved, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
        glDispatchCompute(GLuint((target.width + 7) / 8), GLuint((target.height + 7) / 8), 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
        glBindImageTexture(5, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);

        setOverState(target.framebuffer, target, DepthTest::Off);
        glUseProgram(r.compositeProgram->id);
        glUniform2i(r.compositeProgram->uniform(glsl::lists::Origin), target.x, target.y);
        glBindTextureUnit(1, r.resolved);
        glBindVertexArray(r.emptyVao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    GLuint c[kCounterWords] = {};
    glGetNamedBufferSubData(r.counters, 0, sizeof(c), c);
    r.stats.nodes = std::min<std::uint64_t>(c[0], r.poolNodes);
    r.stats.fallback = c[1];
    r.stats.maxSurfaces = c[6];
    r.stats.sectionOverflow = c[7];
    r.stats.overflowPixels = c[8];
    r.stats.mergedNodes = c[9];
    r.stats.sections = r.sectionsThisFrame;
    r.stats.bytes = std::size_t(r.depthSize.x) * r.depthSize.y * 4 * std::size_t(r.depthLayers) /* sorted depths */ +
                    r.poolNodes * kTransparentNodeBytes + std::size_t(r.width) * r.height * kTransparentHeadBytesPerPixel +
                    std::size_t(kCounterBytes) + std::size_t(r.width) * r.height * 8 /* resolved RGBA16F */ +
                    std::size_t(r.sectionSize.x) * r.sectionSize.y * kTransparentSectionBytesPerPixel * std::size_t(r.sectionLayers) +
                    std::size_t(r.tileSize.x) * std::size_t(r.tileSize.y) * 16 /* the survey's tiles (RGBA32UI) */ +
                    std::size_t(r.hostTileSize.x) * std::size_t(r.hostTileSize.y) * 4 /* the host depth tiles (R32F) */;
    // Leave nothing of ours bound where the host's own buffers may live.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTransparentNodeBinding, 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTransparentCounterBinding, 0);
    glBindImageTexture(kTransparentHeadImageUnit, 0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindTextureUnit(1, 0);
    glBindTextureUnit(2, 0);
    glBindTextureUnit(3, 0);
}

// ---- As a pass of the frame (passes/pass.hpp) ----

void FragmentListPass::prepare(const FramePlan& plan, const Frame&) {
    mUsed = plan.lists;
    mSectioned = 0;
}

void FragmentListPass::execute(const PlanStep& step, StepContext& context) {
    const PassTarget& target = context.plan.target;
    const RendererDesc& d = mSplatDesc;
    switch (step.kind) {
    case StepKind::ListsCollect: {
        if (d.restoreState) mSaved.save({.texture2DUnits = 0, .scissor = false});
        const Status s = collectSurfaces(target, context.frame.camera(), context.host.drawTransparent);
        context.listsReady = bool(s);
        if (!s) context.listsNote = s.error();
        if (!s && d.restoreState) mSaved.restore();
        break;
    }
    case StepKind::ListsSplit: {
        if (!context.listsReady) break;
        const Split split = this->split(context.frame.splats(), context.frame.camera(), d.footprintCut, d.trimCorners, d.depthCut, target);
        context.behindEnd = split.behindEnd;
        context.frontBegin = split.frontBegin;
        break;
    }
    case StepKind::ListsSections:
        if (!context.listsReady) break;
        insertSplats(context.frame.splats(), context.behindEnd, context.frontBegin, context.frame.camera(), context.splatLayers, d.footprintCut,
                     d.trimCorners, d.depthCut, target);
        if (context.frontBegin > context.behindEnd) ++mSectioned;
        break;
    case StepKind::ListsResolve:
        if (!context.listsReady) break;
        resolve(target);
        if (d.restoreState) mSaved.restore();
        break;
    default: assert(false && "FragmentListPass: not a list step");
    }
}

void FragmentListPass::report(FrameRenderStats& stats) const {
    if (!mUsed) return;
    const FragmentListStats& ls = mImpl->stats;
    FrameRenderStats::Lists& l = stats.lists;
    l.nodes = ls.nodes;
    l.fallback = ls.fallback;
    l.overflowPixels = ls.overflowPixels;
    l.mergedNodes = ls.mergedNodes;
    l.sectionOverflow = ls.sectionOverflow;
    l.maxSurfaces = ls.maxSurfaces;
    l.sections = ls.sections;
    l.cut = ls.cut;
    l.general = ls.generalSplats;
    l.splatsBehind = ls.splatsBehind;
    l.splatsFront = ls.splatsFront;
    l.splatsSectioned = ls.splatsSectioned;
    l.bytes = ls.bytes;
    stats.drawCalls += mSectioned;
}

} // namespace splatfx::gl::detail
