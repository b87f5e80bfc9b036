#pragma once
// What a session reads and checks before anything else: the options that need
// no file, the protocol (and script), the scene template, every condition's
// frames through the scene loader.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "atonlab/common/input_error.h"
#include "atonlab/common/input_text.h"
#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/runner/session/run_options.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::runner {

/// The options that need no file checked (InputError naming the option); the
/// observer code the session is stored under ("model", "script" or --observer).
std::string checked_observer_code(const RunOptions& o);

struct SessionInputs {
    protocols::Protocol protocol;
    std::optional<protocols::ScriptedObserver> script;
    /// The protocol file's text, with its conditions files (if any) appended as
    /// comments: the study stores the whole design (protocol_file.h).
    std::string protocol_text;
    std::string protocol_sha;  ///< SHA-256 of protocol_text, hex
    /// The scene file's text, as the template was parsed from: the study
    /// stores it beside the protocol (docs/store.md, `scenes`). Its [display]
    /// calibration and glare aperture_image name files that are not stored:
    /// neither says anything of a light's colour, rhythm or spectrum.
    std::string scene_text;
    std::string scene_sha;  ///< SHA-256 of scene_text, hex
    /// The scene file, read and parsed once: a session renders the template
    /// as it was when it began.
    std::optional<stimuli::SceneTemplate> scene;
    stimuli::Scene display_scene;  ///< the template with the protocol's [display]
};

/// Loads the protocol, the script and the scene template, and checks every
/// condition's frames (condition_scene.h). Throws InputError.
SessionInputs load_session_inputs(const RunOptions& o);

}  // namespace atonlab::runner
