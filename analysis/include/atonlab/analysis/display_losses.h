#pragma once
// The light a session's display took from each condition's judged lights, as
// the displayability check stored it before the first trial
// (SessionInfo::display_losses; docs/running.md "Displayability"): the share
// clipped at the display's white (W1) and the share display.out_of_gamut gave
// up (R5), judged by the limits the session ran under. analyze's notes, its
// console lines and the report's table say it in these words
// (docs/analysis.md "Light lost at the display").
#include <optional>
#include <string>
#include <vector>

#include "atonlab/analysis/dataset.h"

namespace atonlab::analysis {

/// Whether the condition's largest share lost at white is over W1's warning
/// share; nullopt where the share or the limit is not recorded.
std::optional<bool> white_over_warning(const SessionInfo& s, const DisplayLoss& c);

/// Whether its largest share given up to display.out_of_gamut is over
/// display.max_out_of_gamut_loss; nullopt where the share or the limit is not recorded.
std::optional<bool> gamut_over_limit(const SessionInfo& s, const DisplayLoss& c);

/// One sentence per condition over a limit, e.g. `condition "ref-high": its
/// reference light "ref" loses 13.8 % of its light at the display's white at
/// level 1 (check warns above 1 %)`; none where a limit is not recorded.
std::vector<std::string> display_loss_sentences(const SessionInfo& s);

/// A loss as the report's table gives it: `13.8 % (reference light "ref", level 1)`,
/// "none" (no share above 0.05 %), or "not recorded".
std::string loss_text(const std::optional<LightLoss>& loss);

}  // namespace atonlab::analysis
