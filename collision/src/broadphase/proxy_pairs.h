#pragma once
// Sorting a broad phase's output. A crowded scene reports tens of thousands
// of pairs a frame, and a comparison sort of them cost as much as finding
// them; pairs packed into integer keys of just the bits the ids need are
// sorted by a least-significant-digit radix sort instead, in as many passes
// of 11 bits as the keys have (three for ids below 2^16).

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <utility>
#include <vector>

#include "dovetail/collision/broadphase.h"

namespace dovetail::collision::detail {

/// Sorts `pairs` by (a, b), using `keys` as scratch.
inline void sort_proxy_pairs(std::vector<ProxyPair>& pairs, std::vector<std::uint64_t>& keys) {
  const std::size_t n = pairs.size();
  if (n < 2) return;
  std::uint32_t largest = 0;
  for (const ProxyPair& p : pairs) largest = std::max({largest, p.a, p.b});
  const int bits = std::bit_width(largest);  // every id < 2^bits
  const std::uint64_t low_mask = (std::uint64_t{1} << bits) - 1;
  keys.resize(2 * n);
  std::uint64_t* in = keys.data();
  std::uint64_t* out = keys.data() + n;
  for (std::size_t i = 0; i < n; ++i) {
    in[i] = (static_cast<std::uint64_t>(pairs[i].a) << bits) | pairs[i].b;
  }
  if (n < 512) {
    std::sort(in, in + n);
  } else {
    constexpr int kDigitBits = 11;
    constexpr std::uint64_t kDigitMask = (1u << kDigitBits) - 1;
    std::array<std::uint32_t, std::size_t{1} << kDigitBits> offset;
    for (int shift = 0; shift < 2 * bits; shift += kDigitBits) {
      offset.fill(0);
      for (std::size_t i = 0; i < n; ++i) ++offset[(in[i] >> shift) & kDigitMask];
      std::uint32_t sum = 0;
      for (std::uint32_t& o : offset) sum += std::exchange(o, sum);
      for (std::size_t i = 0; i < n; ++i) out[offset[(in[i] >> shift) & kDigitMask]++] = in[i];
      std::swap(in, out);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    pairs[i] = {static_cast<ProxyId>(in[i] >> bits), static_cast<ProxyId>(in[i] & low_mask)};
  }
}

}  // namespace dovetail::collision::detail
