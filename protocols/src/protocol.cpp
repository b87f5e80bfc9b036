// Protocol values: names of the enums, the response map, building a
// condition's procedures and the frames a proposal asks for (protocol.h).
#include "atonlab/protocols/protocol.h"

#include <fmt/format.h>


#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>

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
constexpr std::pair<std::string_view, ProcedureKind> kKinds[] = {
    {"staircase", ProcedureKind::Staircase},
    {"weighted-staircase", ProcedureKind::WeightedStaircase},
    {"quest", ProcedureKind::Quest},
    {"adjustment", ProcedureKind::Adjustment},
    {"constant-stimuli", ProcedureKind::ConstantStimuli}};
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

void append(std::vector<Override>& out, const std::vector<Override>& overrides) {
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
    return name_of(kKinds, k);
}
std::optional<ProcedureKind> parse_procedure_kind(std::string_view text) noexcept {
    return lookup(kKinds, text);
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
    return std::visit(
        [](const auto& p) -> std::optional<double> {
            using T = std::decay_t<decltype(p)>;
            if constexpr (std::is_same_v<T, WeightedStaircaseParams>) {
                return p.target;  // Kaernbach 1991
            } else if constexpr (std::is_same_v<T, StaircaseParams>) {
                if (p.up_step_ratio != 1.0) return std::nullopt;
                // Levitt 1971: 1-up/n-down converges on p^n = 0.5, n-up/1-down on (1 - p)^n = 0.5.
                if (p.n_up == 1) return std::pow(0.5, 1.0 / static_cast<double>(p.n_down));
                if (p.n_down == 1) return 1.0 - std::pow(0.5, 1.0 / static_cast<double>(p.n_up));
                return std::nullopt;
            } else if constexpr (std::is_same_v<T, QuestParams>) {
                return p.p_threshold;
            } else if constexpr (std::is_same_v<T, ConstantStimuliParams>) {
                return p.criterion;
            } else {
                return 0.5;  // adjustment: a match
            }
        },
        params);
}

std::vector<double> ProcedureSpec::level_bounds() const {
    return std::visit(
        [](const auto& p) -> std::vector<double> {
            using T = std::decay_t<decltype(p)>;
            std::vector<double> out;
            if constexpr (std::is_same_v<T, ConstantStimuliParams>) {
                if (!p.levels.empty()) {
                    const auto [lo, hi] = std::minmax_element(p.levels.begin(), p.levels.end());
                    out = {*lo, *hi};
                }
            } else {
                if (p.min_level) out.push_back(*p.min_level);
                if (p.max_level) out.push_back(*p.max_level);
            }
            return out;
        },
        params);
}

std::pair<double, double> ProcedureSpec::level_range() const {
    const std::vector<double> bounds = level_bounds();
    if (bounds.size() == 2) return {std::min(bounds[0], bounds[1]), std::max(bounds[0], bounds[1])};
    return search_range();
}

std::pair<double, double> ProcedureSpec::search_range() const {
    return std::visit(
        [&](const auto& p) -> std::pair<double, double> {
            using T = std::decay_t<decltype(p)>;
            if constexpr (std::is_same_v<T, ConstantStimuliParams>) {
                if (p.levels.empty()) return {-1.0, 1.0};
                const auto [lo, hi] = std::minmax_element(p.levels.begin(), p.levels.end());
                return {*lo - 1.0, *hi + 1.0};
            } else if constexpr (std::is_same_v<T, AdjustmentParams>) {
                return {p.min_level.value_or(p.start_min - 2.0), p.max_level.value_or(p.start_max + 2.0)};
            } else {
                double first = 0.0;
                if constexpr (std::is_same_v<T, QuestParams>)
                    first = p.t_guess;
                else
                    first = p.start;
                double lo = first, hi = first;
                for (const double v : track_starts) {
                    lo = std::min(lo, v);
                    hi = std::max(hi, v);
                }
                return {p.min_level.value_or(lo - 3.0), p.max_level.value_or(hi + 3.0)};
            }
        },
        params);
}

std::optional<std::size_t> ProcedureSpec::max_trials_per_track() const {
    return std::visit(
        [](const auto& p) -> std::optional<std::size_t> {
            using T = std::decay_t<decltype(p)>;
            if constexpr (std::is_same_v<T, StaircaseParams> || std::is_same_v<T, WeightedStaircaseParams>) {
                if (p.max_trials) return static_cast<std::size_t>(*p.max_trials);
                return std::nullopt;
            } else if constexpr (std::is_same_v<T, QuestParams>) {
                return static_cast<std::size_t>(p.n_trials);
            } else if constexpr (std::is_same_v<T, ConstantStimuliParams>) {
                return p.levels.size() * static_cast<std::size_t>(p.repetitions);
            } else {
                return std::nullopt;
            }
        },
        params);
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

std::vector<Override> Protocol::display_overrides() const {
    // Each at its [display] line; a value with no line there came from the
    // command line (`atonlab check --set display.KEY=VALUE`).
    const auto at_line = [&](const std::string& key, std::string value) {
        const std::string scene_key = "display." + key;
        const auto it = display.lines.find(key);
        SourceLocation origin = it == display.lines.end()
                                    ? SourceLocation::command_line(std::string(Override::kSetOption), scene_key)
                                    : SourceLocation{file, it->second, 0, scene_key};
        return Override{scene_key, std::move(value), std::move(origin)};
    };
    return {at_line("width_px", fmt::format("{}", display.width_px)),
            at_line("height_px", fmt::format("{}", display.height_px)),
            at_line("width_m", number_text(display.width_m)),
            at_line("viewing_distance_m", number_text(display.viewing_distance_m))};
}

std::vector<std::string> Frame::override_texts() const {
    std::vector<std::string> texts;
    texts.reserve(overrides.size());
    for (const Override& o : overrides) texts.push_back(o.text());
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
    std::unique_ptr<Procedure> p = std::visit(
        [&](const auto& params) -> std::unique_ptr<Procedure> {
            using P = std::decay_t<decltype(params)>;
            P q = params;
            if constexpr (std::is_same_v<P, StaircaseParams>) {
                if (start) q.start = *start;
                return std::make_unique<Staircase>(std::move(q), procedure_seed);
            } else if constexpr (std::is_same_v<P, WeightedStaircaseParams>) {
                if (start) q.start = *start;
                return std::make_unique<WeightedStaircase>(q, procedure_seed);
            } else if constexpr (std::is_same_v<P, QuestParams>) {
                if (start) q.t_guess = *start;
                return std::make_unique<Quest>(std::move(q), procedure_seed);
            } else if constexpr (std::is_same_v<P, AdjustmentParams>) {
                return std::make_unique<Adjustment>(std::move(q), procedure_seed);
            } else {
                return std::make_unique<ConstantStimuli>(std::move(q), procedure_seed);
            }
        },
        spec.params);
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
        return Override{std::move(key), std::move(value),
                        SourceLocation{protocol.file, condition.line, 0, std::string(from)}};
    };
    const Override level_override = made(condition.level_key, number_text(s.scene_value), "level_key");
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
