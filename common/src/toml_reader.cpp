// Strict TOML reading (toml_reader.h).
#include "atonlab/common/toml_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "atonlab/common/input_limits.h"
#include "atonlab/common/input_text.h"
#include "atonlab/common/toml_text.h"

namespace atonlab::toml_reader {

using text::type_phrase;

std::string join_quoted(KeyList items) {
    std::string s;
    for (std::string_view item : items) {
        if (!s.empty()) s += ", ";
        s += fmt::format("'{}'", item);
    }
    return s;
}

std::string number_text(double v) { return fmt::format("{}", v); }

// ---------------------------------------------------------------------------
// Document

int Document::line_of(const toml::node* node) noexcept {
    return node != nullptr ? static_cast<int>(node->source().begin.line) : 0;
}

int Document::column_of(const toml::node* node) noexcept {
    return node != nullptr ? static_cast<int>(node->source().begin.column) : 0;
}

void Document::note(const InputError& e) const {
    if (errors_ != nullptr) errors_->add(text::Problem::of(e));
}

SourceLocation Document::where(const toml::node* node, const std::string& key) const {
    return SourceLocation{file_, line_of(node), column_of(node), key};
}

SourceLocation Document::where(const toml::key& k, const std::string& key) const {
    return SourceLocation{file_, static_cast<int>(k.source().begin.line), static_cast<int>(k.source().begin.column),
                          key};
}

void Document::relocate(SourceLocation&, std::string&) const {}

void Document::fail_at(SourceLocation w, std::string message) const {
    relocate(w, message);
    throw InputError(std::move(w), message);
}

void Document::fail(const toml::node* node, const std::string& key, const std::string& message) const {
    fail_at(where(node, key), message);
}

void Document::fail_at_key(const toml::key& k, const std::string& key, const std::string& message) const {
    fail_at(where(k, key), message);
}

void Document::fail_at_line(int line, const std::string& key, const std::string& message) const {
    fail_at(SourceLocation{file_, line, 0, key}, message);
}

double Document::number(const toml::node* n, const std::string& key, std::string_view name,
                        const std::string& context) const {
    double v = 0.0;
    if (n->is_integer())
        v = static_cast<double>(n->as_integer()->get());
    else if (n->is_floating_point())
        v = n->as_floating_point()->get();
    else
        fail(n, key, context + fmt::format("expected a number, got {}.", type_phrase(n->type())));
    if (!std::isfinite(v))
        fail(n, key, context + fmt::format("{} must be a finite number, got {}.", name, number_text(v)));
    return v;
}

int Document::integer(const toml::node* n, const std::string& key, std::string_view name, long long min, long long max,
                      const std::string& context) const {
    if (!n->is_integer()) fail(n, key, context + fmt::format("expected an integer, got {}.", type_phrase(n->type())));
    const std::int64_t v = n->as_integer()->get();
    if (v < min || v > max)
        fail(n, key, context + fmt::format("{} must be between {} and {}, got {}.", name, min, max, v));
    return static_cast<int>(v);
}

std::int64_t Document::integer64(const toml::node* n, const std::string& key, const std::string& context) const {
    if (!n->is_integer()) fail(n, key, context + fmt::format("expected an integer, got {}.", type_phrase(n->type())));
    return n->as_integer()->get();
}

bool Document::boolean(const toml::node* n, const std::string& key, const std::string& context) const {
    if (!n->is_boolean())
        fail(n, key, context + fmt::format("expected true or false, got {}.", type_phrase(n->type())));
    return n->as_boolean()->get();
}

std::string Document::string(const toml::node* n, const std::string& key, const std::string& context) const {
    if (!n->is_string()) fail(n, key, context + fmt::format("expected a string, got {}.", type_phrase(n->type())));
    return n->as_string()->get();
}

std::vector<double> Document::numbers(const toml::node* n, const std::string& key, std::string_view name,
                                      bool scalar_ok, const std::string& context) const {
    if (scalar_ok && (n->is_integer() || n->is_floating_point())) return {number(n, key, name, context)};
    if (!n->is_array())
        fail(n, key,
             context + fmt::format("expected {}an array of numbers, got {}.", scalar_ok ? "a number or " : "",
                                   type_phrase(n->type())));
    const toml::array& a = *n->as_array();
    if (a.empty()) fail(n, key, context + fmt::format("{} needs at least one number, got an empty array.", name));
    std::vector<double> out;
    out.reserve(a.size());
    for (std::size_t i = 0; i < a.size(); ++i)
        out.push_back(number(a.get(i), fmt::format("{}[{}]", key, i), fmt::format("{}[{}]", name, i), context));
    return out;
}

std::vector<std::string> Document::strings(const toml::node* n, const std::string& key,
                                           const std::string& context) const {
    if (n->is_string()) return {n->as_string()->get()};
    if (!n->is_array())
        fail(n, key,
             context + fmt::format("expected a string or an array of strings, got {}.", type_phrase(n->type())));
    std::vector<std::string> out;
    const toml::array& a = *n->as_array();
    for (std::size_t i = 0; i < a.size(); ++i) out.push_back(string(a.get(i), fmt::format("{}[{}]", key, i), context));
    return out;
}

std::array<double, 3> Document::vec3(const toml::node* n, const std::string& key, std::string_view name,
                                     const std::string& context) const {
    if (!n->is_array() || n->as_array()->size() != 3)
        fail(n, key,
             context + fmt::format("expected an array of 3 numbers [x, y, z], got {}.",
                                   n->is_array() ? fmt::format("{} elements", n->as_array()->size())
                                                 : std::string(type_phrase(n->type()))));
    const toml::array& a = *n->as_array();
    std::array<double, 3> v{};
    for (std::size_t i = 0; i < 3; ++i)
        v[i] = number(a.get(i), fmt::format("{}[{}]", key, i), fmt::format("{}[{}]", name, i), context);
    return v;
}

// ---------------------------------------------------------------------------
// Section

std::string Section::key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

void Section::allow(KeyList allowed, const std::function<std::string(std::string_view)>& belongs) const {
    std::vector<InputError> unknown;
    for (auto&& [k, v] : table_) {
        if (std::find(allowed.begin(), allowed.end(), k.str()) != allowed.end()) continue;
        const std::string elsewhere = belongs ? belongs(k.str()) : std::string();
        const std::string message =
            elsewhere.empty() ? fmt::format("unknown key '{}' in {}.{} Allowed keys: {}.", text::echo(k.str()), title_,
                                            text::did_you_mean(k.str(), allowed), join_quoted(allowed))
                              : fmt::format("'{}' is not a key of {}: {}", text::echo(k.str()), title_, elsewhere);
        unknown.emplace_back(doc_.where(k, key_path(k.str())), message);
    }
    if (unknown.empty()) return;
    for (std::size_t i = 1; i < unknown.size(); ++i) doc_.note(unknown[i]);
    throw unknown.front();
}

void Section::missing(std::string_view key, std::string_view what) const {
    const SourceLocation w = doc_.where(&table_, path_);
    const std::string at_line = !w.from_command_line() && w.line > 0 ? fmt::format(" (line {})", w.line) : std::string();
    doc_.fail(&table_, key_path(key), fmt::format("{}{} has no '{}', which is required ({}).", title_, at_line, key, what));
}

void Section::fail(const toml::node* node, std::string_view key, const std::string& message) const {
    doc_.fail(node, key_path(key), context_ + message);
}

void Section::fail(std::string_view key, const std::string& message) const {
    const toml::node* n = get(key);
    doc_.fail(n != nullptr ? n : &table_, key_path(key), context_ + message);
}

void Section::fail_table(const std::string& message) const { doc_.fail(&table_, path_, context_ + message); }

std::optional<double> Section::number(std::string_view key) const {
    const toml::node* n = get(key);
    if (n == nullptr) return std::nullopt;
    return doc_.number(n, key_path(key), key, context_);
}

double Section::required_number(std::string_view key, std::string_view what) const {
    if (auto v = number(key)) return *v;
    missing(key, what);
}

std::optional<int> Section::integer(std::string_view key, long long min, long long max) const {
    const toml::node* n = get(key);
    if (n == nullptr) return std::nullopt;
    return doc_.integer(n, key_path(key), key, min, max, context_);
}

std::optional<bool> Section::boolean(std::string_view key) const {
    const toml::node* n = get(key);
    if (n == nullptr) return std::nullopt;
    return doc_.boolean(n, key_path(key), context_);
}

std::optional<std::string> Section::string(std::string_view key) const {
    const toml::node* n = get(key);
    if (n == nullptr) return std::nullopt;
    return doc_.string(n, key_path(key), context_);
}

std::optional<std::vector<double>> Section::numbers(std::string_view key, std::size_t size_required,
                                                    std::size_t min_size) const {
    const toml::node* n = get(key);
    if (n == nullptr) return std::nullopt;
    const std::string shape = size_required == 3   ? "an array of 3 numbers [x, y, z]"
                              : size_required == 2 ? "an array of 2 numbers"
                                                   : "an array of numbers";
    if (!n->is_array()) fail(n, key, fmt::format("expected {}, got {}.", shape, type_phrase(n->type())));
    const toml::array& a = *n->as_array();
    if (size_required != 0 && a.size() != size_required)
        fail(n, key, fmt::format("expected {}, got {} element{}.", shape, a.size(), a.size() == 1 ? "" : "s"));
    if (a.size() < min_size) fail(n, key, fmt::format("expected at least {} numbers, got {}.", min_size, a.size()));
    std::vector<double> out;
    out.reserve(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string element = fmt::format("{}[{}]", key, i);
        out.push_back(doc_.number(a.get(i), key_path(element), element, context_));
    }
    return out;
}

const toml::table* Section::table(std::string_view key, std::string_view as_written) const {
    const toml::node* n = get(key);
    if (n == nullptr) return nullptr;
    if (!n->is_table())
        fail(n, key,
             fmt::format("expected a table {}, got {}.",
                         as_written.empty() ? fmt::format("[{}]", key_path(key)) : std::string(as_written),
                         type_phrase(n->type())));
    return n->as_table();
}

void Section::at_least(std::string_view key, double v, double min) const {
    if (!(v >= min)) fail(key, fmt::format("{} must be at least {}, got {}.", key, number_text(min), number_text(v)));
}

void Section::greater_than(std::string_view key, double v, double min) const {
    if (!(v > min))
        fail(key, fmt::format("{} must be greater than {}, got {}.", key, number_text(min), number_text(v)));
}

void Section::within(std::string_view key, double v, double lo, double hi) const {
    if (!(v >= lo && v <= hi))
        fail(key, fmt::format("{} must be between {} and {}, got {}.", key, number_text(lo), number_text(hi),
                              number_text(v)));
}

void Section::duration_at_most(std::string_view key, double v) const {
    if (!(v <= limits::kMaxDurationS))
        fail(key, fmt::format("{} must be at most {} s (a day; durations are counted in whole refreshes), got {}.",
                              key, number_text(limits::kMaxDurationS), number_text(v)));
}

}  // namespace atonlab::toml_reader
