// A GLFW window with an OpenGL 4.5 core context, windowed or full-screen.
#include <epoxy/gl.h>
// GLFW after epoxy: epoxy provides the GL declarations.
#include <GLFW/glfw3.h>

#include <fmt/format.h>

#include "atonlab/stimuli/gl/window.h"

namespace atonlab::gl {
namespace {
int g_glfw_users = 0;
std::string g_last_glfw_error;
void on_glfw_error(int, const char* description) { g_last_glfw_error = description ? description : "?"; }
}  // namespace

std::unique_ptr<WindowContext> create_window_context(const WindowOptions& opt) {
    glfwSetErrorCallback(on_glfw_error);
    if (g_glfw_users == 0 && !glfwInit())
        throw ContextUnavailable(fmt::format("GLFW could not start: {}", g_last_glfw_error));
    ++g_glfw_users;
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, opt.debug ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_VISIBLE, opt.visible ? GLFW_TRUE : GLFW_FALSE);
    GLFWmonitor* monitor = nullptr;
    int width = opt.width, height = opt.height;
    if (opt.fullscreen) {
        int count = 0;
        GLFWmonitor** monitors = glfwGetMonitors(&count);
        if (opt.monitor < 0 || opt.monitor >= count) {
            if (--g_glfw_users == 0) glfwTerminate();
            throw ContextUnavailable(
                fmt::format("monitor {} was asked for but {} monitor(s) are connected", opt.monitor, count));
        }
        monitor = monitors[opt.monitor];
        // The monitor's native mode: full-screen at its own resolution and refresh rate.
        const GLFWvidmode* mode = glfwGetVideoMode(monitor);
        glfwWindowHint(GLFW_RED_BITS, mode->redBits);
        glfwWindowHint(GLFW_GREEN_BITS, mode->greenBits);
        glfwWindowHint(GLFW_BLUE_BITS, mode->blueBits);
        glfwWindowHint(GLFW_REFRESH_RATE, mode->refreshRate);
        width = mode->width;
        height = mode->height;
    }
    GLFWwindow* window = glfwCreateWindow(width, height, opt.title.c_str(), monitor, nullptr);
    if (!window) {
        if (--g_glfw_users == 0) glfwTerminate();
        throw ContextUnavailable(fmt::format("no OpenGL 4.5 core window could be made: {}", g_last_glfw_error));
    }
    std::unique_ptr<WindowContext> ctx(new WindowContext());
    ctx->window_ = window;
    ctx->make_current();
    glfwSwapInterval(opt.vsync ? 1 : 0);
    if (opt.fullscreen) glfwSetInputMode(window, GLFW_CURSOR, GLFW_CURSOR_HIDDEN);
    ctx->info_.platform = "glfw";
    ctx->info_.vendor = reinterpret_cast<const char*>(glGetString(GL_VENDOR));
    ctx->info_.renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    ctx->info_.version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    ctx->info_.glsl_version = reinterpret_cast<const char*>(glGetString(GL_SHADING_LANGUAGE_VERSION));
    ctx->info_.software = ctx->info_.renderer.find("llvmpipe") != std::string::npos;
    require_gl45();
    return ctx;
}

WindowContext::~WindowContext() {
    if (window_) glfwDestroyWindow(window_);
    if (--g_glfw_users == 0) glfwTerminate();
}

void WindowContext::make_current() { glfwMakeContextCurrent(window_); }
void WindowContext::swap_buffers() { glfwSwapBuffers(window_); }
bool WindowContext::should_close() const { return glfwWindowShouldClose(window_) != 0; }
void WindowContext::poll_events() { glfwPollEvents(); }
int WindowContext::framebuffer_width() const {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    return w;
}
int WindowContext::framebuffer_height() const {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    return h;
}

}  // namespace atonlab::gl
