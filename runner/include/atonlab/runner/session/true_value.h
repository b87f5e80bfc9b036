#pragma once
// The model observer's true value of a condition, found on rendered frames.
#include <string>

#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/runner/session/stimulus_renderer.h"

namespace atonlab::runner {

/// The model observer's true value for condition c: the level its procedure
/// should converge on (2AFC and adjust: where the level stimulus is chosen with
/// the procedure's target probability, 0.5 = the PSE; yes-no: the detection
/// threshold at the target P(yes)), found on the frames the renderer makes.
/// Returns "" and sets value, or says why there is none (e.g. the display
/// clips the level stimulus so its brightness never crosses the other's).
std::string true_value(StimulusRenderer& renderer, const protocols::Protocol& protocol,
                       const protocols::Condition& c, const protocols::ModelObserverParams& params, double& value);

}  // namespace atonlab::runner
