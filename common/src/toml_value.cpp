// One TOML value parsed from its text (toml_value.h).
#include "atonlab/common/toml_value.h"

#include <fmt/format.h>

namespace atonlab {

namespace {

/// A TOML basic string holding `text`: quotes and backslashes escaped, control
/// characters written \uXXXX (TOML allows none of them raw but the tab).
std::string toml_quoted(std::string_view text) {
    std::string q = "\"";
    for (const char ch : text) {
        const auto c = static_cast<unsigned char>(ch);
        if (ch == '"' || ch == '\\') {
            q += '\\';
            q += ch;
        } else if (c < 0x20 || c == 0x7f) {
            q += fmt::format("\\u{:04X}", static_cast<unsigned>(c));
        } else {
            q += ch;
        }
    }
    return q + "\"";
}

}  // namespace

std::optional<TomlValue> TomlValue::parse(std::string_view text, std::string* error, std::string_view source) {
    // The value is parsed as the document "v = TEXT": TOML has no grammar for a
    // value alone, and this way an inline table, a string's escapes and a
    // trailing comment read exactly as they do in a file.
    auto doc = std::make_shared<toml::table>();
    try {
        *doc = toml::parse("v = " + std::string(text), source);
    } catch (const toml::parse_error& e) {
        if (error) *error = std::string(e.description());
        return std::nullopt;
    }
    if (doc->size() != 1 || !doc->contains(kKey)) {  // "1\nw = 2"
        if (error) *error = "more than one value";
        return std::nullopt;
    }
    return TomlValue(std::move(doc));
}

std::string TomlValue::quoted(std::string_view text) {
    return toml_quoted(text);
}

std::optional<TomlValue> TomlValue::string(std::string_view text, std::string* error, std::string_view source) {
    return parse(toml_quoted(text), error, source);
}

namespace {

template <class T>
std::shared_ptr<const toml::table> holding(T v) {
    auto doc = std::make_shared<toml::table>();
    doc->insert("v", std::move(v));
    return doc;
}

}  // namespace

TomlValue TomlValue::of(bool v) {
    return TomlValue(holding(v));
}

TomlValue TomlValue::of(std::int64_t v) {
    return TomlValue(holding(v));
}

TomlValue TomlValue::of(double v) {
    return TomlValue(holding(v));
}

TomlValue TomlValue::of(std::string_view v) {
    return TomlValue(holding(std::string(v)));
}

}  // namespace atonlab
