// `atonlab view`: the scene through stimuli::Pipeline (as
// examples/simulator_loop.cpp drives it) in a GLFW window, with the keys of
// view_controls.h, frame time and lights drawn / culled in the window title.
// --frames N --screenshot FILE makes it a test: N frames at a fixed step, then
// the displayed frame (read back from the window) as a PNG.
#include "view_command.h"

#include <epoxy/gl.h>
// GLFW after epoxy: epoxy provides the GL declarations.
#include <GLFW/glfw3.h>
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/gl/window.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/pipeline.h"
#include "atonlab/stimuli/scene_file.h"
#include "atonlab/store/error.h"
#include "atonlab/store/store.h"
#include "calibrate/calibration_policy.h"
#include "calibrate/calibration_record.h"
#include "view_controls.h"

namespace atonlab::runner {
namespace {

constexpr double kFixedStepS = 1.0 / 60.0;  // --frames: every frame advances this much

/// Scripted keys: "g,t,w*30" -> g on frame 1, t on frame 2, w held for frames 3..32.
std::deque<ViewKey> parse_keys(const std::string& text) {
    std::deque<ViewKey> out;
    std::size_t start = 0;
    while (start <= text.size() && !text.empty()) {
        const std::size_t comma = text.find(',', start);
        std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        int count = 1;
        if (const auto star = item.find('*'); star != std::string::npos) {
            try {
                count = std::stoi(item.substr(star + 1));
            } catch (const std::exception&) {
                count = 0;
            }
            item = item.substr(0, star);
            if (count < 1)
                throw InputError(SourceLocation::command_line("--keys"),
                                 fmt::format("\"{}\": the repeat count after * must be a whole number >= 1.", item));
        }
        const auto key = view_key_from_name(item);
        if (!key)
            throw InputError(SourceLocation::command_line("--keys"),
                             fmt::format("unknown key \"{}\" (docs/view.md lists the names).", item));
        for (int i = 0; i < count; ++i) out.push_back(*key);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

std::optional<ViewKey> key_of(int glfw_key) {
    switch (glfw_key) {
        case GLFW_KEY_W:
            return ViewKey::forward;
        case GLFW_KEY_S:
            return ViewKey::back;
        case GLFW_KEY_A:
            return ViewKey::left;
        case GLFW_KEY_D:
            return ViewKey::right;
        case GLFW_KEY_Q:
            return ViewKey::down;
        case GLFW_KEY_E:
            return ViewKey::up;
        case GLFW_KEY_LEFT:
            return ViewKey::yaw_left;
        case GLFW_KEY_RIGHT:
            return ViewKey::yaw_right;
        case GLFW_KEY_UP:
            return ViewKey::pitch_up;
        case GLFW_KEY_DOWN:
            return ViewKey::pitch_down;
        case GLFW_KEY_SPACE:
            return ViewKey::pause;
        case GLFW_KEY_PERIOD:
            return ViewKey::step_forward;
        case GLFW_KEY_COMMA:
            return ViewKey::step_back;
        case GLFW_KEY_0:
        case GLFW_KEY_KP_0:
            return ViewKey::reset_time;
        case GLFW_KEY_EQUAL:
        case GLFW_KEY_KP_ADD:
            return ViewKey::adapt_up;
        case GLFW_KEY_MINUS:
        case GLFW_KEY_KP_SUBTRACT:
            return ViewKey::adapt_down;
        case GLFW_KEY_V:
            return ViewKey::adapt_mode;
        case GLFW_KEY_G:
            return ViewKey::glare_toggle;
        case GLFW_KEY_M:
            return ViewKey::glare_cycle;
        case GLFW_KEY_T:
            return ViewKey::tonemap_cycle;
        case GLFW_KEY_B:
            return ViewKey::blueshift;
        case GLFW_KEY_HOME:
        case GLFW_KEY_C:
            return ViewKey::reset_camera;
        case GLFW_KEY_P:
            return ViewKey::screenshot;
        case GLFW_KEY_H:
        case GLFW_KEY_F1:
            return ViewKey::help;
        case GLFW_KEY_ESCAPE:
            return ViewKey::quit;
        default:
            return std::nullopt;
    }
}

/// What the window's callbacks collect between frames.
struct WindowInput {
    std::vector<ViewKey> pressed;
    bool dragging = false;
    double last_x = 0.0, last_y = 0.0;
    double drag_x = 0.0, drag_y = 0.0;  ///< pixels dragged since the last frame
};

/// The frame's pixels as the window holds them (rows top first), for a PNG.
std::vector<float> read_displayed(int x, int y, int w, int h) {
    std::vector<unsigned char> px(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(x, y, w, h, GL_RGB, GL_UNSIGNED_BYTE, px.data());
    std::vector<float> out(px.size());
    const std::size_t row = static_cast<std::size_t>(w) * 3;
    for (std::size_t r = 0; r < static_cast<std::size_t>(h); ++r)
        for (std::size_t i = 0; i < row; ++i)
            out[r * row + i] = static_cast<float>(px[(static_cast<std::size_t>(h) - 1 - r) * row + i]) / 255.0f;
    return out;
}

/// GLFW started, or ContextUnavailable saying why not.
void start_glfw() {
    if (!glfwInit()) {
        const char* display = std::getenv("DISPLAY");
        throw gl::ContextUnavailable(
            fmt::format("the preview window needs a display server, and GLFW could not start ({})",
                        display ? fmt::format("DISPLAY is {}", display) : std::string("DISPLAY is unset")));
    }
}

/// The window shows the frame pixel for pixel; a display larger than the
/// screen is previewed at a lower resolution with the same field of view.
void fit_display_to_screen(stimuli::Scene& scene) {
    GLFWmonitor* monitor = glfwGetPrimaryMonitor();
    if (const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr) {
        const double s =
            std::min({1.0, 0.9 * mode->width / scene.display.width_px, 0.9 * mode->height / scene.display.height_px});
        if (s < 1.0) {
            const int w = std::max(1, static_cast<int>(std::lround(scene.display.width_px * s)));
            const int h = std::max(1, static_cast<int>(std::lround(scene.display.height_px * s)));
            std::printf(
                "the scene's display (%d x %d) is larger than the screen (%d x %d): previewing at %d x %d, "
                "same field of view\n",
                scene.display.width_px, scene.display.height_px, mode->width, mode->height, w, h);
            scene.display.width_px = w;
            scene.display.height_px = h;
        }
    }
}

/// The window's keys, mouse button and cursor feed the WindowInput its user pointer holds.
void install_input_callbacks(GLFWwindow* win) {
    glfwSetKeyCallback(win, [](GLFWwindow* w, int key, int, int action, int) {
        auto* in = static_cast<WindowInput*>(glfwGetWindowUserPointer(w));
        if (action != GLFW_PRESS) return;
        if (const auto k = key_of(key); k && !is_held_key(*k)) in->pressed.push_back(*k);
    });
    glfwSetMouseButtonCallback(win, [](GLFWwindow* w, int button, int action, int) {
        auto* in = static_cast<WindowInput*>(glfwGetWindowUserPointer(w));
        if (button != GLFW_MOUSE_BUTTON_LEFT) return;
        in->dragging = action == GLFW_PRESS;
        glfwGetCursorPos(w, &in->last_x, &in->last_y);
    });
    glfwSetCursorPosCallback(win, [](GLFWwindow* w, double x, double y) {
        auto* in = static_cast<WindowInput*>(glfwGetWindowUserPointer(w));
        if (in->dragging) {
            in->drag_x += x - in->last_x;
            in->drag_y += y - in->last_y;
        }
        in->last_x = x;
        in->last_y = y;
    });
}

/// The speed of held movement keys: 10 with Shift, 0.1 with Control, else 1.
double held_speed(GLFWwindow* win) {
    double speed = 1.0;
    if (glfwGetKey(win, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS || glfwGetKey(win, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS)
        speed = 10.0;
    if (glfwGetKey(win, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
        glfwGetKey(win, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS)
        speed = 0.1;
    return speed;
}

}  // namespace

void add_view_command(CLI::App& app, ViewOptions& o) {
    CLI::App* cmd = app.add_subcommand("view", "Preview a scene interactively in a window (keys: docs/view.md)");
    cmd->add_option("scene", o.scene, "Scene file (TOML; see docs/scene-file.md)")->required();
    cmd->add_option("--set", o.overrides, "Override a scene key: section.key=value (TOML value; repeatable)");
    cmd->add_option("--time", o.time_s, "Scene time to start at, s (default 0)");
    cmd->add_flag("--paused", o.paused, "Start with the scene's clock paused");
    cmd->add_option("--frames", o.frames,
                    "Draw this many frames and exit; time then advances 1/60 s per frame (for tests)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--screenshot", o.screenshot, "Write the last displayed frame to this PNG on exit");
    cmd->add_option("--keys", o.keys, "Scripted keys, one per frame, e.g. \"g,t,w*30\" (names: docs/view.md)");
    cmd->add_option("--display", o.display, "With --db: encode for this display's measured calibration");
    cmd->add_option("--db", o.db, "Study file holding the --display calibration");
    cmd->add_flag_callback(
        "--hidden", [&o] { o.visible = false; }, "Do not show the window (tests)");
}

int run_view(const ViewOptions& o) {
    // Everything that can be wrong with the input, before a window opens.
    std::vector<stimuli::SceneOverride> overrides;
    for (const auto& s : o.overrides) overrides.push_back(stimuli::SceneOverride::parse(s));
    if (!std::isfinite(o.time_s) || o.time_s < 0.0)
        throw InputError(SourceLocation::command_line("--time"), "the time must be a finite number of seconds >= 0");
    std::deque<ViewKey> script = parse_keys(o.keys);
    stimuli::Scene scene = stimuli::load_scene(o.scene, overrides);
    stimuli::validate_output_settings(scene.output, scene.adaptation_cd_m2);
    if (o.display.empty() != o.db.empty())
        throw InputError(SourceLocation::command_line(o.display.empty() ? "--db" : "--display"),
                         "--display and --db go together: the display's calibration is read from the study file.");
    if (!o.display.empty()) {
        try {
            const store::Store db = store::Store::open_read_only(o.db);
            const auto cal = latest_measured_calibration(db, o.display);
            if (!cal)
                throw InputError(SourceLocation::command_line("--display"),
                                 fmt::format("display \"{}\" has no measured calibration in {}.", o.display, o.db));
            apply_display_model(scene, display_model_of(*cal));
            std::printf("encoding for calibration %lld of display \"%s\" (measured %s)\n",
                        static_cast<long long>(cal->id.value), o.display.c_str(), cal->measured_at.c_str());
        } catch (const store::StoreError& e) {
            std::fprintf(stderr, "atonlab: %s\n", e.what());
            return 4;
        }
    }

    start_glfw();
    fit_display_to_screen(scene);
    gl::WindowOptions wo;
    wo.width = scene.display.width_px;
    wo.height = scene.display.height_px;
    wo.title = "atonlab view";
    wo.visible = o.visible;
    wo.vsync = o.frames == 0;  // a test runs as fast as it can
    auto window = gl::create_window_context(wo);
    GLFWwindow* win = window->glfw_window();
    WindowInput input;
    glfwSetWindowUserPointer(win, &input);
    install_input_callbacks(win);

    std::printf("%s: %d x %d, %s\n%s", o.scene.c_str(), scene.display.width_px, scene.display.height_px,
                window->info().renderer.c_str(), kViewHelp);
    ViewControls controls(scene, o.time_s, !o.paused);
    std::printf("%s\n", controls.status().c_str());
    stimuli::Pipeline pipeline;
    const std::string name = std::filesystem::path(o.scene).filename().string();
    auto last = std::chrono::steady_clock::now();
    auto last_title = last - std::chrono::seconds(1);
    double frame_ms = 0.0, total_ms = 0.0;
    int frame = 0, screenshots = 0;
    bool first = true;
    const bool fixed_step = o.frames > 0;
    while (!controls.quit_requested() && !window->should_close() && (!fixed_step || frame < o.frames)) {
        window->poll_events();
        const auto now = std::chrono::steady_clock::now();
        const double wall_dt = first ? 0.0 : std::chrono::duration<double>(now - last).count();
        last = now;
        const double dt = first ? 0.0 : fixed_step ? kFixedStepS : wall_dt;
        if (!first) {
            frame_ms = frame_ms == 0.0 ? 1000.0 * wall_dt : 0.9 * frame_ms + 100.0 * wall_dt;
            total_ms += 1000.0 * wall_dt;
        }

        // Keys: the window's presses, the held keys, then this frame's scripted key.
        std::vector<ViewKey> pressed = std::move(input.pressed);
        input.pressed.clear();
        std::vector<ViewKey> held;
        for (const int k : {GLFW_KEY_W, GLFW_KEY_S, GLFW_KEY_A, GLFW_KEY_D, GLFW_KEY_Q, GLFW_KEY_E, GLFW_KEY_LEFT,
                            GLFW_KEY_RIGHT, GLFW_KEY_UP, GLFW_KEY_DOWN})
            if (glfwGetKey(win, k) == GLFW_PRESS) held.push_back(*key_of(k));
        if (!first && !script.empty()) {
            const ViewKey k = script.front();
            script.pop_front();
            (is_held_key(k) ? held : pressed).push_back(k);
        }
        const double speed = held_speed(win);
        const double adapted = first ? scene.adaptation_cd_m2 : pipeline.display().adaptation_cd_m2();
        for (const ViewKey k : pressed) {
            const std::string said = controls.press(k, adapted);
            try {
                stimuli::validate_output_settings(controls.scene().output, controls.scene().adaptation_cd_m2);
            } catch (const InputError& e) {
                controls.revert();
                std::printf("not possible: %s\n", e.message().c_str());
                continue;
            }
            if (!said.empty()) std::printf("%s%s", said.c_str(), said.back() == '\n' ? "" : "\n");
        }
        controls.hold(held, dt, speed);
        if (input.drag_x != 0.0 || input.drag_y != 0.0) {
            if (!first)
                controls.drag(input.drag_x, input.drag_y, pipeline.frame().projection().degrees_per_pixel_at_centre());
            input.drag_x = input.drag_y = 0.0;
        }
        controls.advance(dt);

        pipeline.render(controls.scene(), controls.time_s(), dt);
        const int fb_w = window->framebuffer_width(), fb_h = window->framebuffer_height();
        const int w = controls.scene().display.width_px, h = controls.scene().display.height_px;
        const int x0 = std::max(0, (fb_w - w) / 2), y0 = std::max(0, (fb_h - h) / 2);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, fb_w, fb_h);
        glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        pipeline.present(x0, y0);
        ++frame;
        const bool last_frame = fixed_step && frame == o.frames;
        if (controls.screenshot_requested()) {
            const std::string path = fmt::format("atonlab-view-{}.png", ++screenshots);
            stimuli::write_png_rgb8(path, w, h, read_displayed(x0, y0, w, h));
            std::printf("screenshot: %s\n", path.c_str());
        }
        if (!o.screenshot.empty() && (last_frame || controls.quit_requested() || window->should_close()))
            stimuli::write_png_rgb8(o.screenshot, w, h, read_displayed(x0, y0, w, h));
        window->swap_buffers();
        first = false;

        if (now - last_title > std::chrono::milliseconds(250) || last_frame) {
            last_title = now;
            const stimuli::FrameStats st = pipeline.frame().stats();
            glfwSetWindowTitle(win, fmt::format("atonlab view — {} | {:.1f} ms | lights {} drawn, {} culled | {}", name,
                                                frame_ms, st.drawn, st.lights - st.drawn, controls.status())
                                        .c_str());
        }
    }
    const stimuli::FrameStats st = pipeline.frame().stats();
    std::printf("%d frames, %.1f ms per frame on average; last frame: %d of %d lights drawn, %d culled\n", frame,
                frame > 1 ? total_ms / (frame - 1) : 0.0, st.drawn, st.lights, st.lights - st.drawn);
    if (!o.screenshot.empty()) std::printf("screenshot: %s\n", o.screenshot.c_str());
    glfwSetWindowUserPointer(win, nullptr);
    return 0;
}

}  // namespace atonlab::runner
