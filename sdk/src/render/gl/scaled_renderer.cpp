#include "splatfx/gl/scaled_renderer.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <optional>
#include <string>

#include <epoxy/gl.h>

#include "context_check.hpp"
#include "host_depth.hpp"
#include "formats.hpp"
#include "saved_state.hpp"
#include "over_state.hpp"
#include "program_library.hpp"

namespace splatfx::gl {
namespace {

// Window-space rectangle (x0, y0, x1, y1), relative to the viewport, that the
// splats' quads can touch; the whole viewport when one crosses the eye plane.
glm::ivec4 splatBounds(std::span<const Splat> splats, const Camera& camera, int w, int h) {
    const glm::mat4 vp = camera.proj * camera.view;
    float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
    for (const Splat& s : splats)
        for (int k = 0; k < 4; ++k) {
            const glm::vec3 p = s.center + ((k & 1) ? 1.0f : -1.0f) * s.axisU + ((k & 2) ? 1.0f : -1.0f) * s.axisV;
            const glm::vec4 c = vp * glm::vec4(p, 1.0f);
            if (!(c.w > 1e-6f)) return {0, 0, w, h};
            const float px = (c.x / c.w * 0.5f + 0.5f) * float(w), py = (c.y / c.w * 0.5f + 0.5f) * float(h);
            x0 = std::min(x0, px), x1 = std::max(x1, px), y0 = std::min(y0, py), y1 = std::max(y1, py);
        }
    auto clampTo = [](float v, int hi) { return int(std::clamp(v, 0.0f, float(hi))); };
    return {clampTo(std::floor(x0) - 1.0f, w), clampTo(std::floor(y0) - 1.0f, h), clampTo(std::ceil(x1) + 1.0f, w), clampTo(std::ceil(y1) + 1.0f, h)};
}

} // namespace

struct ScaledRenderer::Impl {
    ScaledRendererDesc desc;
    std::optional<Renderer> inner;
    detail::Programs programs;
    const detail::ProgramLibrary::Program* downsample = nullptr;
    const detail::ProgramLibrary::Program* composite = nullptr;
    GLuint emptyVao = 0;
    GLuint fbo = 0, color = 0, depth = 0;
    int lowW = 0, lowH = 0;
    // Private copy of the host depth: sampling a texture attached to the
    // framebuffer being drawn is a feedback loop (undefined, and slow on llvmpipe).
    GLuint hostCopy = 0;
    int copyW = 0, copyH = 0;
    GLenum copyFormat = 0;
    // Between begin() and composite().
    bool open = false, useDepth = false;
    PassTarget target;
    glm::ivec4 lowBox{0}, fullBox{0};
    detail::SavedState saved;

    ~Impl() {
        if (!detail::contextIsCurrent()) return; // the context took our objects with it
        if (emptyVao) glDeleteVertexArrays(1, &emptyVao);
        if (hostCopy) glDeleteTextures(1, &hostCopy);
        releaseTarget();
    }
    void releaseTarget() {
        if (fbo) glDeleteFramebuffers(1, &fbo);
        if (color) glDeleteTextures(1, &color);
        if (depth) glDeleteTextures(1, &depth);
        fbo = color = depth = 0;
        lowW = lowH = 0;
    }
    void ensureTarget(int w, int h) {
        if (w == lowW && h == lowH && fbo) return;
        releaseTarget();
        const GLenum format = detail::colorFormat(desc.precision);
        glCreateTextures(GL_TEXTURE_2D, 1, &color);
        glTextureStorage2D(color, 1, format, w, h);
        glCreateTextures(GL_TEXTURE_2D, 1, &depth);
        glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT32F, w, h);
        for (GLuint t : {color, depth}) {
            glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        }
        glCreateFramebuffers(1, &fbo);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
        glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
        lowW = w;
        lowH = h;
    }
};

ScaledRenderer::ScaledRenderer(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
ScaledRenderer::ScaledRenderer(ScaledRenderer&&) noexcept = default;
ScaledRenderer& ScaledRenderer::operator=(ScaledRenderer&&) noexcept = default;
ScaledRenderer::~ScaledRenderer() = default;
const ScaledRendererDesc& ScaledRenderer::desc() const { return mImpl->desc; }
const Renderer& ScaledRenderer::renderer() const { return *mImpl->inner; }
Renderer& ScaledRenderer::renderer() { return *mImpl->inner; }

Result<ScaledRenderer> ScaledRenderer::create(const ScaledRendererDesc& desc) { return create(desc, std::make_shared<detail::ProgramLibrary>()); }

Result<ScaledRenderer> ScaledRenderer::create(const ScaledRendererDesc& desc, detail::Programs programs) {
    if (desc.scale != 1 && desc.scale != 2 && desc.scale != 4)
        return makeError("ScaledRendererDesc::scale must be 1, 2 or 4 (got " + std::to_string(desc.scale) + ")");
    if (!(desc.depthThreshold > 0.0f))
        return makeError("ScaledRendererDesc::depthThreshold must be positive (got " + std::to_string(desc.depthThreshold) + ")");
    RendererDesc innerDesc = desc.renderer;
    innerDesc.restoreState = false; // draw() saves and restores once around all three passes
    auto inner = Renderer::create(innerDesc, programs);
    if (!inner) return makeError(inner.error());
    auto impl = std::make_unique<Impl>();
    impl->desc = desc;
    impl->inner = std::move(*inner);
    impl->programs = std::move(programs);
    auto down = impl->programs->get({glsl::ProgramId::DepthDownsample});
    if (!down) return makeError(down.error());
    impl->downsample = *down;
    auto comp = impl->programs->get({glsl::ProgramId::ScaledComposite});
    if (!comp) return makeError(comp.error());
    impl->composite = *comp;
    glCreateVertexArrays(1, &impl->emptyVao);
    return ScaledRenderer(std::move(impl));
}

Status ScaledRenderer::upload(const Materials& materials) { return mImpl->inner->upload(materials); }

void ScaledRenderer::draw(std::span<const Splat> splats, const Camera& camera, const PassTarget& target) {
    drawResolved(splats, camera, detail::resolveTarget(target));
}

PassTarget ScaledRenderer::begin(const PassTarget& target, glm::ivec4 box, const DepthConvention& depth) {
    return beginResolved(detail::resolveTarget(target), box, depth);
}

void ScaledRenderer::drawResolved(std::span<const Splat> splats, const Camera& camera, const PassTarget& target) {
    Impl& r = *mImpl;
    assert(target.width > 0 && target.height > 0 && "PassTarget::width and height must be positive");
    if (r.desc.scale == 1) {
        detail::SavedState saved;
        if (r.desc.renderer.restoreState) saved.save({.texture2DUnits = 3, .scissor = true});
        r.inner->drawResolved(splats, camera, target);
        if (r.desc.renderer.restoreState) saved.restore();
        return;
    }
    // The passes at full resolution only touch the splats' screen rectangle
    // (grown by a low-resolution texel for the bilinear taps): on a CPU
    // rasterizer a full-screen pass costs as much as the effect itself.
    const glm::ivec4 box = splatBounds(splats, camera, target.width, target.height);
    if (box.z <= box.x || box.w <= box.y) return;
    beginResolved(target, box, camera.depth);
    drawSplats(splats, camera);
    composite(camera);
}

PassTarget ScaledRenderer::beginResolved(const PassTarget& target, glm::ivec4 box, const DepthConvention& depth) {
    Impl& r = *mImpl;
    assert(target.width > 0 && target.height > 0 && "PassTarget::width and height must be positive");
    assert(!r.open && "ScaledRenderer::begin: composite() the previous layer first");
    // The passes bind GL_TEXTURE_2D on units 0-2 (colour, depth, host depth
    // copy), the texture array on unit 0, and scissor to the box.
    if (r.desc.renderer.restoreState) r.saved.save({.texture2DUnits = 3, .scissor = true});
    r.open = true;
    r.target = target;
    const int s = r.desc.scale;
    r.ensureTarget((target.width + s - 1) / s, (target.height + s - 1) / s);
    box = {std::clamp(box.x, 0, target.width), std::clamp(box.y, 0, target.height), std::clamp(box.z, 0, target.width),
           std::clamp(box.w, 0, target.height)};
    r.lowBox = {std::max(box.x / s - 1, 0), std::max(box.y / s - 1, 0), std::min(box.z / s + 2, r.lowW), std::min(box.w / s + 2, r.lowH)};
    r.fullBox = {std::max(r.lowBox.x * s, 0), std::max(r.lowBox.y * s, 0), std::min(r.lowBox.z * s, target.width),
                 std::min(r.lowBox.w * s, target.height)};

    const GLuint hostDepth = target.depthTexture;
    r.useDepth = hostDepth != 0;
    if (r.useDepth) {
        GLint format = 0;
        glGetTextureLevelParameteriv(hostDepth, 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
        if (!r.hostCopy || r.copyW != target.width || r.copyH != target.height || r.copyFormat != GLenum(format)) {
            if (r.hostCopy) glDeleteTextures(1, &r.hostCopy);
            glCreateTextures(GL_TEXTURE_2D, 1, &r.hostCopy);
            glTextureStorage2D(r.hostCopy, 1, GLenum(format), target.width, target.height);
            r.copyW = target.width, r.copyH = target.height, r.copyFormat = GLenum(format);
        }
        glCopyImageSubData(hostDepth, GL_TEXTURE_2D, 0, target.x, target.y, 0, r.hostCopy, GL_TEXTURE_2D, 0, 0, 0, 0, target.width, target.height, 1);
    }
    // The copy starts at the viewport's corner, so the shaders read it at offset 0.
    const GLint hostRect[4] = {0, 0, target.width, target.height};

    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r.fbo);
    glViewport(0, 0, r.lowW, r.lowH);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    const float clear[4] = {0.0f, 0.0f, 0.0f, 0.0f}, farDepth = float(depth.farWindow());
    glDisable(GL_SCISSOR_TEST);
    glClearNamedFramebufferfv(r.fbo, GL_COLOR, 0, clear);
    glClearNamedFramebufferfv(r.fbo, GL_DEPTH, 0, &farDepth);
    glBindVertexArray(r.emptyVao);
    if (r.useDepth) {
        glEnable(GL_SCISSOR_TEST);
        glScissor(r.lowBox.x, r.lowBox.y, r.lowBox.z - r.lowBox.x, r.lowBox.w - r.lowBox.y);
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_ALWAYS);
        glUseProgram(r.downsample->id);
        glUniform4iv(r.downsample->uniform(glsl::downsample::HostRect), 1, hostRect);
        glUniform1i(r.downsample->uniform(glsl::downsample::Scale), s);
        glUniform1i(r.downsample->uniform(glsl::downsample::Reversed), depth.reversed ? 1 : 0);
        glBindTextureUnit(2, r.hostCopy);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDisable(GL_SCISSOR_TEST);
    }
    return {.framebuffer = r.fbo, .width = r.lowW, .height = r.lowH, .depthTexture = r.depth};
}

void ScaledRenderer::drawSplats(std::span<const Splat> splats, const Camera& camera) {
    Impl& r = *mImpl;
    assert(r.open && "ScaledRenderer::drawSplats: begin() first");
    // Into the low-resolution target (transparent black, premultiplied).
    r.inner->drawResolved(splats, camera, {.framebuffer = r.fbo, .width = r.lowW, .height = r.lowH, .depthTexture = r.depth});
}

void ScaledRenderer::composite(const Camera& camera) {
    Impl& r = *mImpl;
    assert(r.open && "ScaledRenderer::composite: begin() first");
    const PassTarget& target = r.target;
    const GLint hostRect[4] = {0, 0, target.width, target.height};
    glEnable(GL_SCISSOR_TEST);
    glScissor(target.x + r.fullBox.x, target.y + r.fullBox.y, r.fullBox.z - r.fullBox.x, r.fullBox.w - r.fullBox.y);
    detail::setOverState(target.framebuffer, target, detail::DepthTest::Off);
    glDisable(GL_CULL_FACE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glUseProgram(r.composite->id);
    glUniform4iv(r.composite->uniform(glsl::composite::HostRect), 1, hostRect);
    glUniform2i(r.composite->uniform(glsl::composite::ViewportOrigin), target.x, target.y);
    glUniform1i(r.composite->uniform(glsl::composite::Scale), r.desc.scale);
    glUniform1i(r.composite->uniform(glsl::composite::UseDepth), r.useDepth ? 1 : 0);
    glUniform1f(r.composite->uniform(glsl::composite::Threshold), r.desc.depthThreshold);
    const glm::vec3 depthMap = detail::hostDepthMap(camera);
    glUniform3fv(r.composite->uniform(glsl::composite::HostDepthMap), 1, glm::value_ptr(depthMap));
    glBindTextureUnit(0, r.color);
    glBindTextureUnit(1, r.depth);
    if (r.useDepth) glBindTextureUnit(2, r.hostCopy);
    glBindVertexArray(r.emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_SCISSOR_TEST);
    r.open = false;
    if (r.desc.renderer.restoreState) r.saved.restore();
}

} // namespace splatfx::gl
