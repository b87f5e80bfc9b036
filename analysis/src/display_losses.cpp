#include "atonlab/analysis/display_losses.h"

#include <fmt/format.h>

namespace atonlab::analysis {

std::optional<bool> white_over_warning(const SessionInfo& s, const DisplayLoss& c) {
    if (!c.white || !s.white_loss_warning_share) return std::nullopt;
    // W1's own comparison (runner/src/displayability.cpp, judge_losses): strictly more.
    return c.white->share > *s.white_loss_warning_share;
}

std::optional<bool> gamut_over_limit(const SessionInfo& s, const DisplayLoss& c) {
    if (!c.gamut || !s.max_out_of_gamut_loss) return std::nullopt;
    return c.gamut->share > *s.max_out_of_gamut_loss;  // R5's comparison
}

std::vector<std::string> display_loss_sentences(const SessionInfo& s) {
    std::vector<std::string> out;
    for (const DisplayLoss& c : s.display_losses) {
        std::string said;
        if (white_over_warning(s, c).value_or(false))
            said = fmt::format(
                "its {} light \"{}\" loses {:.1f} % of its light at the display's white at level {:.4g} "
                "(check warns above {:.3g} %)",
                c.white->role, c.white->light, 100.0 * c.white->share, c.white->level,
                100.0 * *s.white_loss_warning_share);
        if (gamut_over_limit(s, c).value_or(false))
            said += fmt::format(
                "{}its {} light \"{}\" gives up {:.1f} % of its light to display.out_of_gamut = \"{}\" "
                "at level {:.4g} (more than display.max_out_of_gamut_loss, {:.3g} %)",
                said.empty() ? "" : "; ", c.gamut->role, c.gamut->light, 100.0 * c.gamut->share, c.out_of_gamut,
                c.gamut->level, 100.0 * *s.max_out_of_gamut_loss);
        if (!said.empty()) out.push_back(fmt::format("condition \"{}\": {}", c.condition, said));
    }
    return out;
}

std::string loss_text(const std::optional<LightLoss>& loss) {
    if (!loss) return "not recorded";
    // The check's table shows a share from 0.5 %; below 0.05 % nothing reads as lost at one decimal.
    if (loss->share < 0.0005) return "none";
    return fmt::format("{:.1f} % ({} light \"{}\", level {:.4g})", 100.0 * loss->share, loss->role, loss->light,
                       loss->level);
}

}  // namespace atonlab::analysis
