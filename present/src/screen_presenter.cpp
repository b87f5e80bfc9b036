// The on-screen presenter (screen_presenter.h; docs/running.md "Timing").
#include "atonlab/present/screen_presenter.h"

#include <epoxy/gl.h>
// GLFW after epoxy: epoxy provides the GL declarations.
#include <GLFW/glfw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <list>
#include <thread>

#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/gl/window.h"
#include "atonlab/stimuli/image_io.h"

namespace atonlab::present {
namespace {

/// Codes as present.frag reads them: per pixel uvec2(r | g << 16, b), rows
/// from the bottom (GL's), for `w` × `h` pixels taken from `codes` at (x0, y0)
/// (row 0 at the top).
gl::Buffer pack_codes(const stimuli::EncodedImage& codes, int x0, int y0, int w, int h) {
    std::vector<std::uint32_t> packed(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 2);
    for (int yg = 0; yg < h; ++yg) {
        const int y = y0 + (h - 1 - yg);
        for (int x = 0; x < w; ++x) {
            const std::size_t src = (static_cast<std::size_t>(y) * static_cast<std::size_t>(codes.width) +
                                     static_cast<std::size_t>(x0 + x)) *
                                    3;
            const std::size_t dst =
                (static_cast<std::size_t>(yg) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 2;
            packed[dst] =
                static_cast<std::uint32_t>(codes.rgb[src]) | (static_cast<std::uint32_t>(codes.rgb[src + 1]) << 16);
            packed[dst + 1] = codes.rgb[src + 2];
        }
    }
    return gl::Buffer::from(std::span<const std::uint32_t>(packed));
}

float max_code(int bits) {
    return static_cast<float>((1u << static_cast<unsigned>(bits)) - 1u);
}

}  // namespace

struct ScreenPresenter::Gl {
    gl::Program present =
        gl::Program::build({{gl::ShaderStage::vertex, "fullscreen.vert"}, {gl::ShaderStage::fragment, "present.frag"}});
    gl::VertexArray vao = gl::VertexArray::create();

    // Pictures uploaded recently (a block's background is shown every trial).
    struct Cached {
        std::shared_ptr<const stimuli::EncodedImage> image;
        gl::Buffer codes;
    };
    std::list<Cached> pictures;

    const gl::Buffer& upload(const std::shared_ptr<const stimuli::EncodedImage>& image) {
        for (auto it = pictures.begin(); it != pictures.end(); ++it)
            if (it->image == image) {
                pictures.splice(pictures.begin(), pictures, it);
                return pictures.front().codes;
            }
        pictures.push_front(Cached{image, pack_codes(*image, 0, 0, image->width, image->height)});
        constexpr std::size_t kKeep = 6;
        while (pictures.size() > kKeep) pictures.pop_back();
        return pictures.front().codes;
    }

    /// Codes into the bound framebuffer, lower-left corner at (x, y).
    void draw_codes(const gl::Buffer& codes, int w, int h, int x, int y, int bits) const {
        codes.bind_storage(8);
        present.set("size", w, h);
        present.set("origin", x, y);
        present.set("max_code", max_code(bits));
        present.use();
        vao.bind();
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
};

namespace {

struct PreparedScreen final : Presenter::Prepared {
    Screen screen;
    const gl::Buffer* picture = nullptr;
    int pic_x = 0, pic_y = 0;  // lower-left corner on screen (GL)
    bool covers = false;       // the picture fills the screen
    struct Box {
        gl::Buffer codes;
        int x = 0, y = 0, w = 0, h = 0;  // lower-left corner (GL) and size
    };
    std::vector<Box> boxes;
};

}  // namespace

ScreenPresenter::ScreenPresenter(const ScreenOptions& options) : Presenter(1.0 / 60.0), options_(options) {}

ScreenPresenter::~ScreenPresenter() {
    if (window_) {
        window_->make_current();
        gl_.reset();  // GL objects go while their context lives
    }
}

std::unique_ptr<ScreenPresenter> ScreenPresenter::open(const ScreenOptions& o) {
    std::unique_ptr<ScreenPresenter> p(new ScreenPresenter(o));
    gl::WindowOptions w;
    w.fullscreen = true;
    w.monitor = o.monitor;
    w.vsync = !o.software_vsync_hz;
    w.title = o.title;
    p->window_ = gl::create_window_context(w);
    GLFWwindow* win = p->window_->glfw_window();
    p->width_ = p->window_->framebuffer_width();
    p->height_ = p->window_->framebuffer_height();
    if (GLFWmonitor* m = glfwGetWindowMonitor(win)) {
        if (const GLFWvidmode* mode = glfwGetVideoMode(m)) p->mode_hz_ = mode->refreshRate;
        if (const char* name = glfwGetMonitorName(m)) p->monitor_name_ = name;
    }
    GLint red = 8;
    glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, GL_BACK_LEFT, GL_FRAMEBUFFER_ATTACHMENT_RED_SIZE, &red);
    p->bits_ = red > 0 ? red : 8;
    glfwSetWindowUserPointer(win, p.get());
    glfwSetKeyCallback(win, &ScreenPresenter::on_key);
    p->gl_ = std::make_unique<Gl>();
    p->measure_refresh();
    return p;
}

std::string ScreenPresenter::timing_method() const {
    if (options_.software_vsync_hz)
        return fmt::format(
            "software vsync at {:g} Hz (no vertical blank: testing only); glfwSwapBuffers + glFinish, "
            "then a timer to the next {:.3f} ms tick, then glfwGetTime",
            *options_.software_vsync_hz, 1e3 / *options_.software_vsync_hz);
    return "vsync (swap interval 1); glfwSwapBuffers + glFinish, then glfwGetTime";
}

void ScreenPresenter::measure_refresh() {
    Screen black;
    const std::unique_ptr<Prepared> p = prepare(black);
    // A few flips first: the first swaps of a new window are not paced.
    for (int i = 0; i < 5; ++i) {
        draw(*p, 0.0);
        flip();
    }
    std::vector<double> t;
    const double start = now_s();
    constexpr std::size_t kMaxSamples = 600;
    while (t.size() < kMaxSamples) {
        draw(*p, 0.0);
        t.push_back(flip());
        if (t.back() - start > options_.sync.max_duration_s) break;
        if (t.size() > static_cast<std::size_t>(options_.sync.min_samples)) {
            const RefreshEstimate e = estimate_refresh(t);
            // Done when it passes; when the test is skipped, as soon as there are enough samples.
            if (sync_sampling_done(e, options_.sync) ||
                (options_.skip_sync_test && e.valid >= options_.sync.min_samples))
                break;
        }
    }
    refresh_ = estimate_refresh(t);
    std::optional<double> nominal;
    if (options_.software_vsync_hz)
        nominal = *options_.software_vsync_hz;
    else if (mode_hz_ > 0)
        nominal = mode_hz_;
    std::string why = sync_verdict(refresh_, nominal, options_.sync);
    if (why.empty() && options_.expected_hz) {
        const double deviation = std::abs(refresh_.hz() - *options_.expected_hz) / *options_.expected_hz;
        if (!(deviation < options_.sync.max_deviation))
            why = fmt::format(
                "the display refreshes at {:.3f} Hz but the protocol is written for {:g} Hz ([timing] refresh_hz): "
                "its durations would be counted in the wrong frames",
                refresh_.hz(), *options_.expected_hz);
    }
    if (!why.empty() && !options_.skip_sync_test)
        throw DisplayTimingRefused(fmt::format(
            "monitor {} ({}×{}{}): {}. The session was not started; see docs/running.md, \"Timing\" (--skip-sync-test "
            "runs anyway, for testing only).",
            options_.monitor, width_, height_, mode_hz_ > 0 ? fmt::format(" at {} Hz", mode_hz_) : std::string(), why));
    if (!why.empty())
        std::fprintf(stderr,
                     "atonlab: warning: the display timing check failed (%s); running anyway (--skip-sync-test)\n",
                     why.c_str());
    double period = refresh_.valid > 0 ? refresh_.period_s : 0.0;
    if (!(period > 0.0)) period = nominal ? 1.0 / *nominal : 1.0 / 60.0;
    set_period(period);
}

double ScreenPresenter::now_s() {
    return glfwGetTime();
}

std::unique_ptr<Presenter::Prepared> ScreenPresenter::prepare(const Screen& s) {
    auto p = std::make_unique<PreparedScreen>();
    p->screen = s;
    if (s.picture) {
        p->picture = &gl_->upload(s.picture);
        // Centred when it is not the screen's size (the session refuses that
        // for stimuli; text screens may be smaller).
        p->pic_x = (width_ - s.picture->width) / 2;
        p->pic_y = (height_ - s.picture->height) / 2;
        p->covers = s.picture->width == width_ && s.picture->height == height_;
    }
    for (const Overlay& o : s.overlays) {
        if (!o.coverage) continue;
        // The overlay's box, cut to the screen; its pixels are the background
        // under it blended with the ink (text.h blend_text).
        const int x0 = std::max(0, o.x), y0 = std::max(0, o.y);
        const int x1 = std::min(width_, o.x + o.coverage->width), y1 = std::min(height_, o.y + o.coverage->height);
        if (x1 <= x0 || y1 <= y0) continue;
        stimuli::EncodedImage box;
        box.width = x1 - x0;
        box.height = y1 - y0;
        box.bits = s.bits;
        box.rgb.resize(static_cast<std::size_t>(box.width) * static_cast<std::size_t>(box.height) * 3);
        const int top_of_picture = s.picture ? height_ - p->pic_y - s.picture->height : 0;  // row 0 at the top
        for (int y = 0; y < box.height; ++y)
            for (int x = 0; x < box.width; ++x) {
                const std::size_t d =
                    (static_cast<std::size_t>(y) * static_cast<std::size_t>(box.width) + static_cast<std::size_t>(x)) *
                    3;
                Code3 c = s.background;
                if (s.picture) {
                    const int px = x0 + x - p->pic_x, py = y0 + y - top_of_picture;
                    if (px >= 0 && py >= 0 && px < s.picture->width && py < s.picture->height) {
                        const std::size_t i =
                            (static_cast<std::size_t>(py) * static_cast<std::size_t>(s.picture->width) +
                             static_cast<std::size_t>(px)) *
                            3;
                        c = {s.picture->rgb[i], s.picture->rgb[i + 1], s.picture->rgb[i + 2]};
                    }
                }
                box.rgb[d] = c[0];
                box.rgb[d + 1] = c[1];
                box.rgb[d + 2] = c[2];
            }
        blend_text(box, *o.coverage, o.x - x0, o.y - y0, o.ink);
        PreparedScreen::Box b;
        b.codes = pack_codes(box, 0, 0, box.width, box.height);
        b.x = x0;
        b.y = height_ - y1;
        b.w = box.width;
        b.h = box.height;
        p->boxes.push_back(std::move(b));
    }
    return p;
}

void ScreenPresenter::draw(const Prepared& prepared, double t_s) {
    const auto& p = static_cast<const PreparedScreen&>(prepared);
    auto bind_screen = [this] {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, width_, height_);
        glDisable(GL_BLEND);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_SCISSOR_TEST);
        glDisable(GL_FRAMEBUFFER_SRGB);
        glDisable(GL_DITHER);
    };
    bind_screen();
    if (p.screen.animate && p.screen.present) {
        p.screen.animate(t_s);
        bind_screen();
        p.screen.present(0, 0);  // the session refuses a protocol display that is not the screen's size
    } else {
        if (!p.covers) {
            const float m = max_code(p.screen.bits);
            glClearColor(p.screen.background[0] / m, p.screen.background[1] / m, p.screen.background[2] / m, 1.0f);
            glClear(GL_COLOR_BUFFER_BIT);
        }
        if (p.picture)
            gl_->draw_codes(*p.picture, p.screen.picture->width, p.screen.picture->height, p.pic_x, p.pic_y,
                            p.screen.picture->bits);
    }
    for (const PreparedScreen::Box& b : p.boxes) gl_->draw_codes(b.codes, b.w, b.h, b.x, b.y, p.screen.bits);
}

void ScreenPresenter::finish() {
    glFinish();
}

double ScreenPresenter::flip() {
    window_->swap_buffers();
    // glFinish after the swap: with vsync the driver blocks here until the
    // swap is done (the flip at the vertical blank), so the time read after it
    // is when the new frame started to scan out, up to the driver's queueing.
    glFinish();
    if (options_.software_vsync_hz) {
        const double period = 1.0 / *options_.software_vsync_hz;
        const double now = glfwGetTime();
        if (soft_origin_s_ < 0.0) soft_origin_s_ = now;
        const double tick = soft_origin_s_ + std::ceil((now - soft_origin_s_) / period) * period;
        // Sleep to 1.5 ms before the tick, then spin: a sleep alone overshoots
        // by milliseconds on a busy machine.
        const double wait = tick - glfwGetTime() - 0.0015;
        if (wait > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
        while (glfwGetTime() < tick) {
        }
    }
    const double t = glfwGetTime();
    glfwPollEvents();
    poll_gamepads();
    return t;
}

void ScreenPresenter::stall(int frames) {
    std::this_thread::sleep_for(std::chrono::duration<double>(frames * period_s()));
}

void ScreenPresenter::wait_events(double until_s) {
    double timeout = until_s - now_s();
    bool pads = false;
    for (int j = GLFW_JOYSTICK_1; j <= GLFW_JOYSTICK_LAST && !pads; ++j) pads = glfwJoystickIsGamepad(j) == GLFW_TRUE;
    // Gamepads are polled (GLFW reports their state, not events): every 2 ms while one is connected.
    if (pads) timeout = std::min(timeout, 0.002);
    if (timeout > 0.0)
        glfwWaitEventsTimeout(timeout);
    else
        glfwPollEvents();
    poll_gamepads();
}

void ScreenPresenter::poll_gamepads() {
    for (int j = GLFW_JOYSTICK_1; j <= GLFW_JOYSTICK_LAST && j < static_cast<int>(pads_.size()); ++j) {
        GamepadButtons& before = pads_[static_cast<std::size_t>(j)];
        GLFWgamepadstate state{};
        if (glfwJoystickIsGamepad(j) != GLFW_TRUE || glfwGetGamepadState(j, &state) != GLFW_TRUE) {
            before.fill(GLFW_RELEASE);
            continue;
        }
        const double t = glfwGetTime();
        GamepadButtons now{};
        std::copy(std::begin(state.buttons), std::end(state.buttons), now.begin());
        for (const std::string_view name : newly_pressed(before, now))
            input_.push(InputEvent{InputEvent::Source::gamepad, std::string(name), t});
        before = now;
    }
}

void ScreenPresenter::on_key(GLFWwindow* window, int key, int, int action, int) {
    if (action != GLFW_PRESS) return;  // presses only: no auto-repeat, no releases
    const double t = glfwGetTime();
    auto* self = static_cast<ScreenPresenter*>(glfwGetWindowUserPointer(window));
    if (!self) return;
    if (const auto name = key_name(key))
        self->input_.push(InputEvent{InputEvent::Source::keyboard, std::string(*name), t});
}

void ScreenPresenter::capture_back(const std::filesystem::path& png) const {
    std::vector<unsigned char> px(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 3);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width_, height_, GL_RGB, GL_UNSIGNED_BYTE, px.data());
    std::vector<float> rgb(px.size());
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_ * 3; ++x)
            rgb[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) * 3 + static_cast<std::size_t>(x)] =
                px[static_cast<std::size_t>(height_ - 1 - y) * static_cast<std::size_t>(width_) * 3 +
                   static_cast<std::size_t>(x)] /
                255.0f;
    stimuli::write_png_rgb8(png, width_, height_, rgb);
}

void ScreenPresenter::sync_with_server() const {
    // glfwGetWindowPos asks the X server (a round trip): every request sent
    // before it on the connection, the swap's image included, has been executed
    // when it returns.
    int x = 0, y = 0;
    glfwGetWindowPos(window_->glfw_window(), &x, &y);
}

}  // namespace atonlab::present
