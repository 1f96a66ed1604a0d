#include "splatfx/context.hpp"

#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <epoxy/egl.h>
#include <epoxy/gl.h>

namespace splatfx {

namespace {

// An EGLDisplay is one per device and process, shared by every context made
// on it, and eglTerminate ends all of them: each context counts its display
// in, and only the last one out terminates it.
struct DisplayUsers {
    std::mutex mutex;
    std::map<EGLDisplay, int> count;
};
DisplayUsers& displayUsers() {
    static auto* users = new DisplayUsers(); // never freed: contexts may outlive static destruction
    return *users;
}
void enterDisplay(EGLDisplay display) {
    std::lock_guard lock(displayUsers().mutex);
    ++displayUsers().count[display];
}
bool leaveDisplay(EGLDisplay display) { // true: the last user left
    std::lock_guard lock(displayUsers().mutex);
    auto& count = displayUsers().count;
    if (--count[display] > 0) return false;
    count.erase(display);
    return true;
}

} // namespace

struct HeadlessContext::Impl {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    ~Impl() {
        if (display != EGL_NO_DISPLAY) {
            // Only this context is released: another one current on this thread stays current.
            if (context != EGL_NO_CONTEXT && eglGetCurrentContext() == context)
                eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            if (context != EGL_NO_CONTEXT) eglDestroyContext(display, context);
            if (leaveDisplay(display)) eglTerminate(display);
        }
    }
};

namespace {

bool hasExtension(const char* list, const char* name) {
    if (!list) return false;
    const size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)); p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

// Candidate displays, best first: EGL devices (a GPU, or Mesa's software
// device), then Mesa's surfaceless platform, then the default display.
std::vector<EGLDisplay> candidateDisplays(std::string& tried) {
    std::vector<EGLDisplay> out;
    const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    if (getPlatformDisplay && queryDevices && hasExtension(clientExts, "EGL_EXT_platform_device")) {
        EGLDeviceEXT devices[16];
        EGLint count = 0;
        if (queryDevices(16, devices, &count)) {
            tried += " device platform (" + std::to_string(count) + " devices);";
            for (EGLint i = 0; i < count; ++i) {
                EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
                if (d != EGL_NO_DISPLAY) out.push_back(d);
            }
        }
    }
    if (getPlatformDisplay && hasExtension(clientExts, "EGL_MESA_platform_surfaceless")) {
        tried += " surfaceless platform;";
        EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (d != EGL_NO_DISPLAY) out.push_back(d);
    }
    tried += " default display;";
    EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (d != EGL_NO_DISPLAY) out.push_back(d);
    return out;
}

} // namespace

HeadlessContext::HeadlessContext(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
HeadlessContext::HeadlessContext(HeadlessContext&&) noexcept = default;
HeadlessContext& HeadlessContext::operator=(HeadlessContext&&) noexcept = default;
HeadlessContext::~HeadlessContext() = default;

Result<HeadlessContext> HeadlessContext::create(const HeadlessDesc& desc) {
    std::string tried;
    const std::vector<EGLDisplay> displays = candidateDisplays(tried);
    std::string why;
    for (EGLDisplay display : displays) {
        EGLint major = 0, minor = 0;
        if (!eglInitialize(display, &major, &minor)) {
            why = "eglInitialize failed";
            continue;
        }
        auto impl = std::make_unique<Impl>();
        impl->display = display;
        enterDisplay(display);
        if (!hasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
            why = "display lacks EGL_KHR_surfaceless_context";
            continue;
        }
        if (!eglBindAPI(EGL_OPENGL_API)) {
            why = "display cannot bind the desktop OpenGL API";
            continue;
        }
        const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint n = 0;
        if (!eglChooseConfig(display, configAttribs, &config, 1, &n) || n < 1) {
            // Surfaceless contexts may need no config at all.
            config = EGL_NO_CONFIG_KHR;
        }
        const EGLint ctxAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                     4,
                                     EGL_CONTEXT_MINOR_VERSION,
                                     5,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                     EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                     EGL_CONTEXT_OPENGL_DEBUG,
                                     desc.debug ? EGL_TRUE : EGL_FALSE,
                                     EGL_NONE};
        impl->context = eglCreateContext(display, config, EGL_NO_CONTEXT, ctxAttribs);
        if (impl->context == EGL_NO_CONTEXT) {
            why = "the display offers no OpenGL 4.5 core context";
            continue;
        }
        if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl->context)) {
            why = "eglMakeCurrent failed";
            continue;
        }
        return HeadlessContext(std::move(impl));
    }
    if (displays.empty())
        return makeError("no EGL display found (tried:" + tried +
                         " ). Install Mesa's EGL (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri) or a GPU driver with EGL.");
    return makeError("no EGL display could give an OpenGL 4.5 core context (last reason: " + why + "; tried:" + tried +
                     " ). Install Mesa 20+ (llvmpipe provides 4.5) or a GPU driver with EGL.");
}

void HeadlessContext::makeCurrent() { eglMakeCurrent(mImpl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, mImpl->context); }

std::string HeadlessContext::renderer() const {
    const GLubyte* s = glGetString(GL_RENDERER);
    return s ? reinterpret_cast<const char*>(s) : "unknown";
}

} // namespace splatfx
