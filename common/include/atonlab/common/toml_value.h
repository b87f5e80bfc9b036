#pragma once
// One TOML value, parsed from the text a person wrote for it: a `--set` value,
// a protocol's `set` line, a conditions file's cell, a setting's stored text.
// This is the one place that text becomes a value (docs/architecture.md,
// "Overrides"); past it, values travel typed.
//
// A TomlValue owns its node (a toml++ tree of one key, shared and immutable,
// so copies are cheap and the node outlives the text). Its nodes carry the
// source path they were parsed with, so a reader can say where they came from.
#include <toml++/toml.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace atonlab {

class TomlValue {
public:
    /// The TOML text of exactly one value: "120", "-0.5", "true", "\"none\"",
    /// "'raw'", "[0.0, 3.0, -500.0]", "[[1, 2], [3]]", "{ from_deg = 0 }";
    /// blanks and a comment may follow it, nothing else. nullopt when the
    /// text is empty, is not TOML, or holds more than one value ("1 2",
    /// "1\nw = 2"); `error` (when given) then gets toml++'s description.
    /// `source` becomes the source path of every node parsed.
    static std::optional<TomlValue> parse(std::string_view text, std::string* error = nullptr,
                                          std::string_view source = {});
    /// `text` as a TOML string (a value that was not TOML, taken as written).
    /// nullopt when it cannot be one (it is not UTF-8); `error` then says why.
    static std::optional<TomlValue> string(std::string_view text, std::string* error = nullptr,
                                           std::string_view source = {});

    /// `text` as the TOML text of a basic string: quoted, quotes and
    /// backslashes escaped, control characters written \uXXXX. What string()
    /// parses; also the value text of an override's stored form ("key=\"red\"").
    static std::string quoted(std::string_view text);

    /// A value made in code, not read from text (a Python keyword's value):
    /// its nodes have no source.
    static TomlValue of(bool v);
    static TomlValue of(std::int64_t v);
    static TomlValue of(double v);
    static TomlValue of(std::string_view v);

    /// The value (never a table of the document itself: an inline table is one).
    const toml::node& node() const noexcept { return *doc_->get(kKey); }
    toml::node_type type() const noexcept { return node().type(); }

private:
    static constexpr std::string_view kKey = "v";
    explicit TomlValue(std::shared_ptr<const toml::table> doc) : doc_(std::move(doc)) {}
    std::shared_ptr<const toml::table> doc_;  ///< { v = VALUE }: never null
};

}  // namespace atonlab
