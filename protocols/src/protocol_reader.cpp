// What the protocol file adds to the strict TOML reader (protocol_reader.h).
#include "protocol_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>

#include "atonlab/common/scene_override.h"
#include "atonlab/common/toml_text.h"

namespace atonlab::protocols::detail {

namespace {

/// A dotted scene key: at least two non-empty parts, no spaces or '='.
bool is_scene_key(std::string_view k) {
    if (k.empty() || k.front() == '.' || k.back() == '.') return false;
    if (k.find('.') == std::string_view::npos || k.find("..") != std::string_view::npos) return false;
    return std::none_of(k.begin(), k.end(), [](char c) { return c == ' ' || c == '\t' || c == '=' || c == '"'; });
}

}  // namespace

// ---------------------------------------------------------------------------
// Document

void Document::relocate(SourceLocation& w, std::string& message) const {
    const std::string key = w.key;
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
        w = SourceLocation{row.file, row.line, col, ""};
        message = where + message;
        return;
    }
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

SceneOverride Document::scene_override(const toml::node* n, const std::string& key, const std::string& context) const {
    const std::string text = string(n, key, context);
    // The one reader of "key=value" (common/scene_override.h).
    const std::optional<KeyValue> kv = read_key_value(text);
    if (!kv)
        fail(n, key,
             context + fmt::format("expected \"section.key=value\" with a TOML value, e.g. 'eye.glare=\"none\"', "
                                   "got \"{}\".",
                                   text));
    // Where it was written: the protocol's line and key, or a conditions
    // file's row and column; errors about the value name it (scene loader).
    SourceLocation origin = where(n, key);
    std::string no_message;
    relocate(origin, no_message);
    // The value is parsed here, once (SceneOverride's constructor).
    SceneOverride o(kv->key, kv->text, std::move(origin));
    if (!is_scene_key(o.key))
        fail(n, key,
             context + fmt::format("\"{}\" is not a scene key: write section.key as in the scene file, e.g. "
                                   "'eye.glare=\"none\"'.",
                                   o.key));
    const bool ok = o.not_toml().empty();  // one TOML value (empty text is none)
    if (!ok)
        fail(n, key,
             context + fmt::format("the value of '{}' is not one TOML value (a string needs quotes, as in "
                                   "'{}=\"{}\"'), got '{}'.",
                                   o.key, o.key, o.value, o.value));
    return o;
}

std::vector<SceneOverride> Document::scene_overrides(const toml::node* n, const std::string& key,
                                                     const std::string& context) const {
    if (n->is_string()) return {scene_override(n, key, context)};
    if (!n->is_array())
        fail(n, key,
             context +
                 fmt::format("expected an array of \"section.key=value\" strings, got {}.", text::type_phrase(n->type())));
    std::vector<SceneOverride> out;
    const toml::array& a = *n->as_array();
    for (std::size_t i = 0; i < a.size(); ++i)
        out.push_back(scene_override(a.get(i), fmt::format("{}[{}]", key, i), context));
    return out;
}

}  // namespace atonlab::protocols::detail
