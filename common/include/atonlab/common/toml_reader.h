#pragma once
// Reading TOML input strictly, the one reader of the scene file (stimuli) and
// the protocol file (protocols): every value type-checked and finite, every
// unknown key refused with a suggestion, every error one InputError naming the
// file, the line and the dotted key (docs/scene-file.md, docs/protocol-file.md).
//
// A Document turns nodes into locations and throws; a loader whose values may
// come from elsewhere (the scene's --set overrides, the protocol's conditions
// files) derives from it and says where a node came from (where) or where an
// error belongs (fail_at). A Section is one table of a schema.
#include <toml++/toml.h>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/common/error_list.h"
#include "atonlab/common/input_error.h"

namespace atonlab::toml_reader {

using KeyList = std::span<const std::string_view>;

/// "'a', 'b', 'c'".
std::string join_quoted(KeyList items);
/// A number as messages print it ("0.5", "1e+300", "inf").
std::string number_text(double v);

/// The file being read: turns nodes into locations and throws.
class Document {
public:
    explicit Document(std::string file) : file_(std::move(file)) {}
    virtual ~Document() = default;
    Document(const Document&) = delete;
    Document& operator=(const Document&) = delete;

    const std::string& file() const noexcept { return file_; }

    /// Where errors found past the first one of a table go (Section::allow
    /// reports every unknown key of a table); none: only the first is thrown.
    void collect_into(text::ErrorList* errors) noexcept { errors_ = errors; }
    /// Adds `e` to the error list (when there is one).
    void note(const InputError& e) const;

    /// Where `node` was written, with its dotted schema key ("light[2].intensity_cd").
    virtual SourceLocation where(const toml::node* node, const std::string& key) const;
    virtual SourceLocation where(const toml::key& k, const std::string& key) const;
    /// Throws the error at `w` (after relocate).
    [[noreturn]] void fail_at(SourceLocation w, std::string message) const;

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

protected:
    /// Where an error found at `w` belongs, and its sentence: a derived
    /// document may move it (a conditions file's row and column) or add to it
    /// (an override read as a string). Unchanged by default.
    virtual void relocate(SourceLocation& w, std::string& message) const;

private:
    std::string file_;
    text::ErrorList* errors_ = nullptr;
};

/// One table of the schema, named by its dotted path ("timing", "light[2]",
/// "block[1].condition[0]") and by how a sentence names it ("the [display]
/// table", "[[light]] \"buoy\"").
class Section {
public:
    Section(const Document& doc, const toml::table& table, std::string path, std::string title)
        : doc_(doc), table_(table), path_(std::move(path)), title_(std::move(title)) {}

    const toml::table& table() const noexcept { return table_; }
    const std::string& path() const noexcept { return path_; }
    const std::string& title() const noexcept { return title_; }
    const Document& doc() const noexcept { return doc_; }
    /// Prefix for value errors, e.g. "in light \"buoy\", ".
    void set_context(std::string context) { context_ = std::move(context); }
    void set_title(std::string title) { title_ = std::move(title); }
    std::string key_path(std::string_view key) const;
    int line() const noexcept { return Document::line_of(&table_); }

    /// Every key must be in `allowed`. Every unknown key is an error (the
    /// first thrown, the others noted in the document's error list);
    /// `belongs` names, for a key that is known elsewhere, where it belongs
    /// ("'levels' belongs in [defaults.procedure]."), else "".
    void allow(KeyList allowed, const std::function<std::string(std::string_view)>& belongs = {}) const;
    const toml::node* get(std::string_view key) const { return table_.get(key); }
    bool has(std::string_view key) const { return table_.contains(key); }
    [[noreturn]] void missing(std::string_view key, std::string_view what) const;
    /// The error at `node` (the value of `key` or an element of it).
    [[noreturn]] void fail(const toml::node* node, std::string_view key, const std::string& message) const;
    /// The error at `key`'s value, or at the table when the key is absent.
    [[noreturn]] void fail(std::string_view key, const std::string& message) const;
    [[noreturn]] void fail_table(const std::string& message) const;

    // Values, type-checked and finite. Integers are accepted as numbers.
    std::optional<double> number(std::string_view key) const;
    double number_or(std::string_view key, double fallback) const { return number(key).value_or(fallback); }
    double required_number(std::string_view key, std::string_view what) const;
    std::optional<int> integer(std::string_view key, long long min, long long max) const;
    std::optional<bool> boolean(std::string_view key) const;
    std::optional<std::string> string(std::string_view key) const;
    /// A numeric array; size_required 0 = any length of at least min_size.
    std::optional<std::vector<double>> numbers(std::string_view key, std::size_t size_required,
                                               std::size_t min_size = 0) const;
    /// The sub-table `key`, or nullptr; an error when it is not a table.
    /// `as_written` names it in that error ("[display]"); empty: "[PATH.KEY]".
    const toml::table* table(std::string_view key, std::string_view as_written = {}) const;

    // Range checks, one sentence each, at the key's line.
    void at_least(std::string_view key, double v, double min) const;
    void greater_than(std::string_view key, double v, double min) const;
    void within(std::string_view key, double v, double lo, double hi) const;
    /// A duration in seconds: at most limits::kMaxDurationS (a frame count must hold it).
    void duration_at_most(std::string_view key, double v) const;

private:
    const Document& doc_;
    const toml::table& table_;
    std::string path_;
    std::string title_;
    std::string context_;
};

}  // namespace atonlab::toml_reader
