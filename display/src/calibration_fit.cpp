// Display calibration: the monotonicity check, gain-offset-gamma fits and the
// DisplayModel they define (docs/display-calibration.md). The readers are in
// calibration_readers.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <nlopt.hpp>
#include <optional>

#include "atonlab/common/input_error.h"
#include "atonlab/display/calibration.h"
#include "atonlab/display/colour.h"

namespace atonlab::display {
namespace {

bool is_black(const Measurement& m) {
    return m.channel != Channel::other && m.level == 0.0;
}

std::string luminance_key(const Measurement& m) {
    return m.file.ends_with(".ti3") ? "XYZ_Y" : "cd_m2";
}

}  // namespace

// ---------------------------------------------------------------------------
// Checks.

void check_monotonic(const std::vector<Measurement>& measurements, double relative_tolerance) {
    for (const auto& m : measurements) {
        const SourceLocation at{m.file, m.line, 0, luminance_key(m)};
        if (!std::isfinite(m.luminance_cd_m2) || m.luminance_cd_m2 < 0.0)
            throw InputError(at, fmt::format("luminance {} cd/m² is not a finite number >= 0", m.luminance_cd_m2));
        if (!std::isfinite(m.level) || m.level < 0.0 || m.level > 1.0)
            throw InputError(SourceLocation{m.file, m.line, 0, "level"},
                             fmt::format("drive level {} is outside [0, 1]", m.level));
    }
    for (const Channel ch : {Channel::red, Channel::green, Channel::blue, Channel::grey}) {
        std::vector<const Measurement*> ramp;
        for (const auto& m : measurements)
            if (m.channel == ch || is_black(m)) ramp.push_back(&m);
        std::stable_sort(ramp.begin(), ramp.end(), [](auto* x, auto* y) { return x->level < y->level; });
        double max_below = -1.0, max_below_level = 0.0;  // brightest reading at a lower level
        double max_here = -1.0, level_here = -1.0;
        for (const Measurement* m : ramp) {
            if (m->level > level_here) {
                if (max_here > max_below) {
                    max_below = max_here;
                    max_below_level = level_here;
                }
                level_here = m->level;
                max_here = -1.0;
            }
            if (m->luminance_cd_m2 < max_below * (1.0 - relative_tolerance))
                throw InputError(
                    SourceLocation{m->file, m->line, 0, luminance_key(*m)},
                    fmt::format("the {} ramp is not monotonic: {} cd/m² at level {} is below the {} cd/m² "
                                "measured at the lower level {}",
                                channel_name(ch), m->luminance_cd_m2, m->level, max_below, max_below_level));
            max_here = std::max(max_here, m->luminance_cd_m2);
        }
    }
}

// ---------------------------------------------------------------------------
// GOG fits.

double gog_luminance_cd_m2(const GogFit& fit, double level) {
    const double base = fit.b + fit.k * level;
    return base > 0.0 ? fit.a + std::pow(base, fit.gamma) : fit.a;
}

GogParams gog_params(const GogFit& fit) {
    return GogParams{fit.a, fit.b, fit.k, fit.gamma};
}

namespace {

struct FitData {
    std::vector<double> level;
    std::vector<double> log10_cd;  // floored
    double scale;                  // S: the model is S (alpha + (beta + kappa V)^gamma)
    double floor_cd;               // luminance floor for logs (a photometer's noise floor)
};

double model_normalised(const double* x, double v) {
    const double base = x[1] + x[2] * v;
    return x[0] + (base > 0.0 ? std::pow(base, x[3]) : 0.0);
}

double sum_squares(unsigned n, const double* x, double* grad, void* data) {
    (void)n;
    (void)grad;  // derivative-free (BOBYQA)
    const auto& d = *static_cast<const FitData*>(data);
    double s = 0.0;
    for (std::size_t i = 0; i < d.level.size(); ++i) {
        const double L = std::max(d.scale * model_normalised(x, d.level[i]), d.floor_cd);
        const double r = std::log10(L) - d.log10_cd[i];
        s += r * r;
    }
    return s;
}

}  // namespace

GogFit fit_gog(const std::vector<Measurement>& ramp) {
    const SourceLocation where =
        ramp.empty() ? SourceLocation{} : SourceLocation{ramp.front().file, ramp.front().line, 0, "level"};
    std::vector<double> levels;
    for (const auto& m : ramp) levels.push_back(m.level);
    std::sort(levels.begin(), levels.end());
    const auto distinct = std::unique(levels.begin(), levels.end()) - levels.begin();
    if (distinct < 4)
        throw InputError(
            where, fmt::format("a GOG fit needs readings at 4 or more distinct levels, this ramp has {}", distinct));

    // Black (mean at level 0, else the darkest reading) and white (mean at the top level).
    const double top = levels[static_cast<std::size_t>(distinct - 1)];
    double black_sum = 0.0, white_sum = 0.0, darkest = std::numeric_limits<double>::infinity(), brightest = 0.0;
    int n_black = 0, n_white = 0;
    for (const auto& m : ramp) {
        if (m.level == 0.0) {
            black_sum += m.luminance_cd_m2;
            ++n_black;
        }
        if (m.level == top) {
            white_sum += m.luminance_cd_m2;
            ++n_white;
        }
        darkest = std::min(darkest, m.luminance_cd_m2);
        brightest = std::max(brightest, m.luminance_cd_m2);
    }
    const double black = n_black > 0 ? black_sum / n_black : darkest;
    const double white = white_sum / n_white;
    if (!(white > black))
        throw InputError(where, fmt::format("the ramp does not rise: {} cd/m² at level {} against {} cd/m² at black",
                                            white, top, black));

    FitData d;
    d.scale = white - black;
    d.floor_cd = 1e-6 * brightest;  // readings below a millionth of the peak are photometer noise
    for (const auto& m : ramp) {
        d.level.push_back(m.level);
        d.log10_cd.push_back(std::log10(std::max(m.luminance_cd_m2, d.floor_cd)));
    }

    // Starting point: the straight line log10(L - black) = gamma log10 V + c over V >= 0.1.
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    int n_line = 0;
    for (const auto& m : ramp) {
        if (m.level < 0.1 || m.luminance_cd_m2 <= black) continue;
        const double x = std::log10(m.level), y = std::log10(m.luminance_cd_m2 - black);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        ++n_line;
    }
    double gamma0 = 2.2, kappa0 = 1.0;
    if (n_line >= 2 && n_line * sxx - sx * sx > 0.0) {
        gamma0 = (n_line * sxy - sx * sy) / (n_line * sxx - sx * sx);
        const double c = (sy - gamma0 * sx) / n_line;
        kappa0 = std::pow(std::pow(10.0, c) / d.scale, 1.0 / gamma0);
    }

    // Bounds in the normalised parameters (alpha, beta, kappa, gamma); wide enough for any
    // real display (gamma 0.5-5, cut-off or offset up to half the drive range).
    const std::vector<double> lb = {0.0, -0.5, 0.1, 0.5};
    const std::vector<double> ub = {std::max(1.0, 2.0 * black / d.scale), 0.5, 3.0, 5.0};
    auto clamp_to_bounds = [&](std::vector<double> x) {
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::clamp(x[i], lb[i] + 1e-9, ub[i] - 1e-9);
        return x;
    };

    std::vector<double> best;
    double best_f = std::numeric_limits<double>::infinity();
    // Three starts (no offset, cut-off, offset) guard against the a/b trade-off near black.
    for (const double beta0 : {0.0, -0.05, 0.05}) {
        std::vector<double> x = clamp_to_bounds({black / d.scale, beta0, kappa0 - beta0, gamma0});
        nlopt::opt opt(nlopt::LN_BOBYQA, 4);
        opt.set_lower_bounds(lb);
        opt.set_upper_bounds(ub);
        opt.set_min_objective(sum_squares, &d);
        opt.set_xtol_rel(1e-10);
        opt.set_ftol_abs(1e-16);
        opt.set_maxeval(20000);
        double f = 0.0;
        try {
            opt.optimize(x, f);
        } catch (const nlopt::roundoff_limited&) {
            // x holds the best point found; the residual is as small as rounding allows.
            f = sum_squares(4, x.data(), nullptr, &d);
        }
        if (f < best_f) {
            best_f = f;
            best = x;
        }
    }

    const double root = std::pow(d.scale, 1.0 / best[3]);
    GogFit fit;
    fit.a = d.scale * best[0];
    fit.b = best[1] * root;
    fit.k = best[2] * root;
    fit.gamma = best[3];
    fit.n = static_cast<int>(ramp.size());
    fit.rmse_log10 = std::sqrt(best_f / static_cast<double>(fit.n));
    return fit;
}

double effective_gamma(const GogFit& fit) {
    const double l0 = gog_luminance_cd_m2(fit, 0.0);
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    int n = 0;
    for (int i = 0; i <= 45; ++i) {
        const double lv = -1.0 + static_cast<double>(i) / 45.0;  // log10 V from -1 to 0
        const double dl = gog_luminance_cd_m2(fit, std::pow(10.0, lv)) - l0;
        if (dl <= 0.0) continue;
        const double y = std::log10(dl);
        sx += lv;
        sy += y;
        sxx += lv * lv;
        sxy += lv * y;
        ++n;
    }
    if (n < 2) return 0.0;
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// ---------------------------------------------------------------------------
// The whole calibration.

const RampReport* CalibrationReport::ramp(Channel c) const {
    for (const auto& r : ramps)
        if (r.channel == c) return &r;
    return nullptr;
}

CalibrationReport fit_calibration(const std::vector<Measurement>& measurements) {
    const std::string file = measurements.empty() ? std::string() : measurements.front().file;
    if (measurements.empty()) throw InputError(SourceLocation{file, 0, 0, ""}, "there are no measurements to fit");
    check_monotonic(measurements);

    CalibrationReport report;
    report.n_measurements = static_cast<int>(measurements.size());
    double black_sum = 0.0;
    int n_black = 0;
    for (const auto& m : measurements) {
        if (m.channel == Channel::other) ++report.n_other;
        if (is_black(m)) {
            black_sum += m.luminance_cd_m2;
            ++n_black;
        }
    }
    if (n_black == 0)
        throw InputError(SourceLocation{file, 0, 0, ""}, "the calibration has no black reading (level 0)");
    report.black_cd_m2 = black_sum / n_black;

    auto mean_at_full = [&](Channel ch) -> std::optional<double> {
        double s = 0.0;
        int n = 0;
        for (const auto& m : measurements)
            if (m.channel == ch && m.level == 1.0) {
                s += m.luminance_cd_m2;
                ++n;
            }
        return n > 0 ? std::optional<double>(s / n) : std::nullopt;
    };
    if (const auto w = mean_at_full(Channel::grey)) {
        report.white_cd_m2 = *w;
    } else {
        const auto r = mean_at_full(Channel::red), g = mean_at_full(Channel::green), b = mean_at_full(Channel::blue);
        if (!r || !g || !b)
            throw InputError(SourceLocation{file, 0, 0, ""},
                             "the calibration has no white reading (grey at level 1, or red, green and blue at 1)");
        // The channels add; each reading includes the other two channels' black.
        report.white_cd_m2 = *r + *g + *b - 2.0 * report.black_cd_m2;
    }
    report.contrast_ratio =
        report.black_cd_m2 > 0.0 ? report.white_cd_m2 / report.black_cd_m2 : std::numeric_limits<double>::infinity();

    for (const Channel ch : {Channel::red, Channel::green, Channel::blue, Channel::grey}) {
        std::vector<Measurement> ramp;
        bool lit = false;
        for (const auto& m : measurements) {
            if (m.channel == ch && m.level > 0.0) lit = true;
            if (m.channel == ch || is_black(m)) ramp.push_back(m);
        }
        if (!lit) continue;
        std::vector<double> levels;
        for (const auto& m : ramp) levels.push_back(m.level);
        std::sort(levels.begin(), levels.end());
        const int distinct = static_cast<int>(std::unique(levels.begin(), levels.end()) - levels.begin());
        if (distinct < 4) {
            report.notes.push_back(
                fmt::format("the {} ramp has {} distinct levels (black included); 4 are needed for "
                            "a fit, so it is not fitted",
                            channel_name(ch), distinct));
            continue;
        }
        RampReport r;
        r.channel = ch;
        r.fit = fit_gog(ramp);
        r.effective_gamma = effective_gamma(r.fit);
        r.black_cd_m2 = gog_luminance_cd_m2(r.fit, 0.0);
        r.white_cd_m2 = gog_luminance_cd_m2(r.fit, 1.0);
        r.levels = distinct;
        report.ramps.push_back(r);
    }
    if (report.ramps.empty())
        throw InputError(
            SourceLocation{file, 0, 0, ""},
            "no ramp (red, green, blue or grey) has readings at 4 or more levels, so nothing can be fitted");
    return report;
}

DisplayModel display_from_calibration(const CalibrationReport& report, std::string name) {
    std::array<GogParams, 3> params{};
    const RampReport* rgb[3] = {report.ramp(Channel::red), report.ramp(Channel::green), report.ramp(Channel::blue)};
    const RampReport* grey = report.ramp(Channel::grey);
    if (rgb[0] && rgb[1] && rgb[2]) {
        for (int c = 0; c < 3; ++c) {
            // Each ramp was read with the other two channels at black; channel c keeps its
            // Rec.709 share of that black so that the three add up to the measured black.
            auto& p = params[static_cast<std::size_t>(c)];
            p = gog_params(rgb[c]->fit);
            p.a -= (1.0 - rec709_rgb_to_xyz()[c][1]) * report.black_cd_m2;
        }
    } else if (grey) {
        for (int c = 0; c < 3; ++c) {
            // w (b + k V)^gamma = (w^(1/gamma) b + w^(1/gamma) k V)^gamma.
            const double w = rec709_rgb_to_xyz()[c][1];
            const auto g = gog_params(grey->fit);
            const double root = std::pow(w, 1.0 / g.gamma);
            params[static_cast<std::size_t>(c)] = GogParams{w * g.a, root * g.b, root * g.k, g.gamma};
        }
    } else {
        throw InputError(SourceLocation{"", 0, 0, ""},
                         "a display model needs fitted red, green and blue ramps or a fitted grey ramp");
    }
    DisplayModel model = DisplayModel::gog(params, std::move(name));
    model.validate();
    return model;
}

}  // namespace atonlab::display
