#include "json_text.h"

#include <fmt/format.h>

#include <cmath>

namespace atonlab::runner {

std::string json_number(double v) {
    return std::isfinite(v) ? fmt::format("{}", v) : std::string("null");
}

std::string json_string(std::string_view text) {
    std::string out = "\"";
    for (const char ch : text) {
        switch (ch) {
            case '"':
                out += "\\\"";
                break;
            case '\\':
                out += "\\\\";
                break;
            case '\n':
                out += "\\n";
                break;
            case '\r':
                out += "\\r";
                break;
            case '\t':
                out += "\\t";
                break;
            default:
                if (static_cast<unsigned char>(ch) < 0x20)
                    out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(ch)));
                else
                    out += ch;
        }
    }
    return out + "\"";
}

}  // namespace atonlab::runner
