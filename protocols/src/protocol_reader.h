#pragma once
// Reading the protocol file's TOML strictly: every value type-checked and
// finite, every unknown key refused with a suggestion, every error one
// sentence naming the file, the line and the dotted key (the scene file's
// rules, docs/scene-file.md; protocols may not include stimuli's reader).
#include <toml++/toml.h>

#include <array>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/common/error_list.h"
#include "atonlab/protocols/protocol.h"

namespace atonlab::protocols::detail {

using KeyList = std::span<const std::string_view>;

/// " Did you mean 'x'?" for the nearest of `allowed` within two edits (or the
/// key with a unit suffix: "stimulus" -> "stimulus_s"), else "".
std::string suggestion(std::string_view key, KeyList allowed);
/// "'a', 'b', 'c'".
std::string join_quoted(KeyList items);
/// "a string", "an integer", ...
std::string_view type_phrase(toml::node_type type);

/// The file being read: turns nodes into locations and throws.
class Document {
public:
    explicit Document(std::string file) : file_(std::move(file)) {}
    const std::string& file() const noexcept { return file_; }

    /// Where errors found past the first one of a table go (Section::allow
    /// reports every unknown key of a table); none: only the first is thrown.
    void collect_into(text::ErrorList* errors) noexcept { errors_ = errors; }
    /// Adds `e` to the error list (when there is one).
    void note(const ProtocolError& e) const;
    static text::Problem problem(const ProtocolError& e);

    /// A condition read from a row of a conditions file (CSV): its errors name
    /// the CSV file, the row's line and the column instead of the TOML path.
    struct CsvRow {
        std::string file;
        int line = 0;                                      ///< 1-based line of the row in the CSV file
        std::vector<std::pair<std::string, int>> columns;  ///< (column name, 1-based column) of the row's cells
        std::vector<int> set, test_set, reference_set;     ///< the column of each override, in order
    };
    /// Registers the condition at `path` ("block[0].condition[2]") as `row`.
    void add_csv_row(std::string path, CsvRow row) { csv_rows_.emplace_back(std::move(path), std::move(row)); }

    [[noreturn]] void fail(const toml::node* node, const std::string& key, const std::string& message) const;
    [[noreturn]] void fail_at_key(const toml::key& k, const std::string& key, const std::string& message) const;
    [[noreturn]] void fail_at_line(int line, const std::string& key, const std::string& message) const;
    static int line_of(const toml::node* node) noexcept;
    static int column_of(const toml::node* node) noexcept;

    // Typed values; `key` is the dotted path for messages, `name` the short
    // name used in the sentence, `context` a prefix ("in condition \"x\", ").
    double number(const toml::node* n, const std::string& key, std::string_view name,
                  const std::string& context = {}) const;
    int integer(const toml::node* n, const std::string& key, std::string_view name, long long min, long long max,
                const std::string& context = {}) const;
    std::int64_t integer64(const toml::node* n, const std::string& key, const std::string& context = {}) const;
    bool boolean(const toml::node* n, const std::string& key, const std::string& context = {}) const;
    std::string string(const toml::node* n, const std::string& key, const std::string& context = {}) const;
    /// An array of at least one number (or a single number when `scalar_ok`).
    std::vector<double> numbers(const toml::node* n, const std::string& key, std::string_view name, bool scalar_ok,
                                const std::string& context = {}) const;
    /// A string, or an array of strings.
    std::vector<std::string> strings(const toml::node* n, const std::string& key,
                                     const std::string& context = {}) const;
    std::array<double, 3> vec3(const toml::node* n, const std::string& key, std::string_view name,
                               const std::string& context = {}) const;
    /// One "section.key=value" scene override (value: one TOML value).
    Override scene_override(const toml::node* n, const std::string& key, const std::string& context = {}) const;
    /// An array of overrides (a single string is one override).
    std::vector<Override> scene_overrides(const toml::node* n, const std::string& key,
                                          const std::string& context = {}) const;
    /// A dotted scene key ("light.reference.intensity_cd").
    std::string scene_key(const toml::node* n, const std::string& key, const std::string& context = {}) const;

private:
    /// The error at `key`: in the CSV file when the key is a conditions-file row's.
    [[noreturn]] void throw_at(int line, int column, const std::string& key, const std::string& message) const;

    std::string file_;
    text::ErrorList* errors_ = nullptr;
    std::vector<std::pair<std::string, CsvRow>> csv_rows_;
};

/// One table of the schema, named by its dotted path ("timing",
/// "block[1].condition[0]") and by how a sentence names it.
class Section {
public:
    Section(const Document& doc, const toml::table& table, std::string path, std::string title)
        : doc_(doc), table_(table), path_(std::move(path)), title_(std::move(title)) {}

    const toml::table& table() const noexcept { return table_; }
    const std::string& path() const noexcept { return path_; }
    const Document& doc() const noexcept { return doc_; }
    std::string key_path(std::string_view key) const;
    int line() const noexcept { return Document::line_of(&table_); }

    /// Every key must be in `allowed`. Every unknown key is an error (the
    /// first thrown, the others noted in the document's error list);
    /// `belongs` names, for a key that is known elsewhere, where it belongs
    /// ("'levels' belongs in [defaults.procedure]."), else "".
    void allow(KeyList allowed, const std::function<std::string(std::string_view)>& belongs = {}) const;
    const toml::node* get(std::string_view key) const { return table_.get(key); }
    [[noreturn]] void missing(std::string_view key, std::string_view what) const;
    [[noreturn]] void fail(std::string_view key, const std::string& message) const;

    std::optional<double> number(std::string_view key) const;
    double required_number(std::string_view key, std::string_view what) const;
    std::optional<int> integer(std::string_view key, long long min, long long max) const;
    std::optional<std::string> string(std::string_view key) const;
    /// The sub-table `key`, or nullptr; an error when it is not a table.
    const toml::table* table(std::string_view key) const;

    // Range checks, one sentence each, at the key's line.
    void at_least(std::string_view key, double v, double min) const;
    void greater_than(std::string_view key, double v, double min) const;
    /// A duration in seconds: at most limits::kMaxDurationS (a frame count must hold it).
    void duration_at_most(std::string_view key, double v) const;

private:
    const Document& doc_;
    const toml::table& table_;
    std::string path_;
    std::string title_;
};

}  // namespace atonlab::protocols::detail
