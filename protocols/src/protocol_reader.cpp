// Strict TOML reading for the protocol file (protocol_reader.h).
#include "protocol_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "atonlab/common/input_limits.h"
#include "atonlab/common/toml_text.h"

namespace atonlab::protocols::detail {

namespace {

std::string number_text(double v) {
    return fmt::format("{}", v);
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

/// A dotted scene key: at least two non-empty parts, no spaces or '='.
bool is_scene_key(std::string_view k) {
    if (k.empty() || k.front() == '.' || k.back() == '.') return false;
    if (k.find('.') == std::string_view::npos || k.find("..") != std::string_view::npos) return false;
    return std::none_of(k.begin(), k.end(), [](char c) { return c == ' ' || c == '\t' || c == '=' || c == '"'; });
}

}  // namespace

std::string suggestion(std::string_view key, KeyList allowed) { return text::did_you_mean(key, allowed); }

std::string join_quoted(KeyList items) {
    std::string s;
    for (std::string_view item : items) {
        if (!s.empty()) s += ", ";
        s += fmt::format("'{}'", item);
    }
    return s;
}

std::string_view type_phrase(toml::node_type type) { return text::type_phrase(type); }

// ---------------------------------------------------------------------------
// Document

int Document::line_of(const toml::node* node) noexcept {
    return node != nullptr ? static_cast<int>(node->source().begin.line) : 0;
}

int Document::column_of(const toml::node* node) noexcept {
    return node != nullptr ? static_cast<int>(node->source().begin.column) : 0;
}

void Document::note(const ProtocolError& e) const {
    if (errors_ != nullptr) errors_->add(problem(e));
}

text::Problem Document::problem(const ProtocolError& e) {
    return text::Problem{e.file(), e.line(), e.column(), e.key(), e.message(), e.what()};
}

void Document::throw_at(int line, int column, const std::string& key, const std::string& message) const {
    for (const auto& entry : csv_rows_) {
        // Named references, not structured bindings: clang 14 (the fuzz
        // build) cannot capture a binding in a lambda.
        const auto& path = entry.first;
        const auto& row = entry.second;
        if (key != path && key.rfind(path + ".", 0) != 0) continue;
        const std::string rest = key.size() > path.size() ? key.substr(path.size() + 1) : std::string();
        // The column: an override's by its index, a procedure parameter's by
        // "procedure.NAME", any other key's by its name.
        int col = 0;
        std::string name;
        auto by_name = [&](const std::string& n) {
            for (const auto& [cn, c] : row.columns)
                if (cn == n) {
                    name = cn;
                    col = c;
                }
        };
        auto by_index = [&](const std::string& list_name, const std::vector<int>& cols) {
            if (rest.rfind(list_name + "[", 0) != 0) return false;
            const std::size_t i = static_cast<std::size_t>(std::atoi(rest.c_str() + list_name.size() + 1));
            if (i < cols.size()) {
                col = cols[i];
                for (const auto& [cn, c] : row.columns)
                    if (c == col) name = cn;
            }
            return true;
        };
        if (!by_index("set", row.set) && !by_index("test_set", row.test_set) &&
            !by_index("reference_set", row.reference_set)) {
            const std::size_t dot = rest.find('.', rest.rfind("procedure.", 0) == 0 ? 10 : 0);
            by_name(rest.substr(0, dot));
        }
        const std::string where = col > 0 ? fmt::format("column {} '{}': ", col, name) : std::string();
        throw ProtocolError(row.file, row.line, col, "", where + message);
    }
    throw ProtocolError(file_, line, column, key, message);
}

void Document::fail(const toml::node* node, const std::string& key, const std::string& message) const {
    throw_at(line_of(node), column_of(node), key, message);
}

void Document::fail_at_key(const toml::key& k, const std::string& key, const std::string& message) const {
    throw_at(static_cast<int>(k.source().begin.line), static_cast<int>(k.source().begin.column), key, message);
}

void Document::fail_at_line(int line, const std::string& key, const std::string& message) const {
    throw_at(line, 0, key, message);
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

std::string Document::scene_key(const toml::node* n, const std::string& key, const std::string& context) const {
    const std::string k = string(n, key, context);
    if (!is_scene_key(k))
        fail(n, key,
             context + fmt::format("\"{}\" is not a scene key: write section.key as in the scene file, e.g. "
                                   "\"light.reference.intensity_cd\".",
                                   k));
    return k;
}

Override Document::scene_override(const toml::node* n, const std::string& key, const std::string& context) const {
    const std::string text = string(n, key, context);
    const auto eq = text.find('=');
    if (eq == std::string::npos)
        fail(n, key,
             context + fmt::format("expected \"section.key=value\" with a TOML value, e.g. 'eye.glare=\"none\"', "
                                   "got \"{}\".",
                                   text));
    Override o;
    o.key = std::string(trim(std::string_view(text).substr(0, eq)));
    o.value = std::string(trim(std::string_view(text).substr(eq + 1)));
    o.line = line_of(n);
    o.column = column_of(n);
    if (!is_scene_key(o.key))
        fail(n, key,
             context + fmt::format("\"{}\" is not a scene key: write section.key as in the scene file, e.g. "
                                   "'eye.glare=\"none\"'.",
                                   o.key));
    bool ok = !o.value.empty();
    if (ok) {
        try {
            const toml::table parsed = toml::parse("v = " + o.value);
            ok = parsed.size() == 1 && parsed.contains("v");
        } catch (const toml::parse_error&) {
            ok = false;
        }
    }
    if (!ok)
        fail(n, key,
             context + fmt::format("the value of '{}' is not one TOML value (a string needs quotes, as in "
                                   "'{}=\"{}\"'), got '{}'.",
                                   o.key, o.key, o.value, o.value));
    return o;
}

std::vector<Override> Document::scene_overrides(const toml::node* n, const std::string& key,
                                                const std::string& context) const {
    if (n->is_string()) return {scene_override(n, key, context)};
    if (!n->is_array())
        fail(n, key,
             context +
                 fmt::format("expected an array of \"section.key=value\" strings, got {}.", type_phrase(n->type())));
    std::vector<Override> out;
    const toml::array& a = *n->as_array();
    for (std::size_t i = 0; i < a.size(); ++i)
        out.push_back(scene_override(a.get(i), fmt::format("{}[{}]", key, i), context));
    return out;
}

// ---------------------------------------------------------------------------
// Section

std::string Section::key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

void Section::allow(KeyList allowed, const std::function<std::string(std::string_view)>& belongs) const {
    std::vector<ProtocolError> unknown;
    for (auto&& [k, v] : table_) {
        if (std::find(allowed.begin(), allowed.end(), k.str()) != allowed.end()) continue;
        const std::string elsewhere = belongs ? belongs(k.str()) : std::string();
        const std::string message = elsewhere.empty()
                                        ? fmt::format("unknown key '{}' in {}.{} Allowed keys: {}.", k.str(), title_,
                                                      suggestion(k.str(), allowed), join_quoted(allowed))
                                        : fmt::format("'{}' is not a key of {}: {}", k.str(), title_, elsewhere);
        unknown.emplace_back(doc_.file(), static_cast<int>(k.source().begin.line),
                             static_cast<int>(k.source().begin.column), key_path(k.str()), message);
    }
    if (unknown.empty()) return;
    for (std::size_t i = 1; i < unknown.size(); ++i) doc_.note(unknown[i]);
    throw unknown.front();
}

void Section::missing(std::string_view key, std::string_view what) const {
    const int at = line();
    const std::string at_line = at > 0 ? fmt::format(" (line {})", at) : std::string();
    doc_.fail_at_line(at, key_path(key),
                      fmt::format("{}{} has no '{}', which is required ({}).", title_, at_line, key, what));
}

void Section::fail(std::string_view key, const std::string& message) const {
    const toml::node* n = get(key);
    doc_.fail(n != nullptr ? n : &table_, key_path(key), message);
}

std::optional<double> Section::number(std::string_view key) const {
    const toml::node* n = get(key);
    if (n == nullptr) return std::nullopt;
    return doc_.number(n, key_path(key), key);
}

double Section::required_number(std::string_view key, std::string_view what) const {
    if (auto v = number(key)) return *v;
    missing(key, what);
}

std::optional<int> Section::integer(std::string_view key, long long min, long long max) const {
    const toml::node* n = get(key);
    if (n == nullptr) return std::nullopt;
    return doc_.integer(n, key_path(key), key, min, max);
}

std::optional<std::string> Section::string(std::string_view key) const {
    const toml::node* n = get(key);
    if (n == nullptr) return std::nullopt;
    return doc_.string(n, key_path(key));
}

const toml::table* Section::table(std::string_view key) const {
    const toml::node* n = get(key);
    if (n == nullptr) return nullptr;
    if (!n->is_table())
        doc_.fail(n, key_path(key),
                  fmt::format("expected a table [{}], got {}.", key_path(key), type_phrase(n->type())));
    return n->as_table();
}

void Section::at_least(std::string_view key, double v, double min) const {
    if (!(v >= min)) fail(key, fmt::format("{} must be at least {}, got {}.", key, number_text(min), number_text(v)));
}

void Section::greater_than(std::string_view key, double v, double min) const {
    if (!(v > min))
        fail(key, fmt::format("{} must be greater than {}, got {}.", key, number_text(min), number_text(v)));
}

void Section::duration_at_most(std::string_view key, double v) const {
    if (!(v <= limits::kMaxDurationS))
        fail(key, fmt::format("{} must be at most {} s (a day; durations are counted in whole refreshes), got {}.",
                              key, number_text(limits::kMaxDurationS), number_text(v)));
}

}  // namespace atonlab::protocols::detail
