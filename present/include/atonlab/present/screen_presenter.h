#pragma once
// The on-screen presenter (presenter.h): a full-screen GLFW window on one
// monitor at its native mode, vertical sync on, cursor hidden; the refresh
// period measured at start (sync test, frame_clock.h), every flip timestamped
// after it returns (docs/running.md "Timing": glfwSwapBuffers, then glFinish,
// then glfwGetTime), keys and gamepad buttons timestamped as they arrive.
//
// Pictures are drawn with the stimuli library's present pass (present.frag:
// code / (2^bits − 1) into a unorm framebuffer of the same depth is the code
// itself), so the screen gets exactly the codes the display pipeline made.
// The window's GL context is the one the session renders its stimuli in.
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "atonlab/present/presenter.h"

struct GLFWwindow;

namespace atonlab::gl {
class WindowContext;
}

namespace atonlab::present {

/// The display's timing failed the start-up measurement; what() is one sentence.
class DisplayTimingRefused : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct ScreenOptions {
    int monitor = 0;  ///< index into GLFW's monitors; 0 is the primary
    /// A display without a vertical blank to wait for (Xvfb, some virtual
    /// machines): pace flips with a timer at this rate instead (testing only;
    /// docs/running.md).
    std::optional<double> software_vsync_hz;
    SyncCriteria sync;
    /// Measure and report, but start whatever the measurement says.
    bool skip_sync_test = false;
    /// The rate the protocol is written for (its [timing] refresh_hz): the
    /// measured rate must agree within sync.max_deviation.
    std::optional<double> expected_hz;
    std::string title = "atonlab";
};

class ScreenPresenter final : public Presenter {
public:
    /// Opens the window (throws gl::ContextUnavailable when it cannot) and
    /// measures the refresh period; throws DisplayTimingRefused when the
    /// measurement fails its criteria (unless skip_sync_test).
    static std::unique_ptr<ScreenPresenter> open(const ScreenOptions& options);
    ~ScreenPresenter() override;

    bool on_screen() const override { return true; }
    double now_s() override;
    int width_px() const override { return width_; }
    int height_px() const override { return height_; }

    /// The start-up measurement (its mean is period_s()).
    const RefreshEstimate& refresh() const noexcept { return refresh_; }
    /// The monitor mode's refresh rate, Hz (0: the mode does not say, e.g. Xvfb).
    int mode_hz() const noexcept { return mode_hz_; }
    /// Bits per channel of the window's framebuffer.
    int framebuffer_bits() const noexcept { return bits_; }
    const std::string& monitor_name() const noexcept { return monitor_name_; }
    /// How the flips are timed, in words (for the session's report).
    std::string timing_method() const;

    /// Test hook: the back buffer (drawn, before its flip) as an 8-bit RGB PNG.
    /// (The front buffer after a flip is not readable everywhere: Mesa's GLX
    /// on Xvfb gives black.)
    void capture_back(const std::filesystem::path& png) const;
    /// Makes sure the display server has executed every request so far (a
    /// round trip), e.g. before reading its screen from elsewhere.
    void sync_with_server() const;

protected:
    std::unique_ptr<Prepared> prepare(const Screen& screen) override;
    void draw(const Prepared& screen, double t_s) override;
    void finish() override;
    double flip() override;
    void stall(int frames) override;
    void wait_events(double until_s) override;
    bool has_person() const override { return true; }

private:
    explicit ScreenPresenter(const ScreenOptions& options);
    void measure_refresh();
    void poll_gamepads();
    static void on_key(GLFWwindow* window, int key, int scancode, int action, int mods);

    struct Gl;
    ScreenOptions options_;
    std::unique_ptr<gl::WindowContext> window_;
    std::unique_ptr<Gl> gl_;
    int width_ = 0, height_ = 0, bits_ = 8, mode_hz_ = 0;
    std::string monitor_name_;
    RefreshEstimate refresh_;
    double soft_origin_s_ = -1.0;  ///< software vsync: the time of refresh 0
    std::array<GamepadButtons, 16> pads_{};
};

}  // namespace atonlab::present
