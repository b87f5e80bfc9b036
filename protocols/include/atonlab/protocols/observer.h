#pragma once
// Observers: whoever answers a trial (docs/architecture.md "One trial, from protocol to store"). A person at the
// runner's keyboard is one; here are the two that run headless:
//
//  - ModelObserver: a deterministic brightness model with Gaussian decision
//    noise and lapses, so that protocols and analysis can be tested end to end
//    against a known true PSE or threshold (true_pse, true_threshold);
//  - ScriptedObserver: answers read from a file, one per line.
//
// Images are displayed luminance (cd/m²) in visual angle: what reaches the
// observer's eye, not scene-referred values, so a model observer judges what
// the tone mapper and display actually produced.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <glm/vec2.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/protocols/procedure.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/rng.h"

namespace atonlab::protocols {

/// A displayed-luminance image. Pixel (x, y) covers [x, x+1) x [y, y+1) in
/// pixel coordinates, row-major (index y * width + x). With focal_px > 0 the
/// pixels lie on a flat screen seen from the eye at focal_px pixel pitches
/// (the viewing distance), principal_px straight ahead: each pixel subtends its
/// own exact solid angle (display/solid_angle.h pixel_solid_angle_sr; about
/// cos³θ of the centre's at θ off-axis) and a window of radius r degrees
/// holds the pixels whose centres are within r degrees of visual angle of the
/// light's direction. With focal_px = 0 (an image without that geometry) every
/// pixel subtends deg_per_px x deg_per_px degrees (square pixels,
/// small-angle: solid angle (deg_per_px · π/180)² sr) and the window is a
/// circle of r / deg_per_px pixels.
struct DisplayedImage {
    int width = 0;
    int height = 0;
    double deg_per_px = 0.0;  ///< at the principal point (the screen's centre)
    /// The viewing distance in pixel pitches (DisplayGeometry::focal_px(),
    /// the camera's focal length for a veridical camera); 0: small-angle pixels.
    double focal_px = 0.0;
    /// Where the line of sight meets the screen at right angles, in this
    /// image's pixel coordinates (row 0 at the top; may lie outside the image).
    glm::dvec2 principal_px{0.0};
    std::vector<float> luminance_cd_m2;  ///< width * height values, cd/m², >= 0
    /// What the same pixels show with the judged light off (cd/m²): empty, or
    /// width * height values. When given, a light's brightness and increment
    /// are what it adds to this, pixel by pixel; when empty, the light's
    /// brightness is the whole window's and its increment is over the annulus
    /// mean (see window_light_lux, increment_illuminance_lux).
    std::vector<float> background_cd_m2;
    /// The display codes the same pixels were given: empty, or width * height * 3
    /// values (R, G, B; row 0 at the top; 0 beyond the screen) of code_bits bits.
    /// luminance_cd_m2 is these decoded through the display model. The model
    /// observer judges the luminance; a custom observer (docs/python.md) gets both.
    std::vector<std::uint16_t> codes_rgb;
    int code_bits = 0;

    float at(int x, int y) const { return luminance_cd_m2[static_cast<std::size_t>(y) * width + x]; }
    bool has_background() const noexcept { return !background_cd_m2.empty(); }
    /// Solid angle of pixel (x, y), sr: exact with focal_px > 0, else (deg_per_px · π/180)².
    double pixel_sr(int x, int y) const;
};

/// Σ L · Ω_px over the pixels whose centre lies within radius_deg of centre_px
/// (DisplayedImage: the angle and each pixel's own Ω_px):
/// the illuminance (lux) that window of the image puts at the eye.
double window_illuminance_lux(const DisplayedImage& image, glm::dvec2 centre_px, double radius_deg);

/// The illuminance (lux) the light adds within radius_deg of centre_px:
/// Σ (L − L_off) · Ω over the window, L_off the background image (what the
/// screen shows there with the light off), or 0 when the image has none (then
/// equal to window_illuminance_lux). Clamped at 0 (a light cannot take light
/// away; dithering can make the sum a hair negative).
double window_light_lux(const DisplayedImage& image, glm::dvec2 centre_px, double radius_deg);

/// Brightness of a light: window_light_lux^exponent, a power law
/// (Stevens 1961, "To honor Fechner and repeal his law", Science 133:80-86,
/// Table 1: exponent 0.33 for a 5° target in the dark-adapted eye, 0.5 for a
/// point source). Arbitrary units; only ratios matter.
double brightness(const DisplayedImage& image, glm::dvec2 centre_px, double radius_deg, double exponent);

/// The light's increment over its surround: Σ (L − L_bg) · Ω over the window
/// (lux; may be negative). L_bg is the background image pixel by pixel when the
/// image has one (exact: a glare halo reaching the annulus is not mistaken for
/// surround), else the mean luminance of the annulus radius_deg … 2·radius_deg.
/// What yes/no detection is decided on.
double increment_illuminance_lux(const DisplayedImage& image, glm::dvec2 centre_px, double radius_deg);

/// One light the observer judges: an image and the light's position in it (pixels).
struct View {
    const DisplayedImage* image = nullptr;  ///< not owned; valid during answer()
    glm::dvec2 light_px{0.0};
};

/// What one trial (or, for adjust, one step of it) showed.
struct Shown {
    Task task = Task::TwoAfc;
    /// 2AFC and adjust: [0] left / first interval, [1] right / second. Yes-no: [0].
    std::vector<View> views;
    std::optional<std::size_t> adjusted_view;  ///< adjust: the view the actions change
};

struct Answer {
    Response response = Response::No;
    double response_time_s = 0.0;  ///< stimulus offset (or onset: the runner says) to answer, s, >= 0
};

class Observer {
public:
    virtual ~Observer() = default;
    /// The answer to what was shown. 2AFC: Left / Right, the view judged
    /// brighter; yes-no: Yes / No; adjust: one adjustment action.
    virtual Answer answer(const Shown& shown) = 0;

protected:
    Observer() = default;
    Observer(const Observer&) = default;
    Observer& operator=(const Observer&) = default;
    Observer(Observer&&) = default;
    Observer& operator=(Observer&&) = default;
};

struct ModelObserverParams {
    double window_radius_deg = 0.5;  ///< r: the window a light's brightness is summed over, degrees
    double exponent = 0.33;          ///< p: brightness = E^p (Stevens 1961; see brightness())
    /// σ: sd of the Gaussian noise on each decision, log10 brightness units
    /// (2AFC: on log10 B_first − log10 B_second; yes-no: on log10 B − log10 B_threshold).
    double noise_sd_log10 = 0.03;
    double lapse_rate = 0.0;  ///< λ: the fraction of answers given at random, 0 <= λ < 1
    /// Yes-no: the increment illuminance seen half the time (lapses aside), lux.
    /// Default 2e-7 lx, the night-time threshold illuminance of IALA
    /// Recommendation E-200-2 (luminous range).
    double detection_threshold_lux = 2e-7;
    double rt_base_s = 0.45;  ///< response time of an easy decision, s
    double rt_hard_s = 0.6;   ///< added at the PSE, falling as exp(−|Δ|/σ)
    /// Adjust: beyond this |log10 brightness difference| the observer takes coarse steps.
    double adjust_coarse_log10 = 0.05;
    /// Adjust: the observer confirms once its fine steps have changed direction
    /// this often (it has bracketed the match), ...
    int adjust_reversals = 3;
    /// ... or when the difference it sees is within this (0: only exactly equal).
    double adjust_match_log10 = 0.0;
    int adjust_max_actions = 400;  ///< ... or after this many actions in the trial
};

/// The deterministic brightness model with noise and lapses. Seeded: the same
/// (params, seed, sequence of Shown) gives the same answers on every platform
/// (rng.h; the Gaussian is the inverse normal CDF of one uniform draw).
///
/// 2AFC: D = log10 B(view 0) − log10 B(view 1) + σ·N(0,1); Left if D > 0, Right
/// if D < 0 (a coin at exactly 0). With probability λ the answer is a coin.
/// So P(view 0 chosen) = λ/2 + (1 − λ)·Φ(Δ/σ), Δ the noiseless difference.
/// Yes-no: Yes if p·log10(E_inc / E_threshold) + σ·N > 0 (E_inc <= 0: No), or a coin with probability λ.
/// Adjust: D = log10 B(other) − log10 B(adjusted) + σ·N; D > coarse: CoarseUp;
/// D < −coarse: CoarseDown; else FineUp (D > 0) / FineDown (D < 0). Confirm
/// when the fine steps have reversed direction adjust_reversals times, when
/// |D| <= adjust_match_log10, or after adjust_max_actions actions. No lapses in adjust.
class ModelObserver : public Observer {
public:
    /// Throws std::invalid_argument for out-of-range parameters.
    ModelObserver(ModelObserverParams params, std::uint64_t seed);

    Answer answer(const Shown& shown) override;
    const ModelObserverParams& params() const noexcept { return params_; }

    /// Noiseless log10 brightness of a view.
    double log10_brightness(const View& v) const;

    /// The noiseless decision variable of a 2AFC trial: log10 B(view 0) − log10 B(view 1).
    double decision_2afc(const Shown& shown) const;
    /// The noiseless decision variable of a yes-no trial: p·log10(E_inc / E_θ),
    /// −∞ when the light adds no increment.
    double decision_yes_no(const Shown& shown) const;
    /// The answer to a 2AFC (or yes-no) trial whose decision variable is
    /// `delta`: what answer() gives for a Shown with that decision variable,
    /// draw for draw (simulated_observer.h answers tabulated trials with it).
    Answer answer_2afc_delta(double delta);
    Answer answer_yes_no_delta(double delta);

private:
    double gaussian();
    Answer answer_2afc(const Shown& shown);
    Answer answer_yes_no(const Shown& shown);
    Answer answer_adjust(const Shown& shown);

    ModelObserverParams params_;
    Rng rng_;
    // Adjust: the current trial's action count, last fine step's sign and fine reversals.
    int actions_ = 0;
    int last_fine_sign_ = 0;
    int fine_reversals_ = 0;
};

/// The model observer's response time (s) for a decision of delta_over_sigma:
/// rt_base_s + rt_hard_s · exp(−|Δ/σ|) (ModelObserverParams).
double model_response_time_s(const ModelObserverParams& params, double delta_over_sigma);
/// The standard normal CDF Φ(z) = erfc(−z/√2)/2: 0 at −∞, 1 at +∞.
double standard_normal_cdf(double z);
/// The standard normal quantile Φ⁻¹(u) = √2 erf⁻¹(2u − 1) of u in (0, 1), by
/// Boost.Math: the same on every platform (the model observer's noise draws).
double standard_normal_quantile(double u);

/// P(yes) of the model for a view (lapses included).
double model_p_yes(const ModelObserverParams& params, const View& view);
/// P(view 0 chosen) of the model in 2AFC (lapses included).
double model_p_first(const ModelObserverParams& params, const View& first, const View& second);

/// The observer's true point of subjective equality: the reference level at
/// which brightness(reference) = brightness(test), where the model chooses each
/// half the time. reference_at(level) renders the reference; the level is
/// searched in [lo, hi] (brightness must cross between them; TOMS 748 root
/// finding, Boost.Math). Throws std::invalid_argument when it does not cross.
double true_pse(const std::function<DisplayedImage(double level)>& reference_at, glm::dvec2 reference_px,
                const DisplayedImage& test, glm::dvec2 test_px, double lo, double hi,
                const ModelObserverParams& params);

/// The level at which the model chooses the reference with probability
/// p_reference (lapses included), e.g. 0.75 for a weighted staircase. 0.5 gives true_pse.
double true_matching_level(const std::function<DisplayedImage(double level)>& reference_at, glm::dvec2 reference_px,
                           const DisplayedImage& test, glm::dvec2 test_px, double p_reference, double lo, double hi,
                           const ModelObserverParams& params);

/// The level at which the model says Yes with probability p_yes (lapses
/// included): the detection threshold a yes-no procedure aiming at p_yes
/// should find. image_at(level) renders the stimulus.
double true_threshold(const std::function<DisplayedImage(double level)>& image_at, glm::dvec2 light_px, double p_yes,
                      double lo, double hi, const ModelObserverParams& params);

/// Answers from a file, one per line: a response word and, optionally, the
/// response time in seconds ("left 0.62"). Words: left, right (also first,
/// second), yes, no, coarse_up, coarse_down, fine_up, fine_down, confirm
/// (hyphens may replace underscores). '#' starts a comment; blank lines are
/// skipped. Every error is an InputError naming the file and the line.
class ScriptedObserver : public Observer {
public:
    static ScriptedObserver load(const std::filesystem::path& file);
    static ScriptedObserver parse(std::string_view text, std::string_view file_name);

    /// The next line's answer. Throws InputError when the answers are used
    /// up, or when the line's answer does not fit the task (naming the line).
    Answer answer(const Shown& shown) override;
    std::size_t size() const noexcept { return lines_.size(); }
    std::size_t remaining() const noexcept { return lines_.size() - next_; }

private:
    struct Line {
        Answer answer;
        int line = 0;
        std::string word;
    };
    ScriptedObserver(std::string file, std::vector<Line> lines) : file_(std::move(file)), lines_(std::move(lines)) {}

    std::string file_;
    std::vector<Line> lines_;
    std::size_t next_ = 0;
};

}  // namespace atonlab::protocols
