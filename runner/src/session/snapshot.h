#pragma once
// The snapshot a session stores of each condition: its first trial's frames.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/session/stimulus_renderer.h"

namespace atonlab::runner {

/// One EXR of the condition's first trial: its frames stacked top to bottom
/// in presentation order, scene-referred (cd/m²), as the file's bytes.
std::vector<std::byte> snapshot_exr(StimulusRenderer& renderer, const protocols::Protocol& protocol,
                                    const protocols::Condition& c, const protocols::ScheduledTrial& t,
                                    std::int64_t session);

}  // namespace atonlab::runner
