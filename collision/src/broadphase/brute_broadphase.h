#pragma once
// The reference broad phase: every pair of present boxes, n^2/2 box tests.

#include <array>
#include <vector>

#include "dovetail/collision/broadphase.h"

namespace dovetail::collision {

/// Exhaustive reference. Keeps the boxes by id and, on `pairs()`, runs the
/// closed-box test (the comparisons of `Aabb::overlaps`, x first) on every pair
/// of present boxes in id order, so its output is sorted without a sort and
/// depends on nothing but the boxes.
class BruteBroadphase final : public Broadphase {
 public:
  void add(ProxyId id, const Aabb& box) override;
  void remove(ProxyId id) override;
  void move(ProxyId id, const Aabb& box) override;
  void pairs(std::vector<ProxyPair>& out) override;

  std::size_t size() const override { return count_; }
  BroadphaseStats stats() const override { return last_stats_; }

 private:
  std::vector<Aabb> boxes_;    ///< by id
  std::vector<char> present_;  ///< by id
  std::size_t count_ = 0;
  std::vector<ProxyId> ids_;                 ///< scratch: present ids in order
  std::array<std::vector<Real>, 6> packed_;  ///< scratch: min x, y, z, max x, y, z
  BroadphaseStats last_stats_;
};

}  // namespace dovetail::collision
