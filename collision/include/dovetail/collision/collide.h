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

/// Where a first-hit query of the same two models found its hit last time:
/// a pair of hierarchy nodes a few levels above the intersecting leaves.
///
/// Why: under coherent motion a contact moves a few triangles per frame. The
/// next query searches the remembered subtree pair first, which takes a
/// handful of volume tests, and traverses from the roots only when the
/// subtree pair holds no intersection any more. A hit is a proof either way,
/// so the verdict never depends on the hint; only the work does.
struct TraversalHint {
  std::uint32_t node_a = 0;  ///< node of A's hierarchy (its own numbering)
  std::uint32_t node_b = 0;  ///< node of B's hierarchy
  bool valid = false;        ///< false until a first-hit query has found a hit
};

/// What a query should find.
struct CollideRequest {
  /// false: stop at the first intersecting pair (yes/no); true: report every
  /// intersecting triangle pair, sorted by (a, b).
  bool all_pairs = false;
  /// First-hit queries on the AABB, OBB and DOP trees: read, when valid, and
  /// rewritten with the subtree pair of this query's hit (left unchanged when
  /// there is none). Must come from queries of the same two models. Ignored
  /// by all-pairs queries and by the other methods.
  TraversalHint* hint = nullptr;
  /// Time-critical detection: a first-hit query on the AABB, OBB and DOP
  /// trees that reaches this many levels below the root pair (one level: one
  /// tree descends once) with the volumes still overlapping stops there and
  /// reports colliding, with no triangle pair. Conservative: never misses a
  /// collision, may report one that is not. Negative (the default): exact.
  /// Ignored by all-pairs queries and by the other methods.
  int max_depth = -1;
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
