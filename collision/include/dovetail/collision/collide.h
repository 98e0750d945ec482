#pragma once
/// \file collide.h
/// Request and result of a collision query between two rigid meshes.

#include <cstdint>
#include <vector>

namespace dovetail::collision {

/// One intersecting pair: triangle `a` of mesh A and triangle `b` of mesh B,
/// indices into each Mesh::triangles.
struct TrianglePair {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  friend bool operator==(const TrianglePair&, const TrianglePair&) = default;
  friend auto operator<=>(const TrianglePair&, const TrianglePair&) = default;
};

/// What a query should find.
struct CollideRequest {
  /// false: stop at the first intersecting pair (yes/no); true: report every
  /// intersecting triangle pair, sorted by (a, b).
  bool all_pairs = false;
};

/// Work a query did; the cost model is volume_tests * C_bv + triangle_tests * C_p.
struct CollideStats {
  std::uint64_t volume_tests = 0;
  std::uint64_t triangle_tests = 0;
};

/// Outcome of a query. `pairs` holds the first pair found (first-hit query) or
/// all pairs sorted (all-pairs query); it is empty when not colliding.
struct CollideResult {
  bool colliding = false;
  std::vector<TrianglePair> pairs;
  CollideStats stats;
};

}  // namespace dovetail::collision
