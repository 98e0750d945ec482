#include "brute_broadphase.h"

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
  // Gather the present boxes contiguously, in id order.
  ids_.clear();
  packed_.clear();
  for (std::size_t id = 0; id < present_.size(); ++id) {
    if (present_[id] == 0) continue;
    ids_.push_back(static_cast<ProxyId>(id));
    packed_.push_back(boxes_[id]);
  }
  // Every pair i < j; id order makes the output sorted.
  const std::size_t n = ids_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Aabb& a = packed_[i];
    for (std::size_t j = i + 1; j < n; ++j) {
      if (a.overlaps(packed_[j])) out.push_back({ids_[i], ids_[j]});
    }
  }
  last_stats_ = {};
  last_stats_.box_tests = n < 2 ? 0 : std::uint64_t{n} * (n - 1) / 2;
}

}  // namespace dovetail::collision
