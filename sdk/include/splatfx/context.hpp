// splatfx/context.hpp: creating an OpenGL 4.5 context (headless EGL, or a GLFW window).
//
// The SDK renders in whatever context is current; this small module exists
// for samples, tools and tests, and for hosts that want a ready headless
// context. Headless uses EGL's device or surfaceless platform (on machines
// without a GPU that is Mesa's llvmpipe); it fails with a clear message when
// EGL, a display or GL 4.5 core is missing. Link splatfx::context for it.
//
// By default the first display that gives a 4.5 core context is taken. The
// environment variable SPLATFX_EGL_DEVICE restricts it to EGL's device
// platform (EGL_EXT_device_enumeration + EGL_EXT_platform_device): "any" (the
// first device), "gpu" (no software device), "nvidia" (GL_VENDOR contains
// NVIDIA) or a device index; when none fits, create() says which devices it
// found (tools/gpu-check.sh uses "nvidia").
//
//   auto ctx = splatfx::HeadlessContext::create();
//   if (!ctx) { std::fprintf(stderr, "%s\n", ctx.error().c_str()); return 1; }
//
// Threading: the context is current on the thread that created it.
#pragma once

#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "splatfx/result.hpp"

struct GLFWwindow;

namespace splatfx {

struct HeadlessDesc {
    bool debug = false; // request a debug context; default false
};

class HeadlessContext {
public:
    static Result<HeadlessContext> create(const HeadlessDesc& desc = {});
    HeadlessContext(HeadlessContext&&) noexcept;
    HeadlessContext& operator=(HeadlessContext&&) noexcept;
    ~HeadlessContext();

    void makeCurrent();
    std::string renderer() const; // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

private:
    struct Impl;
    explicit HeadlessContext(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

struct WindowDesc {
    int width = 1280; // default 1280
    int height = 720; // default 720
    std::string title = "splatfx";
    bool vsync = true; // default true
};

class Window {
public:
    static Result<Window> create(const WindowDesc& desc);
    Window(Window&&) noexcept;
    Window& operator=(Window&&) noexcept;
    ~Window();

    bool shouldClose() const;
    void swapBuffers();
    void pollEvents();
    glm::ivec2 framebufferSize() const;
    GLFWwindow* handle() const { return mWindow; }

private:
    Window() = default;
    GLFWwindow* mWindow = nullptr;
};

} // namespace splatfx
