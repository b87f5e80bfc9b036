#pragma once
// Reads values out of JSON text (a calibration's fit_json, a check's
// results_json) with SQLite's own JSON functions: the parser whose
// json_valid() the schema's CHECKs already trust, so atonlab needs no second
// JSON library. Paths are SQLite JSON paths: "$.display.channels[1].gamma".
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace atonlab::store {

class JsonReader {
public:
    /// Throws StoreError (invalid_argument) when `text` is not valid JSON;
    /// `what` names the text in that message (e.g. "fit_json of calibration 3").
    explicit JsonReader(std::string text, std::string what = "the JSON text");
    JsonReader(JsonReader&&) noexcept;
    JsonReader& operator=(JsonReader&&) noexcept;
    ~JsonReader();

    /// The number at `path` (an integer or a real), or nullopt when the path is
    /// absent or holds something else.
    std::optional<double> number(std::string_view path) const;
    /// The string at `path`, or nullopt when absent or not a string.
    std::optional<std::string> string(std::string_view path) const;
    /// true / false at `path`, or nullopt when absent or not a boolean.
    std::optional<bool> boolean(std::string_view path) const;
    /// The number of elements of the array at `path`; 0 when absent or not an array.
    std::size_t array_length(std::string_view path) const;

    const std::string& text() const noexcept;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace atonlab::store
