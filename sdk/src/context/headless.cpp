#include "splatfx/context.hpp"

#include <cctype>
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

// Which displays SPLATFX_EGL_DEVICE allows (unset: every candidate, best first).
struct DeviceChoice {
    bool devicesOnly = false; // any value: EGL's device platform alone (EGL_EXT_device_enumeration + EGL_EXT_platform_device)
    bool hardware = false;    // "gpu": skip software devices (EGL_MESA_device_software)
    std::string vendor;       // "nvidia": GL_VENDOR must contain this (case-insensitive)
    int index = -1;           // "N": device N alone
    std::string value;        // as given, for messages
};

Result<DeviceChoice> deviceChoice() {
    DeviceChoice c;
    const char* env = std::getenv("SPLATFX_EGL_DEVICE");
    if (!env || !*env) return c;
    c.value = env;
    c.devicesOnly = true;
    if (c.value == "any") return c;
    if (c.value == "gpu") {
        c.hardware = true;
        return c;
    }
    if (c.value == "nvidia") {
        c.vendor = "nvidia"; // every device tried, so that the message can list what each one is
        return c;
    }
    char* end = nullptr;
    const long n = std::strtol(env, &end, 10);
    if (end != env && *end == '\0' && n >= 0 && n < 16) {
        c.index = int(n);
        return c;
    }
    return makeError("SPLATFX_EGL_DEVICE expects any, gpu, nvidia or a device index in [0, 15], got '" + c.value + "'");
}

struct Candidate {
    EGLDisplay display = EGL_NO_DISPLAY;
    std::string label; // "EGL device 1 (software)", "surfaceless platform", ...
};

// Candidate displays, best first: EGL devices (a GPU, or Mesa's software
// device), then Mesa's surfaceless platform, then the default display.
std::vector<Candidate> candidateDisplays(const DeviceChoice& choice, std::string& tried) {
    std::vector<Candidate> out;
    const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto queryDeviceString = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    if (getPlatformDisplay && queryDevices && hasExtension(clientExts, "EGL_EXT_platform_device")) {
        EGLDeviceEXT devices[16];
        EGLint count = 0;
        if (queryDevices(16, devices, &count)) {
            tried += " device platform (" + std::to_string(count) + " devices);";
            for (EGLint i = 0; i < count; ++i) {
                const char* exts = queryDeviceString ? queryDeviceString(devices[i], EGL_EXTENSIONS) : nullptr;
                const bool software = hasExtension(exts, "EGL_MESA_device_software");
                std::string label = "EGL device " + std::to_string(i) + (software ? " (software)" : "");
                if (choice.index >= 0 && i != choice.index) continue;
                if (choice.hardware && software) {
                    tried += " " + label + " skipped;";
                    continue;
                }
                EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
                if (d != EGL_NO_DISPLAY) out.push_back({d, std::move(label)});
            }
        }
    } else if (choice.devicesOnly) {
        tried += " device platform (not offered: this libEGL lacks EGL_EXT_platform_device / EGL_EXT_device_enumeration);";
    }
    if (choice.devicesOnly) return out;
    if (getPlatformDisplay && hasExtension(clientExts, "EGL_MESA_platform_surfaceless")) {
        tried += " surfaceless platform;";
        EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (d != EGL_NO_DISPLAY) out.push_back({d, "surfaceless platform"});
    }
    tried += " default display;";
    EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (d != EGL_NO_DISPLAY) out.push_back({d, "default display"});
    return out;
}

bool containsNoCase(std::string text, std::string what) {
    for (char& ch : text) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    for (char& ch : what) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return text.find(what) != std::string::npos;
}

} // namespace

HeadlessContext::HeadlessContext(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
HeadlessContext::HeadlessContext(HeadlessContext&&) noexcept = default;
HeadlessContext& HeadlessContext::operator=(HeadlessContext&&) noexcept = default;
HeadlessContext::~HeadlessContext() = default;

Result<HeadlessContext> HeadlessContext::create(const HeadlessDesc& desc) {
    auto choice = deviceChoice();
    if (!choice) return makeError(choice.error());
    std::string tried;
    const std::vector<Candidate> displays = candidateDisplays(*choice, tried);
    std::string why, rejected; // rejected: devices that gave a context of another vendor
    for (const Candidate& candidate : displays) {
        EGLDisplay display = candidate.display;
        EGLint major = 0, minor = 0;
        if (!eglInitialize(display, &major, &minor)) {
            why = candidate.label + ": eglInitialize failed";
            continue;
        }
        auto impl = std::make_unique<Impl>();
        impl->display = display;
        enterDisplay(display);
        if (!hasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
            why = candidate.label + ": display lacks EGL_KHR_surfaceless_context";
            continue;
        }
        if (!eglBindAPI(EGL_OPENGL_API)) {
            why = candidate.label + ": display cannot bind the desktop OpenGL API";
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
            why = candidate.label + ": the display offers no OpenGL 4.5 core context";
            continue;
        }
        if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl->context)) {
            why = candidate.label + ": eglMakeCurrent failed";
            continue;
        }
        if (!choice->vendor.empty()) {
            const GLubyte* vendor = glGetString(GL_VENDOR);
            const std::string v = vendor ? reinterpret_cast<const char*>(vendor) : "unknown";
            if (!containsNoCase(v, choice->vendor)) {
                const GLubyte* renderer = glGetString(GL_RENDERER);
                rejected += " " + candidate.label + ": " + v + ", " + (renderer ? reinterpret_cast<const char*>(renderer) : "unknown") + ";";
                continue; // ~Impl releases the context and the display
            }
        }
        return HeadlessContext(std::move(impl));
    }
    if (!choice->value.empty()) {
        // Asked for a device: say exactly which were found and why none was taken.
        std::string msg = "SPLATFX_EGL_DEVICE=" + choice->value + ": ";
        if (!choice->vendor.empty())
            msg += "no " + choice->value + " device among the EGL devices (found:" + (rejected.empty() ? std::string(" none") : rejected) + ")";
        else
            msg += "no EGL device gave an OpenGL 4.5 core context";
        return makeError(msg + (why.empty() ? "" : " (last reason: " + why + ")") + "; tried:" + tried +
                         " ). The device platform needs libEGL with EGL_EXT_device_enumeration and EGL_EXT_platform_device "
                         "(glvnd's libEGL.so.1 with the NVIDIA driver's EGL vendor library, or Mesa's)");
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
