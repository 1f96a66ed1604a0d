// Private to splatfx::c: the handles behind splatfx_c.h and the boundary every call goes through.
//
// Each public function is `return capi::guard("name", error, [&] { ... });`:
// the body returns an Outcome (ok, or a status and a message), guard()
// writes it into the caller's error object and turns any C++ exception into
// a status, so none crosses the C boundary.
//
// Every handle the library returns is listed, with its type, in one registry
// (handles.cpp) until it is destroyed. A handle is checked against that list,
// never by reading through the pointer, so a handle of the wrong type (an
// easy mistake through a foreign-function interface, where they are all
// void*), one destroyed already (a double destroy) or a stray pointer is an
// error or an ignored destroy, not a read of freed memory. A render holds the
// handles it draws with: a hook that destroys one of them only marks it, and
// the render deletes it when it returns, with an error saying so.
#pragma once

#include <cstdint>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "splatfx/splatfx_c.h"

#include "splatfx/context.hpp"
#include "splatfx/frame.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/texture_set.hpp"

namespace splatfx::capi {

// One per handle type ('S','F','X', type letter): the registry's type of a handle, also kept in it (for debuggers).
enum class Magic : std::uint32_t {
    Materials = 0x53465801,
    TextureSet = 0x53465802,
    Scene = 0x53465803,
    Frame = 0x53465804,
    Renderer = 0x53465805,
    Context = 0x53465806,
    Error = 0x53465807,
    Dead = 0,
};

} // namespace splatfx::capi

struct splatfx_error {
    splatfx::capi::Magic magic = splatfx::capi::Magic::Error;
    splatfx_status status = SPLATFX_OK;
    std::string message;
};

namespace splatfx::capi {

// "splatfx_scene" for Magic::Scene.
const char* typeName(Magic type);

// ---- the registry of live handles (handles.cpp; thread-safe) ----

// Lists a new handle; throws std::bad_alloc (the caller deletes it then).
// `tag`: an identity to find it by (findHandle); a headless context's GL context.
void registerHandle(const void* handle, Magic type, const void* tag = nullptr);
// The live handle of `type` listed with `tag`, or null.
const void* findHandle(Magic type, const void* tag);
// What `handle` is: its type when it is live (listed, and not destroyed by a
// hook during a render), Magic::Dead otherwise. `destroyed`, when given, is
// set when it was destroyed by a hook and awaits the end of the render.
Magic liveType(const void* handle, bool* destroyed = nullptr);
inline bool isLive(const void* handle, Magic type) { return handle && liveType(handle) == type; }
// True while a render holds it (see hold()).
bool isHeld(const void* handle);
// A *_destroy's first step. Delete: unlisted, the caller deletes it now.
// Deferred: a render holds it; it is marked and release() hands it back.
// Ignore: NULL, not listed, another type, or marked already (a double destroy).
enum class DestroyStep { Delete, Deferred, Ignore };
DestroyStep beginDestroy(const void* handle, Magic type);
// A render holds the handles it draws with (a count, for nested renders).
void hold(const void* handle);
// Ends one hold(); true when that was the last and a destroy was deferred:
// the handle is unlisted and the caller deletes it.
bool release(const void* handle);

// What a body returns.
struct Outcome {
    splatfx_status status = SPLATFX_OK;
    std::string message;
    bool ok() const { return status == SPLATFX_OK; }
};
inline Outcome success() { return {}; }
inline Outcome failure(splatfx_status status, std::string message) { return {status, std::move(message)}; }
inline Outcome invalid(std::string message) { return failure(SPLATFX_ERROR_INVALID_ARGUMENT, std::move(message)); }

// Writes the outcome into `error` (when given); never throws.
inline splatfx_status report(splatfx_error* error, const char* function, splatfx_status status, const std::string& message) {
    if (error && isLive(error, Magic::Error)) { // a destroyed error object is not written to
        error->status = status;
        try {
            if (status == SPLATFX_OK) error->message.clear();
            else error->message = std::string(function) + ": " + message;
        } catch (...) {
            // No memory for the message: splatfx_error_message() says so from a constant.
            error->message.clear();
        }
    }
    return status;
}

template <class Body>
splatfx_status guard(const char* function, splatfx_error* error, Body&& body) noexcept {
    try {
        Outcome o = body();
        return report(error, function, o.status, o.message);
    } catch (const std::bad_alloc&) {
        return report(error, function, SPLATFX_ERROR_OUT_OF_MEMORY, "out of memory");
    } catch (const std::exception& e) {
        return report(error, function, SPLATFX_ERROR_INTERNAL, std::string("unexpected C++ exception: ") + e.what());
    } catch (...) { return report(error, function, SPLATFX_ERROR_INTERNAL, "unexpected C++ exception of unknown type"); }
}

// "materials is NULL" / "materials is not a splatfx_materials (it is a splatfx_scene)" / "... (it was destroyed ...)".
std::string notLive(const void* h, Magic magic, const char* param);
template <class Handle>
std::optional<Outcome> checkHandle(const Handle* h, Magic magic, const char* param, const char* type) {
    (void)type;
    if (!h) return invalid(std::string(param) + " is NULL");
    if (!isLive(h, magic)) return invalid(notLive(h, magic, param));
    return std::nullopt;
}

// A new handle, listed: what every *_create hands out.
template <class Handle>
Handle* listed(std::unique_ptr<Handle> h, Magic type, const void* tag = nullptr) {
    registerHandle(h.get(), type, tag);
    return h.release();
}

// Every *_destroy: deletes a live handle of its type now, or after the render
// drawing with it returns; ignores anything else (NULL, a double destroy, a
// handle of another type, a stray pointer), never reading through it.
template <class Handle>
void deleteHandle(Handle* h) noexcept;
template <class Handle>
void destroyHandle(Handle* h, Magic type) noexcept {
    try {
        if (beginDestroy(h, type) == DestroyStep::Delete) deleteHandle(h);
    } catch (...) { // a lock that failed: the handle stays listed and alive rather than an exception crossing into C
    }
}

} // namespace splatfx::capi

struct splatfx_materials {
    splatfx::capi::Magic magic = splatfx::capi::Magic::Materials;
    splatfx::Materials value;
    // Identity that outlives address reuse: frames and renderers keep a
    // weak_ptr to it, so "the materials this was prepared with" is exact even
    // after the handle is destroyed and a new one lands at the same address.
    std::shared_ptr<int> identity = std::make_shared<int>(0);
    explicit splatfx_materials(const splatfx::MaterialsDesc& d) : value(splatfx::Footprint{}, d) {}
};

struct splatfx_texture_set {
    splatfx::capi::Magic magic = splatfx::capi::Magic::TextureSet;
    splatfx::TextureSet value;
};

struct splatfx_scene {
    splatfx::capi::Magic magic = splatfx::capi::Magic::Scene;
    splatfx::Scene value;
    // The materials its effects registered their texture sets and colour
    // tables in (set at the first add or load): their ids mean nothing in
    // other materials, so adding or preparing with others is refused.
    std::weak_ptr<int> materials;
    bool hasMaterials = false;
    // The C API's effect ids (0, 1, ... in the order added or loaded) as ids
    // of `value`, which also holds the volumes a scene file declares.
    std::vector<splatfx::EffectId> effects;
};

struct splatfx_frame {
    splatfx::capi::Magic magic = splatfx::capi::Magic::Frame;
    splatfx::Frame value;
    bool prepared = false;
    bool hdrLit = false;          // prepared with Scene::hdrLit(): needs a floating-point colour target
    std::weak_ptr<int> materials; // identity of the materials it was prepared with
};

struct splatfx_renderer {
    splatfx::capi::Magic magic = splatfx::capi::Magic::Renderer;
    splatfx::gl::FrameRendererDesc desc;
    std::optional<splatfx::gl::FrameRenderer> value;
    bool uploadedOnce = false;
    std::weak_ptr<int> uploaded; // identity of the materials last uploaded
};

struct splatfx_headless_context {
    splatfx::capi::Magic magic = splatfx::capi::Magic::Context;
    std::optional<splatfx::HeadlessContext> value;
    std::string renderer;
};

namespace splatfx::capi {
template <class Handle>
void deleteHandle(Handle* h) noexcept {
    h->magic = Magic::Dead;
    try {
        delete h;
    } catch (...) { // a destructor that throws must not cross into C
    }
}
// Deletes its GL objects only in its own context (capi_gl.cpp).
template <>
void deleteHandle(splatfx_renderer* h) noexcept;
} // namespace splatfx::capi

// The C side sees int-sized enums (splatfx_c.h, SPLATFX_C_ENUM).
static_assert(sizeof(splatfx_status) == 4 && sizeof(splatfx_easing) == 4, "splatfx_c.h enums must be 32-bit");
