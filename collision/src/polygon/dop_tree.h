#pragma once
// DOP-tree (Zachmann, "Rapid collision detection by dynamically aligned
// DOP-trees", VRAIS 1998).
//
// Why: a k-DOP bounds tighter than a box for little more memory, and the
// moving tree's DOPs need not be re-fitted: a tumbled DOP is enclosed by an
// axis-aligned DOP in the other tree's frame in O(k), because which three of
// its planes bound it in each direction depends only on the rotation, not on
// the node, so that correspondence is computed once per query.

#include <array>
#include <cstdint>
#include <vector>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"
#include "polygon/binary_layout.h"

namespace dovetail::collision {

/// The fixed plane normals of a k-DOP (k = 6, 14, 18 or 26) and the cones
/// between them used to enclose a rotated DOP.
struct DopBasis {
  static constexpr int kMaxAxes = 13;
  int axes = 0;                         ///< k / 2
  std::array<Vec3, kMaxAxes> normal{};  ///< integer normals, not unit length

  /// A cone spanned by three of the 2 * axes directions +-normal[j]; the cones
  /// of all faces of the directions' convex hull cover every direction.
  struct Cone {
    std::array<int, 3> direction;  ///< index j, + axes when the direction is -normal[j]
    Mat3 inverse;                  ///< inverse of the matrix whose columns are the directions
  };
  std::vector<Cone> cones;

  explicit DopBasis(int k);
  Vec3 direction(int d) const { return d < axes ? normal[d] : Vec3(-normal[d - axes]); }
};

/// DOP-tree over one mesh; immutable after construction.
class DopTree {
 public:
  DopTree(const Mesh& mesh, int k, int max_leaf_size = 2);

  CollideResult collide(const Mesh& mesh_a, const DopTree& b, const Mesh& mesh_b,
                        const Transform& X_AB, const CollideRequest& request) const;

  /// The same query divided into independent parts (see SplitQuery).
  std::unique_ptr<SplitQuery> split(const Mesh& mesh_a, const DopTree& b, const Mesh& mesh_b,
                                    const Transform& X_AB, const CollideRequest& request) const;

  int k() const { return 2 * basis_.axes; }
  std::size_t node_count() const { return links_.size(); }
  std::size_t leaf_count() const { return leaves_; }
  std::size_t depth() const { return depth_; }
  std::size_t bytes() const;

 private:
  friend class DopPolicy;

  DopBasis basis_;
  std::vector<float> bounds_;  ///< per node: lo[axes] then hi[axes], in own frame
  std::vector<detail::NodeLink> links_;
  std::vector<std::uint32_t> order_;
  Real max_abs_ = 0;
  std::size_t leaves_ = 0;
  std::size_t depth_ = 0;
};

}  // namespace dovetail::collision
