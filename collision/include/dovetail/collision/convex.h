#pragma once
/// \file convex.h
/// Convex level: convex hulls of parts, the separating-plane test with a
/// plane cached per pair, and GJK with warm start.
///
/// Why: between the object level and the polygon level, a convex test rejects
/// most pairs whose boxes overlap at a cost independent of the triangle count;
/// with coherent motion the plane that separated a pair last frame usually
/// still does, so most frames re-check one plane.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// Convex hull of a point set, in the part's own frame. Immutable after
/// construction; shared by every instance of a part.
///
/// Why exact: a "separated" verdict of the convex level is a proof, so the
/// hull must contain every input point exactly and be exactly convex; then a
/// vertex no neighbour beats in a direction is the maximum over the whole hull.
/// compute_convex_hull checks both with exact orient3d (docs/convex.md).
struct ConvexHull {
  std::vector<Vec3> vertices;          ///< hull vertices only (input points)
  std::vector<TriangleIndices> faces;  ///< outward, counter-clockwise
  /// Vertex adjacency along hull edges, compressed: the neighbours of vertex
  /// i are neighbors[neighbor_offsets[i] .. neighbor_offsets[i + 1]).
  std::vector<std::uint32_t> neighbor_offsets;
  std::vector<std::uint32_t> neighbors;
  Vec3 center = Vec3::Zero();  ///< mean of the vertices (inside the hull)
  Real radius = 0;             ///< largest distance from `center` to a vertex
  /// Largest |coordinate| of a vertex: bounds the rounding error of d . v for
  /// every point of the hull. The exactness arguments of support() and of the
  /// separating-plane test rely on it; compute_convex_hull sets it.
  Real extent = 0;

  /// Index of a vertex maximising d . v, by hill climbing along edges from
  /// `start` (an out-of-range start means 0). Exact maximum of d . v for the
  /// given doubles: comparisons the rounding could decide wrongly are redone
  /// exactly, and on an exactly convex hull a vertex no neighbour strictly
  /// beats is a global maximum. Moves only on strict improvement, so on a
  /// plateau (a face or edge perpendicular to d) it stops at the first
  /// maximising vertex reached from `start`: deterministic.
  std::uint32_t support(const Vec3& d, std::uint32_t start = 0) const;
};

/// Hull of `points` through reentrant qhull (triangulated output, option
/// `Qt`), checked exactly and rebuilt exactly from qhull's vertices when the
/// check fails (docs/convex.md). Throws std::invalid_argument naming `source`
/// for an empty input, a non-finite coordinate, more than 2^31 - 1 points,
/// fewer than 4 affinely independent points (a flat or degenerate part: the
/// pipeline then skips the convex level for it) or a qhull error.
ConvexHull compute_convex_hull(std::span<const Vec3> points, const std::string& source);

/// Whether every triangle lies in a supporting plane of `hull` (the hull of
/// `points`), decided exactly: then the triangles lie on the hull's boundary,
/// and a closed mesh of them (is_closed, containment.h) is that boundary, so
/// the part is convex and its hull is the part itself. A triangle with a hull
/// vertex is checked against that vertex's hull neighbours (on an exactly
/// convex hull a plane through a vertex that no neighbour crosses supports
/// the whole hull), any other against every hull vertex. A triangle whose
/// three corners are collinear makes the answer false.
bool surface_on_hull(const ConvexHull& hull, std::span<const Vec3> points,
                     std::span<const TriangleIndices> triangles);

/// Per-pair state of the separating-plane test, kept by the caller across frames.
struct SeparatingPlaneCache {
  Vec3 normal = Vec3::UnitX();  ///< plane normal in A's frame, pointing from A to B
  Real offset = 0;              ///< plane: normal . x = offset
  /// False until the first test. Afterwards normal/offset hold the last
  /// separating plane, or, when the last test gave up, its last candidate.
  bool valid = false;
  std::uint32_t support_a = 0;  ///< last support vertex of A (warm start of its hill climb)
  std::uint32_t support_b = 0;  ///< last support vertex of B
  /// Vertex pairs (A index, B index) of the search's last simplex; four pairs
  /// after an overlap: the witness re-checked first by the next test.
  std::array<std::uint32_t, 4> simplex_a{};
  std::array<std::uint32_t, 4> simplex_b{};
  int simplex_size = 0;
};

/// Settings of the separating-plane search.
struct SeparatingPlaneSettings {
  int max_iterations = 64;  ///< then give up and report "maybe colliding"
};

/// Outcome of one separating-plane test.
struct SeparatingPlaneResult {
  bool separated = false;  ///< true: a plane strictly separates the hulls (proof)
  bool cache_hit = false;  ///< the cached plane still separated them
  /// Not separated because the search stopped without a plane: it reached
  /// max_iterations; or its normal, a point of the Minkowski difference
  /// B - A, became shorter than kSeparatingPlaneContact * (a.radius +
  /// b.radius), so the hulls are at most that far apart; or that point
  /// could not be shortened any more; or `overlap`. Every "not separated"
  /// answer is a give-up: "maybe colliding", never a proof.
  bool gave_up = false;
  /// Gave up because the origin lies inside a tetrahedron of four support
  /// pairs (points of B - A): the hulls overlap, up to rounding.
  bool overlap = false;
  bool witness_hit = false;  ///< the cached overlap witness still held (no support query)
  int iterations = 0;        ///< support-query pairs evaluated (1 on a cache hit)
};

/// Relative length below which the separating-plane search stops (see
/// SeparatingPlaneResult::gave_up).
inline constexpr Real kSeparatingPlaneContact = 1e-3;

/// Searches for a plane separating hull A from hull B (B at pose X_AB in A's
/// frame), starting from `cache` and leaving the found plane in it: first the
/// cached overlap witness or the cached normal (two warm-started support
/// queries), then the perceptron rule with a fully corrective step
/// (docs/convex.md). Biased towards "collision": when the search
/// gives up it reports not separated. "Separated" is a proof for the meshes
/// the hulls were built from, with B's vertices placed by X_AB.apply.
SeparatingPlaneResult separating_plane_test(const ConvexHull& a, const ConvexHull& b,
                                            const Transform& X_AB, SeparatingPlaneCache& cache,
                                            const SeparatingPlaneSettings& settings = {});

/// Per-pair warm-start state of GJK, kept by the caller across frames.
struct GjkCache {
  std::uint32_t support_a = 0;     ///< last support vertex of A
  std::uint32_t support_b = 0;     ///< last support vertex of B
  Vec3 direction = Vec3::UnitX();  ///< last search direction, in A's frame
  bool valid = false;
  /// Vertex pairs of the last final simplex (A index, B index); the next call
  /// starts from these points at the new pose.
  std::array<std::uint32_t, 4> simplex_a{};
  std::array<std::uint32_t, 4> simplex_b{};
  int simplex_size = 0;
};

/// GJK stops as converged when the gap between the distance's upper bound
/// |v| and its lower bound (v . w) / |v| is at most this fraction of |v|.
inline constexpr Real kGjkRelativeTolerance = 1e-10;
/// GJK reports "intersecting" when the distance is at most this fraction of
/// the pair's scale (|t_AB| + a.extent + b.extent): the touching band.
inline constexpr Real kGjkContactTolerance = 1e-9;
/// Cap on GJK iterations (support-query pairs); reached only on numerical
/// trouble, reported in GjkResult::hit_iteration_cap.
inline constexpr int kGjkMaxIterations = 128;

/// Kind of a closest feature: how many hull vertices span it.
enum class FeatureType : std::uint8_t {
  kNone = 0,    ///< no closest feature (the hulls overlap; see GjkResult)
  kVertex = 1,  ///< one vertex
  kEdge = 2,    ///< the segment between two vertices
  kFace = 3,    ///< the triangle of three vertices
};

/// A closest feature of one hull: the hull vertices (indices into
/// ConvexHull::vertices, in the hull's own frame) that carry weight in the
/// closest point, ascending. The closest point is a convex combination of
/// them, and all of them lie on the hull's supporting plane facing the other
/// hull (up to GJK's tolerance). Where the hull has a polygonal face (coplanar
/// triangles), an edge may be a diagonal of that face and a face any three of
/// its vertices, not necessarily one of ConvexHull::faces.
struct HullFeature {
  FeatureType type = FeatureType::kNone;
  std::array<std::uint32_t, 3> vertices{};  ///< the first size() entries are used
  /// Number of vertices: 0 for kNone, 1 vertex, 2 edge, 3 face.
  int size() const { return static_cast<int>(type); }
  friend bool operator==(const HullFeature&, const HullFeature&) = default;
};

/// Outcome of GJK on two hulls.
struct GjkResult {
  bool intersecting = false;      ///< distance within the touching band (see kGjkContactTolerance)
  Real distance = 0;              ///< 0 when intersecting
  Vec3 closest_a = Vec3::Zero();  ///< on A, in A's frame (when intersecting: a point of A near B)
  Vec3 closest_b = Vec3::Zero();  ///< on B, in A's frame
  /// Closest features of A and B, from the final simplex's support pairs with
  /// repeated vertices merged (a simplex whose A indices are {5, 5, 7} gives
  /// the edge (5, 7) on A). closest_a lies in the convex hull of feature_a's
  /// vertices, closest_b in that of feature_b's placed by X_AB.apply.
  /// Intersecting within the touching band (a final simplex of one to three
  /// points), they are the features in contact, defined as for separated
  /// hulls. When the final simplex is a tetrahedron holding the origin (the
  /// hulls overlap beyond the band), or on non-finite input, both are kNone.
  HullFeature feature_a;
  HullFeature feature_b;
  int iterations = 0;  ///< support-query pairs evaluated
  bool hit_iteration_cap = false;
};

/// GJK distance/intersection of hull A and hull B (B at X_AB in A's frame),
/// warm-started from `cache` when given (and updated). Signed-volume
/// sub-distance; always returns finite values for finite input.
GjkResult gjk(const ConvexHull& a, const ConvexHull& b, const Transform& X_AB,
              GjkCache* cache = nullptr);

/// Penetration depth of two convex parts: the length of the shortest
/// translation of B that leaves the interiors apart, and its direction.
struct PenetrationDepth {
  Real depth = 0;               ///< 0 when the hulls do not overlap
  Vec3 normal = Vec3::UnitZ();  ///< unit, in A's frame: B moves along it to separate
};

/// The penetration depth of hulls A and B (B at X_AB in A's frame), when each
/// is its part (surface_on_hull on a closed mesh): the smallest overlap of
/// the two along a face normal of either or the cross product of an edge of
/// each. The smallest over every direction is attained at a face normal of
/// their Minkowski difference, which is one of these, so the result is
/// exact up to rounding. Costs (faces + edge pairs) support queries; nothing
/// (std::nullopt) when the edge pairs exceed `max_edge_pairs`.
std::optional<PenetrationDepth> convex_penetration_depth(const ConvexHull& a, const ConvexHull& b,
                                                         const Transform& X_AB,
                                                         std::size_t max_edge_pairs = 65536);

}  // namespace dovetail::collision
