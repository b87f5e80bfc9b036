#pragma once
// What a session prints when it ends: the per-condition estimates, and the
// model observer's true values beside them.
#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "session/session_observer.h"
#include "session/stimulus_renderer.h"

namespace atonlab::runner {

/// Per condition: the mean estimate over its tracks, the method, how many
/// tracks finished; with compute_true, the model observer's true value
/// (true_value.h) and the estimate's error against it.
void print_summary(const protocols::Protocol& protocol, const protocols::Schedule& schedule,
                   StimulusRenderer* renderer, const SessionObserver& observer, bool compute_true);

}  // namespace atonlab::runner
