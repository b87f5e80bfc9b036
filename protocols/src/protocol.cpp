// Protocol values: names of the enums, the response map, building a
// condition's procedures and the frames a proposal asks for (protocol.h).
#include "atonlab/protocols/protocol.h"

#include <fmt/format.h>


#include <algorithm>
#include <cmath>

namespace atonlab::protocols {

namespace {

/// Looks `text` up in a table of (name, value) pairs.
template <class E, std::size_t N>
std::optional<E> lookup(const std::pair<std::string_view, E> (&table)[N], std::string_view text) noexcept {
    for (const auto& [name, value] : table)
        if (name == text) return value;
    return std::nullopt;
}

template <class E, std::size_t N>
std::string_view name_of(const std::pair<std::string_view, E> (&table)[N], E e) noexcept {
    for (const auto& [name, value] : table)
        if (value == e) return name;
    return "?";
}

constexpr std::pair<std::string_view, Task> kTasks[] = {
    {"2afc", Task::TwoAfc}, {"yes-no", Task::YesNo}, {"adjust", Task::Adjust}};
constexpr std::pair<std::string_view, Presentation> kPresentations[] = {{"single", Presentation::Single},
                                                                        {"two-interval", Presentation::TwoInterval},
                                                                        {"side-by-side", Presentation::SideBySide}};
constexpr std::pair<std::string_view, LevelScale> kScales[] = {{"log10", LevelScale::Log10},
                                                               {"linear", LevelScale::Linear}};
constexpr std::pair<std::string_view, Role> kRoles[] = {{"test", Role::Test}, {"reference", Role::Reference}};
constexpr std::pair<std::string_view, Action> kActions[] = {{"left", Action::Left},
                                                            {"right", Action::Right},
                                                            {"yes", Action::Yes},
                                                            {"no", Action::No},
                                                            {"coarse_up", Action::CoarseUp},
                                                            {"coarse_down", Action::CoarseDown},
                                                            {"fine_up", Action::FineUp},
                                                            {"fine_down", Action::FineDown},
                                                            {"confirm", Action::Confirm},
                                                            {"continue", Action::Continue},
                                                            {"quit", Action::Quit}};

constexpr Action kTwoAfcActions[] = {Action::Left, Action::Right};
constexpr Action kYesNoActions[] = {Action::Yes, Action::No};
constexpr Action kAdjustActions[] = {Action::CoarseUp, Action::CoarseDown, Action::FineUp, Action::FineDown,
                                     Action::Confirm};

std::optional<Action> find_binding(const std::array<std::vector<std::string>, kActionCount>& table,
                                   std::span<const Action> actions, std::string_view name) {
    auto bound = [&](Action a) {
        const auto& names = table[static_cast<std::size_t>(a)];
        return std::find(names.begin(), names.end(), name) != names.end();
    };
    for (Action a : actions)
        if (bound(a)) return a;
    if (bound(Action::Quit)) return Action::Quit;
    return std::nullopt;
}

std::string number_text(double v) {
    return fmt::format("{}", v);
}

std::string position_text(const std::array<double, 3>& p) {
    return fmt::format("[{}, {}, {}]", number_text(p[0]), number_text(p[1]), number_text(p[2]));
}

void append(std::vector<SceneOverride>& out, const std::vector<SceneOverride>& overrides) {
    out.insert(out.end(), overrides.begin(), overrides.end());
}

}  // namespace

std::string_view to_string(Task t) noexcept {
    return name_of(kTasks, t);
}
std::optional<Task> parse_task(std::string_view text) noexcept {
    return lookup(kTasks, text);
}
std::string_view to_string(Presentation p) noexcept {
    return name_of(kPresentations, p);
}
std::optional<Presentation> parse_presentation(std::string_view text) noexcept {
    return lookup(kPresentations, text);
}
std::string_view to_string(LevelScale s) noexcept {
    return name_of(kScales, s);
}
std::optional<LevelScale> parse_level_scale(std::string_view text) noexcept {
    return lookup(kScales, text);
}
std::string_view to_string(Role r) noexcept {
    return name_of(kRoles, r);
}
std::optional<Role> parse_role(std::string_view text) noexcept {
    return lookup(kRoles, text);
}
std::string_view to_string(ProcedureKind k) noexcept {
    return procedure_type(k).name;
}
std::optional<ProcedureKind> parse_procedure_kind(std::string_view text) noexcept {
    const ProcedureType* t = find_procedure_type(text);
    return t ? std::optional<ProcedureKind>(t->kind) : std::nullopt;
}
std::string_view to_string(Action a) noexcept {
    return name_of(kActions, a);
}

std::optional<Response> response_of(Action a) noexcept {
    switch (a) {
        case Action::Left:
            return Response::Left;
        case Action::Right:
            return Response::Right;
        case Action::Yes:
            return Response::Yes;
        case Action::No:
            return Response::No;
        case Action::CoarseUp:
            return Response::CoarseUp;
        case Action::CoarseDown:
            return Response::CoarseDown;
        case Action::FineUp:
            return Response::FineUp;
        case Action::FineDown:
            return Response::FineDown;
        case Action::Confirm:
            return Response::Confirm;
        case Action::Continue:
        case Action::Quit:
            break;
    }
    return std::nullopt;
}

std::span<const Action> task_actions(Task t) noexcept {
    switch (t) {
        case Task::TwoAfc:
            return kTwoAfcActions;
        case Task::YesNo:
            return kYesNoActions;
        case Task::Adjust:
            return kAdjustActions;
    }
    return {};
}

ResponseMap ResponseMap::defaults() {
    ResponseMap m;
    auto set = [&m](Action a, std::vector<std::string> names) { m.keys[static_cast<std::size_t>(a)] = std::move(names); };
    set(Action::Left, {"left"});
    set(Action::Right, {"right"});
    set(Action::Yes, {"y"});
    set(Action::No, {"n"});
    set(Action::CoarseUp, {"up"});
    set(Action::CoarseDown, {"down"});
    set(Action::FineUp, {"right"});
    set(Action::FineDown, {"left"});
    set(Action::Confirm, {"enter", "space"});
    set(Action::Continue, {"space", "enter"});
    set(Action::Quit, {"escape"});
    return m;
}

std::optional<Action> ResponseMap::key_action(Task task, std::string_view key) const {
    return find_binding(keys, task_actions(task), key);
}

std::optional<Action> ResponseMap::button_action(Task task, std::string_view button) const {
    return find_binding(buttons, task_actions(task), button);
}

std::optional<Action> ResponseMap::screen_key_action(std::string_view key) const {
    constexpr Action kScreen[] = {Action::Continue};
    return find_binding(keys, kScreen, key);
}

std::optional<double> ProcedureSpec::target_p_yes() const {
    return type().target_p_yes(params);
}

std::vector<double> ProcedureSpec::level_bounds() const {
    return type().level_bounds(params);
}

std::pair<double, double> ProcedureSpec::level_range() const {
    const std::vector<double> bounds = level_bounds();
    if (bounds.size() == 2) return {std::min(bounds[0], bounds[1]), std::max(bounds[0], bounds[1])};
    return search_range();
}

std::pair<double, double> ProcedureSpec::search_range() const {
    return type().search_range(params, track_starts);
}

std::optional<std::size_t> ProcedureSpec::max_trials_per_track() const {
    return type().max_trials_per_track(params);
}

bool Condition::yes_means_level() const noexcept {
    return task != Task::TwoAfc || ((choice == ChoiceMapping::ChoseReference) == (level_on == Role::Reference));
}

double Condition::scene_value(double level) const {
    return level_scale == LevelScale::Log10 ? std::pow(10.0, level) : level;
}

const Condition* Protocol::find_condition(std::string_view condition_name) const {
    for (const Block& b : blocks)
        for (const Condition& c : b.conditions)
            if (c.name == condition_name) return &c;
    return nullptr;
}

std::vector<SceneOverride> Protocol::display_overrides() const {
    // Each at its [display] line; a value with no line there came from the
    // command line (`atonlab check --set display.KEY=VALUE`).
    const auto at_line = [&](const std::string& key, std::string value) {
        const std::string scene_key = "display." + key;
        const auto it = display.lines.find(key);
        SourceLocation origin = it == display.lines.end()
                                    ? SourceLocation::command_line(std::string(SceneOverride::kSetOption), scene_key)
                                    : SourceLocation{file, it->second, 0, scene_key};
        return SceneOverride{scene_key, std::move(value), std::move(origin)};
    };
    return {at_line("width_px", fmt::format("{}", display.width_px)),
            at_line("height_px", fmt::format("{}", display.height_px)),
            at_line("width_m", number_text(display.width_m)),
            at_line("viewing_distance_m", number_text(display.viewing_distance_m))};
}

std::vector<std::string> Frame::override_texts() const {
    std::vector<std::string> texts;
    texts.reserve(overrides.size());
    for (const SceneOverride& o : overrides) texts.push_back(o.text());
    return texts;
}

std::unique_ptr<Procedure> make_track(const Condition& condition, std::size_t track, std::uint64_t seed) {
    const ProcedureSpec& spec = condition.procedure;
    if (track >= spec.tracks())
        throw std::out_of_range(
            fmt::format("condition \"{}\" has {} track(s), not {}", condition.name, spec.tracks(), track + 1));
    const std::optional<double> start =
        spec.track_starts.empty() ? std::nullopt : std::optional<double>(spec.track_starts[track]);
    const std::uint64_t procedure_seed = derive_seed(seed, 0);
    std::unique_ptr<Procedure> p = spec.type().make(spec.params, start, procedure_seed);
    if (condition.task == Task::TwoAfc)
        return std::make_unique<ForcedChoice>(std::move(p), condition.choice, derive_seed(seed, 1));
    return p;
}

std::unique_ptr<Procedure> make_procedure(const Condition& condition, std::uint64_t seed) {
    const std::size_t n = condition.procedure.tracks();
    if (n == 1) return make_track(condition, 0, derive_seed(seed, 0));
    std::vector<std::unique_ptr<Procedure>> tracks;
    tracks.reserve(n);
    for (std::size_t t = 0; t < n; ++t) tracks.push_back(make_track(condition, t, derive_seed(seed, t)));
    return std::make_unique<Interleaver>(std::move(tracks), InterleaveOrder::Random, derive_seed(seed, n));
}

Stimulus make_stimulus(const Protocol& protocol, const Condition& condition, const Proposal& proposal) {
    Stimulus s;
    s.level = proposal.level;
    s.scene_value = condition.scene_value(proposal.level);
    // The values the protocol makes for the condition stand at its line.
    const auto made = [&](std::string key, std::string value, std::string_view from) {
        return SceneOverride{std::move(key), std::move(value),
                             SourceLocation{protocol.file, condition.line, 0, std::string(from)}};
    };
    const SceneOverride level_override = made(condition.level_key, number_text(s.scene_value), "level_key");
    const bool test_first = proposal.test_on_left.value_or(true);

    auto frame_for = [&](Role role) {
        Frame f;
        f.role = role;
        f.overrides = protocol.display_overrides();
        append(f.overrides, condition.set);
        append(f.overrides, role == Role::Test ? condition.test_set : condition.reference_set);
        if (condition.level_on == role) f.overrides.push_back(level_override);
        return f;
    };
    auto light_of = [&](Role role) { return condition.judged(role); };

    switch (condition.presentation) {
        case Presentation::Single:
            s.frames.push_back(frame_for(Role::Test));
            s.views.push_back({0, condition.test_light, Role::Test});
            break;
        case Presentation::TwoInterval: {
            const Role first = test_first ? Role::Test : Role::Reference;
            const Role second = test_first ? Role::Reference : Role::Test;
            s.frames.push_back(frame_for(first));
            s.frames.push_back(frame_for(second));
            s.views.push_back({0, light_of(first), first});
            s.views.push_back({1, light_of(second), second});
            break;
        }
        case Presentation::SideBySide: {
            Frame f;
            f.overrides = protocol.display_overrides();
            append(f.overrides, condition.set);
            append(f.overrides, condition.test_set);
            append(f.overrides, condition.reference_set);
            f.overrides.push_back(level_override);
            // The parser makes sure both positions and both lights are given.
            const std::array<double, 3> left = condition.left_position_m.value_or(std::array<double, 3>{});
            const std::array<double, 3> right = condition.right_position_m.value_or(std::array<double, 3>{});
            const char* const left_key = "left_position_m";
            const char* const right_key = "right_position_m";
            f.overrides.push_back(made(fmt::format("light.{}.position_m", condition.test_light),
                                       position_text(test_first ? left : right), test_first ? left_key : right_key));
            // A reference disc moves like a light (scene.h Disc: its centre's direction).
            const char* reference_table = condition.reference_disc.empty() ? "light" : "disc";
            f.overrides.push_back(
                made(fmt::format("{}.{}.position_m", reference_table, condition.judged(Role::Reference)),
                     position_text(test_first ? right : left), test_first ? right_key : left_key));
            s.frames.push_back(std::move(f));
            const Role left_role = test_first ? Role::Test : Role::Reference;
            const Role right_role = test_first ? Role::Reference : Role::Test;
            s.views.push_back({0, light_of(left_role), left_role});
            s.views.push_back({0, light_of(right_role), right_role});
            break;
        }
    }
    if (condition.task == Task::Adjust) {
        for (std::size_t i = 0; i < s.views.size(); ++i)
            if (s.views[i].role == condition.level_on) s.adjusted_view = i;
    }
    return s;
}

}  // namespace atonlab::protocols
