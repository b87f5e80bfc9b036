// A protocol with keys set from the command line (protocol_variant.h).
#include "simulate/protocol_variant.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <sstream>

#include "atonlab/common/input_error.h"
#include "atonlab/common/scene_override.h"
#include "atonlab/common/toml_value.h"

namespace atonlab::runner {

namespace {

std::vector<std::string> split_path(const std::string& key) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    while (true) {
        const std::size_t dot = key.find('.', start);
        parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    return parts;
}

}  // namespace

ProtocolSet parse_protocol_set(std::string_view text, std::string_view option) {
    // The one reader of "key=value" (common/scene_override.h).
    const std::optional<KeyValue> kv = read_key_value(text);
    if (!kv || kv->key.empty())
        throw InputError(SourceLocation::command_line(std::string(option), std::string(text)),
                         fmt::format("a protocol key to set is KEY=VALUE (e.g. defaults.procedure.max_trials=40), "
                                     "not \"{}\".",
                                     text));
    ProtocolSet s;
    s.key = kv->key;
    s.value = kv->text;
    if (s.key.find('.') == std::string::npos) s.key = "defaults.procedure." + s.key;
    for (const std::string& part : split_path(s.key))
        if (part.empty())
            throw InputError(SourceLocation::command_line(std::string(option), s.key),
                             fmt::format("the key \"{}\" has an empty part.", s.key));
    if (!kv->not_toml.empty())
        throw InputError(SourceLocation::command_line(std::string(option), s.key),
                         fmt::format("\"{}\" is not one TOML value ({}); a string needs quotes, e.g. "
                                     "display.name='\"lab-1\"'.",
                                     s.value, kv->not_toml));
    return s;
}

std::vector<ProtocolSet> parse_vary(std::string_view text) {
    const std::size_t eq = text.find('=');
    if (eq == std::string_view::npos || eq == 0 || eq + 1 == text.size())
        throw InputError(SourceLocation::command_line("--vary", std::string(text)),
                         fmt::format("--vary takes KEY=v1,v2,... (e.g. max_trials=20,40,80), not \"{}\".", text));
    const std::string_view key = text.substr(0, eq);
    std::vector<ProtocolSet> out;
    int depth = 0;
    char quote = 0;
    std::size_t start = eq + 1;
    for (std::size_t i = eq + 1; i <= text.size(); ++i) {
        const char c = i < text.size() ? text[i] : ',';
        if (quote != 0) {
            if (c == quote) quote = 0;
            continue;
        }
        if (c == '"' || c == '\'') quote = c;
        if (c == '[' || c == '{') ++depth;
        if (c == ']' || c == '}') --depth;
        if (c == ',' && depth == 0) {
            out.push_back(parse_protocol_set(fmt::format("{}={}", key, text.substr(start, i - start)), "--vary"));
            start = i + 1;
        }
    }
    if (out.size() < 2)
        throw InputError(SourceLocation::command_line("--vary", std::string(key)),
                         "--vary needs at least two values to compare, separated by commas.");
    return out;
}

std::string protocol_with(const std::string& text, std::string_view file_label, const std::vector<ProtocolSet>& sets,
                          std::string_view option) {
    if (sets.empty()) return text;
    toml::table doc;
    try {
        doc = toml::parse(text, std::string(file_label));
    } catch (const toml::parse_error& e) {
        throw InputError(SourceLocation{std::string(file_label), static_cast<int>(e.source().begin.line),
                                        static_cast<int>(e.source().begin.column), ""},
                         fmt::format("TOML syntax error: {}", e.description()));
    }
    std::string header = fmt::format("# atonlab simulate: {} with", file_label);
    for (const ProtocolSet& s : sets) {
        const std::vector<std::string> path = split_path(s.key);
        toml::table* t = &doc;
        for (std::size_t i = 0; i + 1 < path.size(); ++i) {
            toml::node* n = t->get(path[i]);
            if (n == nullptr) {
                t->insert(path[i], toml::table{});
                n = t->get(path[i]);
            }
            t = n->as_table();
            if (t == nullptr)
                throw InputError(SourceLocation::command_line(std::string(option), s.key),
                                 fmt::format("\"{}\" in {} is not a table, so {} cannot be set in it.", path[i],
                                             file_label, s.key));
        }
        const std::optional<TomlValue> v = TomlValue::parse(s.value);
        v->node().visit([&](const auto& node) { t->insert_or_assign(path.back(), node); });
        header += " " + s.text();
    }
    std::ostringstream out;
    out << header << "\n" << toml::toml_formatter(doc) << "\n";
    return out.str();
}

}  // namespace atonlab::runner
