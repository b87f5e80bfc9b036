#pragma once
// SHA-256 (FIPS 180-4), for the protocol text's hash and snapshot checksums.
// A small self-contained implementation: the store needs no crypto library, and
// the test checks it against the FIPS 180-2 example vectors.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace atonlab::store {

std::array<std::uint8_t, 32> sha256(std::span<const std::byte> data) noexcept;

/// Lowercase hex digest of `data`'s bytes (64 characters).
std::string sha256_hex(std::span<const std::byte> data);
std::string sha256_hex(std::string_view text);

}  // namespace atonlab::store
