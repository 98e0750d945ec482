#pragma once
/// \file collide.h
/// Request and result of a collision query between two rigid meshes.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "dovetail/collision/types.h"

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

/// Where the last complete query of the same two OBB trees stopped: the cut
/// through the pairs of their nodes that it visited. Every pair of triangles
/// lies under exactly one entry, either a node pair whose boxes it found
/// apart, with the gap between them, or a leaf pair whose triangles it tested.
///
/// Why: a part sliding in a hole is queried many times a frame at poses a few
/// micrometres apart, and each query that finds it free descends to the same
/// few thousand box pairs along the walls. Boxes that were apart by a gap g
/// are still apart after B moves by less than g (any point of B, in A's
/// frame), so the next query starts from the front, skips those entries
/// without a test, and tests and descends only the rest. The entries are kept
/// in depth-first order and a skipped entry holds no intersecting triangles,
/// so the query finds the very pairs, and the very first hit, of a traversal
/// from the roots in the fixed order (CollideRequest::nearer_first = false);
/// only the work differs. (With a TraversalHint as well, the
/// hint is read and rewritten as usual, but a hit found below a front entry
/// sets it no higher than that entry; the next first hit may then be another
/// intersecting pair than with the hint alone.)
///
/// A query given a front reads it when it belongs to the same two trees and
/// rewrites it when it visits the whole cut: a query that finds no hit, and
/// every all-pairs query. A first-hit query that stops at a hit leaves it as
/// it was. The trees must outlive the front (it is checked against them by
/// address and node counts). Only the OBB tree (Method::kObb) uses fronts;
/// other methods, split (parallel) and time-critical queries ignore them.
struct SeparationFront {
  /// A node pair found apart (gap > 0: no point of B's box within that
  /// distance of A's box along the separating axis found), or a leaf pair
  /// whose triangles were tested (gap < 0).
  struct Entry {
    std::uint32_t node_a = 0;
    std::uint32_t node_b = 0;
    Real gap = 0;
  };
  std::vector<Entry> entries;  ///< depth-first order
  Transform X_AB{};            ///< the pose at which the gaps hold
  const void* tree_a = nullptr;
  const void* tree_b = nullptr;
  std::size_t nodes_a = 0, nodes_b = 0;
  /// Entries of the last front built from the roots. A front only deepens
  /// (a pair found apart is never merged back into its parent), so once it
  /// holds twice as many the next query starts from the roots again.
  std::size_t root_entries = 0;
  bool valid = false;
  std::vector<Entry> scratch;  ///< the next front while a query builds it
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
  /// Detection within a tolerance: a first-hit query on the AABB and OBB
  /// trees that meets two overlapping volumes whose diameters sum to at most
  /// this stops there and reports colliding, with no triangle pair. A point lies in both
  /// volumes, and every triangle under each is within that volume's diameter
  /// of it, so the parts are then at most `max_size` apart. Hint and front
  /// work as in an exact query.
  /// Conservative: never misses a collision. 0 (the default): exact. Ignored
  /// by all-pairs queries and by the other methods.
  Real max_size = 0;
  /// Coherence across queries of the same two models (see SeparationFront):
  /// read where valid, rewritten by a query that visits all of it.
  SeparationFront* front = nullptr;
  /// First-hit queries on the AABB, OBB and DOP trees that use no `front`:
  /// where both child pairs of a node pair overlap, enter first the one
  /// whose volumes' centres are nearer (fewer volume tests near contact).
  /// The pair reported then depends on the pose. false, or a front the
  /// query uses (an exact query on the OBB tree), keeps the fixed
  /// depth-first order, whose first hit (without a hint) is the same with a
  /// front and without; sliding relies on it. The verdict is the same
  /// either way.
  bool nearer_first = true;
};

/// Work a query did; the cost model is volume_tests * C_bv + triangle_tests * C_p.
struct CollideStats {
  std::uint64_t volume_tests = 0;
  std::uint64_t triangle_tests = 0;
  /// A triangle against one bounding volume (CollisionModel::search_triangle).
  std::uint64_t triangle_volume_tests = 0;
};

/// Outcome of a query. `pairs` holds the first pair found (first-hit query) or
/// all pairs sorted (all-pairs query); it is empty when not colliding.
struct CollideResult {
  bool colliding = false;
  std::vector<TrianglePair> pairs;
  CollideStats stats;
};

}  // namespace dovetail::collision
