#include "splatfx/context.hpp"

#include <utility>

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

namespace splatfx {

Result<Window> Window::create(const WindowDesc& desc) {
    if (!glfwInit()) {
        const char* why = nullptr;
        glfwGetError(&why);
        return makeError(
            std::string("cannot open a window: GLFW failed to initialize (") + (why ? why : "no display?") +
            "). A window needs a display: set DISPLAY or start an X server (e.g. Xvfb); without one, render headless (HeadlessContext).");
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    Window w;
    w.mWindow = glfwCreateWindow(desc.width, desc.height, desc.title.c_str(), nullptr, nullptr);
    if (!w.mWindow) {
        const char* why = nullptr;
        glfwGetError(&why);
        return makeError(std::string("cannot open an OpenGL 4.5 core window: ") + (why ? why : "unknown reason"));
    }
    glfwMakeContextCurrent(w.mWindow);
    glfwSwapInterval(desc.vsync ? 1 : 0);
    return w;
}

Window::Window(Window&& o) noexcept : mWindow(std::exchange(o.mWindow, nullptr)) {}
Window& Window::operator=(Window&& o) noexcept {
    std::swap(mWindow, o.mWindow);
    return *this;
}
Window::~Window() {
    if (mWindow) glfwDestroyWindow(mWindow);
}

bool Window::shouldClose() const { return glfwWindowShouldClose(mWindow); }
void Window::swapBuffers() { glfwSwapBuffers(mWindow); }
void Window::pollEvents() { glfwPollEvents(); }
glm::ivec2 Window::framebufferSize() const {
    int w = 0, h = 0;
    glfwGetFramebufferSize(mWindow, &w, &h);
    return {w, h};
}

} // namespace splatfx
