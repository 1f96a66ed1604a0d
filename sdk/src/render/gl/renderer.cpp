#include "splatfx/gl/renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <cassert>
#include <cstddef>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

#include "context_check.hpp"
#include "partial_texture.hpp"
#include "saved_state.hpp"
#include "splatfx/gl/program.hpp"
#include "shaders.hpp"

namespace splatfx::gl {
namespace {

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
            for (int k = 0; k < 4; ++k)
                o[k] = (1.0f - ay) * ((1.0f - ax) * a[k] + ax * b[k]) + ay * ((1.0f - ax) * c[k] + ax * d[k]);
        }
    }
    return out.data();
}

} // namespace

struct Renderer::Impl {
    RendererDesc desc;
    DrawStats stats;
    // Programs by variant (kCrossfade | kFog | ...), compiled on first use:
    // each draw run picks the cheapest variant that is exact for its splats.
    enum Variant : unsigned { kCrossfade = 1, kFog = 2, kCut = 4, kHostDepth = 8, kNear = 16, kGeneral = 32 };
    struct Program {
        GLuint id = 0;
        GLint uViewProj = -1, uOctagon = -1, uCut = -1;
        // Fog (issue 14)
        GLint uFogEye = -1, uParams = -1, uColour = -1, uFar = -1;
        // Depth cut (issue 15)
        GLint uEye = -1, uForward = -1, uNearZ = -1, uPersp = -1, uKernelRadius = -1, uDepthToView = -1, uInvViewProj = -1,
              uViewport = -1;
    };
    std::map<unsigned, Program> programs;
    std::string programError; // the last variant that failed to build (never expected: a shader bug)
    std::string fogSource; // generated GLSL the fog programs were built from
    std::string fogUniform;
    int fogVec4s = 0;
    const Fog* fog = nullptr;
    double fogTimeSec = 0.0;
    std::vector<glm::vec4> fogParams;
    // Depth cut (issue 15): the partial table, its GLSL, per-splat classes.
    detail::PartialTexture partial;
    std::string partialSource;
    float kernelRadius = 1.6f;
    std::array<float, 256> rho{}; // rayScaleRho by code
    std::vector<std::uint8_t> classes;
    GLuint depthQueried = 0;  // the host depth texture last checked, and whether it can be sampled
    bool depthUsable = false;
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
    void dropPrograms(unsigned mask) {
        for (auto it = programs.begin(); it != programs.end();)
            if (it->first & mask) {
                if (it->second.id) glDeleteProgram(it->second.id);
                it = programs.erase(it);
            } else {
                ++it;
            }
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
        for (const auto& p : programs)
            if (p.second.id) glDeleteProgram(p.second.id);
        if (vao) glDeleteVertexArrays(1, &vao);
        if (instances) glDeleteBuffers(1, &instances);
        if (layers) glDeleteTextures(1, &layers);
    }
};

const Renderer::Impl::Program* Renderer::Impl::program(unsigned v) {
    if (auto it = programs.find(v); it != programs.end()) return it->second.id ? &it->second : nullptr;
    Program& p = programs[v];
    const bool cut = v & kCut;
    std::string head = "#version 450 core\n";
    head += (v & kFog) ? "#define FOG 1\n" : "#define FOG 0\n";
    head += (v & kFog) && desc.fogPerSplat ? "#define FOG_PER_SPLAT 1\n" : "#define FOG_PER_SPLAT 0\n";
    head += cut ? "#define CUT 1\n" : "#define CUT 0\n";
    head += cut && (v & kHostDepth) ? "#define HOST_DEPTH 1\n" : "#define HOST_DEPTH 0\n";
    head += cut && (v & (kNear | kGeneral)) ? "#define NEAR_CUT 1\n" : "#define NEAR_CUT 0\n";
    head += cut && (v & kGeneral) ? "#define GENERAL 1\n" : "#define GENERAL 0\n";
    const std::string fs = head + ((v & kCrossfade) ? "#define CROSSFADE 1\n" : "#define CROSSFADE 0\n");
    const char* fogSrc = (v & kFog) ? fogSource.c_str() : "";
    const char* partialSrc = cut ? partialSource.c_str() : "";
    auto linked = linkProgram({head.c_str(), fogSrc, partialSrc, detail::kSplatVertex}, {fs.c_str(), fogSrc, partialSrc, detail::kSplatFragment},
                              (v & kFog) ? "splat (fog)" : "splat");
    if (!linked) {
        programError = linked.error();
        return nullptr;
    }
    p.id = *linked;
    auto loc = [&](const char* name) { return glGetUniformLocation(p.id, name); };
    p.uViewProj = loc("uViewProj");
    p.uOctagon = loc("uOctagon");
    p.uCut = loc("uCut");
    if (v & kFog) {
        p.uFogEye = loc("uFogEye");
        p.uParams = loc(fogUniform.c_str());
        p.uColour = loc("splatfx_fog_colour");
        p.uFar = loc("splatfx_fog_far");
    }
    p.uEye = loc("uEye");
    p.uForward = loc("uForward");
    p.uNearZ = loc("uNearZ");
    p.uPersp = loc("uPersp");
    p.uKernelRadius = loc("uKernelRadius");
    p.uDepthToView = loc("uDepthToView");
    p.uInvViewProj = loc("uInvViewProj");
    p.uViewport = loc("uViewport");
    return &p;
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

Result<Renderer> Renderer::create(const RendererDesc& desc) {
    if (!detail::contextIsCurrent()) return makeError("splatfx::gl::Renderer::create: no OpenGL context is current on this thread");
    if (epoxy_gl_version() < 45)
        return makeError("splatfx::gl::Renderer::create: OpenGL 4.5 is required, the current context has " +
                         std::to_string(epoxy_gl_version() / 10) + "." + std::to_string(epoxy_gl_version() % 10));
    auto impl = std::make_unique<Impl>();
    impl->desc = desc;
    for (int c = 0; c < 256; ++c) impl->rho[size_t(c)] = rayScaleRho(std::uint8_t(c));
    // The plain program now, so a broken build of the shaders fails here
    // (the cut variants need the materials' footprint: built at upload).
    if (!impl->program(0)) return makeError(impl->programError);

    glCreateVertexArrays(1, &impl->vao);
    impl->grow(0);
    if (!impl->mapped) return makeError("splatfx::gl::Renderer::create: cannot map a persistent instance buffer");
    glVertexArrayBindingDivisor(impl->vao, 0, 1);
    // The Splat struct as vertex attributes (one per instance):
    // three vec4s, the layer pair as two u16, blend, and the RGBA8 colour.
    for (GLuint a = 0; a < 3; ++a) glVertexArrayAttribFormat(impl->vao, a, 4, GL_FLOAT, GL_FALSE, a * 16);
    glVertexArrayAttribIFormat(impl->vao, 3, 2, GL_UNSIGNED_SHORT, offsetof(Splat, layer));
    glVertexArrayAttribFormat(impl->vao, 4, 1, GL_FLOAT, GL_FALSE, offsetof(Splat, blend));
    glVertexArrayAttribFormat(impl->vao, 5, 4, GL_UNSIGNED_BYTE, GL_TRUE, offsetof(Splat, color));
    for (GLuint a = 0; a < 6; ++a) {
        glEnableVertexArrayAttrib(impl->vao, a);
        glVertexArrayAttribBinding(impl->vao, a, 0);
    }
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
    const std::string partial = partialGlsl(materials.footprint(), 2);
    if (partial != r.partialSource) {
        r.dropPrograms(Impl::kCut);
        r.partialSource = partial;
    }
    if (r.desc.depthCut && !r.program(Impl::kCut)) return makeError("splatfx::gl::Renderer::upload: " + r.programError);
    return {};
}

Status Renderer::setFog(const Fog* fog, double timeSec) {
    Impl& r = *mImpl;
    r.fog = fog && !fog->empty() ? fog : nullptr; // zero terms: clear air, the plain shaders
    r.fogTimeSec = timeSec;
    if (!r.fog) return {};
    auto glsl = fogGlsl(*r.fog);
    if (!glsl) {
        r.fog = nullptr;
        return makeError("splatfx::gl::Renderer::setFog: " + glsl.error());
    }
    if (glsl->source == r.fogSource) return {};
    r.dropPrograms(Impl::kFog);
    r.fogSource = glsl->source;
    r.fogUniform = glsl->uniformName;
    r.fogVec4s = glsl->vec4Count;
    if (!r.program(Impl::kFog | (r.desc.depthCut && !r.partialSource.empty() ? Impl::kCut : 0u))) {
        r.fog = nullptr;
        r.fogSource.clear();
        return makeError(r.programError);
    }
    return {};
}

namespace {

// The host depth the cut reads: the target's texture, else the framebuffer's
// depth attachment when it is a texture (the default framebuffer's never is).
GLuint hostDepthTexture(const Target& target) {
    if (target.depthTexture) return target.depthTexture;
    if (target.framebuffer == 0) return 0;
    GLint type = GL_NONE, name = 0;
    glGetNamedFramebufferAttachmentParameteriv(target.framebuffer, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
    if (type != GL_TEXTURE) return 0;
    glGetNamedFramebufferAttachmentParameteriv(target.framebuffer, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &name);
    return GLuint(name);
}

} // namespace

void Renderer::draw(const std::vector<Splat>& splats, const Camera& camera, const Target& target) {
    Impl& r = *mImpl;
    assert(r.layers && "splatfx::gl::Renderer::draw: call upload(materials) first");
    r.stats.splats = splats.size();
    r.stats.drawCalls = 0;
    r.stats.cutNear = r.stats.cutGeneral = 0;
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
    // One pass over the splats: copy into the ring, note whether any
    // cross-fades and (cut) which need the near-plane cut or the general
    // variant. Class 0: support wholly beyond the near plane; 1: the near
    // plane meets it; 2: the drawn polygon nearly crosses the eye plane
    // (perspective), drawn as a screen-covering quad. The thresholds leave
    // margin against the vertex shader's own float arithmetic (which drops
    // a polygon only below 0.25 near).
    Splat* dst = r.mapped + first;
    bool anyCrossfade = false;
    if (cut) r.classes.resize(splats.size());
    for (std::size_t i = 0; i < splats.size(); ++i) {
        const Splat& sp = splats[i];
        dst[i] = sp;
        anyCrossfade |= sp.blend > 0.0f;
        if (!cut) continue;
        const float a = std::abs(glm::dot(sp.axisU, fwd)), b = std::abs(glm::dot(sp.axisV, fwd));
        const float reach = r.desc.trimCorners ? std::max(a + 0.41421356f * b, 0.41421356f * a + b) : a + b;
        const float minZ = glm::dot(sp.center - eye, fwd) - cutExtent * reach;
        const float area = glm::length(glm::cross(sp.axisU, sp.axisV));
        const float l = r.rho[sp.color >> 24] * std::sqrt(area) / r.kernelRadius;
        std::uint8_t c = minZ - 1.01f * r.kernelRadius * l < nearZ * 1.01f + 1e-6f ? 1 : 0;
        if (persp && !(minZ >= 0.5f * nearZ)) c = 2; // also NaN
        r.classes[i] = c;
    }

    // draw() binds unit 0's texture array and, with the cut, 2D textures on units 1 and 2.
    detail::SavedState saved;
    if (r.desc.restoreState) saved.save({.texture2DUnits = cut ? 3 : 0, .scissor = false});

    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target.framebuffer);
    glViewport(target.x, target.y, target.width, target.height);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glBlendEquationSeparate(GL_FUNC_ADD, GL_FUNC_ADD);
    if (r.desc.depthTest) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LEQUAL);
    } else {
        glDisable(GL_DEPTH_TEST);
    }
    glDepthMask(GL_FALSE);
    glDisable(GL_CULL_FACE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);

    // The cut reads the host depth where it can sample it (single-sampled),
    // and keeps the hardware test (LEQUAL, read-only) on the polygons the
    // vertex shader moved in front of each support, to skip hidden ones early.
    GLuint depthTex = 0;
    if (cut && r.desc.depthTest) {
        depthTex = hostDepthTexture(target);
        if (depthTex && depthTex != r.depthQueried) {
            GLint samples = 0;
            glGetTextureLevelParameteriv(depthTex, 0, GL_TEXTURE_SAMPLES, &samples);
            r.depthQueried = depthTex;
            r.depthUsable = samples <= 1;
        }
        if (depthTex && !r.depthUsable) depthTex = 0; // multisampled: the plain test at the splat plane
    }
    r.stats.cutHostDepth = depthTex != 0;

    const bool fogged = r.fog && !r.fogSource.empty();
    const unsigned base = (anyCrossfade ? Impl::kCrossfade : 0u) | (fogged ? Impl::kFog : 0u) | (cut ? Impl::kCut : 0u) |
                          (depthTex ? Impl::kHostDepth : 0u);
    const glm::mat4 vp = camera.proj * camera.view;
    const glm::mat4 invProj = glm::inverse(camera.proj);
    const glm::mat4 invVp = glm::inverse(vp);
    if (fogged) r.fogParams = r.fog->glslParameters(r.fogTimeSec, glm::dvec3(eye));
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
            glUniform3f(p->uFogEye, eye.x, eye.y, eye.z);
            glUniform4fv(p->uParams, GLsizei(r.fogParams.size()), glm::value_ptr(r.fogParams[0]));
            const glm::dvec3 col = r.fog->desc().colour;
            glUniform3f(p->uColour, float(col.x), float(col.y), float(col.z));
            glUniform1f(p->uFar, float(r.fog->desc().farDistanceWorld));
        }
        glUniformMatrix4fv(p->uViewProj, 1, GL_FALSE, glm::value_ptr(vp));
        glUniform1i(p->uOctagon, r.desc.trimCorners ? 1 : 0);
        glUniform1f(p->uCut, cutExtent);
        if (variant & Impl::kCut) {
            glUniform3f(p->uEye, eye.x, eye.y, eye.z);
            glUniform3f(p->uForward, fwd.x, fwd.y, fwd.z);
            glUniform1f(p->uNearZ, nearZ);
            glUniform1i(p->uPersp, persp ? 1 : 0);
            glUniform1f(p->uKernelRadius, r.kernelRadius);
            glUniform4f(p->uDepthToView, invProj[2][2], invProj[3][2], invProj[2][3], invProj[3][3]);
            glUniformMatrix4fv(p->uInvViewProj, 1, GL_FALSE, glm::value_ptr(invVp));
            glUniform4f(p->uViewport, float(target.x), float(target.y), float(target.width), float(target.height));
        }
        glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, corners, GLsizei(end - begin), GLuint(first + begin));
        ++r.stats.drawCalls;
    };

    if (!cut) {
        drawRange(base, 0, splats.size());
    } else {
        // Back to front, the splats the near plane meets come last: the bulk
        // in one draw without the near cut, then runs of near and general.
        std::size_t i = 0;
        while (i < splats.size() && r.classes[i] == 0) ++i;
        drawRange(base, 0, i);
        while (i < splats.size()) {
            const bool general = r.classes[i] == 2;
            std::size_t j = i;
            while (j < splats.size() && (r.classes[j] == 2) == general) ++j;
            drawRange(base | (general ? Impl::kGeneral : Impl::kNear), i, j);
            if (general) r.stats.cutGeneral += j - i;
            else r.stats.cutNear += j - i;
            i = j;
        }
    }
    r.fences[r.region] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);

    if (r.desc.restoreState) saved.restore();
}

} // namespace splatfx::gl
