#include "view_controls.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>

#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/display/tonemap.h"

namespace atonlab::runner {
namespace {

constexpr double kMoveMPerS = 10.0;  // ~20 knots: a ship's pace
constexpr double kTurnDegPerS = 20.0;
constexpr double kTimeStepS = 0.1;                    // , and .
const double kAdaptationStep = std::pow(10.0, 0.25);  // + and -

constexpr std::pair<std::string_view, ViewKey> kNames[] = {
    {"w", ViewKey::forward},       {"s", ViewKey::back},
    {"a", ViewKey::left},          {"d", ViewKey::right},
    {"q", ViewKey::down},          {"e", ViewKey::up},
    {"left", ViewKey::yaw_left},   {"right", ViewKey::yaw_right},
    {"up", ViewKey::pitch_up},     {"down", ViewKey::pitch_down},
    {"space", ViewKey::pause},     {"period", ViewKey::step_forward},
    {"comma", ViewKey::step_back}, {"0", ViewKey::reset_time},
    {"plus", ViewKey::adapt_up},   {"minus", ViewKey::adapt_down},
    {"v", ViewKey::adapt_mode},    {"g", ViewKey::glare_toggle},
    {"m", ViewKey::glare_cycle},   {"t", ViewKey::tonemap_cycle},
    {"b", ViewKey::blueshift},     {"home", ViewKey::reset_camera},
    {"c", ViewKey::reset_camera},  {"p", ViewKey::screenshot},
    {"h", ViewKey::help},          {"escape", ViewKey::quit},
};

double wrap_degrees(double deg) {
    deg = std::fmod(deg, 360.0);
    return deg < 0.0 ? deg + 360.0 : deg;
}

}  // namespace

const char* const kViewHelp =
    "keys: W/S forward/back, A/D sideways, Q/E down/up (shift 10x, ctrl 0.1x); arrows or mouse drag turn\n"
    "      space pause/play, ./, step the scene's time +-0.1 s, 0 time 0\n"
    "      +/- adaptation x/÷ 10^0.25, v fixed/dynamic adaptation\n"
    "      g glare on/off, m next glare model, t next tone mapper, b blueshift on/off\n"
    "      home (or c) the scene's camera, p screenshot, h this help, escape quit\n";

std::optional<ViewKey> view_key_from_name(std::string_view name) {
    for (const auto& [n, k] : kNames)
        if (n == name) return k;
    return std::nullopt;
}

bool is_held_key(ViewKey key) {
    return key <= ViewKey::pitch_down;
}

ViewControls::ViewControls(stimuli::Scene initial, double time_s, bool playing)
    : initial_(std::move(initial)), scene_(initial_), previous_(initial_), time_s_(time_s), playing_(playing) {
    last_glare_ =
        initial_.glare.model == stimuli::GlareModel::none ? stimuli::GlareModel::wave_optics : initial_.glare.model;
}

std::string ViewControls::press(ViewKey key, double adapted_cd_m2) {
    previous_ = scene_;
    stimuli::Scene& s = scene_;
    auto set_fixed = [&](double cd_m2) {
        s.output.adaptation.mode = stimuli::AdaptationMode::fixed;
        s.adaptation_cd_m2 = cd_m2;  // the tone mapper's level; the pupil, hence the glare PSF, follows it
    };
    switch (key) {
        case ViewKey::pause:
            playing_ = !playing_;
            return fmt::format("time {} at {:.2f} s", playing_ ? "plays" : "paused", time_s_);
        case ViewKey::step_forward:
        case ViewKey::step_back:
            time_s_ = std::max(0.0, time_s_ + (key == ViewKey::step_forward ? kTimeStepS : -kTimeStepS));
            return fmt::format("time {:.2f} s", time_s_);
        case ViewKey::reset_time:
            time_s_ = 0.0;
            return "time 0 s";
        case ViewKey::adapt_up:
        case ViewKey::adapt_down: {
            const bool dynamic = s.output.adaptation.mode == stimuli::AdaptationMode::dynamic;
            const double from = dynamic ? adapted_cd_m2 : s.adaptation_cd_m2;
            set_fixed(key == ViewKey::adapt_up ? from * kAdaptationStep : from / kAdaptationStep);
            return fmt::format("adaptation fixed at {:.4g} cd/m²", s.adaptation_cd_m2);
        }
        case ViewKey::adapt_mode:
            if (s.output.adaptation.mode == stimuli::AdaptationMode::dynamic) {
                set_fixed(adapted_cd_m2);
                return fmt::format("adaptation fixed at {:.4g} cd/m²", adapted_cd_m2);
            }
            s.output.adaptation.mode = stimuli::AdaptationMode::dynamic;
            return "adaptation dynamic (log-average, K2012 eq 4.15-4.17)";
        case ViewKey::glare_toggle:
            if (s.glare.model == stimuli::GlareModel::none) {
                s.glare.model = last_glare_;
            } else {
                last_glare_ = s.glare.model;
                s.glare.model = stimuli::GlareModel::none;
            }
            return fmt::format("glare {}", stimuli::glare_model_name(s.glare.model));
        case ViewKey::glare_cycle: {
            // Every model that draws glare and can with these settings (the aperture needs its image).
            std::vector<stimuli::GlareModel> models;
            for (const stimuli::GlareModelType* m : stimuli::glare_models())
                if (m->available(s.glare)) models.push_back(m->id());
            const auto it = std::find(models.begin(), models.end(), s.glare.model);
            s.glare.model = it == models.end() || it + 1 == models.end() ? models.front() : *(it + 1);
            last_glare_ = s.glare.model;
            return fmt::format("glare {}", stimuli::glare_model_name(s.glare.model));
        }
        case ViewKey::tonemap_cycle: {
            const std::vector<std::string> names = display::tone_operator_names();
            const std::string current(display::tone_operator_name(s.output.tonemap.tone_operator));
            auto it = std::find(names.begin(), names.end(), current);
            const std::string& next = it == names.end() || it + 1 == names.end() ? names.front() : *(it + 1);
            s.output.tonemap.tone_operator = *display::tone_operator_from_name(next);
            return "tone mapper " + next;
        }
        case ViewKey::blueshift:
            s.output.tonemap.blueshift = !s.output.tonemap.blueshift;
            return fmt::format("blueshift {}", s.output.tonemap.blueshift ? "on" : "off");
        case ViewKey::reset_camera:
            s.camera = initial_.camera;
            return "camera as in the scene file";
        case ViewKey::screenshot:
            screenshot_ = true;
            return "";
        case ViewKey::help:
            return kViewHelp;
        case ViewKey::quit:
            quit_ = true;
            return "";
        default:
            return "";  // held keys act in hold()
    }
}

void ViewControls::hold(std::span<const ViewKey> held, double dt_s, double speed) {
    stimuli::Camera& c = scene_.camera;
    const double yaw = c.yaw_deg * std::numbers::pi / 180.0;
    // Heading clockwise from north (-z); x is east: forward (sin, 0, -cos), right (cos, 0, sin).
    const glm::dvec3 forward(std::sin(yaw), 0.0, -std::cos(yaw)), right(std::cos(yaw), 0.0, std::sin(yaw));
    const double step = kMoveMPerS * speed * dt_s, turn = kTurnDegPerS * speed * dt_s;
    for (const ViewKey k : held) {
        switch (k) {
            case ViewKey::forward:
                c.position_m += step * forward;
                break;
            case ViewKey::back:
                c.position_m -= step * forward;
                break;
            case ViewKey::right:
                c.position_m += step * right;
                break;
            case ViewKey::left:
                c.position_m -= step * right;
                break;
            case ViewKey::up:
                c.position_m.y += step;
                break;
            case ViewKey::down:
                c.position_m.y -= step;
                break;
            case ViewKey::yaw_left:
                c.yaw_deg = wrap_degrees(c.yaw_deg - turn);
                break;
            case ViewKey::yaw_right:
                c.yaw_deg = wrap_degrees(c.yaw_deg + turn);
                break;
            case ViewKey::pitch_up:
                c.pitch_deg = std::min(89.0, c.pitch_deg + turn);
                break;
            case ViewKey::pitch_down:
                c.pitch_deg = std::max(-89.0, c.pitch_deg - turn);
                break;
            default:
                break;
        }
    }
}

void ViewControls::drag(double dx_px, double dy_px, double degrees_per_pixel) {
    stimuli::Camera& c = scene_.camera;
    c.yaw_deg = wrap_degrees(c.yaw_deg - dx_px * degrees_per_pixel);
    c.pitch_deg = std::clamp(c.pitch_deg + dy_px * degrees_per_pixel, -89.0, 89.0);
}

void ViewControls::advance(double dt_s) {
    if (playing_) time_s_ += dt_s;
}

std::string ViewControls::status() const {
    const stimuli::Scene& s = scene_;
    const bool dynamic = s.output.adaptation.mode == stimuli::AdaptationMode::dynamic;
    return fmt::format(
        "glare {}, tone {}, adaptation {}, t {:.2f} s{}, camera [{:.1f}, {:.1f}, {:.1f}] m yaw {:.1f}° pitch {:.1f}°",
        stimuli::glare_model_name(s.glare.model), display::tone_operator_name(s.output.tonemap.tone_operator),
        dynamic ? std::string("dynamic") : fmt::format("{:.4g} cd/m²", s.adaptation_cd_m2), time_s_,
        playing_ ? "" : " (paused)", s.camera.position_m.x, s.camera.position_m.y, s.camera.position_m.z,
        s.camera.yaw_deg, s.camera.pitch_deg);
}

}  // namespace atonlab::runner
