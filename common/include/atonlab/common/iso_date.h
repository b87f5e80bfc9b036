#pragma once
// The one reader of the dates atonlab stores (a calibration's measured_at, a
// check's checked_at) and compares (a calibration's age): ISO 8601, read from
// its leading YYYY-MM-DD; a time after it ("T10:00:00Z") is not read. With that
// prefix, text order is date order (the store's indexes rely on it).
#include <chrono>
#include <optional>
#include <string_view>

namespace atonlab {

/// The calendar day `iso` starts with (YYYY-MM-DD, a real date of the
/// proleptic Gregorian calendar), or nullopt when it does not start with one.
std::optional<std::chrono::sys_days> iso_date(std::string_view iso);

}  // namespace atonlab
