#pragma once
// The presentation margin (docs/running.md, "Presentation margin"): before
// the first trial, on screen, how long showing a prepared frame of the
// protocol's heaviest condition takes (its codes uploaded, drawn, the GPU
// finished; Presenter::time_showing) against the measured refresh period.
// margin = 1 − show / period: the share of a refresh left over. Under 50 % the
// run warns; under 0 (a frame cannot be shown within a refresh) --strict-timing
// refuses the session (exit status 5, nothing stored).
#include <optional>
#include <string>

#include "atonlab/present/presenter.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/runner/displayability.h"
#include "atonlab/runner/session/stimulus_renderer.h"

namespace atonlab::runner {

struct PresentationMargin {
    std::string condition;  ///< the condition whose frame was shown
    bool animated = false;  ///< its frame is rendered again at every flip (a light with a rhythm)
    int times = 0;          ///< showings timed
    double period_s = 0.0;  ///< the refresh period measured at start, s
    double upload_s = 0.0;  ///< the median upload (prepare), s
    double draw_s = 0.0;    ///< the median draw and finish, s
    double show_s = 0.0;    ///< the median of upload + draw, s
    double worst_show_s = 0.0;
    /// 1 − show / period: the share of a refresh left once a frame is shown.
    double margin() const noexcept { return 1.0 - show_s / period_s; }
};

/// Below this margin the run warns (the 50 %).
inline constexpr double kMarginWarning = 0.5;

/// Times `times` showings of the first frame of the protocol's heaviest
/// condition (one with a rhythm, which is rendered at every flip, if there is
/// one; otherwise the first: every other frame is a full-screen picture of the
/// same size), at the top of its level range (displayability.h). extra_s:
/// test-only, added to each draw (--inject-frame-cost-ms). Only on screen.
PresentationMargin measure_margin(present::Presenter& presenter, StimulusRenderer& renderer,
                                  const protocols::Protocol& protocol, const Displayability& displayability, int bits,
                                  int times = 30, double extra_s = 0.0);

/// The margin as stored (in displayability_json's "presentation" and in a
/// stop record; docs/store.md), JSON object text.
std::string margin_json(const PresentationMargin& m);
/// One line for the start of the session.
std::string margin_text(const PresentationMargin& m);

}  // namespace atonlab::runner
