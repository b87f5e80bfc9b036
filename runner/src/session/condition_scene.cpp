// Condition scenes and their load-time checks (condition_scene.h).
#include "session/condition_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include "atonlab/protocols/procedure.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/display/tonemap.h"
#include "session/scene_queries.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;

OverrideSource override_source(const p::Condition& c, const std::string& key, const std::string& text) {
    for (const auto* list : {&c.reference_set, &c.test_set, &c.set})
        for (auto it = list->rbegin(); it != list->rend(); ++it)
            if ((text.empty() ? it->key == key : it->text() == text) && it->line > 0) return {it->line, it->column};
    // The level, the display or a side-by-side position: the condition's own line.
    return {c.line, 0};
}

s::SceneOverride parsed_override(const p::Protocol& protocol, const std::string& text) {
    s::SceneOverride o = s::SceneOverride::parse(text);
    const std::vector<std::string> display = protocol.display_overrides();
    if (std::find(display.begin(), display.end(), text) != display.end())
        if (auto it = protocol.display.lines.find(o.key.substr(o.key.find('.') + 1));
            it != protocol.display.lines.end())
            o.origin = SourceLocation{protocol.file, it->second, 0, o.key};
    return o;
}

s::Scene condition_scene(const std::string& scene_text, const std::filesystem::path& scene_file,
                         const p::Protocol& protocol, const p::Condition& condition, const p::Frame& frame) {
    try {
        std::vector<s::SceneOverride> parsed;
        for (const std::string& o : frame.overrides) parsed.push_back(parsed_override(protocol, o));
        s::Scene scene = s::parse_scene(scene_text, scene_file.string(), parsed);
        // parse_scene has checked that the glare billboard fits the display
        // (GL-free, naming the keys), so a session refuses it before it opens anything.
        s::validate_output_settings(scene.output);
        return scene;
    } catch (const InputError& e) {
        const std::optional<SourceLocation>& w = e.where();
        const bool from_override = w && w->option == "--set";
        if (!from_override) {
            // The scene file's own error (it names its file and line), or a
            // setting that only the combination of overrides breaks.
            if (w && !w->file.empty() && w->file != scene_file.string()) throw;
            throw InputError(SourceLocation{protocol.file, condition.line, 0, w ? w->key : std::string()},
                             fmt::format("in condition \"{}\", the scene {} with this condition's overrides is "
                                         "refused: {}",
                                         condition.name, scene_file.filename().string(), e.message()));
        }
        // "--set KEY" (a value) or "--set" with the key: the override's key.
        std::string key = w->key;
        std::string text;
        for (const std::string& o : frame.overrides)
            if (o.compare(0, key.size() + 1, key + "=") == 0) text = o;
        const OverrideSource src = override_source(condition, key, text);
        throw InputError(SourceLocation{protocol.file, src.line, src.column, key},
                         fmt::format("in condition \"{}\" (line {}), the scene override '{}' is refused by the scene "
                                     "{}: {}",
                                     condition.name, condition.line, text.empty() ? key : text,
                                     scene_file.filename().string(), e.message()));
    }
}

void check_stimulus(const p::Protocol& protocol, const std::string& scene_text, const std::filesystem::path& scene_file,
                    const p::Condition& c, const p::Proposal& proposal) {
    const p::Stimulus stim = p::make_stimulus(protocol, c, proposal);
    for (std::size_t f = 0; f < stim.frames.size(); ++f) {
        const s::Scene scene = condition_scene(scene_text, scene_file, protocol, c, stim.frames[f]);
        for (const p::StimulusView& v : stim.views) {
            if (v.frame != f || v.light.empty()) continue;
            if (v.role == p::Role::Reference && !c.reference_disc.empty()) {
                if (find_disc(scene, v.light)) continue;
                std::string names;
                for (const s::Disc& d : scene.discs) names += (names.empty() ? "\"" : ", \"") + d.name + "\"";
                throw InputError(SourceLocation{protocol.file, c.line, 0, "reference_disc"},
                                 fmt::format("in condition \"{}\", the reference disc \"{}\" is not a [[disc]] of the "
                                             "scene {} (its discs: {}).",
                                             c.name, v.light, scene_file.filename().string(),
                                             names.empty() ? "none" : names));
            }
            if (find_light(scene, v.light)) continue;
            std::string names;
            for (const s::Light& l : scene.lights) names += (names.empty() ? "\"" : ", \"") + l.name + "\"";
            throw InputError(
                SourceLocation{protocol.file, c.line, 0, v.role == p::Role::Test ? "test_light" : "reference_light"},
                fmt::format("in condition \"{}\", the {} light \"{}\" is not a light of the scene {} (its lights: {}).",
                            c.name, p::to_string(v.role), v.light, scene_file.filename().string(),
                            names.empty() ? "none" : names));
        }
    }
}

void validate_conditions(const p::Protocol& protocol, const std::string& scene_text,
                         const std::filesystem::path& scene_file) {
    for (const p::Block& block : protocol.blocks) {
        for (const p::Condition& c : block.conditions) {
            std::unique_ptr<p::Procedure> proc;
            try {
                proc = p::make_procedure(c, 0);
            } catch (const p::ProcedureError& e) {
                throw InputError(SourceLocation{protocol.file, c.line, 0, e.parameter()},
                                 fmt::format("in condition \"{}\", {}", c.name, e.message()));
            }
            const std::optional<p::Proposal> first = proc->next();
            if (!first) continue;
            std::vector<double> levels{first->level};
            for (const double b : c.procedure.level_bounds()) levels.push_back(b);
            p::Proposal proposal = *first;
            for (const double level : levels) {
                proposal.level = level;
                if (c.task != p::Task::TwoAfc) {
                    check_stimulus(protocol, scene_text, scene_file, c, proposal);
                    continue;
                }
                for (const bool left : {true, false}) {
                    proposal.test_on_left = left;
                    check_stimulus(protocol, scene_text, scene_file, c, proposal);
                }
            }
        }
    }
}

}  // namespace atonlab::runner
