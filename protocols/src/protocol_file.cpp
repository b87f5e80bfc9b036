// The protocol file (protocol_file.h; every key in docs/protocol-file.md).
// Three steps: parse the TOML text (syntax errors keep the parser's line), read
// every table of the schema strictly, then build each condition's procedures
// once so that the procedures' own parameter checks (ProcedureError) are
// reported at the line of the offending key.
#include "atonlab/protocols/protocol_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <system_error>

#include "atonlab/common/input_limits.h"
#include "atonlab/common/input_text.h"
#include "atonlab/common/toml_text.h"
#include "protocol_reader.h"

namespace atonlab::protocols {

namespace {

using detail::Document;
using detail::KeyList;
using detail::Section;

constexpr std::string_view kRootKeys[] = {"protocol", "display", "timing", "responses", "screens", "defaults", "block"};
constexpr std::string_view kProtocolKeys[] = {"name", "description", "scene", "seed", "adaptation_s"};
constexpr std::string_view kDisplayKeys[] = {"width_px",           "height_px", "width_m",
                                             "viewing_distance_m", "name",      "max_calibration_age_days"};
constexpr std::string_view kTimingKeys[] = {"stimulus_s",          "inter_stimulus_s", "inter_trial_s",
                                            "response_timeout_s",  "repeat_missed",    "refresh_hz",
                                            "adaptation_skippable"};
constexpr std::string_view kScreenKeys[] = {"instructions", "break",         "end",     "text_cd_m2",
                                            "cue_cd_m2",    "text_size_deg", "fixation"};
constexpr std::string_view kResponseKeys[] = {"keys", "gamepad"};
constexpr std::string_view kActionNames[] = {"left",    "right",     "yes",     "no",       "coarse_up", "coarse_down",
                                             "fine_up", "fine_down", "confirm", "continue", "quit"};

// Condition keys may be written in [defaults], in a [[block]] (for all its
// conditions) or in the [[block.condition]] itself; the nearest wins, and the
// override lists add up.
constexpr std::string_view kConditionKeys[] = {
    "task",        "presentation", "prompt", "set",        "test_set",        "reference_set",   "level_key",
    "level_scale", "level_on",     "choice", "test_light", "reference_light", "left_position_m", "right_position_m",
    "procedure",   "reference_disc"};
constexpr std::string_view kBlockOwnKeys[] = {"name",         "adaptation_s", "repetitions",    "interleave",
                                              "instructions", "condition",    "conditions_file"};

constexpr std::string_view kStaircaseKeys[] = {
    "kind",        "start",    "step_sizes", "step_type", "n_up",      "n_down",        "apply_initial_rule",
    "n_reversals", "n_trials", "max_trials", "min_level", "max_level", "up_step_ratio", "estimate_reversals"};
constexpr std::string_view kWeightedKeys[] = {
    "kind",     "start",      "target",    "step_sizes", "step_type",         "n_reversals",
    "n_trials", "max_trials", "min_level", "max_level",  "estimate_reversals"};
constexpr std::string_view kQuestKeys[] = {
    "kind",  "t_guess", "t_guess_sd",     "p_threshold", "beta",          "delta",     "gamma",     "grain",
    "range", "method",  "quantile_order", "n_trials",    "stop_interval", "min_level", "max_level", "first_at_guess"};
constexpr std::string_view kAdjustmentKeys[] = {"kind",      "start_min", "start_max", "coarse_step",
                                                "fine_step", "min_level", "max_level", "n_trials"};
constexpr std::string_view kConstantKeys[] = {"kind", "levels", "repetitions", "order", "criterion"};
constexpr std::string_view kKindNames[] = {"staircase", "weighted-staircase", "quest", "adjustment",
                                           "constant-stimuli"};

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
constexpr std::string_view kButtonNames[] = {
    "a",     "b",          "x",           "y",       "left_bumper", "right_bumper", "back",     "start",
    "guide", "left_thumb", "right_thumb", "dpad_up", "dpad_right",  "dpad_down",    "dpad_left"};

std::string strip_period(std::string s) {
    while (!s.empty() && s.back() == '.') s.pop_back();
    return s;
}

// ---------------------------------------------------------------------------
// A condition's keys, looked up from the most specific table outwards.

struct Found {
    const toml::node* node = nullptr;
    std::string key;  ///< dotted path where it was written
};

struct Layer {
    const toml::table* table = nullptr;  ///< may be null ([defaults] absent)
    std::string path;                    ///< "defaults", "block[0]", "block[0].condition[1]"
};

class ConditionReader {
public:
    ConditionReader(const Document& doc, std::vector<Layer> outer_to_inner, std::string name, int line)
        : doc_(doc), layers_(std::move(outer_to_inner)), name_(std::move(name)), line_(line) {
        context_ = fmt::format("in condition \"{}\", ", name_);
    }

    const std::string& context() const noexcept { return context_; }
    const Layer& own() const { return layers_.back(); }

    std::optional<Found> find(std::string_view key) const {
        for (auto it = layers_.rbegin(); it != layers_.rend(); ++it)
            if (it->table != nullptr)
                if (const toml::node* n = it->table->get(key)) return Found{n, it->path + "." + std::string(key)};
        return std::nullopt;
    }

    /// Every layer's value of a list key, outer first.
    std::vector<Found> find_all(std::string_view key) const {
        std::vector<Found> out;
        for (const Layer& l : layers_)
            if (l.table != nullptr)
                if (const toml::node* n = l.table->get(key)) out.push_back(Found{n, l.path + "." + std::string(key)});
        return out;
    }

    [[noreturn]] void missing(std::string_view key, std::string_view what) const {
        doc_.fail_at_line(line_, own().path + "." + std::string(key),
                          fmt::format("condition \"{}\" (line {}) has no '{}', which is required ({}); give it in "
                                      "the condition, its [[block]] or [defaults].",
                                      name_, line_, key, what));
    }
    [[noreturn]] void fail(const Found& f, const std::string& message) const {
        doc_.fail(f.node, f.key, context_ + message);
    }
    [[noreturn]] void fail_condition(std::string_view key, const std::string& message) const {
        doc_.fail_at_line(line_, own().path + "." + std::string(key), context_ + message);
    }

    std::optional<std::string> string(std::string_view key) const {
        auto f = find(key);
        if (!f) return std::nullopt;
        return doc_.string(f->node, f->key, context_);
    }

    /// An enumerated string value.
    template <class E>
    std::optional<E> choice(std::string_view key, std::optional<E> (*parse)(std::string_view) noexcept,
                            KeyList allowed) const {
        auto f = find(key);
        if (!f) return std::nullopt;
        const std::string text = doc_.string(f->node, f->key, context_);
        if (auto e = parse(text)) return e;
        fail(*f, fmt::format("{} must be one of {}, got \"{}\".", key, toml_reader::join_quoted(allowed), text));
    }

private:
    const Document& doc_;
    std::vector<Layer> layers_;
    std::string name_;
    int line_;
    std::string context_;
};

// ---------------------------------------------------------------------------
// The procedure table, merged over the layers.

KeyList keys_of(ProcedureKind k) {
    switch (k) {
        case ProcedureKind::Staircase:
            return kStaircaseKeys;
        case ProcedureKind::WeightedStaircase:
            return kWeightedKeys;
        case ProcedureKind::Quest:
            return kQuestKeys;
        case ProcedureKind::Adjustment:
            return kAdjustmentKeys;
        case ProcedureKind::ConstantStimuli:
            return kConstantKeys;
    }
    return {};
}

const std::vector<std::string_view>& all_procedure_keys() {
    static const std::vector<std::string_view> all = [] {
        std::set<std::string_view> s;
        for (auto list : {KeyList(kStaircaseKeys), KeyList(kWeightedKeys), KeyList(kQuestKeys),
                          KeyList(kAdjustmentKeys), KeyList(kConstantKeys)})
            s.insert(list.begin(), list.end());
        return std::vector<std::string_view>(s.begin(), s.end());
    }();
    return all;
}

class ProcedureReader {
public:
    ProcedureReader(const Document& doc, const ConditionReader& cond) : doc_(doc), cond_(cond) {}

    /// Merges the layers' procedure tables. A layer that names a different
    /// kind from the one inherited starts afresh.
    void merge(const std::vector<Found>& tables) {
        for (const Found& f : tables) {
            if (!f.node->is_table())
                doc_.fail(f.node, f.key,
                          cond_.context() + fmt::format("expected a procedure table (procedure = {{ kind = "
                                                        "\"staircase\", ... }}), got {}.",
                                                        text::type_phrase(f.node->type())));
            const toml::table& t = *f.node->as_table();
            table_ = f;
            if (const toml::node* k = t.get("kind")) {
                const std::string text = doc_.string(k, f.key + ".kind", cond_.context());
                const auto parsed = parse_procedure_kind(text);
                if (!parsed)
                    doc_.fail(k, f.key + ".kind",
                              cond_.context() + fmt::format("kind must be one of {}, got \"{}\".",
                                                            toml_reader::join_quoted(kKindNames), text));
                if (kind_ && *kind_ != *parsed) entries_.clear();
                kind_ = parsed;
                kind_at_ = Found{k, f.key + ".kind"};
            }
            const KeyList allowed = kind_ ? keys_of(*kind_) : KeyList(all_procedure_keys());
            for (auto&& [key, value] : t) {
                if (std::find(allowed.begin(), allowed.end(), key.str()) == allowed.end()) {
                    const std::string what =
                        kind_ ? fmt::format("a {} procedure", to_string(*kind_)) : std::string("a procedure");
                    if (std::find(std::begin(kConditionKeys), std::end(kConditionKeys), key.str()) !=
                        std::end(kConditionKeys))
                        doc_.fail_at_key(
                            key, f.key + "." + std::string(key.str()),
                            cond_.context() + fmt::format("'{}' is not a key of {}: it belongs beside the procedure, "
                                                          "in [defaults], a [[block]] or a [[block.condition]].",
                                                          key.str(), what));
                    doc_.fail_at_key(
                        key, f.key + "." + std::string(key.str()),
                        cond_.context() + fmt::format("unknown key '{}' in {}.{} Allowed keys: {}.", key.str(), what,
                                                      text::did_you_mean(key.str(), allowed),
                                                      toml_reader::join_quoted(allowed)));
                }
                if (key.str() != "kind")
                    entries_[std::string(key.str())] = Found{&value, f.key + "." + std::string(key.str())};
            }
        }
    }

    std::optional<ProcedureKind> kind() const { return kind_; }
    const std::optional<Found>& kind_at() const { return kind_at_; }
    const std::optional<Found>& table() const { return table_; }

    const Found* entry(std::string_view key) const {
        auto it = entries_.find(std::string(key));
        return it == entries_.end() ? nullptr : &it->second;
    }
    bool has(std::string_view key) const { return entry(key) != nullptr; }

    /// Where a parameter error is reported: at the key when it was written,
    /// else at the nearest procedure table.
    [[noreturn]] void fail(std::string_view key, const std::string& message) const {
        if (const Found* f = entry(key)) doc_.fail(f->node, f->key, cond_.context() + message);
        doc_.fail(table_->node, table_->key + "." + std::string(key), cond_.context() + message);
    }

    std::optional<double> number(std::string_view key) const {
        const Found* f = entry(key);
        return f ? std::optional<double>(doc_.number(f->node, f->key, key, cond_.context())) : std::nullopt;
    }
    void number(std::string_view key, double& out) const {
        if (auto v = number(key)) out = *v;
    }
    void number(std::string_view key, std::optional<double>& out) const {
        if (auto v = number(key)) out = *v;
    }
    std::optional<int> integer(std::string_view key) const {
        const Found* f = entry(key);
        if (f == nullptr) return std::nullopt;
        return doc_.integer(f->node, f->key, key, std::numeric_limits<int>::min(), std::numeric_limits<int>::max(),
                            cond_.context());
    }
    void integer(std::string_view key, int& out) const {
        if (auto v = integer(key)) out = *v;
    }
    void integer(std::string_view key, std::optional<int>& out) const {
        if (auto v = integer(key)) out = *v;
    }
    void boolean(std::string_view key, bool& out) const {
        if (const Found* f = entry(key)) out = doc_.boolean(f->node, f->key, cond_.context());
    }
    std::optional<std::string> string(std::string_view key) const {
        const Found* f = entry(key);
        return f ? std::optional<std::string>(doc_.string(f->node, f->key, cond_.context())) : std::nullopt;
    }
    std::optional<std::vector<double>> numbers(std::string_view key, bool scalar_ok) const {
        const Found* f = entry(key);
        if (f == nullptr) return std::nullopt;
        return doc_.numbers(f->node, f->key, key, scalar_ok, cond_.context());
    }

    /// A start that may be a list (one interleaved track per entry).
    void starts(std::string_view key, double& first, std::vector<double>& tracks) const {
        const Found* f = entry(key);
        if (f == nullptr)
            fail(key, fmt::format("the {} procedure has no '{}', which is required.", to_string(*kind_), key));
        std::vector<double> v = doc_.numbers(f->node, f->key, key, true, cond_.context());
        first = v.front();
        if (f->node->is_array()) tracks = std::move(v);
    }

    void require_stop_rule(std::initializer_list<std::string_view> keys, std::string_view what) const {
        for (std::string_view k : keys)
            if (has(k)) return;
        // Reported at the condition's own procedure table (or the one it inherits).
        doc_.fail(
            table_->node, table_->key,
            cond_.context() + fmt::format("the {} procedure has no stop rule: give {}.", to_string(*kind_), what));
    }

private:
    const Document& doc_;
    const ConditionReader& cond_;
    std::optional<ProcedureKind> kind_;
    std::optional<Found> kind_at_;
    std::optional<Found> table_;
    std::map<std::string, Found> entries_;
};

ProcedureSpec read_procedure(const ProcedureReader& r) {
    ProcedureSpec spec;
    spec.kind = *r.kind();
    switch (spec.kind) {
        case ProcedureKind::Staircase: {
            StaircaseParams p;
            r.starts("start", p.start, spec.track_starts);
            if (auto v = r.numbers("step_sizes", true)) p.step_sizes = *v;
            if (auto s = r.string("step_type")) p.step_type = parse_step_type(*s);
            r.integer("n_up", p.n_up);
            r.integer("n_down", p.n_down);
            r.boolean("apply_initial_rule", p.apply_initial_rule);
            r.integer("n_reversals", p.n_reversals);
            r.integer("n_trials", p.n_trials);
            r.integer("max_trials", p.max_trials);
            r.number("min_level", p.min_level);
            r.number("max_level", p.max_level);
            r.number("up_step_ratio", p.up_step_ratio);
            r.integer("estimate_reversals", p.estimate_reversals);
            r.require_stop_rule({"n_reversals", "n_trials", "max_trials"}, "n_reversals, n_trials or max_trials");
            spec.params = std::move(p);
            break;
        }
        case ProcedureKind::WeightedStaircase: {
            WeightedStaircaseParams p;
            r.starts("start", p.start, spec.track_starts);
            r.number("target", p.target);
            if (auto v = r.numbers("step_sizes", true)) p.step_sizes = *v;
            if (auto s = r.string("step_type")) p.step_type = parse_step_type(*s);
            r.integer("n_reversals", p.n_reversals);
            r.integer("n_trials", p.n_trials);
            r.integer("max_trials", p.max_trials);
            r.number("min_level", p.min_level);
            r.number("max_level", p.max_level);
            r.integer("estimate_reversals", p.estimate_reversals);
            r.require_stop_rule({"n_reversals", "n_trials", "max_trials"}, "n_reversals, n_trials or max_trials");
            spec.params = std::move(p);
            break;
        }
        case ProcedureKind::Quest: {
            QuestParams p;
            r.starts("t_guess", p.t_guess, spec.track_starts);
            r.number("t_guess_sd", p.t_guess_sd);
            r.number("p_threshold", p.p_threshold);
            r.number("beta", p.beta);
            r.number("delta", p.delta);
            r.number("gamma", p.gamma);
            r.number("grain", p.grain);
            r.number("range", p.range);
            if (auto s = r.string("method")) p.method = parse_quest_method(*s);
            r.number("quantile_order", p.quantile_order);
            r.integer("n_trials", p.n_trials);
            r.number("stop_interval", p.stop_interval);
            r.number("min_level", p.min_level);
            r.number("max_level", p.max_level);
            r.boolean("first_at_guess", p.first_at_guess);
            r.require_stop_rule({"n_trials"}, "n_trials (and, if you like, stop_interval)");
            spec.params = std::move(p);
            break;
        }
        case ProcedureKind::Adjustment: {
            AdjustmentParams p;
            if (!r.has("start_min"))
                r.fail("start_min", "the adjustment procedure has no 'start_min', which is required.");
            if (!r.has("start_max"))
                r.fail("start_max", "the adjustment procedure has no 'start_max', which is required.");
            r.number("start_min", p.start_min);
            r.number("start_max", p.start_max);
            r.number("coarse_step", p.coarse_step);
            r.number("fine_step", p.fine_step);
            r.number("min_level", p.min_level);
            r.number("max_level", p.max_level);
            r.integer("n_trials", p.n_trials);
            r.require_stop_rule({"n_trials"}, "n_trials (the matches to make)");
            spec.params = std::move(p);
            break;
        }
        case ProcedureKind::ConstantStimuli: {
            ConstantStimuliParams p;
            auto levels = r.numbers("levels", false);
            if (!levels) r.fail("levels", "the constant-stimuli procedure has no 'levels', which is required.");
            p.levels = std::move(*levels);
            r.integer("repetitions", p.repetitions);
            if (auto s = r.string("order")) p.order = parse_constant_order(*s);
            r.number("criterion", p.criterion);
            spec.params = std::move(p);
            break;
        }
    }
    return spec;
}

// ---------------------------------------------------------------------------
// The whole file.

class Parser {
public:
    explicit Parser(std::string file) : doc_(std::move(file)) {}

    Protocol parse(std::string_view text, bool check_scene_exists) {
        try {
            root_ = toml::parse(text, doc_.file());
        } catch (const toml::parse_error& e) {
            throw InputError(SourceLocation{doc_.file(), static_cast<int>(e.source().begin.line),
                                            static_cast<int>(e.source().begin.column), ""},
                             fmt::format("TOML syntax error: {}.", strip_period(std::string(e.description()))));
        }
        text_ = std::string(text);
        step([&] { expand_conditions_files(); });
        // Every table is read even after an error in another (and every
        // condition after an error in one): all the errors, in file order, in
        // one run (text::ErrorList; docs/protocol-file.md "Errors").
        doc_.collect_into(&errors_);
        Section root(doc_, root_, "", "the protocol file");
        step([&] { root.allow(kRootKeys, [](std::string_view k) { return belongs_elsewhere(k, ""); }); });

        Protocol p;
        p.file = doc_.file();
        step([&] { read_header(root, p, check_scene_exists); });
        step([&] { read_display(root, p); });
        step([&] { read_timing(root, p); });
        step([&] { read_screens(root, p); });
        step([&] { read_blocks(root, p); });
        step([&] { read_responses(root, p); });
        doc_.collect_into(nullptr);
        errors_.throw_if_any();
        return p;
    }

private:
    // --- Conditions files -------------------------------------------------------------

    /// A CSV cell as TOML: the text itself when it is one TOML value (a number,
    /// true / false, an array), else a TOML string of it.
    static std::string toml_value(const std::string& cell, bool always_string) {
        if (!always_string) {
            try {
                (void)toml::parse("v = " + cell);
                return cell;
            } catch (const toml::parse_error&) {
            }
        }
        return toml_string(cell);
    }
    static std::string toml_string(std::string_view text) {
        std::string q = "\"";
        for (const char ch : text) {
            if (ch == '"' || ch == '\\') q += '\\';
            q += ch;
        }
        return q + "\"";
    }

    /// One CSV line split into fields (RFC 4180 quoting; a field may not span lines).
    static std::optional<std::vector<std::string>> csv_fields(std::string_view line, std::string& error) {
        std::vector<std::string> out;
        std::string field;
        bool quoted = false, was_quoted = false;
        for (std::size_t i = 0; i < line.size(); ++i) {
            const char ch = line[i];
            if (quoted) {
                if (ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
                    field += '"';
                    ++i;
                } else if (ch == '"') {
                    quoted = false;
                } else {
                    field += ch;
                }
            } else if (ch == '"' && field.empty() && !was_quoted) {
                quoted = was_quoted = true;
            } else if (ch == ',') {
                out.push_back(was_quoted ? field : std::string(trim_blanks(field)));
                field.clear();
                was_quoted = false;
            } else {
                field += ch;
            }
        }
        if (quoted) {
            error = "a quoted field is not closed on its line (a field may not span lines).";
            return std::nullopt;
        }
        out.push_back(was_quoted ? field : std::string(trim_blanks(field)));
        return out;
    }
    static std::string_view trim_blanks(std::string_view s) {
        while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
        while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
        return s;
    }

    /// The CSV text stored after "#@conditions_file NAME" in the protocol text, if any.
    std::optional<std::string> embedded_csv(const std::string& name) const {
        const std::string tag = "\n#@conditions_file " + name + "\n";
        std::size_t at = text_.find(tag);
        if (at == std::string::npos) return std::nullopt;
        at += tag.size();
        std::string out;
        while (at < text_.size() && text_.compare(at, 3, "#@|") == 0) {
            const std::size_t end = std::min(text_.find('\n', at), text_.size());
            out += text_.substr(at + 3, end - at - 3) + "\n";
            at = end + 1;
        }
        return out;
    }

    /// Each [[block]] with conditions_file = "FILE.csv" gets one
    /// [[block.condition]] per row of the file (after those written in the
    /// block; rows with a `block` column only where it names this block). The
    /// rows are turned into TOML inline tables, one per line at the row's own
    /// line, so that every later check reports the CSV file's row and column
    /// (Document::add_csv_row).
    void expand_conditions_files() {
        toml::node* blocks = root_.get("block");
        if (blocks == nullptr || !blocks->is_array_of_tables()) return;
        toml::array& arr = *blocks->as_array();
        for (std::size_t bi = 0; bi < arr.size(); ++bi) {
            toml::table& bt = *arr.get(bi)->as_table();
            const toml::node* f = bt.get("conditions_file");
            if (f == nullptr) continue;
            step([&] { expand_conditions_file(bt, bi, *f); });
        }
    }

    void expand_conditions_file(toml::table& bt, std::size_t bi, const toml::node& f) {
        const std::string key = fmt::format("block[{}].conditions_file", bi);
        const std::string rel = doc_.string(&f, key);
        if (rel.empty()) doc_.fail(&f, key, "conditions_file must name a CSV file, got an empty string.");
        const std::filesystem::path csv = std::filesystem::path(rel).is_absolute()
                                              ? std::filesystem::path(rel)
                                              : std::filesystem::path(doc_.file()).parent_path() / rel;
        text::FileText read = text::read_text_file(csv);
        std::string file = csv.string();
        if (!read.ok()) {
            // A stored protocol text carries its conditions files (with_conditions_files).
            if (auto embedded = embedded_csv(rel)) {
                read.text = std::move(*embedded);
                read.error.clear();
                file = rel;
            } else {
                doc_.fail(&f, key,
                          fmt::format("cannot read the conditions file \"{}\": {}.", csv.string(), read.error));
            }
        }
        std::vector<std::string> lines;
        for (std::size_t at = 0; at <= read.text.size();) {
            const std::size_t end = std::min(read.text.find('\n', at), read.text.size());
            lines.push_back(read.text.substr(at, end - at));
            at = end + 1;
        }
        if (!lines.empty() && lines.front().rfind("\xEF\xBB\xBF", 0) == 0) lines.front().erase(0, 3);
        std::string error;
        const auto header = csv_fields(lines.empty() ? std::string_view() : std::string_view(lines.front()), error);
        if (!header || header->empty() || (header->size() == 1 && header->front().empty()))
            throw InputError(SourceLocation{file, 1, 0, ""},
                             error.empty() ? "the conditions file has no header row." : error);
        // What each column is.
        enum class Kind { name, block, string_key, other_key, procedure, set, test_set, reference_set };
        constexpr std::string_view kStringKeys[] = {"task",      "presentation", "prompt",
                                                    "level_key", "level_scale",  "level_on",
                                                    "choice",    "test_light",   "reference_light"};
        std::vector<Kind> kinds;
        std::set<std::string> seen;
        for (std::size_t c = 0; c < header->size(); ++c) {
            const std::string& h = (*header)[c];
            const int col = static_cast<int>(c) + 1;
            auto fail = [&](const std::string& m) {
                throw InputError(SourceLocation{file, 1, col, ""}, fmt::format("column {} '{}': {}", col, h, m));
            };
            if (h.empty()) fail("the column has no name.");
            if (!seen.insert(h).second) fail("the column appears twice in the header.");
            if (h == "name")
                kinds.push_back(Kind::name);
            else if (h == "block")
                kinds.push_back(Kind::block);
            else if (std::find(std::begin(kStringKeys), std::end(kStringKeys), h) != std::end(kStringKeys))
                kinds.push_back(Kind::string_key);
            else if (h == "left_position_m" || h == "right_position_m")
                kinds.push_back(Kind::other_key);
            else if (h.rfind("procedure.", 0) == 0 && h.size() > 10)
                kinds.push_back(Kind::procedure);
            else if (h.rfind("test:", 0) == 0 && h.find('.') != std::string::npos)
                kinds.push_back(Kind::test_set);
            else if (h.rfind("reference:", 0) == 0 && h.find('.') != std::string::npos)
                kinds.push_back(Kind::reference_set);
            else if (h.find('.') != std::string::npos && h.find_first_of(" =\"'") == std::string::npos)
                kinds.push_back(Kind::set);
            else
                fail(
                    fmt::format("not a column of a conditions file: give name, a condition key ({}, "
                                "left_position_m, right_position_m), procedure.PARAMETER, a scene key "
                                "(section.key, a `set` override), test:KEY or reference:KEY (test_set, "
                                "reference_set), or block.{}",
                                toml_reader::join_quoted(kStringKeys), text::did_you_mean(h, kStringKeys)));
        }
        // One TOML line per CSV line: row N of the file is line N of the text.
        std::string toml_text = "\n";
        std::vector<std::pair<std::string, Document::CsvRow>> rows;
        const std::string block_name = bt.get("name") && bt.get("name")->is_string()
                                           ? *bt.get("name")->value<std::string>()
                                           : fmt::format("block{}", bi);
        for (std::size_t li = 1; li < lines.size(); ++li) {
            const int line = static_cast<int>(li) + 1;
            if (trim_blanks(lines[li]).empty()) {
                toml_text += "\n";
                continue;
            }
            const auto cells = csv_fields(lines[li], error);
            if (!cells) throw InputError(SourceLocation{file, line, 0, ""}, error);
            if (cells->size() != header->size())
                throw InputError(SourceLocation{file, line, 0, ""},
                    fmt::format("the row has {} fields where the header has {}.", cells->size(), header->size()));
            Document::CsvRow row;
            row.file = file;
            row.line = line;
            std::string fields, procedure;
            std::vector<std::string> set, test_set, reference_set;
            bool take = true;
            for (std::size_t c = 0; c < cells->size(); ++c) {
                const std::string& cell = (*cells)[c];
                const std::string& h = (*header)[c];
                const int col = static_cast<int>(c) + 1;
                if (cell.empty()) continue;  // not given for this row
                row.columns.emplace_back(h, col);
                switch (kinds[c]) {
                    case Kind::block:
                        take = cell == block_name;
                        break;
                    case Kind::name:
                    case Kind::string_key:
                        fields += fmt::format("{} = {}, ", h, toml_string(cell));
                        break;
                    case Kind::other_key:
                        fields += fmt::format("{} = {}, ", h, toml_value(cell, false));
                        break;
                    case Kind::procedure:
                        procedure += fmt::format("{}{} = {}", procedure.empty() ? "" : ", ", h.substr(10),
                                                 toml_value(cell, false));
                        break;
                    case Kind::set:
                        set.push_back(toml_string(h + "=" + toml_value(cell, false)));
                        row.set.push_back(col);
                        break;
                    case Kind::test_set:
                        test_set.push_back(toml_string(h.substr(5) + "=" + toml_value(cell, false)));
                        row.test_set.push_back(col);
                        break;
                    case Kind::reference_set:
                        reference_set.push_back(toml_string(h.substr(10) + "=" + toml_value(cell, false)));
                        row.reference_set.push_back(col);
                        break;
                }
            }
            if (!take) {
                toml_text += "\n";
                continue;
            }
            auto list = [](const std::vector<std::string>& v) {
                std::string out = "[";
                for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + v[i];
                return out + "]";
            };
            if (!set.empty()) fields += "set = " + list(set) + ", ";
            if (!test_set.empty()) fields += "test_set = " + list(test_set) + ", ";
            if (!reference_set.empty()) fields += "reference_set = " + list(reference_set) + ", ";
            if (!procedure.empty()) fields += "procedure = { " + procedure + " }, ";
            if (fields.size() >= 2) fields.resize(fields.size() - 2);
            const std::string row_key = fmt::format("row{}", line);
            toml_text += fmt::format("{} = {{ {} }}\n", row_key, fields);
            rows.emplace_back(row_key, std::move(row));
        }
        toml::table parsed;
        try {
            parsed = toml::parse(toml_text, file);
        } catch (const toml::parse_error& e) {
            throw InputError(SourceLocation{file, static_cast<int>(e.source().begin.line), 0, ""},
                fmt::format("a cell is not a TOML value: {}.", strip_period(std::string(e.description()))));
        }
        if (rows.empty())
            doc_.fail(&f, key,
                      fmt::format("the conditions file \"{}\" has no rows for block \"{}\" (one row per condition{}).",
                                  file, block_name,
                                  std::find(kinds.begin(), kinds.end(), Kind::block) != kinds.end()
                                      ? "; its block column names the block each row belongs to"
                                      : ""));
        if (!bt.contains("condition")) bt.insert("condition", toml::array{});
        toml::node* conds = bt.get("condition");
        if (!conds->is_array_of_tables() && !(conds->is_array() && conds->as_array()->empty()))
            return;  // reported where the block's conditions are read
        toml::array& carr = *conds->as_array();
        for (auto& [row_key, row] : rows) {
            toml::node* t = parsed.get(row_key);
            if (t == nullptr || !t->is_table()) continue;
            doc_.add_csv_row(fmt::format("block[{}].condition[{}]", bi, carr.size()), std::move(row));
            carr.push_back(std::move(*t->as_table()));
        }
    }

    /// Runs one part of the reading; its error is kept and the reading goes on.
    template <class F>
    bool step(F&& f) {
        return errors_.attempt(f);
    }

    /// Where a key written in the wrong table belongs (Section::allow's
    /// `belongs`), "" when it is known nowhere else. `here`: "" for the
    /// top level, "defaults", "block" or "condition".
    static std::string belongs_elsewhere(std::string_view key, std::string_view here) {
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

    void read_header(const Section& root, Protocol& p, bool check_scene_exists) {
        const toml::table* t = root.table("protocol");
        if (t == nullptr)
            doc_.fail_at_line(0, "protocol",
                              "the protocol file has no [protocol] table, which is required (its scene and seed).");
        Section s(doc_, *t, "protocol", "the [protocol] table");
        s.allow(kProtocolKeys);
        p.name = s.string("name").value_or(std::filesystem::path(doc_.file()).stem().string());
        p.description = s.string("description").value_or("");
        const auto scene = s.string("scene");
        if (!scene) s.missing("scene", "the scene file the conditions override, relative to this file");
        if (scene->empty()) s.fail("scene", "scene must name a scene file, got an empty string.");
        const std::filesystem::path as_written(*scene);
        p.scene = as_written.is_absolute()
                      ? as_written
                      : (std::filesystem::path(doc_.file()).parent_path() / as_written).lexically_normal();
        if (check_scene_exists) {
            std::error_code ec;
            if (!std::filesystem::is_regular_file(p.scene, ec))
                s.fail("scene",
                       fmt::format("the scene file \"{}\" does not exist (looked for {}).", *scene, p.scene.string()));
        }
        const toml::node* seed = s.get("seed");
        if (seed == nullptr) s.missing("seed", "the random seed, an integer >= 0");
        const std::int64_t v = doc_.integer64(seed, "protocol.seed");
        if (v < 0) s.fail("seed", fmt::format("seed must be at least 0, got {}.", v));
        p.seed = static_cast<std::uint64_t>(v);
        adaptation_s_ = s.number("adaptation_s").value_or(0.0);
        s.at_least("adaptation_s", adaptation_s_, 0.0);
        s.duration_at_most("adaptation_s", adaptation_s_);
    }

    void read_display(const Section& root, Protocol& p) {
        const toml::table* t = root.table("display");
        if (t == nullptr)
            doc_.fail_at_line(0, "display",
                              "the protocol file has no [display] table, which is required (the observer's display, "
                              "with the scene file's [display] keys).");
        Section s(doc_, *t, "display", "the [display] table");
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
        for (auto&& [k, v] : *t) p.display.lines[std::string(k.str())] = Document::line_of(&v);
    }

    void read_timing(const Section& root, Protocol& p) {
        const toml::table* t = root.table("timing");
        if (t == nullptr) return;
        Section s(doc_, *t, "timing", "the [timing] table");
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
            p.timing.repeat_missed = doc_.boolean(n, s.key_path("repeat_missed"));
        if (auto v = s.number("refresh_hz")) {
            if (!(*v >= 1.0 && *v <= 1000.0))
                s.fail("refresh_hz", fmt::format("the refresh rate must be 1 to 1000 Hz, not {}.", *v));
            p.timing.refresh_hz = *v;
        }
        if (const toml::node* n = s.get("adaptation_skippable"))
            p.timing.adaptation_skippable = doc_.boolean(n, s.key_path("adaptation_skippable"));
    }

    void read_screens(const Section& root, Protocol& p) {
        const toml::table* t = root.table("screens");
        if (t == nullptr) return;
        Section s(doc_, *t, "screens", "the [screens] table");
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
        if (const toml::node* n = s.get("fixation")) p.screens.fixation = doc_.boolean(n, s.key_path("fixation"));
    }

    void read_responses(const Section& root, Protocol& p) {
        p.responses = ResponseMap::defaults();
        // Where the file bound each action (for conflict messages).
        std::array<const toml::node*, kActionCount> key_nodes{};
        std::array<std::string, kActionCount> key_paths{};
        std::array<const toml::node*, kActionCount> button_nodes{};
        std::array<std::string, kActionCount> button_paths{};
        const toml::table* t = root.table("responses");
        if (t != nullptr) {
            Section s(doc_, *t, "responses", "the [responses] table");
            s.allow(kResponseKeys);
            auto read = [&](std::string_view sub, auto& table, auto& nodes, auto& paths, KeyList names,
                            std::string_view what) {
                const toml::table* st = s.table(sub);
                if (st == nullptr) return;
                Section ss(doc_, *st, s.key_path(sub), fmt::format("the [responses.{}] table", sub));
                ss.allow(kActionNames);
                for (std::size_t a = 0; a < kActionCount; ++a) {
                    const std::string_view action = kActionNames[a];
                    const toml::node* n = ss.get(action);
                    if (n == nullptr) continue;
                    std::vector<std::string> v = doc_.strings(n, ss.key_path(action));
                    for (const std::string& name : v)
                        if (std::find(names.begin(), names.end(), name) == names.end())
                            doc_.fail(n, ss.key_path(action),
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
                        doc_.fail(key_nodes[i], key,
                                  fmt::format("'{}' needs at least one key: the protocol uses it.", to_string(a)));
                    doc_.fail_at_line(0, key, fmt::format("'{}' needs at least one key.", to_string(a)));
                }
            }
        check_conflicts(p.responses.keys, key_nodes, key_paths, contexts, "key", "responses.keys");
        check_conflicts(p.responses.buttons, button_nodes, button_paths, contexts, "gamepad button",
                        "responses.gamepad");
    }

    void check_conflicts(const std::array<std::vector<std::string>, kActionCount>& table,
                         const std::array<const toml::node*, kActionCount>& nodes,
                         const std::array<std::string, kActionCount>& paths,
                         const std::vector<std::vector<Action>>& contexts, std::string_view what,
                         std::string_view table_path) const {
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
                        if (nodes[at] != nullptr) doc_.fail(nodes[at], paths[at], message);
                        doc_.fail_at_line(0, fmt::format("{}.{}", table_path, to_string(actions[y])), message);
                    }
                }
    }

    void read_blocks(const Section& root, Protocol& p) {
        const toml::table* defaults = root.table("defaults");
        if (defaults != nullptr) {
            Section d(doc_, *defaults, "defaults", "the [defaults] table");
            step([&] { d.allow(kConditionKeys, [](std::string_view k) { return belongs_elsewhere(k, "defaults"); }); });
        }
        const toml::node* blocks = root.get("block");
        if (blocks == nullptr)
            doc_.fail_at_line(0, "block",
                              "the protocol file has no [[block]], which is required (at least one block of "
                              "conditions).");
        if (!blocks->is_array_of_tables())
            doc_.fail(
                blocks, "block",
                fmt::format("expected an array of tables [[block]], got {}.", text::type_phrase(blocks->type())));
        std::vector<std::string_view> block_keys(std::begin(kBlockOwnKeys), std::end(kBlockOwnKeys));
        block_keys.insert(block_keys.end(), std::begin(kConditionKeys), std::end(kConditionKeys));

        std::map<std::string, int> block_lines;
        std::map<std::string, int> condition_lines;
        const toml::array& arr = *blocks->as_array();
        for (std::size_t bi = 0; bi < arr.size(); ++bi) {
            const toml::table& bt = *arr.get(bi)->as_table();
            const std::string bpath = fmt::format("block[{}]", bi);
            Section bs(doc_, bt, bpath, fmt::format("[[block]] {}", bi));
            step([&] { bs.allow(block_keys, [](std::string_view k) { return belongs_elsewhere(k, "block"); }); });
            Block b;
            b.line = bs.line();
            b.name = fmt::format("block{}", bi);
            step([&] { read_block_own(bs, b, block_lines); });
            const toml::array* carr_ptr = nullptr;
            step([&] { carr_ptr = block_conditions(bs, b); });
            if (carr_ptr == nullptr) {
                p.blocks.push_back(std::move(b));
                continue;
            }
            const toml::array& carr = *carr_ptr;
            for (std::size_t ci = 0; ci < carr.size(); ++ci) {
                step([&] {
                    const toml::table& ct = *carr.get(ci)->as_table();
                    const std::string cpath = fmt::format("{}.condition[{}]", bpath, ci);
                    Section cs(doc_, ct, cpath, fmt::format("[[block.condition]] {} of block \"{}\"", ci, b.name));
                    std::vector<std::string_view> ckeys(std::begin(kConditionKeys), std::end(kConditionKeys));
                    ckeys.push_back("name");
                    step(
                        [&] { cs.allow(ckeys, [](std::string_view k) { return belongs_elsewhere(k, "condition"); }); });
                    std::string name = cs.string("name").value_or(fmt::format("{}-c{}", b.name, ci));
                    if (name.empty()) cs.fail("name", "name must not be empty.");
                    if (auto [it, inserted] = condition_lines.emplace(name, cs.line()); !inserted)
                        cs.fail("name",
                                fmt::format("a condition called \"{}\" already exists (line {}); condition names are "
                                            "unique in the protocol.",
                                            name, it->second));
                    ConditionReader cr(doc_, {Layer{defaults, "defaults"}, Layer{&bt, bpath}, Layer{&ct, cpath}}, name,
                                       cs.line());
                    b.conditions.push_back(read_condition(cr, name, cs.line()));
                });
            }
            p.blocks.push_back(std::move(b));
        }
    }

    /// A block's own keys (not its conditions').
    void read_block_own(const Section& bs, Block& b, std::map<std::string, int>& block_lines) {
        {
            b.name = bs.string("name").value_or(b.name);
            if (b.name.empty()) bs.fail("name", "name must not be empty.");
            if (auto [it, inserted] = block_lines.emplace(b.name, b.line); !inserted)
                bs.fail("name", fmt::format("a block called \"{}\" already exists (line {}).", b.name, it->second));
            b.adaptation_s = bs.number("adaptation_s").value_or(adaptation_s_);
            bs.at_least("adaptation_s", b.adaptation_s, 0.0);
            bs.duration_at_most("adaptation_s", b.adaptation_s);
            b.repetitions = bs.integer("repetitions", 1, 1000).value_or(1);
            if (auto s = bs.string("interleave")) {
                try {
                    b.interleave = parse_interleave_order(*s);
                } catch (const ProcedureError& e) {
                    bs.fail("interleave", fmt::format("interleave {}.", e.message()));
                }
            }
            b.instructions = bs.string("instructions").value_or("");
        }
    }

    /// A block's [[block.condition]] array.
    const toml::array* block_conditions(const Section& bs, const Block& b) {
        {
            const toml::node* conds = bs.get("condition");
            // A conditions file that gave no rows has said so at its own key.
            if (conds == nullptr && bs.get("conditions_file") != nullptr) return nullptr;
            if (conds == nullptr)
                doc_.fail_at_line(b.line, bs.key_path("condition"),
                                  fmt::format("block \"{}\" (line {}) has no [[block.condition]], which is required "
                                              "(at least one condition).",
                                              b.name, b.line));
            if (!conds->is_array_of_tables())
                doc_.fail(conds, bs.key_path("condition"),
                          fmt::format("expected an array of tables [[block.condition]], got {}.",
                                      text::type_phrase(conds->type())));
            return conds->as_array();
        }
    }

    Condition read_condition(const ConditionReader& r, std::string name, int line) {
        Condition c;
        c.name = std::move(name);
        c.line = line;

        const auto task = r.choice<Task>("task", parse_task, kTaskNames);
        if (!task) r.missing("task", "\"2afc\", \"yes-no\" or \"adjust\"");
        c.task = *task;

        c.presentation = c.task == Task::YesNo ? Presentation::Single : Presentation::TwoInterval;
        if (auto v = r.choice<Presentation>("presentation", parse_presentation, kPresentationNames)) {
            c.presentation = *v;
            const bool single = *v == Presentation::Single;
            if (single != (c.task == Task::YesNo))
                r.fail(*r.find("presentation"),
                       c.task == Task::YesNo
                           ? fmt::format("a yes-no task shows one stimulus: presentation must be \"single\", got "
                                         "\"{}\".",
                                         to_string(*v))
                           : fmt::format("a {} task compares two stimuli: presentation must be \"two-interval\" or "
                                         "\"side-by-side\", got \"single\".",
                                         to_string(c.task)));
        }
        c.prompt = r.string("prompt").value_or("");

        // Every override with where it was written, for the conflict check below.
        std::vector<Written> written;
        auto take = [&](const Found& f, Scope scope, std::vector<Override>& into) {
            std::vector<Override> list = doc_.scene_overrides(f.node, f.key, r.context());
            for (std::size_t i = 0; i < list.size(); ++i)
                written.push_back(Written{list[i], scope, layer_of(f.key),
                                          f.node->is_string() ? f.key : fmt::format("{}[{}]", f.key, i)});
            append(into, std::move(list));
        };
        for (const Found& f : r.find_all("set")) take(f, Scope::every_frame, c.set);
        for (const Found& f : r.find_all("test_set")) take(f, Scope::test, c.test_set);
        for (const Found& f : r.find_all("reference_set")) {
            if (c.presentation == Presentation::Single)
                r.fail(f,
                       "a single presentation has no reference: reference_set is not used; put the overrides in "
                       "set or test_set.");
            take(f, Scope::reference, c.reference_set);
        }

        const auto level_key = r.find("level_key");
        if (!level_key)
            r.missing("level_key", "the scene key the procedure's level sets, e.g. \"light.reference.intensity_cd\"");
        c.level_key = doc_.scene_key(level_key->node, level_key->key, r.context());
        c.level_scale = r.choice<LevelScale>("level_scale", parse_level_scale, kScaleNames).value_or(LevelScale::Log10);

        c.level_on = c.task == Task::YesNo ? Role::Test : Role::Reference;
        if (auto v = r.choice<Role>("level_on", parse_role, kRoleNames)) {
            if (c.task == Task::YesNo && *v == Role::Reference)
                r.fail(*r.find("level_on"), "a yes-no task shows the test alone: level_on must be \"test\".");
            c.level_on = *v;
        }
        c.choice = c.level_on == Role::Reference ? ChoiceMapping::ChoseReference : ChoiceMapping::ChoseTest;
        if (auto f = r.find("choice")) {
            if (c.task != Task::TwoAfc)
                r.fail(*f, fmt::format("choice applies to the 2afc task only, not to \"{}\".", to_string(c.task)));
            const std::string text = doc_.string(f->node, f->key, r.context());
            try {
                c.choice = parse_choice_mapping(text);
            } catch (const ProcedureError& e) {
                r.fail(*f, fmt::format("choice {}.", strip_period(e.message())));
            }
        }

        c.test_light = r.string("test_light").value_or("");
        c.reference_light = r.string("reference_light").value_or("");
        c.reference_disc = r.string("reference_disc").value_or("");
        if (!c.reference_disc.empty() && !c.reference_light.empty())
            r.fail(*r.find("reference_disc"),
                   fmt::format("the reference is one thing: give reference_light (\"{}\") or reference_disc (\"{}\"), "
                               "not both.",
                               c.reference_light, c.reference_disc));
        if (!c.reference_disc.empty() && c.presentation == Presentation::Single)
            r.fail(*r.find("reference_disc"), "a single presentation has no reference: reference_disc is not used.");
        if (auto f = r.find("left_position_m"))
            c.left_position_m = doc_.vec3(f->node, f->key, "left_position_m", r.context());
        if (auto f = r.find("right_position_m"))
            c.right_position_m = doc_.vec3(f->node, f->key, "right_position_m", r.context());
        if (c.presentation == Presentation::SideBySide) {
            const std::string_view what = "side-by-side needs both lights and both positions";
            if (c.test_light.empty()) r.missing("test_light", what);
            if (c.reference_light.empty() && c.reference_disc.empty())
                r.missing("reference_light", "side-by-side needs both lights (or a reference_disc) and both positions");
            if (c.test_light == c.reference_light)
                r.fail(*r.find("reference_light"),
                       fmt::format("side-by-side needs two different lights, got \"{}\" twice.", c.test_light));
            if (!c.left_position_m) r.missing("left_position_m", what);
            if (!c.right_position_m) r.missing("right_position_m", what);
        } else {
            for (std::string_view k : {"left_position_m", "right_position_m"})
                if (auto f = r.find(k))
                    r.fail(*f, fmt::format("{} is used by presentation = \"side-by-side\" only, not \"{}\".", k,
                                           to_string(c.presentation)));
        }

        check_conflicts(r, c, written, level_key->key);

        // The procedure.
        const std::vector<Found> tables = r.find_all("procedure");
        if (tables.empty())
            r.missing("procedure",
                      "a table with kind = \"staircase\", \"weighted-staircase\", \"quest\", "
                      "\"adjustment\" or \"constant-stimuli\" and its parameters");
        ProcedureReader pr(doc_, r);
        pr.merge(tables);
        if (!pr.kind())
            doc_.fail(pr.table()->node, pr.table()->key + ".kind",
                      r.context() + fmt::format("the procedure has no kind: give kind = one of {}.",
                                                toml_reader::join_quoted(kKindNames)));
        const bool adjustment = *pr.kind() == ProcedureKind::Adjustment;
        if (adjustment != (c.task == Task::Adjust))
            r.fail(
                *pr.kind_at(),
                adjustment
                    ? fmt::format("the adjustment procedure needs task = \"adjust\", not \"{}\".", to_string(c.task))
                    : fmt::format("task = \"adjust\" needs kind = \"adjustment\", not \"{}\".", to_string(*pr.kind())));
        if (*pr.kind() == ProcedureKind::Quest && c.level_scale != LevelScale::Log10) {
            const auto f = r.find("level_scale");
            r.fail(*f,
                   "QUEST works in log10 units (its Weibull is a function of log intensity): level_scale must be "
                   "\"log10\".");
        }
        try {
            c.procedure = read_procedure(pr);
            for (std::size_t t = 0; t < c.procedure.tracks(); ++t) (void)make_track(c, t, 0);
        } catch (const ProcedureError& e) {
            pr.fail(e.parameter(), fmt::format("{} {}.", e.parameter(), strip_period(e.message())));
        }
        check_level_scale(pr, c);
        return c;
    }

    // --- Conflicting overrides (docs/protocol-file.md "When two overrides set one key").

    /// Which frames an override applies to.
    enum class Scope : std::uint8_t { every_frame, test, reference };
    /// Where it was written, general to specific.
    enum class Origin : std::uint8_t { defaults, block, condition };
    struct Written {
        Override o;
        Scope scope = Scope::every_frame;
        Origin layer = Origin::defaults;
        std::string path;  ///< "block[0].test_set[1]"
    };

    static Origin layer_of(const std::string& found_key) {
        if (found_key.starts_with("defaults.")) return Origin::defaults;
        return found_key.find(".condition[") != std::string::npos ? Origin::condition : Origin::block;
    }

    static std::string_view scope_name(Scope s) {
        switch (s) {
            case Scope::every_frame:
                return "set";
            case Scope::test:
                return "test_set";
            case Scope::reference:
                return "reference_set";
        }
        return "set";
    }

    /// Two TOML value texts that mean the same value: equal numbers, or equal
    /// text once the quotes of a string are set aside.
    static bool same_value(std::string_view a, std::string_view b) {
        auto trim = [](std::string_view v) {
            while (!v.empty() && (v.front() == ' ' || v.front() == '\t')) v.remove_prefix(1);
            while (!v.empty() && (v.back() == ' ' || v.back() == '\t')) v.remove_suffix(1);
            if (v.size() >= 2 && (v.front() == '"' || v.front() == '\'') && v.back() == v.front())
                v = v.substr(1, v.size() - 2);
            return v;
        };
        a = trim(a);
        b = trim(b);
        if (a == b) return true;
        auto number = [](std::string_view v) -> std::optional<double> {
            double x = 0.0;
            const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
            if (ec != std::errc() || ptr != v.data() + v.size()) return std::nullopt;
            return x;
        };
        const auto x = number(a), y = number(b);
        return x && y && *x == *y;
    }

    /// One frame must not take one key from two places that both mean it
    /// (docs/protocol-file.md). By design, a later layer replaces an earlier:
    /// a [[block]] or condition value replaces the [defaults] value of the
    /// same key; in a frame of one role (single, two-interval) the role's
    /// test_set or reference_set replaces `set`. Refused: a block and its
    /// condition, or one list twice, giving one key two values; in a
    /// side-by-side frame (which holds both lights) set, test_set and
    /// reference_set giving one key two values; any override of the key the
    /// procedure's level sets, in the frame the level is on; any override of
    /// a side-by-side light's position_m. In a side-by-side frame a [defaults]
    /// value that a block or condition replaces is dropped, so that the
    /// replacement holds whatever list it is in.
    void check_conflicts(const ConditionReader& r, Condition& c, const std::vector<Written>& written,
                         const std::string& level_key_path) const {
        const bool side_by_side = c.presentation == Presentation::SideBySide;
        auto conflict = [&](const Written& a, const Written& b, const std::string& why) {
            doc_.fail_at_line(b.o.line, b.path,
                              r.context() + fmt::format("{} is set to {} here and to {} by {} (line {}): {} Remove one "
                                                        "of them (docs/protocol-file.md \"When two overrides set one "
                                                        "key\").",
                                                        b.o.key, b.o.value, a.o.value, a.path, a.o.line, why));
        };
        // Frames of the condition, by the scopes that apply to each.
        std::vector<std::vector<Scope>> frames;
        if (side_by_side)
            frames = {{Scope::every_frame, Scope::test, Scope::reference}};
        else if (c.presentation == Presentation::Single)
            frames = {{Scope::every_frame, Scope::test}};
        else
            frames = {{Scope::every_frame, Scope::test}, {Scope::every_frame, Scope::reference}};
        std::set<std::string> dropped;  // paths of [defaults] values a side-by-side frame drops
        for (const auto& scopes : frames) {
            auto applies = [&](const Written& w) {
                return std::find(scopes.begin(), scopes.end(), w.scope) != scopes.end();
            };
            const bool has_level =
                side_by_side || std::find(scopes.begin(), scopes.end(),
                                          c.level_on == Role::Test ? Scope::test : Scope::reference) != scopes.end();
            for (std::size_t j = 0; j < written.size(); ++j) {
                const Written& b = written[j];
                if (!applies(b)) continue;
                if (has_level && b.o.key == c.level_key)
                    doc_.fail_at_line(
                        b.o.line, b.path,
                        r.context() +
                            fmt::format("{} is set to {} here, but it is the level_key ({}): the procedure's level "
                                        "sets it on every trial in the {} frame. Remove this override (docs/protocol-"
                                        "file.md \"When two overrides set one key\").",
                                        b.o.key, b.o.value, level_key_path, side_by_side ? "side-by-side" : to_string(c.level_on)));
                if (side_by_side && (b.o.key == fmt::format("light.{}.position_m", c.test_light) ||
                                     b.o.key == fmt::format("light.{}.position_m", c.reference_light)))
                    doc_.fail_at_line(
                        b.o.line, b.path,
                        r.context() + fmt::format("{} is set to {} here, but a side-by-side frame places its lights "
                                                  "at left_position_m and right_position_m. Remove this override.",
                                                  b.o.key, b.o.value));
                for (std::size_t i = 0; i < j; ++i) {
                    const Written& a = written[i];
                    if (!applies(a) || a.o.key != b.o.key || same_value(a.o.value, b.o.value)) continue;
                    const bool a_default = a.layer == Origin::defaults, b_default = b.layer == Origin::defaults;
                    if (a_default != b_default) {
                        // A block's or condition's value replaces the default.
                        if (side_by_side) dropped.insert(a_default ? a.path : b.path);
                        if (side_by_side || a.scope == b.scope) continue;
                    }
                    if (!side_by_side && a.scope != b.scope) continue;  // the role's list replaces `set`
                    std::string why;
                    if (side_by_side && a.scope != b.scope)
                        why = fmt::format("a side-by-side frame holds both lights, and {} and {} both apply to "
                                          "all of it.",
                                          scope_name(a.scope), scope_name(b.scope));
                    else if (a.layer != b.layer)
                        why = "a condition and its block apply to the same frames.";
                    else
                        why = "one list sets it twice.";
                    conflict(a, b, why);
                }
            }
        }
        if (dropped.empty()) return;
        // Rebuild the lists without the replaced defaults (order kept).
        c.set.clear();
        c.test_set.clear();
        c.reference_set.clear();
        for (const Written& w : written) {
            if (dropped.contains(w.path)) continue;
            (w.scope == Scope::every_frame ? c.set : w.scope == Scope::test ? c.test_set : c.reference_set)
                .push_back(w.o);
        }
    }

    /// Levels that look written for the other scale: on log10 a level above
    /// kMaxLog10Level is 10^9 or more of the key's unit (no light, luminance or
    /// distance in a study is that large: these are linear values); on a linear
    /// scale a negative level of a photometric key (cd, cd/m², lux) cannot be
    /// (these are log10 values).
    void check_level_scale(const ProcedureReader& pr, const Condition& c) const {
        static constexpr double kMaxLog10Level = 9.0;
        const auto ends_with = [&](std::string_view suffix) {
            return c.level_key.size() >= suffix.size() &&
                   c.level_key.compare(c.level_key.size() - suffix.size(), suffix.size(), suffix) == 0;
        };
        const bool photometric = ends_with("_cd") || ends_with("_cd_m2") || ends_with("_lux");
        for (std::string_view key :
             {"start", "levels", "min_level", "max_level", "t_guess", "start_min", "start_max"}) {
            const Found* f = pr.entry(key);
            if (f == nullptr) continue;
            std::vector<double> v;
            if (f->node->is_number())
                v.push_back(f->node->value<double>().value_or(0.0));
            else if (const toml::array* a = f->node->as_array())
                for (const toml::node& x : *a) v.push_back(x.value<double>().value_or(0.0));
            for (const double x : v) {
                if (c.level_scale == LevelScale::Log10 && x > kMaxLog10Level)
                    pr.fail(key, fmt::format("{} has {} on the log10 scale: 10^{} of {}'s unit. These look like linear "
                                             "values: give their log10 (e.g. {} for {}) or set level_scale = "
                                             "\"linear\".",
                                             key, x, x, c.level_key, fmt::format("{:.3g}", std::log10(x)), x));
                if (c.level_scale == LevelScale::Linear && photometric && x < 0.0)
                    pr.fail(key, fmt::format("{} has {} on the linear scale, a negative {}. These look like log10 "
                                             "values: set level_scale = \"log10\" or give the values themselves "
                                             "(e.g. {:.3g} for {}).",
                                             key, x, c.level_key, std::pow(10.0, x), x));
            }
        }
    }

    static void append(std::vector<Override>& to, std::vector<Override> from) {
        to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
    }

    static constexpr std::string_view kTaskNames[] = {"2afc", "yes-no", "adjust"};
    static constexpr std::string_view kPresentationNames[] = {"single", "two-interval", "side-by-side"};
    static constexpr std::string_view kScaleNames[] = {"log10", "linear"};
    static constexpr std::string_view kRoleNames[] = {"test", "reference"};

    Document doc_;
    toml::table root_;
    double adaptation_s_ = 0.0;
    text::ErrorList errors_;  // every error found, reported together at the end of parse()
    std::string text_;        // the protocol text (conditions files stored in it: embedded_csv)
};

std::string read_text(const std::filesystem::path& file) {
    // Only up to a limit: /dev/zero given by mistake is refused, not read until
    // the memory runs out.
    text::FileText read = text::read_text_file(file);
    if (!read.ok())
        throw InputError(SourceLocation{file.string(), 0, 0, ""},
                         fmt::format("cannot read the protocol file: {}.", read.error));
    return std::move(read.text);
}

}  // namespace

Protocol load_protocol(const std::filesystem::path& file) {
    const std::string text = read_text(file);
    return Parser(file.string()).parse(text, true);
}

Protocol parse_protocol(std::string_view toml_text, std::string_view file_name) {
    return Parser(std::string(file_name)).parse(toml_text, false);
}

std::string with_conditions_files(std::string_view text, const std::filesystem::path& protocol_file) {
    std::string out(text);
    toml::table root;
    try {
        root = toml::parse(text);
    } catch (const toml::parse_error&) {
        return out;
    }
    const toml::array* blocks = root["block"].as_array();
    if (blocks == nullptr) return out;
    std::set<std::string> done;
    for (const toml::node& b : *blocks) {
        const toml::table* t = b.as_table();
        if (t == nullptr) continue;
        const auto name = (*t)["conditions_file"].value<std::string>();
        if (!name || !done.insert(*name).second) continue;
        const std::filesystem::path csv = std::filesystem::path(*name).is_absolute()
                                              ? std::filesystem::path(*name)
                                              : protocol_file.parent_path() / *name;
        const text::FileText read = text::read_text_file(csv);
        if (!read.ok()) continue;
        if (!out.empty() && out.back() != '\n') out += '\n';
        out += "\n# atonlab: the conditions file below, as it was when the session ran (docs/protocol-file.md)\n";
        out += "#@conditions_file " + *name + "\n";
        for (std::size_t at = 0; at < read.text.size();) {
            const std::size_t end = std::min(read.text.find('\n', at), read.text.size());
            std::string line = read.text.substr(at, end - at);
            if (!line.empty() && line.back() == '\r') line.pop_back();
            out += "#@|" + line + "\n";
            at = end + 1;
        }
    }
    return out;
}

}  // namespace atonlab::protocols
