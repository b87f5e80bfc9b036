// The Dataset's CSV side: the long-format input, the tidy trials.csv output,
// and merging inputs. The study-file reader is study_reader.cpp.
#include "atonlab/analysis/dataset.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "atonlab/analysis/study_analysis.h"
#include "atonlab/common/atomic_file.h"
#include "atonlab/common/input_text.h"
#include "atonlab/protocols/procedures.h"
#include "csv.h"

namespace atonlab::analysis {

namespace p = atonlab::protocols;

namespace {

/// A CSV file's bad value (line 0: the whole file; column "": no one column).
InputError csv_error(const std::string& file, int line, std::string column, const std::string& message) {
    return InputError(SourceLocation::csv(file, line, std::move(column)), message);
}

}  // namespace

const std::vector<std::string>& required_csv_columns() {
    static const std::vector<std::string> cols{"observer", "condition", "level", "response"};
    return cols;
}

const std::vector<std::string>& trials_csv_columns() {
    static const std::vector<std::string> cols{"session",
                                               "observer",
                                               "trial_index",
                                               "block",
                                               "block_index",
                                               "condition",
                                               "track",
                                               "procedure",
                                               "task",
                                               "level",
                                               "level_key",
                                               "level_scale",
                                               "level_on",
                                               "response",
                                               "outcome",
                                               "test_on_left",
                                               "response_value",
                                               "response_time_s",
                                               "onset_time_s",
                                               "dropped_frames",
                                               "missed_deadline",
                                               "adaptation_cd_m2",
                                               "tone_operator",
                                               "glare_test",
                                               "glare_reference",
                                               "test_intensity_cd",
                                               "test_colour",
                                               "test_rhythm",
                                               "test_spectrum",
                                               "reference_colour",
                                               "reference_rhythm",
                                               "reference_spectrum",
                                               "chose_reference",
                                               "guess_rate",
                                               "target_p",
                                               "reversal",
                                               "posterior_mean",
                                               "posterior_sd",
                                               "posterior_lower",
                                               "posterior_upper",
                                               "source"};
    return cols;
}

// ---------------------------------------------------------------------------
// Reading the CSV

namespace {

class RowReader {
public:
    RowReader(const std::string& file, int line, const std::map<std::string, std::size_t>& index,
              const std::vector<std::string>& fields)
        : file_(file), line_(line), index_(index), fields_(fields) {}

    bool has(const std::string& column) const { return index_.count(column) > 0; }
    /// The field's text, or nullopt when the column is absent or the field empty.
    std::optional<std::string> text(const std::string& column) const {
        const auto it = index_.find(column);
        if (it == index_.end()) return std::nullopt;
        std::string v = trim(fields_[it->second]);
        if (v.empty()) return std::nullopt;
        return v;
    }
    std::string required(const std::string& column) const {
        auto v = text(column);
        if (!v) fail(column, "is empty; every row needs a value here");
        return *v;
    }
    std::optional<double> number(const std::string& column) const {
        const auto v = text(column);
        if (!v) return std::nullopt;
        double x = 0.0;
        const char* begin = v->data();
        const char* end = begin + v->size();
        if (*begin == '+') ++begin;
        const auto [ptr, ec] = std::from_chars(begin, end, x);
        if (ec != std::errc() || ptr != end || !std::isfinite(x))
            fail(column, fmt::format("'{}' is not a finite number", *v));
        return x;
    }
    std::optional<std::int64_t> integer(const std::string& column, std::int64_t min) const {
        const auto v = text(column);
        if (!v) return std::nullopt;
        std::int64_t x = 0;
        const auto [ptr, ec] = std::from_chars(v->data(), v->data() + v->size(), x);
        if (ec != std::errc() || ptr != v->data() + v->size()) fail(column, fmt::format("'{}' is not an integer", *v));
        if (x < min) fail(column, fmt::format("{} is below the smallest allowed value, {}", x, min));
        return x;
    }
    std::optional<bool> boolean(const std::string& column) const {
        const auto v = text(column);
        if (!v) return std::nullopt;
        const auto b = parse_bool(*v);
        if (!b) fail(column, fmt::format("'{}' is not a yes/no value (1, 0, true, false, yes, no)", *v));
        return b;
    }
    [[noreturn]] void fail(const std::string& column, const std::string& message) const {
        throw csv_error(file_, line_, column, message);
    }

    static std::optional<bool> parse_bool(std::string_view v) {
        if (v == "1" || v == "true" || v == "TRUE" || v == "True" || v == "yes") return true;
        if (v == "0" || v == "false" || v == "FALSE" || v == "False" || v == "no") return false;
        return std::nullopt;
    }
    static std::string trim(std::string_view s) {
        while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
        while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
        return std::string(s);
    }

private:
    const std::string& file_;
    int line_;
    const std::map<std::string, std::size_t>& index_;
    const std::vector<std::string>& fields_;
};

/// An adjustment action's word (protocols' response_word), or "match", which
/// hand-made CSVs use for a confirmed match.
bool is_adjust_word(std::string_view word) {
    if (word == "match") return true;
    const std::optional<p::Response> r = p::parse_response_word(word);
    return r && *r != p::Response::Yes && *r != p::Response::No && *r != p::Response::Left && *r != p::Response::Right;
}

/// A trials.csv setting field back as TOML value text (Trial::settings): a
/// number or boolean as written, anything else as a TOML string.
std::string toml_of_field(const std::string& field) {
    const SettingValue v = setting_value(field);
    if (v.number || v.boolean) return field;
    std::string q = "\"";
    for (const char ch : field) {
        if (ch == '"' || ch == '\\') q += '\\';
        q += ch;
    }
    return q + "\"";
}

Trial trial_from_row(const RowReader& row, const std::string& file) {
    Trial t;
    t.source = file;
    t.observer = row.required("observer");
    t.condition = row.required("condition");
    if (const auto task = row.text("task")) {
        const auto parsed = protocols::parse_task(*task);
        if (!parsed) row.fail("task", fmt::format("'{}' is not a task (2afc, yes-no, adjust)", *task));
        t.task = *parsed;
    }
    const auto level = row.number("level");
    if (!level) row.fail("level", "is empty; every row needs a value here");
    t.level = *level;
    if (const auto s = row.text("level_key")) t.level_key = *s;
    if (const auto s = row.text("level_scale")) {
        if (*s != "log10" && *s != "linear") row.fail("level_scale", fmt::format("'{}' is not log10 or linear", *s));
        t.level_scale = *s;
    }
    t.level_on = t.task == protocols::Task::YesNo ? "test" : "reference";
    if (const auto s = row.text("level_on")) {
        if (*s != "test" && *s != "reference") row.fail("level_on", fmt::format("'{}' is not test or reference", *s));
        t.level_on = *s;
    }
    t.test_on_left = row.boolean("test_on_left");
    t.response = row.required("response");
    // The outcome: an explicit `outcome` column wins; else the response, as a
    // yes/no value or (2AFC) a side with test_on_left.
    if (const auto o = row.boolean("outcome")) {
        t.outcome = o;
    } else if (t.task == protocols::Task::Adjust) {
        if (!is_adjust_word(t.response))
            row.fail("response", fmt::format("'{}' is not an adjustment action (confirm or match for a match; "
                                             "coarse_up, coarse_down, fine_up, fine_down)",
                                             t.response));
    } else if (const auto b = RowReader::parse_bool(t.response)) {
        t.outcome = b;
    } else if (const std::optional<p::Response> side = p::parse_response_word(t.response);
               t.task == protocols::Task::TwoAfc && (side == p::Response::Left || side == p::Response::Right)) {
        if (!t.test_on_left)
            row.fail("test_on_left", "is needed to score the answer 'left' or 'right' (where was the test?)");
        const bool chose_test = (side == p::Response::Left) == *t.test_on_left;
        t.outcome = t.level_on == "test" ? chose_test : !chose_test;
    } else if (t.response != p::kTimeoutWord) {
        row.fail("response", fmt::format("'{}' is not an answer: give 1/0, yes/no or true/false (the outcome the "
                                         "psychometric function counts), left/right with test_on_left, or timeout",
                                         t.response));
    }
    if (const auto s = row.text("session")) t.session = *s;
    if (const auto v = row.integer("trial_index", 0)) t.trial_index = *v;
    // `block` is the block's name (trials.csv from 0.2 on; earlier, and in
    // hand-made files, its 0-based index), `block_index` its index.
    if (const auto s = row.text("block")) {
        t.block_name = *s;
        if (!row.has("block_index") && std::all_of(s->begin(), s->end(), [](char c) { return c >= '0' && c <= '9'; }))
            if (const auto v = row.integer("block", 0)) t.block = static_cast<int>(*v);
    }
    if (const auto v = row.integer("block_index", 0)) t.block = static_cast<int>(*v);
    if (const auto s = row.text("track")) t.track = *s;
    if (const auto s = row.text("procedure")) {
        if (!p::find_procedure_type(*s)) {
            std::string names;
            for (const p::ProcedureType* type : p::procedure_types())
                names += fmt::format("{}{}", names.empty() ? "" : ", ", type->name);
            row.fail("procedure", fmt::format("'{}' is not a procedure ({})", *s, names));
        }
        t.procedure = *s;
    }
    t.response_value = row.number("response_value");
    if (const auto v = row.number("response_time_s")) t.response_time_s = *v;
    if (const auto v = row.number("onset_time_s")) t.onset_time_s = *v;
    if (const auto v = row.integer("dropped_frames", 0)) t.dropped_frames = static_cast<int>(*v);
    if (const auto v = row.boolean("missed_deadline")) t.missed_deadline = *v;
    t.adaptation_cd_m2 = row.number("adaptation_cd_m2");
    if (t.adaptation_cd_m2 && *t.adaptation_cd_m2 <= 0.0) row.fail("adaptation_cd_m2", "must be a luminance > 0 cd/m2");
    if (const auto s = row.text("tone_operator")) t.tone_operator = *s;
    if (const auto s = row.text("glare_test")) t.glare_test = *s;
    if (const auto s = row.text("glare_reference")) t.glare_reference = *s;
    for (const auto& [look, side] : {std::pair{&t.test_look, "test"}, std::pair{&t.reference_look, "reference"}}) {
        look->colour = row.text(fmt::format("{}_colour", side)).value_or("");
        look->rhythm = row.text(fmt::format("{}_rhythm", side)).value_or("");
        look->spectrum = row.text(fmt::format("{}_spectrum", side)).value_or("");
    }
    t.test_intensity_cd = row.number("test_intensity_cd");
    if (t.test_intensity_cd && *t.test_intensity_cd <= 0.0)
        row.fail("test_intensity_cd", "must be an intensity > 0 cd");
    if (const auto v = row.number("guess_rate")) {
        if (*v < 0.0 || *v >= 1.0) row.fail("guess_rate", fmt::format("{} is outside [0, 1)", *v));
        t.guess_rate = *v;
    }
    if (const auto v = row.number("target_p")) {
        if (*v <= t.guess_rate || *v >= 1.0)
            row.fail("target_p", fmt::format("{} is outside (guess_rate, 1) = ({}, 1)", *v, t.guess_rate));
        t.target_p = *v;
    }
    t.reversal = row.boolean("reversal");
    t.posterior_mean = row.number("posterior_mean");
    t.posterior_sd = row.number("posterior_sd");
    t.posterior_lower = row.number("posterior_lower");
    t.posterior_upper = row.number("posterior_upper");
    return t;
}

}  // namespace

/// Largest trials CSV read (bytes): 256 MiB, about two million trials.
constexpr std::uintmax_t kMaxCsvBytes = 256u << 20;

Dataset read_trials_csv(const std::filesystem::path& csv_file) {
    const std::string file = csv_file.string();
    std::error_code ec;
    if (std::filesystem::is_directory(csv_file, ec)) throw csv_error(file, 0, "", "is a directory, not a CSV file");
    // Read whole, up to a limit (docs/fuzzing.md "Limits on input"): a trials
    // CSV of a large study is tens of MB; /dev/zero or a mistaken binary file
    // would otherwise be read until the memory runs out.
    const text::FileText read = text::read_text_file(csv_file, kMaxCsvBytes);
    if (!read.opened) throw csv_error(file, 0, "", "cannot be opened for reading (does it exist?)");
    if (!read.ok()) throw csv_error(file, 0, "", fmt::format("cannot be read: {}", read.error));
    CsvReader reader(read.text, file);
    const auto header_record = reader.next();
    if (!header_record) throw csv_error(file, 1, "", "is empty: it needs a header row");
    const std::vector<std::string> header_fields = header_record->texts();
    const auto* header = &header_fields;
    std::map<std::string, std::size_t> index;
    for (std::size_t i = 0; i < header->size(); ++i) {
        const std::string name = RowReader::trim((*header)[i]);
        if (name.empty()) throw csv_error(file, 1, "", fmt::format("column {} of the header has no name", i + 1));
        if (!index.emplace(name, i).second) throw csv_error(file, 1, name, "appears twice in the header");
    }
    // The posterior's columns were quest_* until they were named for what they are (any procedure with a
    // posterior writes them): the old names are still read, with a note.
    std::vector<std::string> renamed;
    for (const char* part : {"mean", "sd", "lower", "upper"}) {
        const std::string old_name = fmt::format("quest_{}", part), new_name = fmt::format("posterior_{}", part);
        const auto it = index.find(old_name);
        if (it == index.end() || index.count(new_name)) continue;
        index.emplace(new_name, it->second);
        index.erase(it);
        renamed.push_back(fmt::format("{} as {}", old_name, new_name));
    }
    for (const std::string& col : required_csv_columns()) {
        if (!index.count(col)) {
            std::string have;
            for (const std::string& f : *header) have += (have.empty() ? "" : ", ") + f;
            throw csv_error(file, 1, col,
                            fmt::format("the header has no column '{}', which is required (required: observer, "
                                        "condition, level, response; the header has: {})",
                                        col, have));
        }
    }
    Dataset d;
    d.sources.push_back(file);
    if (!renamed.empty())
        d.notes.push_back(fmt::format("{}: deprecated column names were read as their new ones: {} (write posterior_*)",
                                      file, fmt::join(renamed, ", ")));
    std::vector<std::string> unknown;
    std::vector<std::pair<std::string, std::size_t>> setting_columns;  // Trial::settings: scene keys, with a dot
    const auto& known = trials_csv_columns();
    for (const auto& [name, i] : index) {
        if (std::find(known.begin(), known.end(), name) != known.end()) continue;
        if (name.find('.') != std::string::npos)
            setting_columns.emplace_back(name, i);
        else
            unknown.push_back(name);
    }
    if (!unknown.empty()) {
        std::string list;
        for (const std::string& u : unknown) list += (list.empty() ? "" : ", ") + u;
        d.notes.push_back(fmt::format("{}: columns not used by the analysis were ignored: {}", file, list));
    }
    std::map<std::string, std::int64_t> next_index;  // per session, when trial_index is not given
    while (true) {
        const auto rec = reader.next();
        if (!rec) break;
        const std::vector<std::string> fields = rec->texts();
        if (fields.size() == 1 && RowReader::trim(fields[0]).empty()) continue;  // a blank line
        if (fields.size() != header->size())
            throw csv_error(
                file, rec->line, "",
                fmt::format("the row has {} fields where the header has {}", fields.size(), header->size()));
        const RowReader row(file, rec->line, index, fields);
        Trial t = trial_from_row(row, file);
        // "KEY[0]", "KEY[1]", ...: one array setting (write_trials_csv writes a position so).
        std::map<std::string, std::map<std::size_t, std::string>> arrays;
        for (const auto& [name, i] : setting_columns) {
            const std::string v = RowReader::trim(fields[i]);
            if (v.empty()) continue;
            const auto open = name.rfind('[');
            std::size_t element = 0;
            if (open != std::string::npos && name.back() == ']' &&
                std::from_chars(name.data() + open + 1, name.data() + name.size() - 1, element).ptr ==
                    name.data() + name.size() - 1 &&
                setting_value(v).number) {
                arrays[name.substr(0, open)][element] = v;
                continue;
            }
            t.settings[name] = toml_of_field(v);
        }
        for (const auto& [key, values] : arrays) {
            std::string toml = "[";
            for (const auto& [element, v] : values) toml += (toml.size() > 1 ? ", " : "") + v;
            t.settings[key] = toml + "]";
        }
        if (t.session.empty())
            t.session = fmt::format("{}:{}", std::filesystem::path(file).filename().string(), t.observer);
        if (!index.count("trial_index")) t.trial_index = next_index[t.session]++;
        d.trials.push_back(std::move(t));
    }
    if (d.trials.empty()) throw csv_error(file, 0, "", "has a header but no trials");
    // One SessionInfo per session key, in order of appearance.
    std::map<std::string, std::size_t> session_at;
    for (const Trial& t : d.trials) {
        auto [it, fresh] = session_at.emplace(t.session, d.sessions.size());
        if (fresh) {
            SessionInfo s;
            s.key = t.session;
            s.source = file;
            s.observer = t.observer;
            d.sessions.push_back(std::move(s));
        } else if (d.sessions[it->second].observer != t.observer) {
            throw csv_error(file, 0, "session",
                            fmt::format("session '{}' has trials of two observers, '{}' and '{}'", t.session,
                                        d.sessions[it->second].observer, t.observer));
        }
        ++d.sessions[it->second].trial_count;
    }
    return d;
}

// ---------------------------------------------------------------------------
// Writing trials.csv

namespace {

/// 2AFC: 1 when the observer chose the reference stimulus, 0 the test; "" for
/// other tasks and for answers that chose neither (a timeout).
std::string chose_reference(const Trial& t) {
    if (t.task != protocols::Task::TwoAfc || !t.test_on_left || (t.response != "left" && t.response != "right"))
        return {};
    const bool chose_test = (t.response == "left") == *t.test_on_left;
    return chose_test ? "0" : "1";
}

/// A setting's TOML value text as a typed CSV field: numbers and booleans as
/// written, a string's contents without its quotes.
std::string setting_field(const std::string& toml_value) {
    const SettingValue v = setting_value(toml_value);
    if (v.number) return detail::number_text(*v.number);
    if (v.boolean) return *v.boolean ? "true" : "false";
    return csv_field(v.text);
}

}  // namespace

void write_trials_csv(const std::filesystem::path& csv_file, const Dataset& data) {
    std::ostringstream out;  // written whole or not at all, as every output file (atomic_file.h)
    const auto& cols = trials_csv_columns();
    for (std::size_t i = 0; i < cols.size(); ++i) out << (i ? "," : "") << cols[i];
    // Then every setting any trial has (Trial::settings), typed, in name order.
    std::set<std::string> setting_keys;
    for (const Trial& t : data.trials)
        for (const auto& kv : t.settings) setting_keys.insert(kv.first);
    // A setting that is an array of numbers (a position) is one column per
    // element, "KEY[0]", "KEY[1]", ..., each a number (read_trials_csv joins them back).
    std::map<std::string, std::size_t> elements;
    for (const Trial& t : data.trials)
        for (const auto& [k, v] : t.settings)
            if (const auto xs = setting_value(v).numbers) elements[k] = std::max(elements[k], xs->size());
    for (const std::string& k : setting_keys) {
        const auto e = elements.find(k);
        if (e == elements.end()) {
            out << ',' << csv_field(k);
            continue;
        }
        for (std::size_t i = 0; i < e->second; ++i) out << ',' << csv_field(fmt::format("{}[{}]", k, i));
    }
    out << '\n';
    auto num = [](const std::optional<double>& v) { return v ? detail::number_text(*v) : std::string(); };
    auto flag = [](const std::optional<bool>& v) { return v ? std::string(*v ? "1" : "0") : std::string(); };
    for (const Trial& t : data.trials) {
        const std::vector<std::string> f{csv_field(t.session),
                                         csv_field(t.observer),
                                         std::to_string(t.trial_index),
                                         csv_field(t.block_name.empty() ? std::to_string(t.block) : t.block_name),
                                         std::to_string(t.block),
                                         csv_field(t.condition),
                                         csv_field(t.track),
                                         csv_field(t.procedure),
                                         std::string(to_string(t.task)),
                                         detail::number_text(t.level),  // noise removed by read_study
                                         csv_field(t.level_key),
                                         csv_field(t.level_scale),
                                         csv_field(t.level_on),
                                         csv_field(t.response),
                                         flag(t.outcome),
                                         flag(t.test_on_left),
                                         num(t.response_value),
                                         detail::number_text(t.response_time_s),
                                         detail::number_text(t.onset_time_s),
                                         std::to_string(t.dropped_frames),
                                         t.missed_deadline ? "1" : "0",
                                         num(t.adaptation_cd_m2),
                                         csv_field(t.tone_operator),
                                         csv_field(t.glare_test),
                                         csv_field(t.glare_reference),
                                         num(t.test_intensity_cd),
                                         csv_field(t.test_look.colour),
                                         csv_field(t.test_look.rhythm),
                                         csv_field(t.test_look.spectrum),
                                         csv_field(t.reference_look.colour),
                                         csv_field(t.reference_look.rhythm),
                                         csv_field(t.reference_look.spectrum),
                                         chose_reference(t),
                                         detail::number_text(t.guess_rate),
                                         detail::number_text(t.target_p),
                                         flag(t.reversal),
                                         num(t.posterior_mean),
                                         num(t.posterior_sd),
                                         num(t.posterior_lower),
                                         num(t.posterior_upper),
                                         csv_field(t.source)};
        for (std::size_t i = 0; i < f.size(); ++i) out << (i ? "," : "") << f[i];
        for (const std::string& k : setting_keys) {
            const auto it = t.settings.find(k);
            const auto e = elements.find(k);
            if (e == elements.end()) {
                out << ',' << (it == t.settings.end() ? std::string() : setting_field(it->second));
                continue;
            }
            const std::optional<std::vector<double>> xs =
                it == t.settings.end() ? std::nullopt : setting_value(it->second).numbers;
            for (std::size_t i = 0; i < e->second; ++i) {
                out << ',';
                if (xs && i < xs->size())
                    out << detail::number_text((*xs)[i]);
                else if (i == 0 && it != t.settings.end() && !xs)
                    out << setting_field(it->second);
            }
        }
        out << '\n';
    }
    files::write_file_atomically(csv_file, out.str());
}

// ---------------------------------------------------------------------------

void merge(Dataset& into, Dataset&& more) {
    std::set<std::string, std::less<>> keys;
    std::map<std::string, std::string> source_of;  // session key -> its input
    for (const SessionInfo& s : into.sessions) {
        keys.insert(s.key);
        source_of[s.key] = s.source;
    }
    auto same_file = [](const std::string& a, const std::string& b) {
        std::error_code ec1, ec2;
        const auto ca = std::filesystem::weakly_canonical(a, ec1);
        const auto cb = std::filesystem::weakly_canonical(b, ec2);
        return ec1 || ec2 ? a == b : ca == cb;
    };
    // Two different study files with the same name (a/study.db, b/study.db):
    // the second one's sessions are named with the file's folder too.
    bool rename = false;
    for (const SessionInfo& s : more.sessions)
        if (keys.count(s.key) && !s.source.empty() && !same_file(source_of[s.key], s.source) && s.id != 0)
            rename = true;
    if (rename) {
        std::map<std::string, std::string> renamed;
        for (SessionInfo& s : more.sessions) {
            const std::filesystem::path p(s.source);
            std::error_code ec;
            const std::filesystem::path full = std::filesystem::weakly_canonical(p, ec);
            const std::string folder = (ec ? p : full).parent_path().filename().string();
            const std::string key = fmt::format("{}/{}#{}", folder, p.filename().string(), s.id);
            renamed[s.key] = key;
            s.key = key;
        }
        for (Trial& t : more.trials)
            if (const auto it = renamed.find(t.session); it != renamed.end()) t.session = it->second;
        for (SnapshotRef& r : more.snapshots)
            if (const auto it = renamed.find(r.session); it != renamed.end()) r.session = it->second;
    }
    for (const SessionInfo& s : more.sessions)
        if (keys.count(s.key))
            throw csv_error(s.source, 0, "",
                            fmt::format("session '{}' is given twice (the same input named twice?)", s.key));
    auto append = [](auto& a, auto& b) {
        a.insert(a.end(), std::make_move_iterator(b.begin()), std::make_move_iterator(b.end()));
    };
    append(into.sources, more.sources);
    append(into.trials, more.trials);
    append(into.sessions, more.sessions);
    append(into.calibrations, more.calibrations);
    append(into.snapshots, more.snapshots);
    append(into.notes, more.notes);
    append(into.damaged, more.damaged);
    append(into.temporaries, more.temporaries);
}

}  // namespace atonlab::analysis
