// A session's inputs, read and checked (session_inputs.h).
#include "atonlab/runner/session/session_inputs.h"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "atonlab/protocols/protocol_file.h"
#include "atonlab/stimuli/scene_file.h"
#include "atonlab/store/sha256.h"
#include "atonlab/common/read_file.h"
#include "session/condition_scene.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;

namespace {

bool valid_observer_code(std::string_view code) {
    if (code.empty() || code.size() > 32) return false;
    return std::all_of(code.begin(), code.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    });
}

}  // namespace

std::string checked_observer_code(const RunOptions& o) {
    // A person answers at the screen; the model or a script answer anywhere.
    const bool person = !o.model_observer && o.script.empty() && !o.custom_observer;
    if (person && o.headless)
        throw InputError(SourceLocation::command_line("--headless"),
                         "a headless run has no screen for a person: give --model-observer or --script FILE with "
                         "--headless, or leave --headless out to run full screen.");
    if (person && o.observer.empty())
        throw InputError(SourceLocation::command_line("--observer"),
                         "give the observer's code with --observer ID (or answer with --model-observer or --script "
                         "FILE).");
    if (o.inject_stall_frames > 0 && !o.inject_stall_at_trial && !o.inject_stall_every_trial)
        throw InputError(SourceLocation::command_line("--inject-stall-frames"),
                         "name the trial to stall with --inject-stall-at-trial N (or stall every trial with "
                         "--inject-stall-every-trial).");
    if (o.inject_stall_every_trial && o.inject_stall_frames <= 0)
        throw InputError(SourceLocation::command_line("--inject-stall-every-trial"),
                         "give the stall's length with --inject-stall-frames N.");
    if (o.capture_trial && o.capture_dir.empty())
        throw InputError(SourceLocation::command_line("--capture-trial"), "give the folder with --capture-dir DIR.");
    const std::string code = !o.observer.empty() ? o.observer : o.model_observer ? std::string("model") : "script";
    if (!valid_observer_code(code))
        throw InputError(SourceLocation::command_line("--observer"),
                         fmt::format("the observer code \"{}\" must be 1 to 32 letters, digits, '_' or '-' (a code, "
                                     "never a name).",
                                     code));
    return code;
}

SessionInputs load_session_inputs(const RunOptions& o) {
    SessionInputs in;
    if (o.protocol_text.empty()) {
        in.protocol = p::load_protocol(o.protocol);
        in.protocol_text = p::with_conditions_files(files::read_text(o.protocol, "protocol file"), o.protocol);
    } else {
        in.protocol_text = p::with_conditions_files(o.protocol_text, o.protocol);
        in.protocol = p::parse_protocol(in.protocol_text, o.protocol);
        if (!std::filesystem::is_regular_file(in.protocol.scene))
            throw InputError(SourceLocation{o.protocol, 0, 0, "protocol.scene"},
                             fmt::format("the scene file {} does not exist.", in.protocol.scene.string()));
    }
    if (!o.script.empty()) in.script = p::ScriptedObserver::load(o.script);
    in.protocol_sha = store::sha256_hex(in.protocol_text);
    in.scene_text = files::read_text(in.protocol.scene, "scene template");
    in.scene_sha = store::sha256_hex(in.scene_text);
    in.scene = s::SceneTemplate::parse(in.scene_text, in.protocol.scene.string());
    // The template with the display first: its own errors name its file and
    // line, the display's its [display] lines.
    in.display_scene = in.scene->instantiate(in.protocol.display_overrides());
    validate_conditions(in.protocol, *in.scene);
    return in;
}

}  // namespace atonlab::runner
