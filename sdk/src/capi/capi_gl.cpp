// splatfx_c.h, the GL half: the headless context and gl::FrameRenderer into the host's framebuffer.
#include <epoxy/gl.h>

#include "capi/capi_internal.hpp"
#include "render/gl/context_check.hpp"

using namespace splatfx;
using namespace splatfx::capi;

namespace {

// GL calls with no current context abort inside the loader: ask first (never calls GL).
std::optional<Outcome> checkContext() {
    if (!gl::detail::contextIsCurrent())
        return failure(SPLATFX_ERROR_GL, "no OpenGL context is current on this thread (make the host's GL 4.5 context current first)");
    return std::nullopt;
}

// A fresh FrameRenderer has uploaded nothing, so its first upload is complete.
Outcome recreate(splatfx_renderer& r) {
    r.value.reset();
    Result<gl::FrameRenderer> fr = gl::FrameRenderer::create(r.desc);
    if (!fr) return failure(SPLATFX_ERROR_GL, fr.error());
    r.value.emplace(std::move(*fr));
    r.uploadedOnce = false;
    r.uploaded.reset();
    return success();
}

// FrameRenderer::upload skips when the materials' version is the one it
// uploaded last, which is only right for the same Materials: other materials
// (even at a reused address) get a fresh renderer, hence a full upload.
Outcome upload(splatfx_renderer& r, const splatfx_materials& m) {
    const std::shared_ptr<int> last = r.uploaded.lock();
    if (r.uploadedOnce && last != m.identity)
        if (Outcome o = recreate(r); !o.ok()) return o;
    if (Status s = r.value->upload(m.value); !s) return failure(SPLATFX_ERROR_GL, s.error());
    r.uploadedOnce = true;
    r.uploaded = m.identity;
    return success();
}

} // namespace

extern "C" {

// ---- [headless context]

splatfx_status splatfx_headless_context_create(splatfx_headless_context** out, splatfx_error* error) {
    return guard("splatfx_headless_context_create", error, [&] {
        if (!out) return invalid("out is NULL");
        *out = nullptr;
        Result<HeadlessContext> ctx = HeadlessContext::create();
        if (!ctx) return failure(SPLATFX_ERROR_GL, ctx.error());
        auto h = std::make_unique<splatfx_headless_context>();
        h->renderer = ctx->renderer();
        h->value.emplace(std::move(*ctx));
        *out = h.release();
        return success();
    });
}

void splatfx_headless_context_destroy(splatfx_headless_context* context) {
    if (!context || context->magic != Magic::Context) return;
    context->magic = Magic::Dead;
    try {
        delete context;
    } catch (...) { // a destructor that throws must not cross into C
    }
}

splatfx_status splatfx_headless_context_make_current(splatfx_headless_context* context, splatfx_error* error) {
    return guard("splatfx_headless_context_make_current", error, [&] {
        if (auto bad = checkHandle(context, Magic::Context, "context", "splatfx_headless_context")) return *bad;
        context->value->makeCurrent();
        return success();
    });
}

const char* splatfx_headless_context_renderer(const splatfx_headless_context* context) {
    return context && context->magic == Magic::Context ? context->renderer.c_str() : nullptr;
}

// ---- [renderer]

void splatfx_renderer_desc_init(splatfx_renderer_desc* desc) {
    if (!desc) return;
    desc->resolution_scale = gl::FrameRendererDesc{}.resolutionScale;
}

void splatfx_host_target_init(splatfx_host_target* target) {
    if (!target) return;
    *target = splatfx_host_target{};
}

splatfx_status splatfx_renderer_create(const splatfx_renderer_desc* desc, splatfx_renderer** out, splatfx_error* error) {
    return guard("splatfx_renderer_create", error, [&] {
        if (!out) return invalid("out is NULL");
        *out = nullptr;
        splatfx_renderer_desc d;
        splatfx_renderer_desc_init(&d);
        if (desc) d = *desc;
        if (d.resolution_scale != 1 && d.resolution_scale != 2 && d.resolution_scale != 4)
            return invalid("desc.resolution_scale is " + std::to_string(d.resolution_scale) + "; expected 1, 2 or 4");
        if (auto bad = checkContext()) return *bad;
        auto r = std::make_unique<splatfx_renderer>();
        r->desc.resolutionScale = d.resolution_scale;
        if (Outcome o = recreate(*r); !o.ok()) return o;
        *out = r.release();
        return success();
    });
}

void splatfx_renderer_destroy(splatfx_renderer* renderer) {
    if (!renderer || renderer->magic != Magic::Renderer) return;
    renderer->magic = Magic::Dead;
    try {
        // Deleting GL objects with no context current would abort in the GL
        // loader. Then they are left to die with their context: the renderer
        // is moved out and its owner deliberately never freed (a documented
        // leak, not a crash; splatfx_c.h, splatfx_renderer_destroy).
        if (renderer->value && !gl::detail::contextIsCurrent()) (void)new gl::FrameRenderer(std::move(*renderer->value));
        delete renderer;
    } catch (...) {}
}

splatfx_status splatfx_renderer_upload(splatfx_renderer* renderer, const splatfx_materials* materials, splatfx_error* error) {
    return guard("splatfx_renderer_upload", error, [&] {
        if (auto bad = checkHandle(renderer, Magic::Renderer, "renderer", "splatfx_renderer")) return *bad;
        if (auto bad = checkHandle(materials, Magic::Materials, "materials", "splatfx_materials")) return *bad;
        if (auto bad = checkContext()) return *bad;
        return upload(*renderer, *materials);
    });
}

splatfx_status splatfx_renderer_render(splatfx_renderer* renderer, const splatfx_materials* materials, const splatfx_frame* frame,
                                       const splatfx_host_target* target, splatfx_error* error) {
    return guard("splatfx_renderer_render", error, [&] {
        if (auto bad = checkHandle(renderer, Magic::Renderer, "renderer", "splatfx_renderer")) return *bad;
        if (auto bad = checkHandle(materials, Magic::Materials, "materials", "splatfx_materials")) return *bad;
        if (auto bad = checkHandle(frame, Magic::Frame, "frame", "splatfx_frame")) return *bad;
        if (!target) return invalid("target is NULL");
        if (!frame->prepared) return failure(SPLATFX_ERROR_INVALID_STATE, "frame has not been prepared (call splatfx_scene_prepare first)");
        const std::shared_ptr<int> preparedWith = frame->materials.lock();
        if (preparedWith != materials->identity)
            return invalid(preparedWith ? "materials are not the ones the frame was prepared with (its splats index their layers)"
                                        : "the materials the frame was prepared with were destroyed; prepare it again");
        const glm::ivec2 viewport = frame->value.camera().viewport;
        if (target->x < 0 || target->y < 0)
            return invalid("target->x, y are " + std::to_string(target->x) + ", " + std::to_string(target->y) + "; expected >= 0");
        const bool sizeGiven = target->width != 0 || target->height != 0;
        if (sizeGiven && (target->width != viewport.x || target->height != viewport.y))
            return invalid("target->width, height are " + std::to_string(target->width) + ", " + std::to_string(target->height) +
                           " but the frame's camera viewport is " + std::to_string(viewport.x) + ", " + std::to_string(viewport.y) +
                           "; prepare the frame with a camera of the target's size (or pass 0, 0)");
        if (auto bad = checkContext()) return *bad;
        if (target->framebuffer != 0 && !glIsFramebuffer(target->framebuffer))
            return failure(SPLATFX_ERROR_GL,
                           "target->framebuffer " + std::to_string(target->framebuffer) + " is not a framebuffer object of the current context");
        if (target->depth_texture != 0) {
            if (!glIsTexture(target->depth_texture))
                return failure(SPLATFX_ERROR_GL,
                               "target->depth_texture " + std::to_string(target->depth_texture) + " is not a texture of the current context");
            GLint depthBits = 0;
            glGetTextureLevelParameteriv(target->depth_texture, 0, GL_TEXTURE_DEPTH_SIZE, &depthBits);
            if (depthBits <= 0)
                return failure(SPLATFX_ERROR_GL, "target->depth_texture " + std::to_string(target->depth_texture) +
                                                     " has no depth component (GL_TEXTURE_DEPTH_SIZE is 0); expected the host's depth texture");
        }
        if (Outcome o = upload(*renderer, *materials); !o.ok()) return o;
        gl::HostTarget host;
        host.framebuffer = target->framebuffer;
        host.x = target->x;
        host.y = target->y;
        host.depthTexture = target->depth_texture;
        if (target->draw_opaque) host.drawOpaque = [f = target->draw_opaque, u = target->user_data] { f(u); };
        if (target->draw_transparent) host.drawTransparent = [f = target->draw_transparent, u = target->user_data] { f(u); };
        renderer->value->render(frame->value, host);
        return success();
    });
}

splatfx_status splatfx_renderer_get_stats(const splatfx_renderer* renderer, splatfx_render_stats* out, splatfx_error* error) {
    return guard("splatfx_renderer_get_stats", error, [&] {
        if (!out) return invalid("out is NULL");
        if (auto bad = checkHandle(renderer, Magic::Renderer, "renderer", "splatfx_renderer")) return *bad;
        const gl::FrameRenderStats& s = renderer->value->stats();
        *out = splatfx_render_stats{s.splats, s.drawCalls, s.resolutionScale};
        return success();
    });
}

} // extern "C"
