#pragma once
// OpenGL 4.5 core contexts: headless (EGL: Mesa llvmpipe without a GPU, the
// vendor driver with one) and windowed (GLFW, windowed or full-screen on a
// chosen monitor). Functions are loaded through libepoxy for both.
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace atonlab::gl {

/// No OpenGL 4.5 core context can be made here; what() is one sentence saying why.
class ContextUnavailable : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A driver or GL-usage failure (shader compile/link error, incomplete framebuffer...).
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct ContextInfo {
    std::string vendor, renderer, version, glsl_version;
    std::string platform;  ///< "egl-device", "egl-surfaceless", "egl-default" or "glfw"
    bool software = false; ///< llvmpipe / softpipe / swrast
};

class Context {
public:
    virtual ~Context() = default;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    virtual void make_current() = 0;
    /// Presents the back buffer (windows); a no-op for headless contexts.
    virtual void swap_buffers() {}
    const ContextInfo& info() const { return info_; }

protected:
    Context() = default;
    ContextInfo info_;
};

struct HeadlessOptions {
    bool debug = false;  ///< a debug context with KHR_debug messages printed to stderr
    /// Prefer a hardware EGL device over a software one (default); set
    /// ATONLAB_EGL_DEVICE=software|hardware|<index> in the environment to override.
    bool prefer_hardware = true;
};

/// Creates and makes current a headless OpenGL 4.5 core context.
/// Throws ContextUnavailable with one sentence when none can be made.
std::unique_ptr<Context> create_headless_context(const HeadlessOptions& options = {});

struct WindowOptions {
    int width = 1280;
    int height = 720;
    std::string title = "atonlab";
    bool fullscreen = false;
    int monitor = 0;      ///< index into the connected monitors, for full-screen
    bool vsync = true;
    bool visible = true;
    bool debug = false;
};

/// A GLFW window with an OpenGL 4.5 core context (made current).
class WindowContext;
std::unique_ptr<WindowContext> create_window_context(const WindowOptions& options);

/// Checks that the current context really is 4.5 core with compute shaders; throws
/// ContextUnavailable otherwise. Called by both factories.
void require_gl45();

}  // namespace atonlab::gl
