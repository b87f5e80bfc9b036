#pragma once
// The stored record of one trial (store::TrialRecord): what was shown (the
// stimulus JSON), the procedure's state after it and who answered (the state
// JSON). analysis/src/study_reader.cpp reads these keys.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/session/session_observer.h"
#include "atonlab/runner/session/stimulus_renderer.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/store/records.h"
#include "session/session_display.h"

namespace atonlab::runner {

/// The glare model a view's light is drawn with in its frame's scene: the
/// light's own, else the eye's (also for a view of the image centre, or of an
/// alternating light, whose channels are "NAME/W", ...).
std::string view_glare(const stimuli::Scene& sc, const std::string& light);

/// The stimulus column: task, level, scene, frames (role, time, overrides,
/// where the glare arithmetic ran), views (frame, light, role, glare), timing
/// asked for and what the flips gave.
std::string stimulus_json(const protocols::Protocol& protocol, const protocols::Condition& c,
                          const protocols::ScheduledTrial& t, const std::vector<double>& frame_times,
                          const std::optional<FramesShown>& frames_shown, const std::vector<std::string>& view_glares,
                          const std::vector<stimuli::FramePlacements>& placements);

/// The procedure's state after the trial, who answered, and what: `answer` is
/// the answer given (kept for a "missed" trial, whose response column says it
/// was repeated), `input` the key or button, `step` the schedule's step.
std::string state_json(const protocols::Schedule& schedule, const SessionObserver& observer, double answer_rt_s,
                       const std::optional<protocols::Response>& answer, const std::string& input, std::size_t step);
/// The same for an observer named by its kind ("person", "model", "script",
/// "simulated") and seed.
std::string state_json(const protocols::Schedule& schedule, std::string_view observer_kind,
                       std::uint64_t observer_seed, double answer_rt_s, const std::optional<protocols::Response>& answer,
                       const std::string& input, std::size_t step);

/// The observer seed a session's first trial recorded, if any.
std::optional<std::uint64_t> logged_observer_seed(const std::vector<store::TrialRecord>& trials);

/// The record of trial `t` (stored as trial_index `row`) as it was shown;
/// `counted`: the procedure took its answer (else it is stored as "timeout" or
/// "missed" and shown again). `schedule` is the state after the trial.
store::TrialRecord trial_record(const protocols::Protocol& protocol, const protocols::ScheduledTrial& t,
                                std::size_t row, const TrialShown& shown, bool counted,
                                const protocols::Schedule& schedule, const SessionObserver& observer,
                                StimulusRenderer& renderer);

}  // namespace atonlab::runner
