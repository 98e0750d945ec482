#pragma once
// Sorting a broad phase's output. A crowded scene reports tens of thousands
// of pairs a frame, and a comparison sort of them cost as much as finding
// them; pairs packed into integer keys of just the bits the ids need are
// sorted by a least-significant-digit radix sort instead, in as few passes
// of at most 14 bits as the keys allow (two for ids below 2^14, whose keys
// are 32-bit words).

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <utility>
#include <vector>

#include "dovetail/collision/broadphase.h"

namespace dovetail::collision::detail {

/// LSD radix sort of `n` keys of `bits` bits in `in`, using `out` as scratch
/// (both hold n keys) and `counts` for the digit counts; returns the one that
/// holds the sorted keys. As few passes as digits of at most 14 bits allow,
/// the digits as even as possible: each pass reads and scatters every key
/// once, so a pass saved is worth more than small count arrays (28-bit keys:
/// two passes of 14 bits took 0.19-0.25 ms for 40,000 keys on the project's
/// machine, three of 11 bits 0.40 ms). But a pass also clears and sums its
/// count array, so no digit has many more buckets than there are keys (a
/// few hundred pairs of 14-bit keys: two passes of 7 bits, not one of 14).
/// The counts of every digit come from one read of the keys.
template <typename Key>
Key* radix_sort(Key* in, Key* out, std::size_t n, int bits, std::vector<std::uint32_t>& counts) {
  const int max_digit_bits = std::clamp(static_cast<int>(std::bit_width(n)), 8, 14);
  const int passes = std::max(1, (bits + max_digit_bits - 1) / max_digit_bits);
  const int digit_bits = (bits + passes - 1) / passes;
  const std::size_t buckets = std::size_t{1} << digit_bits;
  const Key mask = static_cast<Key>(buckets - 1);
  counts.assign(buckets * static_cast<std::size_t>(passes), 0);
  for (std::size_t i = 0; i < n; ++i) {
    for (int p = 0; p < passes; ++p) ++counts[p * buckets + ((in[i] >> (p * digit_bits)) & mask)];
  }
  for (int p = 0; p < passes; ++p) {
    std::uint32_t* offset = counts.data() + p * buckets;
    std::uint32_t sum = 0;
    for (std::size_t d = 0; d < buckets; ++d) sum += std::exchange(offset[d], sum);
    const int shift = p * digit_bits;
    for (std::size_t i = 0; i < n; ++i) out[offset[(in[i] >> shift) & mask]++] = in[i];
    std::swap(in, out);
  }
  return in;
}

/// The sort key of the pair of ids x and y (in either order): (low << bits) | high.
template <typename Key>
Key pair_key(ProxyId x, ProxyId y, int bits) {
  const Key low = std::min(x, y), high = std::max(x, y);
  return static_cast<Key>((low << bits) | high);
}

/// The pairs of the first `n` keys (a << bits) | b of `keys` (which has room
/// for 2n), sorted by (a, b), into `pairs`.
template <typename Key>
void pairs_from_keys(std::vector<Key>& keys, std::size_t n, int bits,
                     std::vector<std::uint32_t>& counts, std::vector<ProxyPair>& pairs) {
  Key* in = keys.data();
  if (n < 512) {
    std::sort(in, in + n);
  } else {
    in = radix_sort(in, in + n, n, 2 * bits, counts);
  }
  const Key low_mask = static_cast<Key>((std::uint64_t{1} << bits) - 1);
  // Appended, not resized and overwritten: no pass to zero them first.
  pairs.clear();
  pairs.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    pairs.push_back({static_cast<ProxyId>(in[i] >> bits), static_cast<ProxyId>(in[i] & low_mask)});
  }
}

/// Sorts `pairs` by (a, b) as keys (a << bits) | b, where every id < 2^bits.
template <typename Key>
void sort_pair_keys(std::vector<ProxyPair>& pairs, std::vector<Key>& keys, int bits,
                    std::vector<std::uint32_t>& counts) {
  const std::size_t n = pairs.size();
  keys.resize(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    keys[i] = pair_key<Key>(pairs[i].a, pairs[i].b, bits);
  }
  pairs_from_keys(keys, n, bits, counts, pairs);
}

/// Scratch of sort_proxy_pairs, kept by its owner from frame to frame.
struct PairSortScratch {
  std::vector<std::uint32_t> narrow;
  std::vector<std::uint64_t> wide;
  std::vector<std::uint32_t> counts;
};

/// Sorts `pairs` by (a, b): 32-bit keys while both ids fit in 16 bits (half
/// the memory traffic of 64-bit keys), 64-bit keys beyond.
inline void sort_proxy_pairs(std::vector<ProxyPair>& pairs, PairSortScratch& scratch) {
  if (pairs.size() < 2) return;
  std::uint32_t largest = 0;
  for (const ProxyPair& p : pairs) largest = std::max({largest, p.a, p.b});
  const int bits = std::max(1, static_cast<int>(std::bit_width(largest)));  // every id < 2^bits
  if (bits <= 16) {
    sort_pair_keys(pairs, scratch.narrow, bits, scratch.counts);
  } else {
    sort_pair_keys(pairs, scratch.wide, bits, scratch.counts);
  }
}

}  // namespace dovetail::collision::detail
