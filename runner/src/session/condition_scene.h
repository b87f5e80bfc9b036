#pragma once
// A condition's frames through the scene template, with a refused override named
// at the protocol line that wrote it; the load-time checks of every condition.
#include <filesystem>
#include <string>

#include "atonlab/protocols/protocol.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::runner {

/// The scene of one of a condition's frames (the template with the frame's
/// overrides). An error in an override the condition gave or made is re-thrown
/// at the line that wrote it with the condition named; one in the scene file,
/// or one that only the combination causes, at the condition's line; one in a
/// [display] value as it is.
stimuli::Scene condition_scene(const stimuli::SceneTemplate& scene, const protocols::Protocol& protocol,
                               const protocols::Condition& condition, const protocols::Frame& frame);

/// Every frame of one proposal through the scene loader, and the judged lights exist.
void check_stimulus(const protocols::Protocol& protocol, const stimuli::SceneTemplate& scene,
                    const protocols::Condition& c, const protocols::Proposal& proposal);

/// Load-time checks of every condition: each frame's scene for a proposal at
/// the procedure's first level and at its level bounds where it has them
/// (2AFC: in both orders), and the judged lights exist.
void validate_conditions(const protocols::Protocol& protocol, const stimuli::SceneTemplate& scene);

}  // namespace atonlab::runner
