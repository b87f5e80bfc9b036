// Condition scenes and their load-time checks (condition_scene.h).
#include "session/condition_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/protocols/procedure.h"
#include "atonlab/runner/session/scene_queries.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;

namespace {

/// The frame's override an error is about: the last one written where the
/// error points (its origin's file, line and column), preferring the one of
/// the error's key (the level and the side-by-side positions share the
/// condition's line). nullptr when the error is at none of them.
const SceneOverride* refused_override(const p::Frame& frame, const SourceLocation& w) {
    const SceneOverride* found = nullptr;
    for (const SceneOverride& o : frame.overrides) {
        if (o.origin.file != w.file || o.origin.line != w.line || o.origin.column != w.column) continue;
        if (found == nullptr || found->key != w.key) found = &o;
    }
    return found;
}

}  // namespace

s::Scene condition_scene(const s::SceneTemplate& scene, const p::Protocol& protocol, const p::Condition& condition,
                         const p::Frame& frame) {
    const std::string scene_name = std::filesystem::path(scene.file_label()).filename().string();
    try {
        s::Scene made = scene.instantiate(frame.overrides);
        // The scene loader has checked that the glare billboard fits the display
        // (GL-free, naming the keys), so a session refuses it before it opens anything.
        s::validate_output_settings(made.output, made.adaptation_cd_m2);
        return made;
    } catch (const InputError& e) {
        const std::optional<SourceLocation>& w = e.where();
        const SceneOverride* refused = w ? refused_override(frame, *w) : nullptr;
        if (refused == nullptr) {
            // The scene file's own error (it names its file and line), or a
            // setting that only the combination of overrides breaks.
            if (w && !w->file.empty() && w->file != scene.file_label()) throw;
            throw InputError(SourceLocation{protocol.file, condition.line, 0, w ? w->key : std::string()},
                             fmt::format("in condition \"{}\", the scene {} with this condition's overrides is "
                                         "refused: {}",
                                         condition.name, scene_name, e.message()));
        }
        // A [display] value (a billboard too wide for the display) is the
        // protocol's, not the condition's: its error stands as it is.
        const std::vector<SceneOverride> display = protocol.display_overrides();
        if (std::find(display.begin(), display.end(), *refused) != display.end()) throw;
        // A value the condition gave (or made: its level, a side-by-side
        // position), already named at the line that wrote it.
        throw InputError(*w, fmt::format("in condition \"{}\" (line {}), the scene override '{}' is refused by the "
                                         "scene {}: {}",
                                         condition.name, condition.line, refused->text(), scene_name, e.message()));
    }
}

void check_stimulus(const p::Protocol& protocol, const s::SceneTemplate& scene_template, const p::Condition& c,
                    const p::Proposal& proposal) {
    const std::string scene_name = std::filesystem::path(scene_template.file_label()).filename().string();
    const p::Stimulus stim = p::make_stimulus(protocol, c, proposal);
    for (std::size_t f = 0; f < stim.frames.size(); ++f) {
        const s::Scene scene = condition_scene(scene_template, protocol, c, stim.frames[f]);
        for (const p::StimulusView& v : stim.views) {
            if (v.frame != f || v.light.empty()) continue;
            if (v.role == p::Role::Reference && !c.reference_disc.empty()) {
                if (find_disc(scene, v.light)) continue;
                std::string names;
                for (const s::Disc& d : scene.discs) names += (names.empty() ? "\"" : ", \"") + d.name + "\"";
                throw InputError(SourceLocation{protocol.file, c.line, 0, "reference_disc"},
                                 fmt::format("in condition \"{}\", the reference disc \"{}\" is not a [[disc]] of the "
                                             "scene {} (its discs: {}).",
                                             c.name, v.light, scene_name,
                                             names.empty() ? "none" : names));
            }
            if (find_light(scene, v.light)) continue;
            std::string names;
            for (const s::Light& l : scene.lights) names += (names.empty() ? "\"" : ", \"") + l.name + "\"";
            throw InputError(
                SourceLocation{protocol.file, c.line, 0, v.role == p::Role::Test ? "test_light" : "reference_light"},
                fmt::format("in condition \"{}\", the {} light \"{}\" is not a light of the scene {} (its lights: {}).",
                            c.name, p::to_string(v.role), v.light, scene_name,
                            names.empty() ? "none" : names));
        }
    }
}

void validate_conditions(const p::Protocol& protocol, const s::SceneTemplate& scene_template) {
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
                    check_stimulus(protocol, scene_template, c, proposal);
                    continue;
                }
                for (const bool left : {true, false}) {
                    proposal.test_on_left = left;
                    check_stimulus(protocol, scene_template, c, proposal);
                }
            }
        }
    }
}

}  // namespace atonlab::runner
