// The windowed backend (GLFW): a 4.5 core context in a real window, windowed and
// full-screen on monitor 0. Runs under Xvfb in CTest (GL.window.xvfb); skips
// where there is no display server.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "atonlab/stimuli/gl/window.h"
#include "../support/skip.h"

namespace atonlab::test {
namespace {

bool have_display() { return std::getenv("DISPLAY") != nullptr || std::getenv("WAYLAND_DISPLAY") != nullptr; }

TEST(GLWindow, WindowedContextClearsItsFramebuffer) {
    if (!have_display()) ATONLAB_SKIP_NO_GPU() << "no display server (DISPLAY unset); CTest runs this under xvfb-run";
    gl::WindowOptions opt;
    opt.width = 64;
    opt.height = 48;
    opt.visible = false;
    auto win = gl::create_window_context(opt);
    EXPECT_NO_THROW(gl::require_gl45());
    EXPECT_EQ(win->framebuffer_width(), 64);
    EXPECT_EQ(win->framebuffer_height(), 48);
    glClearColor(0.25f, 0.5f, 1.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    unsigned char px[4] = {};
    glReadPixels(10, 10, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
    EXPECT_NEAR(px[0], 64, 1);
    EXPECT_NEAR(px[1], 128, 1);
    EXPECT_EQ(px[2], 255);
    win->swap_buffers();
    win->poll_events();
    EXPECT_FALSE(win->should_close());
}

TEST(GLWindow, FullScreenOnMonitorZeroTakesItsNativeMode) {
    if (!have_display()) ATONLAB_SKIP_NO_GPU() << "no display server (DISPLAY unset); CTest runs this under xvfb-run";
    gl::WindowOptions opt;
    opt.fullscreen = true;
    opt.monitor = 0;
    auto win = gl::create_window_context(opt);
    // xvfb-run's screen is 1280x720 (tests/CMakeLists.txt).
    EXPECT_EQ(win->framebuffer_width(), 1280);
    EXPECT_EQ(win->framebuffer_height(), 720);
}

TEST(GLWindow, AMissingMonitorIsAClearError) {
    if (!have_display()) ATONLAB_SKIP_NO_GPU() << "no display server (DISPLAY unset)";
    gl::WindowOptions opt;
    opt.fullscreen = true;
    opt.monitor = 7;
    try {
        gl::create_window_context(opt);
        FAIL() << "monitor 7 exists?";
    } catch (const gl::ContextUnavailable& e) {
        EXPECT_NE(std::string(e.what()).find("monitor 7"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace atonlab::test
