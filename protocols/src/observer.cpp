// Brightness of displayed images and the model observer (observer.h).
#include "atonlab/protocols/observer.h"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/special_functions/erf.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "atonlab/display/solid_angle.h"

namespace atonlab::protocols {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct WindowSums {
    double window_lux = 0.0;     ///< Σ L Ω inside the window
    double background_lux = 0.0; ///< Σ L_off Ω inside the window (0 without a background image)
    double window_sr = 0.0;      ///< Σ Ω inside the window
    double annulus_cd_m2 = 0.0;  ///< Σ L over the annulus r < d <= 2r
    std::size_t annulus_px = 0;
};

/// The direction (unit vector) from the eye through image point p (pixels).
glm::dvec3 direction(const DisplayedImage& image, glm::dvec2 p) {
    return glm::normalize(glm::dvec3(p - image.principal_px, image.focal_px));
}

/// The angle (radians) between unit vectors a and b: 2 asin(|a − b| / 2), exact for small angles too.
double angle_between(glm::dvec3 a, glm::dvec3 b) {
    return 2.0 * std::asin(std::min(1.0, 0.5 * glm::length(a - b)));
}

void validate_image(const DisplayedImage& image) {
    if (image.width <= 0 || image.height <= 0 || !(image.deg_per_px > 0.0) ||
        image.luminance_cd_m2.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
        throw std::invalid_argument(
            fmt::format("a displayed image needs width, height > 0, deg_per_px > 0 and "
                        "width*height values; got {}x{}, {} deg/px, {} values",
                        image.width, image.height, image.deg_per_px, image.luminance_cd_m2.size()));
    if (image.has_background() && image.background_cd_m2.size() != image.luminance_cd_m2.size())
        throw std::invalid_argument(fmt::format("a displayed image's background needs {} values, not {}",
                                                image.luminance_cd_m2.size(), image.background_cd_m2.size()));
    if (!(image.focal_px >= 0.0) || !std::isfinite(image.focal_px) || !std::isfinite(image.principal_px.x) ||
        !std::isfinite(image.principal_px.y))
        throw std::invalid_argument(
            fmt::format("a displayed image's focal length must be >= 0 px, not {}", image.focal_px));
}

WindowSums sums(const DisplayedImage& image, glm::dvec2 centre, double radius_deg, bool annulus) {
    validate_image(image);
    if (!(radius_deg > 0.0) || !std::isfinite(radius_deg))
        throw std::invalid_argument(fmt::format("the window radius must be > 0 degrees, not {}", radius_deg));
    const bool exact = image.focal_px > 0.0;
    const double r = radius_deg / image.deg_per_px;  // pixels at the principal point
    const double outer_deg = annulus ? 2.0 * radius_deg : radius_deg;
    // Exact geometry: a pixel θ off-axis subtends cos²θ (radially) of the
    // centre's angle, so the window reaches 1/cos² further in pixels; search
    // that far (θ the light's angle plus the window's, capped below 90°).
    double reach = annulus ? 2.0 * r : r;
    const glm::dvec3 centre_dir = exact ? direction(image, centre) : glm::dvec3(0.0);
    if (exact) {
        const double theta =
            std::min(angle_between(centre_dir, glm::dvec3(0, 0, 1)) + outer_deg * std::numbers::pi / 180.0,
                     std::numbers::pi / 2.0 * 0.99);
        reach /= std::cos(theta) * std::cos(theta);
    }
    const int x0 = std::max(0, static_cast<int>(std::floor(centre.x - reach)));
    const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(centre.x + reach)));
    const int y0 = std::max(0, static_cast<int>(std::floor(centre.y - reach)));
    const int y1 = std::min(image.height - 1, static_cast<int>(std::ceil(centre.y + reach)));
    const double radius_rad = radius_deg * std::numbers::pi / 180.0;
    WindowSums s;
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const glm::dvec2 p{x + 0.5, y + 0.5};
            // The pixel's distance from the light, in units of the window's radius.
            double rel = 0.0;
            if (exact) {
                rel = angle_between(direction(image, p), centre_dir) / radius_rad;
            } else {
                rel = glm::length(p - centre) / r;
            }
            const double l = image.at(x, y);
            if (rel <= 1.0) {
                const double omega = image.pixel_sr(x, y);
                s.window_lux += l * omega;
                s.window_sr += omega;
                if (image.has_background())
                    s.background_lux +=
                        image.background_cd_m2[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                                               static_cast<std::size_t>(x)] *
                        omega;
            } else if (annulus && rel <= 2.0) {
                s.annulus_cd_m2 += l;
                ++s.annulus_px;
            }
        }
    return s;
}

double log10_or_minus_inf(double v) {
    return v > 0.0 ? std::log10(v) : -kInf;
}

/// a − b for log brightnesses that may be −inf (both −inf: 0).
double log_difference(double a, double b) {
    if (a == b) return 0.0;
    return a - b;
}


/// z such that λ/2 + (1−λ)Φ(z) = p.
double z_for(double p, double lapse) {
    const double q = (p - lapse / 2.0) / (1.0 - lapse);
    if (!(q > 0.0 && q < 1.0))
        throw std::invalid_argument(
            fmt::format("the probability {} is out of reach with a lapse rate of {}", p, lapse));
    if (q == 0.5) return 0.0;
    return standard_normal_quantile(q);
}

/// The root of f in [lo, hi], f increasing or decreasing (TOMS 748).
double root(const std::function<double(double)>& f, double lo, double hi, std::string_view what) {
    if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi))
        throw std::invalid_argument(fmt::format("{}: the search interval [{}, {}] is empty", what, lo, hi));
    const double flo = f(lo);
    const double fhi = f(hi);
    if (flo == 0.0) return lo;
    if (fhi == 0.0) return hi;
    if (!((flo < 0.0) != (fhi < 0.0)) || std::isnan(flo) || std::isnan(fhi))
        throw std::invalid_argument(fmt::format(
            "{}: the brightness does not cross between levels {} and {} (f = {} and {})", what, lo, hi, flo, fhi));
    std::uintmax_t max_iter = 200;
    const auto [a, b] =
        boost::math::tools::toms748_solve(f, lo, hi, flo, fhi, boost::math::tools::eps_tolerance<double>(48), max_iter);
    return 0.5 * (a + b);
}

void check(bool ok, std::string_view parameter, double value, std::string_view rule) {
    if (!ok)
        throw std::invalid_argument(fmt::format("ModelObserverParams::{} must be {}, not {}", parameter, rule, value));
}

void validate(const ModelObserverParams& p) {
    check(std::isfinite(p.window_radius_deg) && p.window_radius_deg > 0, "window_radius_deg", p.window_radius_deg,
          "> 0");
    check(std::isfinite(p.exponent) && p.exponent > 0, "exponent", p.exponent, "> 0");
    check(std::isfinite(p.noise_sd_log10) && p.noise_sd_log10 >= 0, "noise_sd_log10", p.noise_sd_log10, ">= 0");
    check(p.lapse_rate >= 0 && p.lapse_rate < 1, "lapse_rate", p.lapse_rate, "in [0, 1)");
    check(std::isfinite(p.detection_threshold_lux) && p.detection_threshold_lux > 0, "detection_threshold_lux",
          p.detection_threshold_lux, "> 0");
    check(std::isfinite(p.rt_base_s) && p.rt_base_s >= 0, "rt_base_s", p.rt_base_s, ">= 0");
    check(std::isfinite(p.rt_hard_s) && p.rt_hard_s >= 0, "rt_hard_s", p.rt_hard_s, ">= 0");
    check(std::isfinite(p.adjust_match_log10) && p.adjust_match_log10 >= 0, "adjust_match_log10", p.adjust_match_log10,
          ">= 0");
    check(std::isfinite(p.adjust_coarse_log10) && p.adjust_coarse_log10 >= p.adjust_match_log10, "adjust_coarse_log10",
          p.adjust_coarse_log10, ">= adjust_match_log10");
    check(p.adjust_reversals >= 1, "adjust_reversals", p.adjust_reversals, ">= 1");
    check(p.adjust_max_actions >= 1, "adjust_max_actions", p.adjust_max_actions, ">= 1");
}

const View& view_at(const Shown& shown, std::size_t i) {
    if (i >= shown.views.size() || shown.views[i].image == nullptr)
        throw std::invalid_argument(fmt::format("a {} trial needs view {} with an image; got {} view(s)",
                                                to_string(shown.task), i, shown.views.size()));
    return shown.views[i];
}

}  // namespace

double DisplayedImage::pixel_sr(int x, int y) const {
    if (focal_px > 0.0) return display::pixel_solid_angle_sr(x - principal_px.x, y - principal_px.y, focal_px);
    const double a = deg_per_px * std::numbers::pi / 180.0;
    return a * a;
}

double window_illuminance_lux(const DisplayedImage& image, glm::dvec2 centre_px, double radius_deg) {
    return sums(image, centre_px, radius_deg, false).window_lux;
}

double window_light_lux(const DisplayedImage& image, glm::dvec2 centre_px, double radius_deg) {
    const WindowSums s = sums(image, centre_px, radius_deg, false);
    return std::max(0.0, s.window_lux - s.background_lux);
}

double brightness(const DisplayedImage& image, glm::dvec2 centre_px, double radius_deg, double exponent) {
    return std::pow(window_light_lux(image, centre_px, radius_deg), exponent);
}

double increment_illuminance_lux(const DisplayedImage& image, glm::dvec2 centre_px, double radius_deg) {
    if (image.has_background()) {
        const WindowSums s = sums(image, centre_px, radius_deg, false);
        return s.window_lux - s.background_lux;
    }
    const WindowSums s = sums(image, centre_px, radius_deg, true);
    const double background = s.annulus_px > 0 ? s.annulus_cd_m2 / static_cast<double>(s.annulus_px) : 0.0;
    return s.window_lux - background * s.window_sr;
}

// ---------------------------------------------------------------------------
// The model observer

ModelObserver::ModelObserver(ModelObserverParams params, std::uint64_t seed) : params_(params), rng_(seed) {
    validate(params_);
}

double model_response_time_s(const ModelObserverParams& params, double delta_over_sigma) {
    return params.rt_base_s + params.rt_hard_s * std::exp(-std::abs(delta_over_sigma));
}

double standard_normal_cdf(double z) {
    if (z == kInf) return 1.0;
    if (z == -kInf) return 0.0;
    return 0.5 * std::erfc(-z / std::numbers::sqrt2);
}

double standard_normal_quantile(double u) {
    return std::numbers::sqrt2 * boost::math::erf_inv(2.0 * u - 1.0);
}

double ModelObserver::log10_brightness(const View& v) const {
    return params_.exponent * log10_or_minus_inf(window_light_lux(*v.image, v.light_px, params_.window_radius_deg));
}

double ModelObserver::gaussian() {
    // One uniform in (0, 1) through the inverse normal CDF: the same on every platform.
    return standard_normal_quantile(rng_.uniform() + 0x1.0p-54);
}

Answer ModelObserver::answer(const Shown& shown) {
    switch (shown.task) {
        case Task::TwoAfc:
            return answer_2afc(shown);
        case Task::YesNo:
            return answer_yes_no(shown);
        case Task::Adjust:
            return answer_adjust(shown);
    }
    throw std::invalid_argument("unknown task");
}

double ModelObserver::decision_2afc(const Shown& shown) const {
    return log_difference(log10_brightness(view_at(shown, 0)), log10_brightness(view_at(shown, 1)));
}

double ModelObserver::decision_yes_no(const Shown& shown) const {
    const View& v = view_at(shown, 0);
    const double e = increment_illuminance_lux(*v.image, v.light_px, params_.window_radius_deg);
    return e > 0 ? params_.exponent * std::log10(e / params_.detection_threshold_lux) : -kInf;  // log10 B − log10 B_θ
}

Answer ModelObserver::answer_2afc(const Shown& shown) {
    return answer_2afc_delta(decision_2afc(shown));
}

Answer ModelObserver::answer_2afc_delta(double delta) {
    const double sigma = params_.noise_sd_log10;
    const double z = sigma > 0 ? delta / sigma : (delta == 0 ? 0.0 : std::copysign(kInf, delta));
    const Answer easy{Response::Left, model_response_time_s(params_, z)};
    if (rng_.uniform() < params_.lapse_rate)
        return {rng_.coin() ? Response::Left : Response::Right, easy.response_time_s};
    const double d = sigma > 0 ? delta + sigma * gaussian() : delta;
    if (d > 0) return {Response::Left, easy.response_time_s};
    if (d < 0) return {Response::Right, easy.response_time_s};
    return {rng_.coin() ? Response::Left : Response::Right, easy.response_time_s};
}

Answer ModelObserver::answer_yes_no(const Shown& shown) {
    return answer_yes_no_delta(decision_yes_no(shown));
}

Answer ModelObserver::answer_yes_no_delta(double delta) {
    const double sigma = params_.noise_sd_log10;
    const double z = sigma > 0 ? delta / sigma : (delta == 0 ? 0.0 : std::copysign(kInf, delta));
    const double rt = model_response_time_s(params_, z);
    if (rng_.uniform() < params_.lapse_rate) return {rng_.coin() ? Response::Yes : Response::No, rt};
    const double d = sigma > 0 && std::isfinite(delta) ? delta + sigma * gaussian() : delta;
    return {d > 0 ? Response::Yes : Response::No, rt};
}

Answer ModelObserver::answer_adjust(const Shown& shown) {
    if (!shown.adjusted_view || shown.views.size() != 2 || *shown.adjusted_view > 1)
        throw std::invalid_argument("an adjust trial needs two views and adjusted_view 0 or 1");
    const std::size_t adjusted = *shown.adjusted_view;
    const double delta =
        log_difference(log10_brightness(view_at(shown, 1 - adjusted)), log10_brightness(view_at(shown, adjusted)));
    const double sigma = params_.noise_sd_log10;
    const double z = sigma > 0 ? delta / sigma : (delta == 0 ? 0.0 : std::copysign(kInf, delta));
    const double rt = model_response_time_s(params_, z);
    const double d = sigma > 0 && std::isfinite(delta) ? delta + sigma * gaussian() : delta;
    ++actions_;
    const bool coarse = std::abs(d) > params_.adjust_coarse_log10;
    const int sign = d > 0 ? 1 : -1;
    if (!coarse && last_fine_sign_ != 0 && sign != last_fine_sign_) ++fine_reversals_;
    if (actions_ >= params_.adjust_max_actions || std::abs(d) <= params_.adjust_match_log10 ||
        fine_reversals_ >= params_.adjust_reversals) {
        actions_ = 0;
        last_fine_sign_ = 0;
        fine_reversals_ = 0;
        return {Response::Confirm, rt};
    }
    if (coarse) return {sign > 0 ? Response::CoarseUp : Response::CoarseDown, rt};
    last_fine_sign_ = sign;
    return {sign > 0 ? Response::FineUp : Response::FineDown, rt};
}

double model_p_yes(const ModelObserverParams& params, const View& view) {
    validate(params);
    const double e = increment_illuminance_lux(*view.image, view.light_px, params.window_radius_deg);
    const double delta = e > 0 ? params.exponent * std::log10(e / params.detection_threshold_lux) : -kInf;
    const double sigma = params.noise_sd_log10;
    const double p = sigma > 0 ? standard_normal_cdf(delta / sigma) : (delta > 0 ? 1.0 : 0.0);
    return params.lapse_rate / 2.0 + (1.0 - params.lapse_rate) * p;
}

double model_p_first(const ModelObserverParams& params, const View& first, const View& second) {
    validate(params);
    auto log_b = [&](const View& v) {
        return params.exponent * log10_or_minus_inf(window_light_lux(*v.image, v.light_px, params.window_radius_deg));
    };
    const double delta = log_difference(log_b(first), log_b(second));
    const double sigma = params.noise_sd_log10;
    const double p = sigma > 0 ? standard_normal_cdf(delta / sigma) : (delta > 0 ? 1.0 : (delta < 0 ? 0.0 : 0.5));
    return params.lapse_rate / 2.0 + (1.0 - params.lapse_rate) * p;
}

double true_matching_level(const std::function<DisplayedImage(double level)>& reference_at, glm::dvec2 reference_px,
                           const DisplayedImage& test, glm::dvec2 test_px, double p_reference, double lo, double hi,
                           const ModelObserverParams& params) {
    validate(params);
    const double z = p_reference == 0.5 ? 0.0 : z_for(p_reference, params.lapse_rate);
    // log10 B_ref − log10 B_test = σ z  <=>  B_ref = B_test · 10^(σ z).
    const double target = brightness(test, test_px, params.window_radius_deg, params.exponent) *
                          std::pow(10.0, params.noise_sd_log10 * z);
    const auto f = [&](double level) {
        return brightness(reference_at(level), reference_px, params.window_radius_deg, params.exponent) - target;
    };
    return root(f, lo, hi, "true_matching_level");
}

double true_pse(const std::function<DisplayedImage(double level)>& reference_at, glm::dvec2 reference_px,
                const DisplayedImage& test, glm::dvec2 test_px, double lo, double hi,
                const ModelObserverParams& params) {
    return true_matching_level(reference_at, reference_px, test, test_px, 0.5, lo, hi, params);
}

double true_threshold(const std::function<DisplayedImage(double level)>& image_at, glm::dvec2 light_px, double p_yes,
                      double lo, double hi, const ModelObserverParams& params) {
    validate(params);
    const double z = z_for(p_yes, params.lapse_rate);
    // p log10(E / E_θ) = σ z  <=>  E = E_θ 10^(σ z / p).
    const double target = params.detection_threshold_lux * std::pow(10.0, params.noise_sd_log10 * z / params.exponent);
    const auto f = [&](double level) {
        return increment_illuminance_lux(image_at(level), light_px, params.window_radius_deg) - target;
    };
    return root(f, lo, hi, "true_threshold");
}

}  // namespace atonlab::protocols
