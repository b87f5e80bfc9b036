#include "atonlab/common/iso_date.h"

#include <cstddef>

namespace atonlab {

std::optional<std::chrono::sys_days> iso_date(std::string_view iso) {
    if (iso.size() < 10) return std::nullopt;
    int digits[10] = {};
    for (std::size_t i = 0; i < 10; ++i) {
        const bool dash = i == 4 || i == 7;
        if (dash ? iso[i] != '-' : (iso[i] < '0' || iso[i] > '9')) return std::nullopt;
        digits[i] = iso[i] - '0';
    }
    const int y = digits[0] * 1000 + digits[1] * 100 + digits[2] * 10 + digits[3];
    const auto m = static_cast<unsigned>(digits[5] * 10 + digits[6]);
    const auto d = static_cast<unsigned>(digits[8] * 10 + digits[9]);
    const std::chrono::year_month_day ymd{std::chrono::year{y}, std::chrono::month{m}, std::chrono::day{d}};
    if (!ymd.ok()) return std::nullopt;
    return std::chrono::sys_days(ymd);
}

}  // namespace atonlab
