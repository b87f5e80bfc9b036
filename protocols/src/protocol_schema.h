#pragma once
// The protocol file's schema and the readers of a condition's layered keys,
// shared by the parts of the protocol reader (protocol_file.cpp: the whole
// file, [protocol] and the blocks; protocol_settings.cpp: [display],
// [timing], [screens], [responses]; procedure_table.cpp; conditions_file.cpp).
// Not installed.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/common/toml_text.h"
#include "protocol_reader.h"

namespace atonlab::protocols::detail {

inline constexpr std::string_view kRootKeys[] = {"protocol", "display",  "timing", "responses",
                                                 "screens",  "defaults", "block",  "observer"};
inline constexpr std::string_view kProtocolKeys[] = {"name", "description", "scene", "seed", "adaptation_s"};
inline constexpr std::string_view kDisplayKeys[] = {"width_px",           "height_px", "width_m",
                                             "viewing_distance_m", "name",      "max_calibration_age_days",
                                             "max_out_of_gamut_loss"};
inline constexpr std::string_view kTimingKeys[] = {"stimulus_s",          "inter_stimulus_s", "inter_trial_s",
                                            "response_timeout_s",  "repeat_missed",    "refresh_hz",
                                            "adaptation_skippable", "max_missed_in_a_row", "max_missed_fraction"};
inline constexpr std::string_view kScreenKeys[] = {"instructions", "break",         "end",     "text_cd_m2",
                                            "cue_cd_m2",    "text_size_deg", "fixation"};
inline constexpr std::string_view kResponseKeys[] = {"keys", "gamepad"};
inline constexpr std::string_view kActionNames[] = {"left",    "right",     "yes",     "no",       "coarse_up", "coarse_down",
                                             "fine_up", "fine_down", "confirm", "continue", "quit"};

// Condition keys may be written in [defaults], in a [[block]] (for all its
// conditions) or in the [[block.condition]] itself; the nearest wins, and the
// override lists add up.
inline constexpr std::string_view kConditionKeys[] = {
    "task",        "presentation", "prompt", "set",        "test_set",        "reference_set",   "level_key",
    "level_scale", "level_on",     "choice", "test_light", "reference_light", "left_position_m", "right_position_m",
    "procedure",   "reference_disc"};
inline constexpr std::string_view kBlockOwnKeys[] = {"name",         "adaptation_s", "repetitions",    "interleave",
                                              "instructions", "condition",    "conditions_file"};

// Key names (GLFW's key names, lower case with underscores) and gamepad buttons
// (GLFW_GAMEPAD_BUTTON_*).
const std::vector<std::string>& key_names();
inline constexpr std::string_view kButtonNames[] = {
    "a",     "b",          "x",           "y",       "left_bumper", "right_bumper", "back",     "start",
    "guide", "left_thumb", "right_thumb", "dpad_up", "dpad_right",  "dpad_down",    "dpad_left"};

inline std::string strip_period(std::string s) {
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

/// The keys a procedure of kind `k` takes.
KeyList keys_of(ProcedureKind k);
/// Every key of any procedure kind.
const std::vector<std::string_view>& all_procedure_keys();
/// The registered kinds' names (procedures.h).
const std::vector<std::string_view>& procedure_kind_names();
/// The kinds that take the adjustment actions, quoted ("\"adjustment\"").
std::string adjusting_kinds();

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
                                                        "\"{}\", ... }}), got {}.",
                                                        procedure_kind_names().front(),
                                                        text::type_phrase(f.node->type())));
            const toml::table& t = *f.node->as_table();
            table_ = f;
            if (const toml::node* k = t.get("kind")) {
                const std::string text = doc_.string(k, f.key + ".kind", cond_.context());
                const auto parsed = parse_procedure_kind(text);
                if (!parsed)
                    doc_.fail(k, f.key + ".kind",
                              cond_.context() + fmt::format("kind must be one of {}, got \"{}\".",
                                                            toml_reader::join_quoted(procedure_kind_names()), text));
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

/// The procedure the merged table describes.
ProcedureSpec read_procedure(const ProcedureReader& r);

/// Where a key written in the wrong table belongs (Section::allow's
/// `belongs`), "" when it is known nowhere else. `here`: "" for the
/// top level, "defaults", "block" or "condition".
std::string belongs_elsewhere(std::string_view key, std::string_view here);

// The single tables (protocol_settings.cpp).
void read_display(const Document& doc, const Section& root, Protocol& p);
void read_timing(const Document& doc, const Section& root, Protocol& p);
void read_screens(const Document& doc, const Section& root, Protocol& p);
void read_responses(const Document& doc, const Section& root, Protocol& p);
/// [observer]: the model observer's keys and a simulated observer's departures
/// (simulated_observer.h), each checked against its range.
void read_observer(const Document& doc, const Section& root, Protocol& p);

/// Expands the conditions file `f` of block `bi` into [[block.condition]]
/// tables (conditions_file.cpp); `protocol_text` may carry the file.
void expand_conditions_file(Document& doc, std::string_view protocol_text, toml::table& bt, std::size_t bi,
                            const toml::node& f);

}  // namespace atonlab::protocols::detail
