#pragma once
// What the keys of `atonlab view` do to the scene (docs/view.md): the camera,
// the scene's clock, the adaptation level, the glare model and the tone
// mapper. Plain state with no GL or GLFW, so that a scripted key (--keys)
// and a real key press go through the same code.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "atonlab/stimuli/scene.h"

namespace atonlab::runner {

enum class ViewKey {
    forward,        ///< W: move along the heading
    back,           ///< S
    left,           ///< A: sideways
    right,          ///< D
    down,           ///< Q
    up,             ///< E
    yaw_left,       ///< ←
    yaw_right,      ///< →
    pitch_up,       ///< ↑
    pitch_down,     ///< ↓
    pause,          ///< space: pause / play the scene's clock
    step_forward,   ///< . : +0.1 s of scene time
    step_back,      ///< , : -0.1 s
    reset_time,     ///< 0: scene time 0
    adapt_up,       ///< + or =: adaptation × 10^0.25
    adapt_down,     ///< -: adaptation ÷ 10^0.25
    adapt_mode,     ///< v: fixed / dynamic adaptation
    glare_toggle,   ///< g: glare on / off
    glare_cycle,    ///< m: next glare model
    tonemap_cycle,  ///< t: next tone mapper
    blueshift,      ///< b: blueshift on / off
    reset_camera,   ///< home (or c): the scene's own camera
    screenshot,     ///< p: write the displayed frame to a PNG
    help,           ///< h: print the keys
    quit,           ///< escape
};

/// The key a --keys name stands for: "w", "a", "s", "d", "q", "e", "left",
/// "right", "up", "down", "space", "period", "comma", "0", "plus", "minus", "v",
/// "g", "m", "t", "b", "home", "p", "h", "escape".
std::optional<ViewKey> view_key_from_name(std::string_view name);
/// Keys held down move the camera continuously (the others act once per press).
bool is_held_key(ViewKey key);

/// The keys and what they do, for the terminal.
extern const char* const kViewHelp;

class ViewControls {
public:
    /// `initial`: the scene as loaded (validated).
    explicit ViewControls(stimuli::Scene initial, double time_s = 0.0, bool playing = true);

    /// A key pressed once. `adapted_cd_m2`: the pipeline's current adapted
    /// luminance (used when leaving dynamic adaptation). Returns what changed,
    /// for the terminal ("" when nothing did).
    std::string press(ViewKey key, double adapted_cd_m2);
    /// Held keys over dt_s seconds: 10 m/s and 20 °/s, times `speed` (shift 10×, ctrl 0.1×).
    void hold(std::span<const ViewKey> held, double dt_s, double speed);
    /// A mouse drag of (dx, dy) pixels: the view turns by that many pixels'
    /// angle, so the scene follows the pointer.
    void drag(double dx_px, double dy_px, double degrees_per_pixel);
    /// The scene's clock runs by dt_s while playing.
    void advance(double dt_s);

    /// The scene to draw now.
    const stimuli::Scene& scene() const { return scene_; }
    /// Undo the last press (the scene it made did not validate).
    void revert() { scene_ = previous_; }
    double time_s() const { return time_s_; }
    bool playing() const { return playing_; }
    bool quit_requested() const { return quit_; }
    bool screenshot_requested() { return std::exchange(screenshot_, false); }
    /// "glare wave-optics, tone empirical, adaptation 0.001 cd/m² fixed, t 3.20 s (playing)".
    std::string status() const;

private:
    stimuli::Scene initial_;
    stimuli::Scene scene_;
    stimuli::Scene previous_;
    stimuli::GlareModel last_glare_;
    double time_s_ = 0.0;
    bool playing_ = true;
    bool quit_ = false;
    bool screenshot_ = false;
};

}  // namespace atonlab::runner
