#pragma once
// The distance hierarchy: a binary tree of rectangle swept spheres (Larsen,
// Gottschalk, Lin, Manocha, "Fast proximity queries with swept sphere
// volumes", 1999), queried by a simultaneous traversal of two trees for the
// minimum distance or for a tolerance verdict.

#include <cstdint>
#include <vector>

#include "dovetail/collision/distance.h"
#include "dovetail/collision/mesh.h"
#include "polygon/binary_layout.h"

namespace dovetail::collision::detail {

/// A rectangle swept sphere in one frame: the points within `radius` of the
/// rectangle centre + x u + y v, |x| <= hu, |y| <= hv. u and v are unit and
/// orthogonal up to float rounding; every bound is computed from the vectors
/// as they are, so it never relies on exact orthonormality.
struct Rss {
  Vec3 centre;
  Vec3 u;
  Vec3 v;
  Real hu = 0;
  Real hv = 0;
  Real radius = 0;
};

/// A lower bound on the distance between two RSS in one frame (negative when
/// they may overlap). The closest points of the two rectangles are
/// approached by alternating projections (each a clamp in the other
/// rectangle's coordinates); the bound is the gap between the projections of
/// both rectangles on the direction joining those points, less both radii.
/// Any direction gives a valid bound; at the true closest points it is the
/// exact distance. One round of projections (from y's centre) is enough in
/// practice: more rounds tighten the bound by 1-2% and cost more than they
/// prune (see docs/proximity.md).
Real rss_lower_bound(const Rss& x, const Rss& y);

/// RSS tree over one mesh; immutable after construction, queries are const
/// and keep their state on the stack.
///
/// Why: a rectangle swept sphere bounds the distance from below much more
/// tightly than a box (the bound is the distance of two rectangles, with
/// no corners of a box to inflate it), which is what prunes a distance
/// traversal. A node is one 64-byte cache line: the centre in double (so
/// small nodes far from the origin keep tight radii), the axes and sizes in
/// float with the radius measured against exactly those floats, rounded up.
class RssTree {
 public:
  RssTree(const Mesh& mesh, int max_leaf_size);

  struct Node {
    Vec3 centre;       ///< rectangle centre in the mesh's frame
    float axis[2][3];  ///< the rectangle's axes u, v
    float half[2];     ///< half lengths along u and v
    float radius;      ///< swept-sphere radius
    NodeLink link;
  };

  /// Minimum distance to tree `b` (mesh_b at X_AB in this mesh's frame).
  DistanceResult distance(const Mesh& mesh_a, const RssTree& b, const Mesh& mesh_b,
                          const Transform& X_AB, const DistanceRequest& request) const;
  /// Is the distance to tree `b` at most `tolerance`?
  ToleranceResult within(const Mesh& mesh_a, const RssTree& b, const Mesh& mesh_b,
                         const Transform& X_AB, Real tolerance) const;

  const std::vector<Node>& nodes() const { return nodes_; }
  /// Leaf slot -> triangle index.
  const std::vector<std::uint32_t>& order() const { return order_; }
  /// The node's RSS in the mesh's own frame.
  Rss rss(std::uint32_t n) const;
  Real max_abs() const { return max_abs_; }
  std::size_t leaf_count() const { return leaves_; }
  std::size_t depth() const { return depth_; }
  std::size_t bytes() const;

 private:
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
  Real max_abs_ = 0;
  std::size_t leaves_ = 0;
  std::size_t depth_ = 0;
};

}  // namespace dovetail::collision::detail
