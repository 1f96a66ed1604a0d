// The registry of live handles (capi_internal.hpp): what makes a double destroy, a
// handle of the wrong type and a hook destroying what is being drawn safe.
#include <mutex>
#include <unordered_map>

#include "capi/capi_internal.hpp"

namespace splatfx::capi {

namespace {

struct Entry {
    Magic type = Magic::Dead;
    int holds = 0;          // renders drawing with it now
    bool destroyed = false; // destroyed while held: deleted by the last release()
    const void* tag = nullptr;
};

struct Registry {
    std::mutex mutex;
    std::unordered_map<const void*, Entry> live;
};

// Never freed: a handle destroyed from a static destructor or an atexit
// handler of the host, after this library's statics are gone, still finds it.
Registry& registry() {
    static Registry* r = new Registry();
    return *r;
}

} // namespace

const char* typeName(Magic type) {
    switch (type) {
    case Magic::Materials: return "splatfx_materials";
    case Magic::TextureSet: return "splatfx_texture_set";
    case Magic::Scene: return "splatfx_scene";
    case Magic::Frame: return "splatfx_frame";
    case Magic::Renderer: return "splatfx_renderer";
    case Magic::Context: return "splatfx_headless_context";
    case Magic::Error: return "splatfx_error";
    case Magic::Dead: break;
    }
    return "destroyed handle";
}

void registerHandle(const void* handle, Magic type, const void* tag) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    r.live[handle] = Entry{.type = type, .tag = tag};
}

const void* findHandle(Magic type, const void* tag) {
    if (!tag) return nullptr;
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    for (const auto& [handle, e] : r.live)
        if (e.type == type && e.tag == tag && !e.destroyed) return handle;
    return nullptr;
}

Magic liveType(const void* handle, bool* destroyed) {
    if (destroyed) *destroyed = false;
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    const auto it = r.live.find(handle);
    if (it == r.live.end()) return Magic::Dead;
    if (it->second.destroyed) {
        if (destroyed) *destroyed = true;
        return Magic::Dead;
    }
    return it->second.type;
}

bool isHeld(const void* handle) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    const auto it = r.live.find(handle);
    return it != r.live.end() && it->second.holds > 0;
}

DestroyStep beginDestroy(const void* handle, Magic type) {
    if (!handle) return DestroyStep::Ignore;
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    const auto it = r.live.find(handle);
    if (it == r.live.end() || it->second.type != type || it->second.destroyed) return DestroyStep::Ignore;
    if (it->second.holds > 0) {
        it->second.destroyed = true;
        return DestroyStep::Deferred;
    }
    r.live.erase(it);
    return DestroyStep::Delete;
}

void hold(const void* handle) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    const auto it = r.live.find(handle);
    if (it != r.live.end()) ++it->second.holds;
}

bool release(const void* handle) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    const auto it = r.live.find(handle);
    if (it == r.live.end() || it->second.holds == 0) return false;
    if (--it->second.holds > 0 || !it->second.destroyed) return false;
    r.live.erase(it);
    return true;
}

std::string notLive(const void* h, Magic magic, const char* param) {
    bool destroyed = false;
    const Magic actual = liveType(h, &destroyed);
    std::string why;
    if (destroyed) why = "it was destroyed during the render that is drawing with it";
    else if (actual != Magic::Dead) why = std::string("it is a ") + typeName(actual);
    else why = "it was destroyed, or is not a handle this library returned";
    return std::string(param) + " is not a " + typeName(magic) + " (" + why + ")";
}

} // namespace splatfx::capi
