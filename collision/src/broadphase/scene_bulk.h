#pragma once
// Where the bulk of a scene's boxes are, ignoring a few far outliers.

#include <algorithm>
#include <cstddef>
#include <vector>

#include "dovetail/collision/broadphase.h"

namespace dovetail::collision::detail {

/// The 2nd to 98th percentile of the centres of boxes[id], id in `ids`
/// (not empty), along axis k.
struct Bulk {
  Real low = 0;
  Real spread = 0;  ///< high - low
};

inline Bulk bulk_of_centres(const std::vector<Aabb>& boxes, const std::vector<ProxyId>& ids, int k,
                            std::vector<Real>& scratch) {
  const std::size_t n = ids.size();
  scratch.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    scratch[i] = (boxes[ids[i]].min[k] + boxes[ids[i]].max[k]) / 2;
  const auto lo = static_cast<std::ptrdiff_t>(n / 50);
  const auto hi = static_cast<std::ptrdiff_t>(n - 1 - n / 50);
  std::nth_element(scratch.begin(), scratch.begin() + lo, scratch.end());
  const Real low = scratch[static_cast<std::size_t>(lo)];
  std::nth_element(scratch.begin(), scratch.begin() + hi, scratch.end());
  return {low, scratch[static_cast<std::size_t>(hi)] - low};
}

}  // namespace dovetail::collision::detail
