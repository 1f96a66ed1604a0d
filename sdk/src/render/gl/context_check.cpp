#include "context_check.hpp"

#include <cstring>
#include <initializer_list>

#include <dlfcn.h>
#include <epoxy/gl.h>

namespace splatfx::gl::detail {

const void* currentContext() {
    using GetCurrent = void* (*)();
    const char* libs[][2] = {
        {"libEGL.so.1", "eglGetCurrentContext"}, {"libGLX.so.0", "glXGetCurrentContext"}, {"libGL.so.1", "glXGetCurrentContext"}};
    for (const auto& lib : libs) {
        void* handle = dlopen(lib[0], RTLD_LAZY | RTLD_NOLOAD);
        if (!handle) continue;
        auto fn = reinterpret_cast<GetCurrent>(dlsym(handle, lib[1]));
        const void* current = fn ? fn() : nullptr;
        dlclose(handle);
        if (current) return current;
    }
    return nullptr;
}

bool contextIsCurrent() { return currentContext() != nullptr; }

bool softwareRasterizer() {
    const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    if (!name) return false;
    for (const char* cpu : {"llvmpipe", "softpipe", "swrast"})
        if (std::strstr(name, cpu)) return true;
    return false;
}

} // namespace splatfx::gl::detail
