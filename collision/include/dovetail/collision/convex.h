#pragma once
/// \file convex.h
/// Convex level: convex hulls of parts, the separating-plane test with a
/// plane cached per pair, and GJK with warm start.
///
/// Why: between the object level and the polygon level, a convex test rejects
/// most pairs whose boxes overlap at a cost independent of the triangle count;
/// with coherent motion the plane that separated a pair last frame usually
/// still does, so most frames re-check one plane.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// Convex hull of a point set, in the part's own frame. Immutable after
/// construction; shared by every instance of a part.
struct ConvexHull {
  std::vector<Vec3> vertices;            ///< hull vertices only
  std::vector<TriangleIndices> faces;    ///< outward, counter-clockwise
  /// Vertex adjacency along hull edges, compressed: the neighbours of vertex
  /// i are neighbors[neighbor_offsets[i] .. neighbor_offsets[i + 1]).
  std::vector<std::uint32_t> neighbor_offsets;
  std::vector<std::uint32_t> neighbors;

  /// Index of a vertex maximising d . v, by hill climbing along edges from
  /// `start` (exact maximum: the hull is convex).
  std::uint32_t support(const Vec3& d, std::uint32_t start = 0) const;
};

/// Hull of `points` through reentrant qhull. Throws std::invalid_argument
/// naming `source` when fewer than 4 affinely independent points exist (a
/// flat or degenerate part); see docs for how the pipeline treats such parts.
ConvexHull compute_convex_hull(std::span<const Vec3> points, const std::string& source);

/// Per-pair state of the separating-plane test, kept by the caller across frames.
struct SeparatingPlaneCache {
  Vec3 normal = Vec3::UnitX();  ///< plane normal in A's frame, pointing from A to B
  Real offset = 0;              ///< plane: normal . x = offset
  bool valid = false;           ///< false until a plane has been found once
};

/// Settings of the separating-plane search.
struct SeparatingPlaneSettings {
  int max_iterations = 64;  ///< then give up and report "maybe colliding"
};

/// Outcome of one separating-plane test.
struct SeparatingPlaneResult {
  bool separated = false;   ///< true: a plane strictly separates the hulls (proof)
  bool cache_hit = false;   ///< the cached plane still separated them
  int iterations = 0;
};

/// Searches for a plane separating hull A from hull B (B at pose X_AB in A's
/// frame), starting from `cache` and leaving the found plane in it. Biased
/// towards "collision": when the search gives up it reports not separated.
SeparatingPlaneResult separating_plane_test(const ConvexHull& a, const ConvexHull& b,
                                            const Transform& X_AB, SeparatingPlaneCache& cache,
                                            const SeparatingPlaneSettings& settings = {});

/// Per-pair warm-start state of GJK, kept by the caller across frames.
struct GjkCache {
  std::uint32_t support_a = 0;  ///< last support vertex of A
  std::uint32_t support_b = 0;  ///< last support vertex of B
  Vec3 direction = Vec3::UnitX();  ///< last search direction, in A's frame
  bool valid = false;
};

/// Outcome of GJK on two hulls.
struct GjkResult {
  bool intersecting = false;
  Real distance = 0;         ///< 0 when intersecting
  Vec3 closest_a = Vec3::Zero();  ///< on A, in A's frame
  Vec3 closest_b = Vec3::Zero();  ///< on B, in A's frame
  int iterations = 0;
  bool hit_iteration_cap = false;
};

/// GJK distance/intersection of hull A and hull B (B at X_AB in A's frame),
/// warm-started from `cache` when given (and updated).
GjkResult gjk(const ConvexHull& a, const ConvexHull& b, const Transform& X_AB,
              GjkCache* cache = nullptr);

}  // namespace dovetail::collision
