#pragma once
// The windowed context (GLFW). Kept apart from context.h so code that only
// renders headless never sees GLFW types.
#include <functional>

#include "atonlab/stimuli/gl/context.h"

struct GLFWwindow;

namespace atonlab::gl {

class WindowContext final : public Context {
public:
    ~WindowContext() override;
    void make_current() override;
    void swap_buffers() override;

    bool should_close() const;
    void poll_events();
    int framebuffer_width() const;
    int framebuffer_height() const;
    GLFWwindow* glfw_window() const { return window_; }

private:
    friend std::unique_ptr<WindowContext> create_window_context(const WindowOptions&);
    WindowContext() = default;
    GLFWwindow* window_ = nullptr;
};

}  // namespace atonlab::gl
