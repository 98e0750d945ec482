#pragma once
// Sorting a broad phase's output: pairs packed into 64-bit keys sort about
// twice as fast as the pair structs compared member by member.

#include <algorithm>
#include <cstdint>
#include <vector>

#include "dovetail/collision/broadphase.h"

namespace dovetail::collision::detail {

/// Sorts `pairs` by (a, b), using `keys` as scratch.
inline void sort_proxy_pairs(std::vector<ProxyPair>& pairs, std::vector<std::uint64_t>& keys) {
  keys.resize(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    keys[i] = (static_cast<std::uint64_t>(pairs[i].a) << 32) | pairs[i].b;
  }
  std::sort(keys.begin(), keys.end());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    pairs[i] = {static_cast<ProxyId>(keys[i] >> 32), static_cast<ProxyId>(keys[i])};
  }
}

}  // namespace dovetail::collision::detail
