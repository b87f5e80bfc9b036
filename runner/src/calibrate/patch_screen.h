#pragma once
// The screen `atonlab calibrate` shows its patches on: a full-screen GLFW
// window on the chosen monitor (vsync, cursor hidden), or with headless an
// off-screen EGL framebuffer. Every patch is read back from the framebuffer
// and must hold exactly the code values sent (no sRGB encoding, no dither, no
// 6-bit panel format in the way). The window also takes typed readings
// (docs/calibration.md).
#include <glm/vec3.hpp>
#include <memory>
#include <string>

#include "calibration_patches.h"

namespace atonlab::runner {

struct PatchScreenOptions {
    bool headless = false;
    int monitor = 0;                ///< full-screen on this monitor (GLFW's order)
    double window_percent = 100.0;  ///< the patch's share of the screen's area, centred; the rest black
    int headless_width = 256;       ///< the off-screen framebuffer's size, pixels
    int headless_height = 256;
};

class PatchScreen {
public:
    /// Opens the window or the off-screen framebuffer. Throws
    /// gl::ContextUnavailable (no display, no such monitor, no GL 4.5).
    explicit PatchScreen(const PatchScreenOptions& options);
    ~PatchScreen();
    PatchScreen(const PatchScreen&) = delete;
    PatchScreen& operator=(const PatchScreen&) = delete;

    /// Draws the patch and presents it; throws gl::ContextUnavailable when the
    /// framebuffer does not hold the codes sent.
    void show(const Patch& patch);
    /// Keeps the window alive while waiting: redraws the current patch (one
    /// vsync'd frame) and handles events. Headless: does nothing.
    void pump();
    /// The window was closed or Escape pressed in it.
    bool quit_requested() const;
    /// What was typed into the window since the last call: characters, '\n'
    /// for Enter, '\b' for Backspace.
    std::string take_typed();

    /// What an instrument would see: the mean code values of a centred square
    /// of the presented frame, read back with glReadPixels (the window's back
    /// buffer with the patch drawn again, just before it is swapped; or the
    /// off-screen framebuffer).
    struct Aperture {
        glm::dvec3 mean_codes{0.0};  ///< R, G, B, 0..max_code
        int max_code = 255;
        int width_px = 0, height_px = 0;
    };
    Aperture read_shown(int side_px = 32);
    /// Progress for the operator on the window (its title; the patch itself stays uniform).
    void set_progress(const std::string& text);

    int width() const;
    int height() const;
    /// "full-screen 1920 x 1080 on monitor 0 (llvmpipe ...)" or "off-screen 256 x 256 (...)".
    std::string description() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace atonlab::runner
