#pragma once
/// \file distance.h
/// Minimum distance and tolerance queries between two rigid triangle meshes.
///
/// Why: grasping, snapping and clearance checks in an assembly need to know
/// how far apart two parts are, not only whether they touch. A DistanceModel
/// is built once per mesh (a hierarchy of rectangle swept spheres) and then
/// queried for any pose of any pair; like a CollisionModel it is immutable
/// and may be shared and queried from any number of threads at once.
///
/// The distance of two meshes is the smallest distance between a triangle of
/// A and a triangle of B (surfaces only, as in `collide`). It is 0 exactly
/// when `collide` reports the pair colliding: both use the same exact
/// triangle test on the same transformed coordinates. See docs/proximity.md.

#include <cstdint>
#include <limits>
#include <memory>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/types.h"

namespace dovetail::collision {

namespace detail {
class RssTree;
}

/// How to build a DistanceModel.
struct DistanceModelSettings {
  /// Triangles per leaf, 1..7. One triangle per leaf gives the tightest
  /// bounds and the fastest queries; more saves memory.
  int max_leaf_size = 1;
};

/// A mesh with its distance hierarchy. Immutable after build.
class DistanceModel {
 public:
  ~DistanceModel();
  DistanceModel(const DistanceModel&) = delete;
  DistanceModel& operator=(const DistanceModel&) = delete;

  /// The mesh the model was built for.
  const Mesh& mesh() const { return *mesh_; }
  /// The same mesh, shared.
  const std::shared_ptr<const Mesh>& shared_mesh() const { return mesh_; }
  /// Shape and memory of the hierarchy (not counting the mesh).
  ModelInfo info() const;
  /// The hierarchy itself (for the implementation of the queries).
  const detail::RssTree& tree() const { return *tree_; }

 private:
  friend std::shared_ptr<const DistanceModel> build_distance_model(std::shared_ptr<const Mesh>,
                                                                   const DistanceModelSettings&);
  DistanceModel(std::shared_ptr<const Mesh> mesh, std::unique_ptr<const detail::RssTree> tree);

  std::shared_ptr<const Mesh> mesh_;
  std::unique_ptr<const detail::RssTree> tree_;
};

/// Builds the distance hierarchy of `mesh` (top-down, once). Throws
/// std::invalid_argument for a null mesh or a leaf size outside 1..7.
std::shared_ptr<const DistanceModel> build_distance_model(
    std::shared_ptr<const Mesh> mesh, const DistanceModelSettings& settings = {});

/// What a distance query should find.
struct DistanceRequest {
  /// Accept a result up to this factor above the minimum: the query may stop
  /// once no pair can be closer than distance / (1 + relative_error).
  /// 0 (the default): the exact minimum.
  Real relative_error = 0;
  /// Accept a result up to this much above the minimum (absolute, in A's units).
  Real absolute_error = 0;
};

/// Outcome of a distance query. All points are in A's frame.
struct DistanceResult {
  /// Minimum distance between the two surfaces; 0 when they intersect.
  Real distance = std::numeric_limits<Real>::infinity();
  /// Closest point on A. When the meshes intersect, a point of both (p_A == q_A).
  Vec3 p_A = Vec3::Zero();
  /// Closest point on B, expressed in A's frame.
  Vec3 q_A = Vec3::Zero();
  std::uint32_t triangle_a = 0;  ///< index into A's Mesh::triangles of the closest pair
  std::uint32_t triangle_b = 0;  ///< index into B's Mesh::triangles of the closest pair
  /// Work done: bounding-volume pair bounds and triangle-pair distances computed.
  CollideStats stats;
};

/// Outcome of a tolerance query. All points are in A's frame.
struct ToleranceResult {
  /// True when the distance between the surfaces is at most the tolerance.
  bool within = false;
  /// The witness pair's distance (<= tolerance) when `within`; otherwise
  /// infinity (the query proves the distance is larger, it does not measure it).
  Real distance = std::numeric_limits<Real>::infinity();
  Vec3 p_A = Vec3::Zero();       ///< witness point on A (when within)
  Vec3 q_A = Vec3::Zero();       ///< witness point on B in A's frame (when within)
  std::uint32_t triangle_a = 0;  ///< witness triangle of A (when within)
  std::uint32_t triangle_b = 0;  ///< witness triangle of B (when within)
  CollideStats stats;            ///< work done, as in DistanceResult
};

/// Minimum distance between A and B, B at pose X_AB in A's frame, by a
/// simultaneous traversal of both hierarchies that visits the closer pair of
/// volumes first and prunes pairs that cannot beat the best distance so far.
/// Equal to distance_brute (the same triangle pairs give the same bits)
/// unless `request` allows an error. Throws std::invalid_argument for a
/// negative or NaN allowed error.
DistanceResult distance(const DistanceModel& a, const DistanceModel& b, const Transform& X_AB,
                        const DistanceRequest& request = {});

/// Is the distance between A and B at most `tolerance` (>= 0)? Stops at the
/// first triangle pair within the tolerance and prunes every pair of volumes
/// farther apart than it. The verdict equals distance_brute(...).distance <=
/// tolerance. Throws std::invalid_argument for a negative or NaN tolerance.
ToleranceResult within_tolerance(const DistanceModel& a, const DistanceModel& b,
                                 const Transform& X_AB, Real tolerance);

/// Closest points of two closed triangles given in one frame.
struct TrianglePairDistance {
  Real distance = 0;      ///< 0 exactly when the exact triangle test says they intersect
  Vec3 p = Vec3::Zero();  ///< on the first triangle
  Vec3 q = Vec3::Zero();  ///< on the second
};
/// The distance of the leaf test of the distance queries, for one pair.
TrianglePairDistance triangle_pair_distance(const std::array<Vec3, 3>& a,
                                            const std::array<Vec3, 3>& b);

/// The reference: every triangle pair of A and B (a pair is skipped only when
/// its triangles' bounding boxes are provably farther apart than the best so
/// far). For tests and as the `brute` method.
DistanceResult distance_brute(const Mesh& a, const Mesh& b, const Transform& X_AB);

/// Tolerance query over every triangle pair, stopping at the first pair
/// within `tolerance` (the reference for within_tolerance). Throws like
/// within_tolerance.
ToleranceResult within_tolerance_brute(const Mesh& a, const Mesh& b, const Transform& X_AB,
                                       Real tolerance);

}  // namespace dovetail::collision
