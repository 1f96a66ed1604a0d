// splatfx_c.h, the GL half: the headless context and gl::FrameRenderer into the host's framebuffer.
#include <algorithm>
#include <array>

#include <cstdio>

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

// The renderer's GL objects are names in the context it was created in; any
// other context (or none) is refused before a GL call is made.
std::optional<Outcome> checkContext(const splatfx_renderer& r) {
    if (auto bad = checkContext()) return bad;
    if (Status s = r.value->checkContext(); !s) return failure(SPLATFX_ERROR_GL, s.error());
    return std::nullopt;
}

// A hook calling back into its own renderer would re-enter the frame's passes mid-step.
std::optional<Outcome> checkNotRendering(const splatfx_renderer& r) {
    if (isHeld(&r))
        return failure(SPLATFX_ERROR_INVALID_STATE,
                       "renderer is drawing a frame (this call came from one of its hooks); a renderer cannot be used inside its own render");
    return std::nullopt;
}

std::string hex(unsigned v) {
    char text[16];
    std::snprintf(text, sizeof text, "0x%x", v);
    return text;
}

std::string glErrorName(GLenum e) {
    switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
    case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
    case GL_CONTEXT_LOST: return "GL_CONTEXT_LOST";
    }
    return "GL error " + hex(e);
}

std::string framebufferStatusName(GLenum s) {
    switch (s) {
    case GL_FRAMEBUFFER_UNDEFINED: return "GL_FRAMEBUFFER_UNDEFINED";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER";
    case GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER";
    case GL_FRAMEBUFFER_UNSUPPORTED: return "GL_FRAMEBUFFER_UNSUPPORTED";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE: return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    case GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS: return "GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS";
    }
    return "framebuffer status " + hex(s);
}

// The GL errors raised since the last take, each kind once. The GL keeps one
// flag per kind, so a few calls clear them; the bound guards a driver that
// keeps answering.
struct GlErrors {
    std::vector<GLenum> kinds;
    void take() {
        for (int i = 0; i < 16; ++i) {
            const GLenum e = glGetError();
            if (e == GL_NO_ERROR) break;
            if (std::find(kinds.begin(), kinds.end(), e) == kinds.end()) kinds.push_back(e);
        }
    }
    bool any() const { return !kinds.empty(); }
    bool has(GLenum e) const { return std::find(kinds.begin(), kinds.end(), e) != kinds.end(); }
    std::string names() const {
        std::string out;
        for (GLenum e : kinds) out += (out.empty() ? "" : ", ") + glErrorName(e);
        return out;
    }
};

// Errors the host left pending before the call are the host's: taken and
// dropped, so they are never reported as splatfx's.
void dropHostErrors() {
    GlErrors host;
    host.take();
}

// Errors raised by splatfx's own calls in `what` (create, upload, the render).
std::optional<Outcome> sdkErrors(const GlErrors& e, const std::string& what) {
    if (!e.any()) return std::nullopt;
    return failure(SPLATFX_ERROR_GL, e.names() + " raised by splatfx's own GL calls during " + what);
}

// A frame prepared with HDR lit colour keeps colours above 1 only in a
// floating-point target; a fixed-point one clamps each channel at 1 (an orange
// flame turns yellow-white). The colour buffer drawn into: the framebuffer
// object's attachment 0, or the default framebuffer's back buffer.
std::optional<Outcome> checkHdrTarget(GLuint fb) {
    const GLenum attachment = fb == 0 ? GL_BACK_LEFT : GL_COLOR_ATTACHMENT0;
    GLint objectType = GL_NONE, componentType = GL_NONE;
    glGetNamedFramebufferAttachmentParameteriv(fb, attachment, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &objectType);
    if (objectType != GL_NONE) glGetNamedFramebufferAttachmentParameteriv(fb, attachment, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &componentType);
    // A default framebuffer without that buffer (a surfaceless context) answers with an error: nothing to check.
    dropHostErrors();
    if (componentType != GL_UNSIGNED_NORMALIZED && componentType != GL_SIGNED_NORMALIZED) return std::nullopt;
    return invalid("frame was prepared with HDR lit colour (splatfx_scene_set_hdr_lit) but target->framebuffer " + std::to_string(fb) + "'s " +
                   (fb == 0 ? "back buffer" : "GL_COLOR_ATTACHMENT0") + " is fixed-point (" +
                   (componentType == GL_UNSIGNED_NORMALIZED ? "GL_UNSIGNED_NORMALIZED" : "GL_SIGNED_NORMALIZED") +
                   "): its lit colours above 1 would clamp at 1, shifting their hue; draw into a GL_RGBA16F or GL_RGBA32F target, or turn HDR "
                   "lit colour off and prepare the frame again");
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
    GlErrors raised;
    raised.take();
    if (auto bad = sdkErrors(raised, "the upload of the materials")) return *bad;
    r.uploadedOnce = true;
    r.uploaded = m.identity;
    return success();
}

} // namespace

// Deletes the renderer's GL objects only in the context they belong to. In
// another context (or none) the same names are someone else's objects (or a
// GL call aborts in the loader): then they are left to die with their
// context, the FrameRenderer moved out and its owner deliberately never
// freed (a documented leak, not a crash; splatfx_c.h, splatfx_renderer_destroy).
template <>
void splatfx::capi::deleteHandle(splatfx_renderer* renderer) noexcept {
    renderer->magic = Magic::Dead;
    try {
        if (renderer->value && !renderer->value->checkContext()) (void)new gl::FrameRenderer(std::move(*renderer->value));
        delete renderer;
    } catch (...) {}
}

namespace {

// The handles one render draws with, held (handles.cpp) from its checks to
// after its error is reported: a hook that destroys one only marks it, and it
// is deleted here, in an order where each delete still has what it needs (the
// renderer while its context lives).
class HeldHandles {
public:
    void hold(const void* h, const char* param, Magic type) {
        capi::hold(h);
        mHeld[mCount++] = {h, param, type};
    }
    // The first held handle a hook destroyed, as "frame (a splatfx_frame)"; empty when none.
    std::string destroyed() const {
        for (std::size_t i = 0; i < mCount; ++i) {
            bool gone = false;
            liveType(mHeld[i].handle, &gone);
            if (gone) return std::string(mHeld[i].param) + " (a " + typeName(mHeld[i].type) + ")";
        }
        return {};
    }
    void releaseAll() noexcept {
        for (std::size_t i = 0; i < mCount; ++i) {
            const Held& h = mHeld[i];
            try {
                if (!capi::release(h.handle)) continue;
            } catch (...) { continue; }
            // Handles are const in render's signature; the caller asked for them to be destroyed.
            void* p = const_cast<void*>(h.handle);
            switch (h.type) {
            case Magic::Renderer: deleteHandle(static_cast<splatfx_renderer*>(p)); break;
            case Magic::Frame: deleteHandle(static_cast<splatfx_frame*>(p)); break;
            case Magic::Materials: deleteHandle(static_cast<splatfx_materials*>(p)); break;
            case Magic::Context: deleteHandle(static_cast<splatfx_headless_context*>(p)); break;
            case Magic::Error: deleteHandle(static_cast<splatfx_error*>(p)); break;
            default: break; // a render holds no other type
            }
        }
        mCount = 0;
    }
    ~HeldHandles() { releaseAll(); }

private:
    struct Held {
        const void* handle = nullptr;
        const char* param = "";
        Magic type = Magic::Dead;
    };
    std::array<Held, 5> mHeld{};
    std::size_t mCount = 0;
};

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
        // Current now: its GL context is how a render finds it (a hook must not destroy it mid-frame).
        *out = listed(std::move(h), Magic::Context, gl::detail::currentContext());
        return success();
    });
}

void splatfx_headless_context_destroy(splatfx_headless_context* context) { destroyHandle(context, Magic::Context); }

splatfx_status splatfx_headless_context_make_current(splatfx_headless_context* context, splatfx_error* error) {
    return guard("splatfx_headless_context_make_current", error, [&] {
        if (auto bad = checkHandle(context, Magic::Context, "context", "splatfx_headless_context")) return *bad;
        context->value->makeCurrent();
        return success();
    });
}

const char* splatfx_headless_context_renderer(const splatfx_headless_context* context) {
    return isLive(context, Magic::Context) ? context->renderer.c_str() : nullptr;
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
        dropHostErrors();
        auto r = std::make_unique<splatfx_renderer>();
        r->desc.resolutionScale = d.resolution_scale;
        if (Outcome o = recreate(*r); !o.ok()) return o;
        GlErrors raised;
        raised.take();
        if (auto bad = sdkErrors(raised, "the renderer's creation")) return *bad;
        *out = listed(std::move(r), Magic::Renderer);
        return success();
    });
}

void splatfx_renderer_destroy(splatfx_renderer* renderer) { destroyHandle(renderer, Magic::Renderer); }

splatfx_status splatfx_renderer_upload(splatfx_renderer* renderer, const splatfx_materials* materials, splatfx_error* error) {
    return guard("splatfx_renderer_upload", error, [&] {
        if (auto bad = checkHandle(renderer, Magic::Renderer, "renderer", "splatfx_renderer")) return *bad;
        if (auto bad = checkHandle(materials, Magic::Materials, "materials", "splatfx_materials")) return *bad;
        if (auto bad = checkNotRendering(*renderer)) return *bad;
        if (auto bad = checkContext(*renderer)) return *bad;
        dropHostErrors();
        return upload(*renderer, *materials);
    });
}

splatfx_status splatfx_renderer_render(splatfx_renderer* renderer, const splatfx_materials* materials, const splatfx_frame* frame,
                                       const splatfx_host_target* target, splatfx_error* error) {
    HeldHandles held; // released after guard() has written the error object
    const splatfx_status status = guard("splatfx_renderer_render", error, [&] {
        if (auto bad = checkHandle(renderer, Magic::Renderer, "renderer", "splatfx_renderer")) return *bad;
        if (auto bad = checkHandle(materials, Magic::Materials, "materials", "splatfx_materials")) return *bad;
        if (auto bad = checkHandle(frame, Magic::Frame, "frame", "splatfx_frame")) return *bad;
        if (!target) return invalid("target is NULL");
        if (auto bad = checkNotRendering(*renderer)) return *bad;
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
        if (auto bad = checkContext(*renderer)) return *bad;
        dropHostErrors();
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
        if (frame->hdrLit)
            if (auto bad = checkHdrTarget(target->framebuffer)) return *bad;
        if (Outcome o = upload(*renderer, *materials); !o.ok()) return o;

        // From here to the end the handles are held: a hook may destroy them, and they are deleted after the render.
        held.hold(renderer, "renderer", Magic::Renderer);
        held.hold(frame, "frame", Magic::Frame);
        held.hold(materials, "materials", Magic::Materials);
        if (const void* ctx = findHandle(Magic::Context, gl::detail::currentContext()))
            held.hold(ctx, "the current headless context", Magic::Context);
        if (isLive(error, Magic::Error)) held.hold(error, "error", Magic::Error);

        // GL errors are split at the hooks: raised before or after one, splatfx's; inside one, the host's.
        GlErrors ours;
        std::string hookErrors, hookDestroyed, hookContext;
        auto wrap = [&](void (*f)(void*), void* u, const char* name) {
            return [&, f, u, name] {
                ours.take();
                f(u);
                GlErrors theirs;
                if (renderer->value->checkContext()) theirs.take();
                else if (hookContext.empty()) hookContext = name;
                if (theirs.any() && hookErrors.empty()) hookErrors = std::string("the ") + name + " hook raised " + theirs.names();
                if (hookDestroyed.empty()) {
                    const std::string gone = held.destroyed();
                    if (!gone.empty()) hookDestroyed = std::string("the ") + name + " hook destroyed " + gone;
                }
            };
        };
        gl::HostTarget host;
        host.framebuffer = target->framebuffer;
        host.x = target->x;
        host.y = target->y;
        host.depthTexture = target->depth_texture;
        if (target->draw_opaque) host.drawOpaque = wrap(target->draw_opaque, target->user_data, "draw_opaque");
        if (target->draw_transparent) host.drawTransparent = wrap(target->draw_transparent, target->user_data, "draw_transparent");
        renderer->value->render(frame->value, host);

        if (!hookContext.empty())
            return failure(SPLATFX_ERROR_GL, "the " + hookContext + " hook left another OpenGL context current (or none); the rest of the frame " +
                                                 "was not drawn. " + renderer->value->checkContext().error());
        ours.take();
        if (!hookDestroyed.empty())
            return failure(SPLATFX_ERROR_INVALID_STATE, hookDestroyed + " while it was being drawn; the render finished with it and deleted it on "
                                                                        "return. Destroy handles outside the render");
        if (ours.any()) {
            std::string why;
            if (ours.has(GL_INVALID_FRAMEBUFFER_OPERATION)) {
                const GLenum fb = glCheckNamedFramebufferStatus(target->framebuffer, GL_DRAW_FRAMEBUFFER);
                if (fb != GL_FRAMEBUFFER_COMPLETE)
                    why = " (target->framebuffer " + std::to_string(target->framebuffer) + " is incomplete: " + framebufferStatusName(fb) + ")";
            }
            return failure(SPLATFX_ERROR_GL, ours.names() + " raised by splatfx's own GL calls during the render" + why);
        }
        if (!hookErrors.empty())
            return failure(SPLATFX_ERROR_GL, hookErrors + " (the host's own GL calls; splatfx's raised none and the frame was drawn)");
        return success();
    });
    held.releaseAll();
    return status;
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

uint32_t splatfx_renderer_note_count(const splatfx_renderer* renderer) {
    return isLive(renderer, Magic::Renderer) ? std::uint32_t(renderer->value->stats().notes.size()) : 0;
}

const char* splatfx_renderer_note(const splatfx_renderer* renderer, uint32_t index) {
    if (!isLive(renderer, Magic::Renderer)) return nullptr;
    const std::vector<std::string>& notes = renderer->value->stats().notes;
    return index < notes.size() ? notes[index].c_str() : nullptr;
}

} // extern "C"
