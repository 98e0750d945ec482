#pragma once
/// \file convex_internal.h
/// Private parts of the convex level: the hill-climbing support query of
/// ConvexHull, inline so that the separating-plane test and GJK call it
/// without a function call per query, and the hull build with statistics.
///
/// Exactness. With u = 2^-53, fl(d . x) = fl(fl(fl(d0 x0) + fl(d1 x1)) +
/// fl(d2 x2)) carries at most three roundings per term, so
///   |fl(d . x) - d . x| <= g3 sum |d_i x_i| <= g3 |d|_1 extent =: E
/// for every vertex x (|x_i| <= extent), g3 = 3u / (1 - 3u). The query uses
/// kSupportBound = 4u >= g3 (1 + u)^2 for E (two more roundings form E) and
/// adds 8 * 2^-1074 for products that underflow. A computed difference of
/// more than 2E therefore has the sign of the exact one; any closer
/// comparison is redone exactly (dot_difference_sign). The climb moves only
/// to a neighbour that is exactly better, so it stops at a vertex no
/// neighbour beats exactly: on an exactly convex hull, the global maximum.

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "dovetail/collision/convex.h"

namespace dovetail::collision::detail {

/// What compute_convex_hull did, for tests.
struct HullBuildStats {
  std::size_t qhull_vertices = 0;  ///< vertices of qhull's hull
  bool rebuilt_exactly = false;    ///< qhull's hull failed the exact check
  bool direct = false;             ///< built without qhull (HullPath::kDirect)
};

/// How a hull is built.
enum class HullPath {
  kAuto,     ///< kDirect up to kDirectHullPoints points, else kQhull
  kQhull,    ///< qhull's hull when proven exact, else kRebuild from its vertices
  kRebuild,  ///< qhull, then always the exact incremental hull from its vertices
  kDirect,   ///< the exact incremental hull of every point, without qhull
};

/// Up to this many points a hull is built without qhull: starting qhull costs
/// more than the exact incremental hull of a few dozen points (a 34-point
/// capsule of the hand: 4.8 times as fast, `convex_bench --hull-build`); for
/// hundreds of points on the flat facets of CAD parts, where most points are
/// coplanar and each exact decision on them is slow, qhull wins.
inline constexpr std::size_t kDirectHullPoints = 64;

/// compute_convex_hull with statistics and a choice of path (tests use it to
/// exercise every path on any input).
ConvexHull build_convex_hull(std::span<const Vec3> points, const std::string& source,
                             HullBuildStats* stats, HullPath path);

/// True when `triangles` (indices into `points`) are proven, exactly, to bound
/// a convex polytope holding every point: the acceptance test of qhull's hull.
bool is_exact_hull(std::span<const Vec3> points, const std::vector<TriangleIndices>& triangles);

inline constexpr Real kSupportBound = 4.0 * 0x1p-53;

/// Sign (+1, 0, -1) of the exact value of d . u - d . v, from the exact
/// products (two-product by fused multiply-add) summed as a floating-point
/// expansion. Exact unless a product underflows below 2^-1022 * 2^53.
int dot_difference_sign(const Vec3& d, const Vec3& u, const Vec3& v);

/// Bound E on |fl(d . x) - d . x| for every x with |x_i| <= extent.
inline Real dot_error_bound(const Vec3& d, Real extent) {
  const Real norm1 = std::abs(d.x()) + std::abs(d.y()) + std::abs(d.z());
  return kSupportBound * norm1 * extent + 8 * std::numeric_limits<Real>::denorm_min();
}

/// fl(d . x) evaluated in the order the error bound assumes.
inline Real dot(const Vec3& d, const Vec3& x) {
  return (d.x() * x.x() + d.y() * x.y()) + d.z() * x.z();
}

/// Hill climbing along hull edges to the exact maximiser of d . v.
inline std::uint32_t hull_support(const ConvexHull& hull, const Vec3& d, std::uint32_t start) {
  const std::uint32_t* offsets = hull.neighbor_offsets.data();
  const std::uint32_t* neighbors = hull.neighbors.data();
  const Vec3* vertices = hull.vertices.data();
  std::uint32_t current = start < hull.vertices.size() ? start : 0;
  Real value = dot(d, vertices[current]);
  const Real slack = 2 * dot_error_bound(d, hull.extent);
  for (;;) {
    // Highest neighbour by computed value (the first one on ties).
    std::uint32_t best = current;
    Real best_value = -std::numeric_limits<Real>::infinity();
    const std::uint32_t end = offsets[current + 1];
    for (std::uint32_t k = offsets[current]; k < end; ++k) {
      const Real f = dot(d, vertices[neighbors[k]]);
      if (f > best_value) {
        best_value = f;
        best = neighbors[k];
      }
    }
    // Certainly better: move.
    if (best_value > value + slack) {
      current = best;
      value = best_value;
      continue;
    }
    // Every neighbour certainly not better: a maximum.
    if (best_value < value - slack) return current;
    // Close calls: the first neighbour that is exactly better, if any.
    bool moved = false;
    for (std::uint32_t k = offsets[current]; k < end; ++k) {
      const Vec3& x = vertices[neighbors[k]];
      const Real f = dot(d, x);
      if (f >= value - slack && dot_difference_sign(d, x, vertices[current]) > 0) {
        current = neighbors[k];
        value = f;
        moved = true;
        break;
      }
    }
    if (!moved) return current;
  }
}

}  // namespace dovetail::collision::detail
