#pragma once
// Restricted boxtree (Zachmann, "Minimal hierarchical collision detection",
// VRST 2002).
//
// Why: a child box equals its parent box except for one face, so a node needs
// only a split axis and two split values (12 bytes), the smallest node of all
// hierarchies here; and in a simultaneous traversal a child's test re-uses
// its parent's transformed extents: descending one tree changes one face, so
// the child's enclosure in the other tree's frame costs three multiply-adds,
// and in its own frame only the moved face has to be compared.
//
// Subtree frames: boxes aligned with the mesh's axes are loose wherever the
// surface is slanted, and near contact a traversal tests every pair of boxes
// that the gap cannot separate. A subtree whose box is much smaller in a
// frame of its own (its principal axes, turned while that shrinks the box:
// the OBB tree's frame search, box_fit.h) gets one: a frame node (12 bytes,
// the rotation in 16-bit fixed point) and its box and child (28 bytes).
// Below it the tree is an ordinary restricted boxtree in the new frame;
// entering it costs the traversal one full enclosure of each side. On the
// bunny this takes the volume tests a query from 1,286 to 418 and the memory
// from 15.5 to 13.9 bytes a triangle, since a leaf keeps two of its
// triangles in its own node.

#include <bit>
#include <cstdint>
#include <vector>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"

namespace dovetail::collision {

/// Build settings of a Boxtree.
struct BoxtreeSettings {
  int max_leaf_size = 4;        ///< triangles per leaf, 1..4
  double slab_threshold = 0.1;  ///< split off an empty slab wider than this fraction of the box
  int bins = 16;                ///< candidate split positions per axis
  /// Subtree frames: a subtree gets a frame of its own (its searched box
  /// frame) where its box in that frame is smaller than `frame_gain` times its box
  /// in the frame it is in. Tried at the root, then in subtrees `frame_step`
  /// times smaller than the last one tried, down to `frame_min_triangles`.
  bool frames = true;
  int frame_step = 3;  ///< >= 2
  int frame_min_triangles = 8;
  double frame_gain = 0.9;
};

/// One node, 12 bytes. Inner node: children at `child()` (and `child() + 1`
/// when both exist); the left child's box is the parent's with its upper face
/// on `axis` moved to `split_left`, the right child's with its lower face
/// moved to `split_right`. A node with one child splits off an empty slab.
/// Leaf: up to four triangles, the first two in the node itself, the others
/// at Boxtree::triangle_order()[index()]. Frame node: one child, whose box
/// and subtree are in a frame of their own, the rotation in the node (a unit
/// quaternion in 16-bit fixed point) and the box at Boxtree::frames()[index()].
struct BoxtreeNode {
  std::uint32_t word[2] = {0, 0};
  /// axis (2 bits, 3 = leaf) | kind, or leaf count - 1 (2 bits) | index (28 bits)
  std::uint32_t bits = 0;

  static constexpr std::uint32_t kLeafAxis = 3;
  static constexpr std::uint32_t kBothChildren = 0;
  static constexpr std::uint32_t kLeftOnly = 1;
  static constexpr std::uint32_t kRightOnly = 2;
  static constexpr std::uint32_t kFrame = 3;
  static constexpr std::uint32_t kMaxIndex = (1u << 28) - 1;

  std::uint32_t axis() const { return bits & 3u; }
  bool is_leaf() const { return axis() == kLeafAxis; }
  bool is_frame() const { return !is_leaf() && kind() == kFrame; }
  std::uint32_t kind() const { return (bits >> 2) & 3u; }
  int leaf_count() const { return static_cast<int>(kind()) + 1; }
  std::uint32_t index() const { return bits >> 4; }
  float split_left() const { return std::bit_cast<float>(word[0]); }
  float split_right() const { return std::bit_cast<float>(word[1]); }
  /// A frame node's rotation, from its frame to the mesh's.
  Mat3 rotation() const;
};

/// A frame node's box in its frame, and its child.
struct BoxtreeFrame {
  float lo[3] = {0, 0, 0};
  float hi[3] = {0, 0, 0};
  std::uint32_t child = 0;
};

/// Restricted boxtree over one mesh; immutable after construction.
class Boxtree {
 public:
  Boxtree(const Mesh& mesh, const BoxtreeSettings& settings = {});

  /// Query with this tree over `mesh_a` as A and `b` over `mesh_b` as B.
  CollideResult collide(const Mesh& mesh_a, const Boxtree& b, const Mesh& mesh_b,
                        const Transform& X_AB, const CollideRequest& request) const;

  /// The same query divided into independent parts (see SplitQuery).
  std::unique_ptr<SplitQuery> split(const Mesh& mesh_a, const Boxtree& b, const Mesh& mesh_b,
                                    const Transform& X_AB, const CollideRequest& request) const;

  std::size_t node_count() const { return nodes_.size(); }
  std::size_t leaf_count() const { return leaves_; }
  std::size_t depth() const { return depth_; }
  std::size_t bytes() const;

  const std::vector<BoxtreeNode>& nodes() const { return nodes_; }
  const std::vector<std::uint32_t>& triangle_order() const { return order_; }
  const std::vector<BoxtreeFrame>& frames() const { return frames_; }

 private:
  friend class BoxtreeBuilder;
  friend class BoxtreeTraversal;

  std::vector<BoxtreeNode> nodes_;    ///< root at 0
  std::vector<std::uint32_t> order_;  ///< leaves' third and fourth triangles
  std::vector<BoxtreeFrame> frames_;
  float root_lo_[3] = {0, 0, 0};
  float root_hi_[3] = {0, 0, 0};
  Real max_abs_ = 0;  ///< largest absolute vertex coordinate
  std::size_t leaves_ = 0;
  std::size_t depth_ = 0;
};

}  // namespace dovetail::collision
