// The designs a simulation compares, and their tables (simulation_designs.h).
#include "simulate/simulation_designs.h"

#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <system_error>

#include "atonlab/common/atomic_file.h"
#include "atonlab/common/input_error.h"
#include "atonlab/common/read_file.h"
#include "atonlab/common/scene_override.h"
#include "atonlab/common/toml_value.h"
#include "atonlab/runner/displayability.h"
#include "atonlab/runner/session/scene_queries.h"
#include "atonlab/runner/session/session_inputs.h"
#include "atonlab/runner/session/true_value.h"
#include "atonlab/stimuli/gl/context.h"
#include "session/trial_record.h"
#include "simulate/protocol_variant.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace fs = std::filesystem;

namespace {

/// Every combination of the --vary values (one empty combination without --vary).
std::vector<std::vector<ProtocolSet>> combinations(const std::vector<std::string>& vary) {
    std::vector<std::vector<ProtocolSet>> out{{}};
    for (const std::string& v : vary) {
        std::vector<std::vector<ProtocolSet>> next;
        for (const std::vector<ProtocolSet>& head : out)
            for (const ProtocolSet& value : parse_vary(v)) {
                next.push_back(head);
                next.back().push_back(value);
            }
        out = std::move(next);
    }
    return out;
}

/// `--observer KEY=VALUE` over the protocol's [observer] table.
void apply_observer_options(p::SimulatedObserverParams& params, const std::vector<std::string>& options) {
    for (const std::string& text : options) {
        // The one reader of "key=value" (common/scene_override.h).
        const std::optional<KeyValue> kv = read_key_value(text);
        const std::string key = kv ? kv->key : text;
        const SourceLocation where = SourceLocation::command_line("--observer", key);
        if (!kv || kv->key.empty())
            throw InputError(where, fmt::format("--observer takes KEY=VALUE (e.g. eta=0.2), not \"{}\".", text));
        const std::optional<TomlValue>& v = kv->value;
        if (!v || !(v->node().is_floating_point() || v->node().is_integer()))
            throw InputError(where, fmt::format("the observer's {} takes a number, not \"{}\".", key, kv->text));
        set_observer_key(params, key, v->node().value<double>().value_or(0.0), where);
    }
}

/// Each condition's frame moments and view glare models, from the scene (no render).
void fill_frame_facts(SimulationDesign& d, const stimuli::SceneTemplate& scene_template) {
    for (const p::Block& b : d.protocol.blocks)
        for (const p::Condition& c : b.conditions) {
            if (c.task == p::Task::Adjust) continue;
            const auto [lo, hi] = c.procedure.level_range();
            for (int arrangement : {0, 1}) {
                if (arrangement == 1 && c.task != p::Task::TwoAfc) continue;
                if (d.frame_facts.count({c.name, arrangement})) continue;
                p::Proposal proposal;
                proposal.level = 0.5 * (lo + hi);
                if (c.task == p::Task::TwoAfc) proposal.test_on_left = arrangement == 1;
                const p::Stimulus stim = p::make_stimulus(d.protocol, c, proposal);
                FrameFacts facts;
                facts.view_glares.resize(stim.views.size());
                for (std::size_t f = 0; f < stim.frames.size(); ++f) {
                    const stimuli::Scene scene = scene_template.instantiate(stim.frames[f].overrides);
                    facts.frame_times_s.push_back(
                        brightest_moment_s(scene, judged_lights(stim, f), d.protocol.timing.stimulus_s));
                    for (std::size_t v = 0; v < stim.views.size(); ++v)
                        if (stim.views[v].frame == f) facts.view_glares[v] = view_glare(scene, stim.views[v].light);
                }
                d.frame_facts[{c.name, arrangement}] = std::move(facts);
            }
        }
}

/// The table's true values of each condition.
void fill_true_values(SimulationDesign& d) {
    for (const p::Block& b : d.protocol.blocks)
        for (const p::Condition& c : b.conditions) {
            std::string why;
            if (const std::optional<double> v = table_true_value(d.table, c, d.observer.model, why)) {
                d.model_true[c.name] = *v;
            } else {
                d.no_true[c.name] = why;
            }
        }
}

std::string label_of(const SimulateOptions& o, const std::string& protocol, const std::vector<ProtocolSet>& combo,
                     const std::vector<std::string>& vary_texts) {
    std::string label = o.protocols.size() > 1 ? fs::path(protocol).filename().string() : "";
    for (std::size_t i = 0; i < combo.size(); ++i) {
        // The key as the user wrote it: "max_trials=20", not the expanded path.
        const std::string& written = vary_texts[i];
        const std::string key = written.substr(0, written.find('='));
        label += (label.empty() ? "" : " ") + key + "=" + combo[i].value;
    }
    return label;
}

}  // namespace

std::vector<SimulationDesign> read_designs(const SimulateOptions& o) {
    std::vector<ProtocolSet> sets;
    for (const std::string& s : o.sets) sets.push_back(parse_protocol_set(s, "--set"));
    const std::vector<std::vector<ProtocolSet>> combos = combinations(o.vary);
    std::vector<SimulationDesign> designs;
    for (const std::string& file : o.protocols) {
        const std::string text = files::read_text(file, "protocol file");
        for (const std::vector<ProtocolSet>& combo : combos) {
            std::vector<ProtocolSet> all = sets;
            all.insert(all.end(), combo.begin(), combo.end());
            RunOptions ro;
            ro.protocol = file;
            if (!all.empty()) ro.protocol_text = protocol_with(text, file, all, combo.empty() ? "--set" : "--vary");
            SessionInputs in = load_session_inputs(ro);
            SimulationDesign d;
            d.index = designs.size();
            d.label = label_of(o, file, combo, o.vary);
            for (const ProtocolSet& s : all) d.overrides.push_back(s.text());
            d.protocol = std::move(in.protocol);
            d.protocol_path = file;
            d.protocol_text = std::move(in.protocol_text);
            d.protocol_name = fs::path(file).filename().string();
            d.scene_text = std::move(in.scene_text);
            d.scene_name = d.protocol.scene.filename().string();
            d.observer = p::observer_params(d.protocol);
            apply_observer_options(d.observer, o.observer);
            fill_frame_facts(d, *in.scene);
            d.table_key = table_key(d.protocol_text, d.scene_text, "", d.observer.model, o.table_bound);
            designs.push_back(std::move(d));
        }
    }
    return designs;
}

bool prepare_tables(std::vector<SimulationDesign>& designs, const SimulateOptions& o, const fs::path& cache) {
    std::unique_ptr<gl::Context> context;
    for (SimulationDesign& d : designs) {
        const std::string& key = d.table_key;
        const fs::path file = cache / (key + ".json");
        std::error_code ec;
        if (fs::exists(file, ec)) {
            try {
                d.table = DecisionTable::parse(files::read_text(file, "decision table"));
                if (d.table.key == key) {
                    fill_true_values(d);
                    if (!o.quiet) std::printf("simulate: design %zu: decision table %s (cached)\n", d.index,
                                              file.string().c_str());
                    continue;
                }
            } catch (const std::exception& e) {
                std::fprintf(stderr, "atonlab: warning: %s is not a usable decision table (%s); building it again\n",
                             file.string().c_str(), e.what());
            }
        }
        if (o.first)  // an array task: building here would race the other tasks and cost each the build
            throw InputError(SourceLocation::command_line("--first"),
                             fmt::format("design {}'s decision table {} is not in {}: a share of the sessions "
                                         "(--first) never builds a table; build it first with the same command "
                                         "without --first and --count (--slurm and --print-commands build it "
                                         "before any task runs).",
                                         d.index, file.filename().string(), cache.string()));
        if (!context) context = gl::create_headless_context();
        RunOptions ro;
        ro.protocol = d.protocol_path;
        ro.protocol_text = d.protocol_text;
        const SessionInputs in = load_session_inputs(ro);
        StimulusRenderer renderer(*in.scene, d.observer.model.window_radius_deg, d.protocol.timing.stimulus_s);
        const Displayability displayability = check_displayability(renderer, d.protocol);
        if (!displayability.displayable()) {
            if (!o.quiet) std::printf("%s", displayability_table(displayability).c_str());
            std::fprintf(stderr, "atonlab: %s\n", displayability_refusal(displayability, d.protocol_path).c_str());
            std::fprintf(stderr, "atonlab: nothing was written; change the protocol as said, or try it with "
                                 "`atonlab check %s`.\n",
                         d.protocol_path.c_str());
            return false;
        }
        auto progress = [&](std::size_t done, std::size_t total) {
            if (o.quiet) return;
            std::fprintf(stderr, "\rsimulate: design %zu: decision table, curve %zu of %zu (%zu frames rendered)",
                         d.index, done, total, renderer.frames_rendered());
            if (done == total) std::fprintf(stderr, "\n");
        };
        d.table = build_decision_table(renderer, d.protocol, d.observer.model, o.table_bound, progress);
        d.table.key = key;
        d.table.displayability_json = displayability_json(displayability, false);
        if (!o.quiet)
            std::printf("simulate: design %zu: decision table built from %zu frames in %.1f s (%zu levels): it holds the "
                        "decision variable to ±%.2g log10 brightness (asked for %.2g)%s\n",
                        d.index, d.table.renders, d.table.build_s,
                        [&] {
                            std::size_t n = 0;
                            for (const DecisionCurve& c : d.table.curves) n += c.levels.size();
                            return n;
                        }(),
                        d.table.stated_bound, d.table.bound,
                        d.table.bound_met ? ""
                                          : "; the rendered decision variable steps with the display's codes "
                                            "finer than that (docs/simulate.md)");
        fill_true_values(d);
    }
    return true;
}

void save_tables(const std::vector<SimulationDesign>& designs, const fs::path& cache) {
    fs::create_directories(cache);
    for (const SimulationDesign& d : designs)
        if (!d.table.key.empty()) files::write_file_atomically(cache / (d.table.key + ".json"), d.table.json());
}

void render_true_values(std::vector<SimulationDesign>& designs) {
    const std::unique_ptr<gl::Context> context = gl::create_headless_context();
    for (SimulationDesign& d : designs) {
        RunOptions ro;
        ro.protocol = d.protocol_path;
        ro.protocol_text = d.protocol_text;
        const SessionInputs in = load_session_inputs(ro);
        StimulusRenderer renderer(*in.scene, d.observer.model.window_radius_deg, d.protocol.timing.stimulus_s);
        for (const p::Block& b : d.protocol.blocks)
            for (const p::Condition& c : b.conditions) {
                double value = 0.0;
                const std::string why = true_value(renderer, d.protocol, c, d.observer.model, value);
                if (why.empty()) {
                    d.model_true[c.name] = value;
                } else {
                    d.no_true[c.name] = why;
                }
            }
    }
}

}  // namespace atonlab::runner
