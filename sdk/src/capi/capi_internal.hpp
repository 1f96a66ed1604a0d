// Private to splatfx::c: the handles behind splatfx_c.h and the boundary every call goes through.
//
// Each public function is `return capi::guard("name", error, [&] { ... });`:
// the body returns an Outcome (ok, or a status and a message), guard()
// writes it into the caller's error object and turns any C++ exception into
// a status, so none crosses the C boundary. Handles carry a magic number so
// a handle of the wrong type (an easy mistake through a foreign-function
// interface, where they are all void*) is an error, not a crash.
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

struct splatfx_error {
    splatfx_status status = SPLATFX_OK;
    std::string message;
};

namespace splatfx::capi {

// One per handle type ('S','F','X', type letter): a wrong-type or zeroed handle fails the check.
enum class Magic : std::uint32_t {
    Materials = 0x53465801,
    TextureSet = 0x53465802,
    Scene = 0x53465803,
    Frame = 0x53465804,
    Renderer = 0x53465805,
    Context = 0x53465806,
    Dead = 0,
};

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
    if (error) {
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

// "materials is NULL" / "materials is not a splatfx_materials (wrong handle type, or destroyed)".
template <class Handle>
std::optional<Outcome> checkHandle(const Handle* h, Magic magic, const char* param, const char* type) {
    if (!h) return invalid(std::string(param) + " is NULL");
    if (h->magic != magic) return invalid(std::string(param) + " is not a " + type + " (a handle of another type, or one already destroyed)");
    return std::nullopt;
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

// The C side sees int-sized enums (splatfx_c.h, SPLATFX_C_ENUM).
static_assert(sizeof(splatfx_status) == 4 && sizeof(splatfx_easing) == 4, "splatfx_c.h enums must be 32-bit");
