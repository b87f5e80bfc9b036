// The protocol file's single tables: [display], [timing], [screens] and
// [responses] (protocol_schema.h; docs/protocol-file.md).
#include <fmt/format.h>

#include <filesystem>
#include <set>

#include "atonlab/common/input_limits.h"
#include "atonlab/common/toml_text.h"
#include "atonlab/protocols/simulated_observer.h"
#include "protocol_schema.h"

namespace atonlab::protocols::detail {

// Key names (GLFW's key names, lower case with underscores) and gamepad buttons
// (GLFW_GAMEPAD_BUTTON_*).
const std::vector<std::string>& key_names() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> v;
        for (char c = 'a'; c <= 'z'; ++c) v.emplace_back(1, c);
        for (char c = '0'; c <= '9'; ++c) v.emplace_back(1, c);
        for (int i = 1; i <= 12; ++i) v.push_back(fmt::format("f{}", i));
        for (int i = 0; i <= 9; ++i) v.push_back(fmt::format("kp_{}", i));
        for (const char* s :
             {"left",         "right",         "up",        "down",        "space",       "enter",     "escape",
              "backspace",    "tab",           "insert",    "delete",      "home",        "end",       "page_up",
              "page_down",    "kp_enter",      "kp_add",    "kp_subtract", "kp_multiply", "kp_divide", "kp_decimal",
              "comma",        "period",        "slash",     "semicolon",   "apostrophe",  "minus",     "equal",
              "left_bracket", "right_bracket", "backslash", "grave_accent"})
            v.emplace_back(s);
        return v;
    }();
    return names;
}

std::string belongs_elsewhere(std::string_view key, std::string_view here) {
    auto in = [&](KeyList list) { return std::find(list.begin(), list.end(), key) != list.end(); };
    if (here.empty() && in(kConditionKeys))
        return fmt::format("'{}' belongs in [defaults] (or in a [[block]] or [[block.condition]]).", key);
    if (!in(kConditionKeys) && in(all_procedure_keys())) {
        if (here.empty() || here == "defaults")
            return fmt::format(
                "'{}' belongs in [defaults.procedure] (or a block's or condition's procedure "
                "table).",
                key);
        return fmt::format("'{}' belongs in the {}'s procedure table: procedure = {{ {} = ... }}.", key, here, key);
    }
    if (in(kProtocolKeys) && key != "adaptation_s" && key != "name")
        return fmt::format("'{}' belongs in [protocol].", key);
    if (in(kDisplayKeys) && key != "name") return fmt::format("'{}' belongs in [display].", key);
    if (in(kTimingKeys)) return fmt::format("'{}' belongs in [timing].", key);
    if (in(kScreenKeys)) return fmt::format("'{}' belongs in [screens].", key);
    return {};
}

void read_display(const Document& doc, const Section& root, Protocol& p) {
    const toml::table* t = root.table("display");
    if (t == nullptr)
        doc.fail_at_line(0, "display",
                          "the protocol file has no [display] table, which is required (the observer's display, "
                          "with the scene file's [display] keys).");
    Section s(doc, *t, "display", "the [display] table");
    s.allow(kDisplayKeys);
    auto px = [&](std::string_view key, std::string_view what) {
        // What every GL 4.5 context can allocate (common/input_limits.h).
        auto v = s.integer(key, 1, limits::kMaxDisplaySidePx);
        if (!v) s.missing(key, what);
        return *v;
    };
    p.display.width_px = px("width_px", "the display's width in pixels");
    p.display.height_px = px("height_px", "the display's height in pixels");
    const long long pixels = static_cast<long long>(p.display.width_px) * p.display.height_px;
    if (pixels > limits::kMaxDisplayPixels)
        s.fail("height_px", fmt::format("a display of {}×{} px has {} pixels, more than the {} (8192×8192) the "
                                        "renderer's full-frame targets are sized for.",
                                        p.display.width_px, p.display.height_px, pixels,
                                        limits::kMaxDisplayPixels));
    p.display.width_m = s.required_number("width_m", "the picture's visible width in metres");
    s.greater_than("width_m", p.display.width_m, 0.0);
    p.display.viewing_distance_m = s.required_number("viewing_distance_m", "eye to screen in metres");
    s.greater_than("viewing_distance_m", p.display.viewing_distance_m, 0.0);
    // Optional: which calibrated display this is, and how old its calibration may be.
    if (auto name = s.string("name")) {
        if (name->empty()) s.fail("name", "the display's name must not be empty (leave the key out instead).");
        p.display.name = *name;
    }
    if (auto days = s.number("max_calibration_age_days")) {
        s.greater_than("max_calibration_age_days", *days, 0.0);
        p.display.max_calibration_age_days = *days;
    }
    if (auto share = s.number("max_out_of_gamut_loss")) {
        s.within("max_out_of_gamut_loss", *share, 0.0, 1.0);
        p.display.max_out_of_gamut_loss = *share;
    }
    for (auto&& [k, v] : *t) p.display.lines[std::string(k.str())] = Document::line_of(&v);
}

void read_timing(const Document& doc, const Section& root, Protocol& p) {
    const toml::table* t = root.table("timing");
    if (t == nullptr) return;
    Section s(doc, *t, "timing", "the [timing] table");
    s.allow(kTimingKeys);
    if (auto v = s.number("stimulus_s")) {
        s.greater_than("stimulus_s", *v, 0.0);
        s.duration_at_most("stimulus_s", *v);
        p.timing.stimulus_s = *v;
    }
    if (auto v = s.number("inter_stimulus_s")) {
        s.at_least("inter_stimulus_s", *v, 0.0);
        s.duration_at_most("inter_stimulus_s", *v);
        p.timing.inter_stimulus_s = *v;
    }
    if (auto v = s.number("inter_trial_s")) {
        s.at_least("inter_trial_s", *v, 0.0);
        s.duration_at_most("inter_trial_s", *v);
        p.timing.inter_trial_s = *v;
    }
    if (auto v = s.number("response_timeout_s")) {
        s.greater_than("response_timeout_s", *v, 0.0);
        s.duration_at_most("response_timeout_s", *v);
        p.timing.response_timeout_s = *v;
    }
    if (const toml::node* n = s.get("repeat_missed"))
        p.timing.repeat_missed = doc.boolean(n, s.key_path("repeat_missed"));
    if (auto v = s.integer("max_missed_in_a_row", 1, 1000000)) p.timing.max_missed_in_a_row = *v;
    if (auto v = s.number("max_missed_fraction")) {
        if (!(*v > 0.0 && *v <= 1.0))
            s.fail("max_missed_fraction",
                   fmt::format("the share of a session's trials that may miss must be above 0 and at most 1, not {}.",
                               *v));
        p.timing.max_missed_fraction = *v;
    }
    if (auto v = s.number("refresh_hz")) {
        if (!(*v >= 1.0 && *v <= 1000.0))
            s.fail("refresh_hz", fmt::format("the refresh rate must be 1 to 1000 Hz, not {}.", *v));
        p.timing.refresh_hz = *v;
    }
    if (const toml::node* n = s.get("adaptation_skippable"))
        p.timing.adaptation_skippable = doc.boolean(n, s.key_path("adaptation_skippable"));
}

void read_observer(const Document& doc, const Section& root, Protocol& p) {
    const toml::table* t = root.table("observer");
    if (t == nullptr) return;
    Section s(doc, *t, "observer", "the [observer] table");
    std::vector<std::string_view> names;
    for (const ObserverKey& k : observer_keys()) names.push_back(k.name);
    s.allow(names);
    SimulatedObserverParams checked;  // each value checked against its key's range as it is read
    for (auto&& [k, v] : *t) {
        const std::string key(k.str());
        const double value = *s.number(key);
        const SourceLocation where{doc.file(), Document::line_of(&v), 0, s.key_path(key)};
        try {
            set_observer_key(checked, key, value, where);
        } catch (const InputError& e) {
            s.fail(key, e.message());
        }
        p.observer.push_back(ObserverSetting{key, value, where});
    }
}

void read_screens(const Document& doc, const Section& root, Protocol& p) {
    const toml::table* t = root.table("screens");
    if (t == nullptr) return;
    Section s(doc, *t, "screens", "the [screens] table");
    s.allow(kScreenKeys);
    p.screens.instructions = s.string("instructions").value_or("");
    p.screens.between = s.string("break").value_or("");
    p.screens.end = s.string("end").value_or("");
    if (auto v = s.number("text_cd_m2")) {
        s.greater_than("text_cd_m2", *v, 0.0);
        p.screens.text_cd_m2 = *v;
    }
    if (auto v = s.number("cue_cd_m2")) {
        s.greater_than("cue_cd_m2", *v, 0.0);
        p.screens.cue_cd_m2 = *v;
    }
    if (auto v = s.number("text_size_deg")) {
        if (!(*v >= 0.05 && *v <= 10.0))
            s.fail("text_size_deg",
                   fmt::format("a line of text must be 0.05 to 10 degrees of visual angle high, not {}.", *v));
        p.screens.text_size_deg = *v;
    }
    if (const toml::node* n = s.get("fixation")) p.screens.fixation = doc.boolean(n, s.key_path("fixation"));
}

/// No two actions used together share a key (or a button).
void check_conflicts(const Document& doc, const std::array<std::vector<std::string>, kActionCount>& table,
                     const std::array<const toml::node*, kActionCount>& nodes,
                     const std::array<std::string, kActionCount>& paths,
                     const std::vector<std::vector<Action>>& contexts, std::string_view what,
                     std::string_view table_path) {
    for (const auto& actions : contexts)
        for (std::size_t x = 0; x < actions.size(); ++x)
            for (std::size_t y = x + 1; y < actions.size(); ++y) {
                const auto a = static_cast<std::size_t>(actions[x]);
                const auto b = static_cast<std::size_t>(actions[y]);
                for (const std::string& name : table[a]) {
                    if (std::find(table[b].begin(), table[b].end(), name) == table[b].end()) continue;
                    // Report at the binding the file wrote (the later one if both).
                    const std::size_t at = nodes[b] != nullptr ? b : a;
                    const std::string message =
                        fmt::format("the {} \"{}\" is bound to both '{}' and '{}', which are used together.", what,
                                    name, to_string(actions[x]), to_string(actions[y]));
                    if (nodes[at] != nullptr) doc.fail(nodes[at], paths[at], message);
                    doc.fail_at_line(0, fmt::format("{}.{}", table_path, to_string(actions[y])), message);
                }
            }
}


void read_responses(const Document& doc, const Section& root, Protocol& p) {
    p.responses = ResponseMap::defaults();
    // Where the file bound each action (for conflict messages).
    std::array<const toml::node*, kActionCount> key_nodes{};
    std::array<std::string, kActionCount> key_paths{};
    std::array<const toml::node*, kActionCount> button_nodes{};
    std::array<std::string, kActionCount> button_paths{};
    const toml::table* t = root.table("responses");
    if (t != nullptr) {
        Section s(doc, *t, "responses", "the [responses] table");
        s.allow(kResponseKeys);
        auto read = [&](std::string_view sub, auto& table, auto& nodes, auto& paths, KeyList names,
                        std::string_view what) {
            const toml::table* st = s.table(sub);
            if (st == nullptr) return;
            Section ss(doc, *st, s.key_path(sub), fmt::format("the [responses.{}] table", sub));
            ss.allow(kActionNames);
            for (std::size_t a = 0; a < kActionCount; ++a) {
                const std::string_view action = kActionNames[a];
                const toml::node* n = ss.get(action);
                if (n == nullptr) continue;
                std::vector<std::string> v = doc.strings(n, ss.key_path(action));
                for (const std::string& name : v)
                    if (std::find(names.begin(), names.end(), name) == names.end())
                        doc.fail(n, ss.key_path(action),
                                  fmt::format("\"{}\" is not a {} name.{} See docs/protocol-file.md for the "
                                              "names.",
                                              name, what, text::did_you_mean(name, names)));
                table[a] = std::move(v);
                nodes[a] = n;
                paths[a] = ss.key_path(action);
            }
        };
        const auto& kn = key_names();
        const std::vector<std::string_view> key_views(kn.begin(), kn.end());
        read("keys", p.responses.keys, key_nodes, key_paths, KeyList(key_views), "key");
        read("gamepad", p.responses.buttons, button_nodes, button_paths, KeyList(kButtonNames), "gamepad button");
    }

    // Every action the protocol needs has a key, and no key means two things at once.
    std::set<Task> tasks;
    for (const Block& b : p.blocks)
        for (const Condition& c : b.conditions) tasks.insert(c.task);
    std::vector<std::vector<Action>> contexts;
    for (Task task : tasks) {
        std::vector<Action> v(task_actions(task).begin(), task_actions(task).end());
        v.push_back(Action::Quit);
        contexts.push_back(std::move(v));
    }
    contexts.push_back({Action::Continue, Action::Quit});
    for (const auto& actions : contexts)
        for (Action a : actions) {
            const auto i = static_cast<std::size_t>(a);
            if (p.responses.keys[i].empty()) {
                const std::string key = fmt::format("responses.keys.{}", to_string(a));
                if (key_nodes[i] != nullptr)
                    doc.fail(key_nodes[i], key,
                              fmt::format("'{}' needs at least one key: the protocol uses it.", to_string(a)));
                doc.fail_at_line(0, key, fmt::format("'{}' needs at least one key.", to_string(a)));
            }
        }
    check_conflicts(doc, p.responses.keys, key_nodes, key_paths, contexts, "key", "responses.keys");
    check_conflicts(doc, p.responses.buttons, button_nodes, button_paths, contexts, "gamepad button",
                    "responses.gamepad");
}

}  // namespace atonlab::protocols::detail
