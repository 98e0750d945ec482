#pragma once
// Union-find over indices 0..n-1, for grouping: triangles into shells,
// pieces of intersection into contact patches.

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace dovetail::collision::detail {

/// Disjoint sets with path halving; a join keeps the smaller root, so the
/// root of a set is its smallest member whatever the order of the joins.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }

  std::size_t find(std::size_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }

  void join(std::size_t i, std::size_t j) {
    i = find(i);
    j = find(j);
    if (i != j) parent_[std::max(i, j)] = std::min(i, j);
  }

 private:
  std::vector<std::size_t> parent_;
};

}  // namespace dovetail::collision::detail
