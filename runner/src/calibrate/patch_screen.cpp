#include "patch_screen.h"

#include <epoxy/gl.h>
// GLFW after epoxy: epoxy provides the GL declarations.
#include <GLFW/glfw3.h>
#include <fmt/format.h>

#include <cmath>
#include <utility>
#include <vector>

#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/gl/window.h"

namespace atonlab::runner {

struct PatchScreen::Impl {
    PatchScreenOptions options;
    std::unique_ptr<gl::WindowContext> window;
    std::unique_ptr<gl::Context> headless;
    gl::Texture2D target;
    gl::Framebuffer fbo;
    Patch current;
    bool has_patch = false;
    bool quit = false;
    std::string typed;
    int width = 0, height = 0;

    static Impl* of(GLFWwindow* w) { return static_cast<Impl*>(glfwGetWindowUserPointer(w)); }

    /// Clears the bound framebuffer to black and the patch's rectangle to its codes.
    void draw(const Patch& p) const {
        glViewport(0, 0, width, height);
        glDisable(GL_DITHER);
        glDisable(GL_FRAMEBUFFER_SRGB);
        glDisable(GL_SCISSOR_TEST);
        glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        // A centred rectangle with the screen's aspect covering window_percent of its area.
        const double side = std::sqrt(options.window_percent / 100.0);
        const int w = std::max(1, static_cast<int>(std::lround(side * width)));
        const int h = std::max(1, static_cast<int>(std::lround(side * height)));
        glEnable(GL_SCISSOR_TEST);
        glScissor((width - w) / 2, (height - h) / 2, w, h);
        // code / 255 is stored in a unorm8 framebuffer as round(code / 255 · 255) = code.
        glClearColor(static_cast<float>(p.rgb.r) / Patch::max_code, static_cast<float>(p.rgb.g) / Patch::max_code,
                     static_cast<float>(p.rgb.b) / Patch::max_code, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        glDisable(GL_SCISSOR_TEST);
    }

    /// The centre pixel must hold the codes sent.
    void verify(const Patch& p) const {
        unsigned char px[4] = {};
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(width / 2, height / 2, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
        if (px[0] != p.rgb.r || px[1] != p.rgb.g || px[2] != p.rgb.b)
            throw gl::ContextUnavailable(fmt::format(
                "the frame buffer does not hold the patch's code values exactly (sent {} {} {}, read back {} {} {}): "
                "it is not an 8-bit linear frame buffer, so the patches would not be what is measured",
                p.rgb.r, p.rgb.g, p.rgb.b, px[0], px[1], px[2]));
    }
};

PatchScreen::PatchScreen(const PatchScreenOptions& options) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.options = options;
    if (options.headless) {
        m.headless = gl::create_headless_context();
        m.width = options.headless_width;
        m.height = options.headless_height;
        m.target = gl::Texture2D(m.width, m.height, gl::PixelFormat::rgba8);
        m.fbo = gl::Framebuffer::create();
        m.fbo.attach_colour(m.target);
        m.fbo.check_complete("the calibration patch framebuffer");
        m.fbo.bind();
        return;
    }
    gl::WindowOptions w;
    w.fullscreen = true;
    w.monitor = options.monitor;
    w.vsync = true;
    w.title = "atonlab calibrate";
    m.window = gl::create_window_context(w);
    m.width = m.window->framebuffer_width();
    m.height = m.window->framebuffer_height();
    GLFWwindow* win = m.window->glfw_window();
    glfwSetWindowUserPointer(win, &m);
    glfwSetCharCallback(win, [](GLFWwindow* gw, unsigned int cp) {
        if (cp < 0x80) Impl::of(gw)->typed += static_cast<char>(cp);  // readings are ASCII
    });
    glfwSetKeyCallback(win, [](GLFWwindow* gw, int key, int, int action, int) {
        if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
        Impl* self = Impl::of(gw);
        if (key == GLFW_KEY_ESCAPE) self->quit = true;
        if (key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) self->typed += '\n';
        if (key == GLFW_KEY_BACKSPACE) self->typed += '\b';
    });
}

PatchScreen::~PatchScreen() {
    if (impl_->window) glfwSetWindowUserPointer(impl_->window->glfw_window(), nullptr);
}

void PatchScreen::show(const Patch& patch) {
    Impl& m = *impl_;
    m.current = patch;
    m.has_patch = true;
    if (m.headless) {
        m.fbo.bind();
        m.draw(patch);
        m.verify(patch);
        gl::finish();
        return;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    m.draw(patch);
    m.verify(patch);  // the back buffer, before it is shown
    m.window->swap_buffers();
    m.window->poll_events();
}

void PatchScreen::pump() {
    Impl& m = *impl_;
    if (!m.window) return;
    if (m.has_patch) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        m.draw(m.current);
    }
    m.window->swap_buffers();  // vsync paces this loop
    m.window->poll_events();
    if (m.window->should_close()) m.quit = true;
}

PatchScreen::Aperture PatchScreen::read_shown(int side_px) {
    Impl& m = *impl_;
    Aperture a;
    a.width_px = std::min(side_px, m.width);
    a.height_px = std::min(side_px, m.height);
    if (m.window) {
        // The frame about to be presented: the patch drawn again into the back
        // buffer, read, then swapped. (Mesa's GLX reads GL_FRONT as zeros after
        // a swap, so the front buffer cannot be read back there.)
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        if (m.has_patch) m.draw(m.current);
        glReadBuffer(GL_BACK);
    } else {
        m.fbo.bind();
    }
    gl::finish();
    std::vector<unsigned char> px(static_cast<std::size_t>(a.width_px) * static_cast<std::size_t>(a.height_px) * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels((m.width - a.width_px) / 2, (m.height - a.height_px) / 2, a.width_px, a.height_px, GL_RGBA,
                 GL_UNSIGNED_BYTE, px.data());
    if (m.window) {
        m.window->swap_buffers();
        m.window->poll_events();
    }
    glm::dvec3 sum{0.0};
    for (std::size_t i = 0; i < px.size(); i += 4) sum += glm::dvec3(px[i], px[i + 1], px[i + 2]);
    a.mean_codes = sum / static_cast<double>(a.width_px * a.height_px);
    a.max_code = Patch::max_code;
    return a;
}

void PatchScreen::set_progress(const std::string& text) {
    if (impl_->window) glfwSetWindowTitle(impl_->window->glfw_window(), text.c_str());
}

bool PatchScreen::quit_requested() const {
    return impl_->quit;
}

std::string PatchScreen::take_typed() {
    return std::exchange(impl_->typed, std::string());
}

int PatchScreen::width() const {
    return impl_->width;
}

int PatchScreen::height() const {
    return impl_->height;
}

std::string PatchScreen::description() const {
    const Impl& m = *impl_;
    const gl::ContextInfo& info = m.window ? m.window->info() : m.headless->info();
    if (m.window)
        return fmt::format("full-screen {} x {} on monitor {} ({})", m.width, m.height, m.options.monitor,
                           info.renderer);
    return fmt::format("off-screen {} x {} ({})", m.width, m.height, info.renderer);
}

}  // namespace atonlab::runner
