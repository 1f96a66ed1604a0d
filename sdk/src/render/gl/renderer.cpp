#include "splatfx/gl/renderer.hpp"

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

#include "context_check.hpp"
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
    struct Program {
        GLuint id = 0;
        GLint uViewProj = -1, uOctagon = -1, uCut = -1;
    };
    Program programs[2]; // [0]: no cross-fade in the frame, [1]: with cross-fade
    // Fog variant (issue 14): compiled for the structure of the last fog seen.
    struct FogProgram {
        Program p;
        GLint uFogEye = -1, uParams = -1, uColour = -1, uFar = -1;
    };
    FogProgram fogPrograms[2];
    std::string fogSource; // generated GLSL the fog programs were built from
    int fogVec4s = 0;
    const Fog* fog = nullptr;
    double fogTimeSec = 0.0;
    std::vector<glm::vec4> fogParams;
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
        for (const Program& p : programs)
            if (p.id) glDeleteProgram(p.id);
        for (const FogProgram& p : fogPrograms)
            if (p.p.id) glDeleteProgram(p.p.id);
        if (vao) glDeleteVertexArrays(1, &vao);
        if (instances) glDeleteBuffers(1, &instances);
        if (layers) glDeleteTextures(1, &layers);
    }
};

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
    for (int crossfade = 0; crossfade < 2; ++crossfade) {
        auto linked = linkProgram({"#version 450 core\n#define FOG 0\n#define FOG_PER_SPLAT 0\n", detail::kSplatVertex},
                                          {"#version 450 core\n#define FOG 0\n#define FOG_PER_SPLAT 0\n", crossfade ? "#define CROSSFADE 1\n" : "#define CROSSFADE 0\n", detail::kSplatFragment},
                                          "splat");
        if (!linked) return makeError(linked.error());
        Impl::Program& p = impl->programs[crossfade];
        p.id = *linked;
        p.uViewProj = glGetUniformLocation(p.id, "uViewProj");
        p.uOctagon = glGetUniformLocation(p.id, "uOctagon");
        p.uCut = glGetUniformLocation(p.id, "uCut");
    }

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
    for (Impl::FogProgram& p : r.fogPrograms)
        if (p.p.id) glDeleteProgram(p.p.id), p = {};
    r.fogSource.clear();
    for (int crossfade = 0; crossfade < 2; ++crossfade) {
        const char* head = r.desc.fogPerSplat ? "#version 450 core\n#define FOG 1\n#define FOG_PER_SPLAT 1\n"
                                              : "#version 450 core\n#define FOG 1\n#define FOG_PER_SPLAT 0\n";
        auto linked = linkProgram({head, glsl->source.c_str(), detail::kSplatVertex},
                                  {head, crossfade ? "#define CROSSFADE 1\n" : "#define CROSSFADE 0\n", glsl->source.c_str(),
                                   detail::kSplatFragment},
                                  "splat (fog)");
        if (!linked) {
            r.fog = nullptr;
            return makeError(linked.error());
        }
        Impl::FogProgram& p = r.fogPrograms[crossfade];
        p.p.id = *linked;
        p.p.uViewProj = glGetUniformLocation(p.p.id, "uViewProj");
        p.p.uOctagon = glGetUniformLocation(p.p.id, "uOctagon");
        p.p.uCut = glGetUniformLocation(p.p.id, "uCut");
        p.uFogEye = glGetUniformLocation(p.p.id, "uFogEye");
        p.uParams = glGetUniformLocation(p.p.id, glsl->uniformName.c_str());
        p.uColour = glGetUniformLocation(p.p.id, "splatfx_fog_colour");
        p.uFar = glGetUniformLocation(p.p.id, "splatfx_fog_far");
    }
    r.fogSource = glsl->source;
    r.fogVec4s = glsl->vec4Count;
    return {};
}

void Renderer::draw(const std::vector<Splat>& splats, const Camera& camera, const Target& target) {
    Impl& r = *mImpl;
    assert(r.layers && "splatfx::gl::Renderer::draw: call upload(materials) first");
    r.stats.splats = splats.size();
    r.stats.drawCalls = 0;
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
    // One pass over the splats: copy into the ring and note whether any cross-fades.
    Splat* dst = r.mapped + first;
    bool anyCrossfade = false;
    for (std::size_t i = 0; i < splats.size(); ++i) {
        dst[i] = splats[i];
        anyCrossfade |= splats[i].blend > 0.0f;
    }

    // draw() binds only unit 0's texture array (no GL_TEXTURE_2D, no scissor).
    detail::SavedState saved;
    if (r.desc.restoreState) saved.save({.texture2DUnits = 0, .scissor = false});

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
    const bool fogged = r.fog && r.fogPrograms[0].p.id;
    const Impl::Program& p = fogged ? r.fogPrograms[anyCrossfade ? 1 : 0].p : r.programs[anyCrossfade ? 1 : 0];
    glUseProgram(p.id);
    if (fogged) {
        // Parameters in double relative to the eye, rounded to float once (docs/fog.md, GLSL).
        const Impl::FogProgram& fp = r.fogPrograms[anyCrossfade ? 1 : 0];
        const glm::dvec3 eye(camera.eye());
        r.fogParams = r.fog->glslParameters(r.fogTimeSec, eye);
        glUniform3f(fp.uFogEye, float(eye.x), float(eye.y), float(eye.z));
        glUniform4fv(fp.uParams, GLsizei(r.fogParams.size()), glm::value_ptr(r.fogParams[0]));
        const glm::dvec3 col = r.fog->desc().colour;
        glUniform3f(fp.uColour, float(col.x), float(col.y), float(col.z));
        glUniform1f(fp.uFar, float(r.fog->desc().farDistanceWorld));
    }
    const glm::mat4 vp = camera.proj * camera.view;
    glUniformMatrix4fv(p.uViewProj, 1, GL_FALSE, glm::value_ptr(vp));
    glUniform1i(p.uOctagon, r.desc.trimCorners ? 1 : 0);
    glUniform1f(p.uCut, std::clamp(r.desc.footprintCut, 0.05f, 1.0f));
    glBindTextureUnit(0, r.layers);
    glBindVertexArray(r.vao);
    glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, r.desc.trimCorners ? 8 : 4, GLsizei(splats.size()), GLuint(first));
    r.fences[r.region] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    r.stats.drawCalls = 1;

    if (r.desc.restoreState) saved.restore();
}

} // namespace splatfx::gl
