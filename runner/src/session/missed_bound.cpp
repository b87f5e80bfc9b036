// The bound on missed presentations (missed_bound.h).
#include "session/missed_bound.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "atonlab/store/json.h"

namespace atonlab::runner {

MissedBound::MissedBound(const protocols::Timing& timing, std::optional<std::size_t> max_trials, double period_s)
    : enabled_(timing.repeat_missed), in_a_row_max_(timing.max_missed_in_a_row), period_s_(period_s) {
    // ceil(f × N), less a hair so that 0.1 × 30 (3.0000000000000004 in
    // binary) allows 3, not 4; at least 1 for any f > 0 and N ≥ 1.
    if (max_trials && *max_trials > 0)
        per_session_ = std::max(
            1, static_cast<int>(std::ceil(timing.max_missed_fraction * static_cast<double>(*max_trials) - 1e-9)));
}

void MissedBound::add(bool missed, int dropped) {
    ++presented_;
    if (!enabled_) return;
    if (!missed) {
        in_a_row_ = 0;
        return;
    }
    ++in_a_row_;
    ++missed_;
    dropped_ += std::max(0, dropped);
    worst_dropped_ = std::max(worst_dropped_, dropped);
}

const char* MissedBound::reason() const noexcept {
    if (!enabled_) return nullptr;
    if (in_a_row_ >= in_a_row_max_) return "missed_in_a_row";
    if (per_session_ && missed_ > *per_session_) return "missed_per_session";
    return nullptr;
}

std::string MissedBound::record(std::size_t trials_stored, const std::string& margin_json) const {
    using Json = nlohmann::ordered_json;
    const Json j{{"reason", reason() ? reason() : ""},
                 {"trials_stored", trials_stored},
                 {"presented_this_run", presented_},
                 {"missed_this_run", missed_},
                 {"missed_in_a_row", in_a_row_},
                 {"max_missed_in_a_row", in_a_row_max_},
                 {"max_missed_this_run", per_session_ ? Json(*per_session_) : Json(nullptr)},
                 {"dropped_frames", dropped_},
                 {"worst_dropped_frames", worst_dropped_},
                 {"refresh_period_s", period_s_},
                 {"presentation_margin", margin_json.empty() ? Json(nullptr) : Json::parse(margin_json)}};
    return store::dump_json(j);
}

std::string MissedBound::message(long long session) const {
    const std::string bound =
        std::string(reason() ? reason() : "") == "missed_in_a_row"
            ? fmt::format("{} presentations in a row missed their refresh (the protocol's [timing] "
                          "max_missed_in_a_row = {})",
                          in_a_row_, in_a_row_max_)
            : fmt::format("{} of this run's {} presentations missed their refresh, more than the {} that "
                          "[timing] max_missed_fraction allows",
                          missed_, presented_, per_session_.value_or(0));
    const double mean = missed_ > 0 ? static_cast<double>(dropped_) / missed_ : 0.0;
    return fmt::format(
        "session {} stopped: {}. Each was shown again (repeat_missed); their flips lost {} refreshes in all "
        "(mean {:.1f}, worst {}, {:.0f} ms late at the {:.2f} ms refresh). Every trial answered so far is kept. "
        "This machine cannot show the stimuli on time: close other programs (updates, backups, browsers, "
        "simulations), check that vertical sync is on and that nothing else draws on this display, then continue "
        "with --resume {} (or --resume-last).",
        session, bound, dropped_, mean, worst_dropped_, worst_dropped_ * period_s_ * 1e3, period_s_ * 1e3,
        session);
}

}  // namespace atonlab::runner
