#include "csv.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>

namespace atonlab::analysis::detail {

std::string number_text(double v) {
    // fmt's "{}" is the shortest text that round-trips (Ryu / Dragonbox).
    return std::isfinite(v) ? fmt::format("{}", v) : std::string();
}

double level_value(double v, bool log10_scale) {
    if (!std::isfinite(v)) return v;
    const double tolerance = log10_scale ? 1e-12 : 1e-12 * std::abs(v);
    if (std::abs(v) <= tolerance) return 0.0;  // 0.3 - 0.1 - 0.2 is -2.8e-17
    for (int digits = 1; digits < 17; ++digits) {
        const std::string decimal = fmt::format("{:.{}g}", v, digits);
        double d = 0.0;
        const auto [ptr, ec] = std::from_chars(decimal.data(), decimal.data() + decimal.size(), d);
        if (ec == std::errc() && ptr == decimal.data() + decimal.size() && std::abs(d - v) <= tolerance) return d;
    }
    return v;  // 17 significant digits: the level itself
}

}  // namespace atonlab::analysis::detail
