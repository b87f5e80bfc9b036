#pragma once
// Helpers for Procedure::state(): exact text for doubles (hex floating point,
// so a round trip through the log loses nothing) and a 64-bit FNV-1a hash for
// tables too large to print with every trial.
#include <fmt/format.h>

#include <bit>
#include <cstdint>
#include <string>
#include <vector>

namespace atonlab::protocols::detail {

inline std::string hex(double x) {
    return fmt::format("{:a}", x);
}

inline std::uint64_t fnv1a(std::uint64_t h, std::uint64_t word) noexcept {
    for (int i = 0; i < 8; ++i) {
        h ^= (word >> (8 * i)) & 0xFFu;
        h *= 0x100000001B3ULL;
    }
    return h;
}

constexpr std::uint64_t kFnvOffset = 0xCBF29CE484222325ULL;

inline std::uint64_t hash_doubles(const std::vector<double>& v) noexcept {
    std::uint64_t h = kFnvOffset;
    for (double x : v) h = fnv1a(h, std::bit_cast<std::uint64_t>(x));
    return h;
}

template <class Int>
std::uint64_t hash_ints(const std::vector<Int>& v) noexcept {
    std::uint64_t h = kFnvOffset;
    for (Int x : v) h = fnv1a(h, static_cast<std::uint64_t>(x));
    return h;
}

}  // namespace atonlab::protocols::detail
