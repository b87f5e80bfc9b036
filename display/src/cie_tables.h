#pragma once
// Internal: the raw CIE tables behind cie1931_cmf(), cie_d65() and cie1951_scotopic_efficiency()
// (sources cited in cie_tables.cpp).
#include <cstddef>
#include <span>

namespace atonlab::display::cie {

inline constexpr double kCmfFirstNm = 360.0;  ///< CIE 1931 2° CMFs: 360..830 nm, 1 nm
inline constexpr std::size_t kCmfCount = 471;
inline constexpr double kD65FirstNm = 300.0;  ///< D65 relative SPD: 300..830 nm, 1 nm
inline constexpr std::size_t kD65Count = 531;
inline constexpr double kScotopicFirstNm = 380.0;  ///< CIE 1951 scotopic V'(lambda): 380..780 nm, 1 nm
inline constexpr std::size_t kScotopicCount = 401;

/// D65 relative SPD (100 at 560 nm), kD65Count samples 1 nm apart from kD65FirstNm.
std::span<const double> d65_table();

}  // namespace atonlab::display::cie
