#pragma once
// Reference hierarchies with box volumes: the AABB tree (boxes aligned with
// the mesh's own frame) and the OBB tree (Gottschalk, Lin, Manocha,
// "OBB-Tree", SIGGRAPH 1996: boxes fitted by covariance). Both are queried by
// the 15-axis separating-axis test.

#include <cstdint>
#include <vector>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"
#include "polygon/binary_layout.h"

namespace dovetail::collision {

/// AABB tree over one mesh; immutable after construction.
class AabbTree {
 public:
  explicit AabbTree(const Mesh& mesh, int max_leaf_size = 2);

  CollideResult collide(const Mesh& mesh_a, const AabbTree& b, const Mesh& mesh_b,
                        const Transform& X_AB, const CollideRequest& request) const;
  /// The same query divided into independent parts (see SplitQuery).
  std::unique_ptr<SplitQuery> split(const Mesh& mesh_a, const AabbTree& b, const Mesh& mesh_b,
                                    const Transform& X_AB, const CollideRequest& request) const;

  std::size_t node_count() const { return nodes_.size(); }
  std::size_t leaf_count() const { return leaves_; }
  std::size_t depth() const { return depth_; }
  std::size_t bytes() const;

 private:
  friend class AabbPolicy;
  struct Node {
    float lo[3];
    float hi[3];
    detail::NodeLink link;
  };
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
  Real max_abs_ = 0;
  std::size_t leaves_ = 0;
  std::size_t depth_ = 0;
};

/// OBB tree over one mesh; immutable after construction.
class ObbTree {
 public:
  explicit ObbTree(const Mesh& mesh, int max_leaf_size = 2);

  CollideResult collide(const Mesh& mesh_a, const ObbTree& b, const Mesh& mesh_b,
                        const Transform& X_AB, const CollideRequest& request) const;
  /// The same query divided into independent parts (see SplitQuery).
  std::unique_ptr<SplitQuery> split(const Mesh& mesh_a, const ObbTree& b, const Mesh& mesh_b,
                                    const Transform& X_AB, const CollideRequest& request) const;

  std::size_t node_count() const { return nodes_.size(); }
  std::size_t leaf_count() const { return leaves_; }
  std::size_t depth() const { return depth_; }
  std::size_t bytes() const;

  /// CollisionModel::search_triangle: a box is passed over when one of its
  /// own three axes or the triangle's normal separates it from the triangle
  /// by more than `margin` (box_lanes.h); children in their order.
  bool search_triangle(const std::array<Vec3, 3>& corners, Real margin, TriangleVisit visit,
                       CollideStats& stats) const;

  /// At least how far any point of any box of this tree moves when the
  /// tree's pose in another frame changes from X_from to X_to, with room for
  /// the rounding of both (SeparationFront).
  Real reach(const Transform& X_from, const Transform& X_to) const;

 private:
  friend class ObbPolicy;
  /// A box as the lane test reads it (polygon/box_lanes.h): fifteen
  /// doubles, the rotation into the box's frame (column-major; its rows are
  /// the box's axes in the mesh's frame), the centre, the half extents.
  struct Node {
    double box[15];
    detail::NodeLink link;

    Eigen::Map<const Mat3> to_box() const { return Eigen::Map<const Mat3>(box); }
    Eigen::Map<const Vec3> centre() const { return Eigen::Map<const Vec3>(box + 9); }
    Eigen::Map<const Vec3> half() const { return Eigen::Map<const Vec3>(box + 12); }
  };
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
  Real max_abs_ = 0;
  std::size_t leaves_ = 0;
  std::size_t depth_ = 0;
  /// A ball holding every box of the tree (centre, radius), for reach().
  Vec3 ball_centre_ = Vec3::Zero();
  Real ball_radius_ = 0;
};

}  // namespace dovetail::collision
