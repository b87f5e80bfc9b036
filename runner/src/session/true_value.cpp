// The model observer's true value (true_value.h): a root of the model's
// choice probability against the level, each level rendered.
#include "atonlab/runner/session/true_value.h"

#include <fmt/format.h>

#include <cmath>
#include <exception>

#include "atonlab/runner/session/scene_queries.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;

/// The model observer's true value for a condition: the level its procedure
/// should converge on (2AFC and adjust: where the level stimulus is chosen
/// with the procedure's target probability, 0.5 = the PSE; yes-no: the
/// detection threshold at the target P(yes)). Renders the level stimulus at
/// each level the root finder asks for.
std::string true_value(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c,
                       const p::ModelObserverParams& params, double& value) {
    const std::optional<double> p_yes = c.procedure.target_p_yes();
    if (!p_yes) return "no target probability for this procedure";
    const auto [lo, hi] = c.procedure.search_range();
    auto stimulus_at = [&](double level) {
        p::Proposal proposal;
        proposal.level = level;
        if (c.task == p::Task::TwoAfc) proposal.test_on_left = true;
        return p::make_stimulus(protocol, c, proposal);
    };
    // The window around view `i` of the stimulus at `level`. Levels are rounded
    // to 0.001: the display's integer codes make the brightness a step function
    // of the level, on which the root finder would otherwise bisect down to
    // 1e-14 with a render per step; once its bracket is inside one 0.001 cell
    // every further call is a cache hit. So the true value is resolved to
    // ±0.001 (log10 units with level_scale = "log10").
    auto window_at = [&](double level, std::size_t i) {
        const p::Stimulus stim = stimulus_at(std::round(level * 1000.0) / 1000.0);
        const std::vector<std::string> lights = judged_lights(stim, stim.views[i].frame);
        std::size_t j = 0;
        for (std::size_t k = 0; k < i; ++k) j += stim.views[k].frame == stim.views[i].frame ? 1 : 0;
        return renderer.views(stim.frames[stim.views[i].frame], lights)->windows[j];
    };
    const double mid = 0.5 * (lo + hi);
    // Where the model's brightness of the level stimulus stands against the
    // other's (log10), to say why no crossing was found.
    auto no_crossing = [&](const LightWindow& other, std::size_t view) {
        const double r = params.window_radius_deg, e = params.exponent;
        const double b_other = std::log10(p::brightness(other.image, other.light_px, r, e));
        const LightWindow at_lo = window_at(lo, view), at_hi = window_at(hi, view);
        const double d_lo = std::log10(p::brightness(at_lo.image, at_lo.light_px, r, e)) - b_other;
        const double d_hi = std::log10(p::brightness(at_hi.image, at_hi.light_px, r, e)) - b_other;
        return fmt::format(
            "none in [{:.4g}, {:.4g}]: the level stimulus is {:+.3f} log10 brightness from the other "
            "at {:.4g} and {:+.3f} at {:.4g}{}",
            lo, hi, d_lo, lo, d_hi, hi,
            std::abs(d_hi - d_lo) < 1e-6 ? " (unchanged by the level: the display clips it)" : "");
    };
    try {
        if (c.task == p::Task::YesNo) {
            const LightWindow w = window_at(mid, 0);
            const LightWindow at_lo = window_at(lo, 0), at_hi = window_at(hi, 0);
            if ((p::model_p_yes(params, p::View{&at_lo.image, at_lo.light_px}) - *p_yes) *
                    (p::model_p_yes(params, p::View{&at_hi.image, at_hi.light_px}) - *p_yes) >
                0)
                return fmt::format("none in [{:.4g}, {:.4g}]: P(yes) does not cross {:.3f} there", lo, hi, *p_yes);
            value = p::true_threshold([&](double level) { return window_at(level, 0).image; }, w.light_px, *p_yes, lo,
                                      hi, params);
            return {};
        }
        const p::Stimulus probe = stimulus_at(mid);
        std::size_t level_view = probe.views.size(), other_view = probe.views.size();
        for (std::size_t i = 0; i < probe.views.size(); ++i)
            (probe.views[i].role == c.level_on ? level_view : other_view) = i;
        if (level_view >= probe.views.size() || other_view >= probe.views.size())
            return "the stimulus has no two views to compare";
        // Yes means "chose the level stimulus" when the choice and level_on name the same role.
        const double p_level = c.yes_means_level() ? *p_yes : 1.0 - *p_yes;
        const LightWindow level_w = window_at(mid, level_view);
        const LightWindow other_w = window_at(mid, other_view);
        {
            const LightWindow at_lo = window_at(lo, level_view), at_hi = window_at(hi, level_view);
            const double p_lo = p::model_p_first(params, p::View{&at_lo.image, at_lo.light_px},
                                                 p::View{&other_w.image, other_w.light_px});
            const double p_hi = p::model_p_first(params, p::View{&at_hi.image, at_hi.light_px},
                                                 p::View{&other_w.image, other_w.light_px});
            if ((p_lo - p_level) * (p_hi - p_level) > 0) return no_crossing(other_w, level_view);
        }
        value = p::true_matching_level([&](double level) { return window_at(level, level_view).image; },
                                       level_w.light_px, other_w.image, other_w.light_px, p_level, lo, hi, params);
        return {};
    } catch (const std::exception& e) {
        return fmt::format("not found in [{:.4g}, {:.4g}]: {}", lo, hi, e.what());
    }
}

}  // namespace atonlab::runner
