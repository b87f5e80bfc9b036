#pragma once
// A condition's frames through the scene loader, with a refused override named
// at the protocol line that wrote it; the load-time checks of every condition.
#include <filesystem>
#include <string>

#include "atonlab/protocols/protocol.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::runner {

/// Where an override a frame applies was written in the protocol.
struct OverrideSource {
    int line = 0;
    int column = 0;
};

/// `text` is the frame's override the scene refused ("key=value"; the last of
/// its key: the scene loader validates the value each key ends with).
OverrideSource override_source(const protocols::Condition& c, const std::string& key, const std::string& text);

/// A frame's override parsed; one of the protocol's [display] keys keeps its
/// line, so that a limit the scene derives from the display (a glare billboard
/// too wide for it) names the protocol's line rather than "--set".
stimuli::SceneOverride parsed_override(const protocols::Protocol& protocol, const std::string& text);

/// The scene of one of a condition's frames, with an error in an override
/// re-thrown at the protocol's line that wrote it (the condition named).
stimuli::Scene condition_scene(const std::string& scene_text, const std::filesystem::path& scene_file,
                               const protocols::Protocol& protocol, const protocols::Condition& condition,
                               const protocols::Frame& frame);

/// Every frame of one proposal through the scene loader, and the judged lights exist.
void check_stimulus(const protocols::Protocol& protocol, const std::string& scene_text,
                    const std::filesystem::path& scene_file, const protocols::Condition& c,
                    const protocols::Proposal& proposal);

/// Load-time checks of every condition: each frame's scene for a proposal at
/// the procedure's first level and at its level bounds where it has them
/// (2AFC: in both orders), and the judged lights exist.
void validate_conditions(const protocols::Protocol& protocol, const std::string& scene_text,
                         const std::filesystem::path& scene_file);

}  // namespace atonlab::runner
