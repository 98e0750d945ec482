#include "broadphase/brute_broadphase.h"

#include <algorithm>
#include <bit>
#include <cassert>

namespace dovetail::collision {

void BruteBroadphase::add(ProxyId id, const Aabb& box) {
  if (id >= boxes_.size()) {
    boxes_.resize(std::size_t{id} + 1);
    present_.resize(std::size_t{id} + 1, 0);
  }
  assert(present_[id] == 0);
  boxes_[id] = box;
  present_[id] = 1;
  ++count_;
}

void BruteBroadphase::remove(ProxyId id) {
  assert(id < present_.size() && present_[id] != 0);
  present_[id] = 0;
  --count_;
}

void BruteBroadphase::move(ProxyId id, const Aabb& box) {
  assert(id < present_.size() && present_[id] != 0);
  boxes_[id] = box;
}

void BruteBroadphase::pairs(std::vector<ProxyPair>& out) {
  out.clear();
  // Gather the present boxes contiguously, in id order, one array per bound.
  ids_.clear();
  for (auto& bound : packed_) bound.clear();
  for (std::size_t id = 0; id < present_.size(); ++id) {
    if (present_[id] == 0) continue;
    ids_.push_back(static_cast<ProxyId>(id));
    for (int k = 0; k < 3; ++k) {
      packed_[k].push_back(boxes_[id].min[k]);
      packed_[3 + k].push_back(boxes_[id].max[k]);
    }
  }
  // Every pair i < j; id order makes the output sorted. The x test runs over
  // blocks of 64 boxes into a bit mask (it rejects almost all), then y and z.
  const std::size_t n = ids_.size();
  const Real* lo_x = packed_[0].data();
  const Real* hi_x = packed_[3].data();
  for (std::size_t i = 0; i < n; ++i) {
    const Real a_lo = lo_x[i], a_hi = hi_x[i];
    for (std::size_t block = i + 1; block < n; block += 64) {
      const std::size_t count = std::min<std::size_t>(64, n - block);
      std::uint64_t mask = 0;
      for (std::size_t t = 0; t < count; ++t) {
        const std::size_t j = block + t;
        mask |= static_cast<std::uint64_t>((lo_x[j] <= a_hi) & (a_lo <= hi_x[j])) << t;
      }
      for (; mask != 0; mask &= mask - 1) {
        const std::size_t j = block + static_cast<std::size_t>(std::countr_zero(mask));
        if (packed_[1][i] <= packed_[4][j] && packed_[1][j] <= packed_[4][i] &&
            packed_[2][i] <= packed_[5][j] && packed_[2][j] <= packed_[5][i]) {
          out.push_back({ids_[i], ids_[j]});
        }
      }
    }
  }
  drop_fixed_pairs(out);
  last_stats_ = {};
  last_stats_.box_tests = n < 2 ? 0 : std::uint64_t{n} * (n - 1) / 2;
}

}  // namespace dovetail::collision
