#pragma once
/// \file xoshiro256.h
/// xoshiro256** (Blackman and Vigna, 2018), seeded through splitmix64.
///
/// Why: scripts' math.random must give the same sequence for the same seed on
/// every platform and Lua build, so the generator is ours, not the library's.

#include <array>
#include <cstdint>

namespace dovetail::scripting {

/// A 64-bit generator with 256 bits of state.
class Xoshiro256 {
 public:
  explicit Xoshiro256(std::uint64_t seed = 0) { reseed(seed); }

  /// The state for (seed, stream), expanded by splitmix64 (never all zero).
  void reseed(std::uint64_t seed, std::uint64_t stream = 0) {
    std::uint64_t x = seed;
    state_[0] = splitmix64(x);
    state_[1] = splitmix64(x);
    x ^= stream * 0xD1B54A32D192ED03u;
    state_[2] = splitmix64(x);
    state_[3] = splitmix64(x);
  }

  std::uint64_t next() {
    const std::uint64_t result = rotl(state_[1] * 5, 7) * 9;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15u);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
    return z ^ (z >> 31);
  }

  std::array<std::uint64_t, 4> state_{};
};

}  // namespace dovetail::scripting
