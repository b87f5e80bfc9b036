#pragma once
// The procedures' own random numbers: xoshiro256** (Blackman & Vigna 2018),
// seeded through splitmix64, with our own integer-to-double and bounded-integer
// conversions. std::uniform_*_distribution is implementation-defined, so a log
// written by one build would replay differently under another; this generator
// gives the same sequence on every compiler and platform.
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace atonlab::protocols {

/// splitmix64 (Steele, Lea & Flood 2014): one step of the mixer, used to expand
/// a seed and to derive independent child seeds.
constexpr std::uint64_t splitmix64(std::uint64_t& state) noexcept {
    state += 0x9E3779B97F4A7C15ULL;
    std::uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/// A seed for child `index` of a procedure seeded with `seed` (e.g. the
/// staircases of an interleaved block): distinct children get unrelated streams.
constexpr std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t index) noexcept {
    std::uint64_t s = seed ^ (0xD1B54A32D192ED03ULL * (index + 1));
    splitmix64(s);
    return splitmix64(s);
}

/// xoshiro256** 1.0. Value type: copying it copies the stream position.
class Rng {
public:
    explicit Rng(std::uint64_t seed = 0) noexcept {
        std::uint64_t sm = seed;
        for (std::uint64_t& w : s_) w = splitmix64(sm);
    }

    /// A generator in a given raw state (tests against published vectors).
    static Rng from_state(std::uint64_t s0, std::uint64_t s1, std::uint64_t s2, std::uint64_t s3) noexcept {
        Rng r;
        r.s_[0] = s0;
        r.s_[1] = s1;
        r.s_[2] = s2;
        r.s_[3] = s3;
        return r;
    }

    /// The next 64 random bits.
    std::uint64_t next_u64() noexcept {
        const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
        const std::uint64_t t = s_[1] << 17;
        s_[2] ^= s_[0];
        s_[3] ^= s_[1];
        s_[1] ^= s_[2];
        s_[0] ^= s_[3];
        s_[2] ^= t;
        s_[3] = rotl(s_[3], 45);
        return result;
    }

    /// Uniform in [0, 1): the top 53 bits scaled by 2^-53 (exact, no rounding).
    double uniform() noexcept { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

    /// Uniform in [lo, hi).
    double uniform(double lo, double hi) noexcept { return lo + (hi - lo) * uniform(); }

    /// Uniform integer in [0, n), n > 0, without modulo bias (rejection on the
    /// top of the 64-bit range). Returns 0 for n == 0.
    std::uint64_t below(std::uint64_t n) noexcept {
        if (n == 0) return 0;
        const std::uint64_t limit = UINT64_MAX - UINT64_MAX % n;  // largest multiple of n, exclusive
        std::uint64_t x = next_u64();
        while (x >= limit) x = next_u64();
        return x % n;
    }

    /// A fair coin.
    bool coin() noexcept { return (next_u64() >> 63) != 0; }

    /// Fisher-Yates shuffle (Knuth's Algorithm P, from the back), using below().
    template <class T>
    void shuffle(std::vector<T>& v) noexcept {
        for (std::size_t i = v.size(); i > 1; --i) {
            const auto j = static_cast<std::size_t>(below(i));
            std::swap(v[i - 1], v[j]);
        }
    }

    /// The raw state words (for Procedure::state()).
    std::array<std::uint64_t, 4> raw() const noexcept { return {s_[0], s_[1], s_[2], s_[3]}; }

    bool operator==(const Rng&) const = default;

private:
    static constexpr std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
    std::uint64_t s_[4]{};
};

}  // namespace atonlab::protocols
