// `atonlab check PROTOCOL.toml [--set display.KEY=VALUE ...] [--db STUDY.db]`:
// the displayability check of `atonlab run` (displayability.h) on its own, so
// that a protocol can be tried against a display before a session. Prints the
// table; exit 0 when every condition can produce a match, 2 when one cannot
// (one sentence each on stderr) or the input is bad, 3 without GL. Writes nothing.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <charconv>
#include <functional>
#include <memory>
#include <cmath>
#include <cstdio>
#include <string>
#include <system_error>

#include "atonlab/common/input_error.h"
#include "atonlab/common/input_text.h"
#include "atonlab/common/read_file.h"
#include "atonlab/common/scene_override.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/runner/check_command.h"
#include "atonlab/runner/displayability.h"
#include "atonlab/runner/session/run_session.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/store/error.h"
#include "atonlab/store/store.h"
#include "calibrate/calibration_policy.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;

namespace {

/// `--set display.KEY=VALUE`: the protocol's [display] for this check.
void apply_display_set(p::Display& display, const std::string& set) {
    // The one reader of "key=value" (common/scene_override.h): the value typed once.
    if (set.find('=') == std::string::npos)
        throw InputError(SourceLocation::command_line("--set", set),
                         "a --set is KEY=VALUE, e.g. display.width_px=3840.");
    const SceneOverride o = SceneOverride::parse(set);
    const std::string& key = o.key;
    const std::string& value = o.value;
    if (key != "display.width_px" && key != "display.height_px" && key != "display.width_m" &&
        key != "display.viewing_distance_m")
        throw InputError(SourceLocation::command_line("--set", key),
                         "check sets only the display: display.width_px, display.height_px, display.width_m or "
                         "display.viewing_distance_m.");
    display.lines.erase(key.substr(std::string_view("display.").size()));  // its errors name --set, not the file
    const toml::node* n = o.typed() ? &o.typed()->node() : nullptr;
    const double v = n && (n->is_integer() || n->is_floating_point()) ? *n->value<double>() : 0.0;
    if (!std::isfinite(v) || !(v > 0))
        throw InputError(SourceLocation::command_line("--set", key),
                         fmt::format("\"{}\" is not a positive number.", text::echo(value)));
    const bool whole = v == std::floor(v) && v <= 65536;
    if (key == "display.width_px" || key == "display.height_px") {
        if (!whole)
            throw InputError(SourceLocation::command_line("--set", key),
                             fmt::format("{} is a whole number of pixels from 1 to 65536.", text::echo(value)));
        (key == "display.width_px" ? display.width_px : display.height_px) = static_cast<int>(v);
    } else if (key == "display.width_m") {
        display.width_m = v;
    } else {
        display.viewing_distance_m = v;
    }
}

}  // namespace

void add_check_command(CLI::App& app, CheckOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "check",
        "Work out what a display will show of a protocol's stimuli at both ends of each level range, and whether a "
        "match can be made (exit 0) or not (exit 2); writes nothing");
    cmd->add_option("protocol", o.protocol, "Protocol file (TOML; see docs/protocol-file.md)")->required();
    cmd->add_option("--set", o.sets,
                    "Another display: display.width_px=N, display.height_px=N, display.width_m=X, "
                    "display.viewing_distance_m=X (repeatable)");
    cmd->add_option("--db", o.db,
                    "Study file whose latest calibration of the protocol's display.name encodes the frames, as "
                    "`atonlab run --db` would (read only)");
    cmd->add_flag("--strict", o.strict,
                  "Refuse (exit 2) also where a judged light is clipped at the display's white at a level where the "
                  "match may lie (otherwise a warning)");
}

Displayability check_protocol(const CheckOptions& o, const std::function<void()>& make_context) {
    p::Protocol protocol = p::load_protocol(o.protocol);
    for (const std::string& set : o.sets) apply_display_set(protocol.display, set);
    stimuli::SceneTemplate scene =
        stimuli::SceneTemplate::parse(files::read_text(protocol.scene, "scene template"), protocol.scene.string());

    std::optional<display::DisplayModel> model;
    if (!o.db.empty()) {
        const store::Store study = store::Store::open_read_only(o.db);
        const SessionCalibration cal = session_calibration(&study, protocol.display, std::nullopt, utc_today(), o.db);
        for (const std::string& w : cal.warnings) std::fprintf(stderr, "atonlab: warning: %s\n", w.c_str());
        model = cal.display;
    }
    make_context();
    const p::ModelObserverParams params{};
    StimulusRenderer renderer(std::move(scene), params.window_radius_deg, protocol.timing.stimulus_s);
    if (model) renderer.use_display_model(*model);
    return check_displayability(renderer, protocol);
}

int run_check(const CheckOptions& o) {
    std::unique_ptr<gl::Context> context;
    Displayability d;
    try {
        d = check_protocol(o, [&context] { context = gl::create_headless_context(); });
    } catch (const store::StoreError& e) {
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 4;
    }
    std::printf("%s", displayability_table(d).c_str());
    const std::string warnings = displayability_warnings(d, o.protocol);
    if (!warnings.empty()) std::fprintf(stderr, "%s\n", warnings.c_str());
    if (o.strict && !warnings.empty() && d.displayable()) {
        std::fprintf(stderr, "atonlab: --strict: the warnings above refuse the protocol\n");
        return 2;
    }
    if (d.displayable()) {
        std::printf("every condition can produce a match on this display\n");
        return 0;
    }
    std::fprintf(stderr, "atonlab: %s\n", displayability_refusal(d, o.protocol).c_str());
    return 2;
}

}  // namespace atonlab::runner
