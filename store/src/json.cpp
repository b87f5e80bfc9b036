// Parsing, writing and reading JSON with nlohmann::json (json.h).
#include "atonlab/store/json.h"

#include <fmt/format.h>

#include "atonlab/common/input_text.h"
#include "atonlab/store/error.h"

namespace atonlab::store {

nlohmann::json parse_json(std::string_view text, std::string_view what) {
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
        // e.what() is "[json.exception.parse_error.101] parse error at line 1, column 6: syntax error ..."
        // -- a sentence for a programmer; the byte and the reason after the last ": " say where.
        // The reason quotes the bytes last read, which need not be UTF-8: echoed escaped.
        const std::string why = e.what();
        const std::size_t colon = why.rfind(": ");
        throw StoreError(StoreErrc::invalid_argument, {},
                         fmt::format("{} is not valid JSON (at byte {}: {})", what, e.byte,
                                     text::echo(colon == std::string::npos ? why : why.substr(colon + 2), 200)));
    }
}

std::string dump_json(const nlohmann::ordered_json& j, int indent) {
    return j.dump(indent, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

const nlohmann::json* json_at(const nlohmann::json& j, std::string_view at) {
    const nlohmann::json::json_pointer pointer{std::string(at)};
    return j.contains(pointer) ? &j.at(pointer) : nullptr;
}

std::optional<double> number_at(const nlohmann::json& j, std::string_view at) {
    const nlohmann::json* v = json_at(j, at);
    if (!v || !v->is_number()) return std::nullopt;
    return v->get<double>();
}

std::optional<std::string> string_at(const nlohmann::json& j, std::string_view at) {
    const nlohmann::json* v = json_at(j, at);
    if (!v || !v->is_string()) return std::nullopt;
    return v->get<std::string>();
}

std::optional<bool> boolean_at(const nlohmann::json& j, std::string_view at) {
    const nlohmann::json* v = json_at(j, at);
    if (!v || !v->is_boolean()) return std::nullopt;
    return v->get<bool>();
}

const nlohmann::json& array_at(const nlohmann::json& j, std::string_view at) {
    static const nlohmann::json empty = nlohmann::json::array();
    const nlohmann::json* v = json_at(j, at);
    return v && v->is_array() ? *v : empty;
}

}  // namespace atonlab::store
