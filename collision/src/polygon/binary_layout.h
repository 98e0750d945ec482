#pragma once
// Top-down construction shared by the hierarchies with tight volumes (AABB
// tree, DOP-tree, OBB tree): a binary partition of the triangles by binned
// surface-area cost, as a flat array of nodes with adjacent children. Each
// hierarchy then computes its own volume for every node.

#include <cstdint>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "polygon/hierarchy_common.h"

namespace dovetail::collision::detail {

/// A node of the partition: triangle slots [begin, end) of BinaryLayout::order.
struct LayoutNode {
  std::uint32_t begin = 0;
  std::uint32_t end = 0;
  std::uint32_t first_child = 0;  ///< children at first_child, first_child + 1; 0 for a leaf
  bool is_leaf() const { return first_child == 0; }
};

struct BinaryLayout {
  std::vector<LayoutNode> nodes;         ///< root at 0, every parent before its children
  std::vector<BuildTriangle> triangles;  ///< in slot order
  std::size_t depth = 0;
  std::size_t leaves = 0;
};

/// Partitions the mesh's triangles until a node holds at most `max_leaf` of them.
BinaryLayout build_binary_layout(const Mesh& mesh, int max_leaf);

/// Packed node link used by the tight-volume trees: an inner node's first
/// child index, or a leaf's first slot and triangle count.
struct NodeLink {
  std::uint32_t bits = 0;
  static constexpr std::uint32_t kLeafFlag = 1u << 31;
  static constexpr int kCountBits = 3;  ///< leaves hold 1..7 triangles

  static NodeLink from(const LayoutNode& n) {
    if (!n.is_leaf()) return {n.first_child};
    return {kLeafFlag | n.begin << kCountBits | (n.end - n.begin)};
  }
  bool is_leaf() const { return (bits & kLeafFlag) != 0; }
  std::uint32_t first_child() const { return bits; }
  std::uint32_t first_slot() const { return (bits & ~kLeafFlag) >> kCountBits; }
  int count() const { return static_cast<int>(bits & ((1u << kCountBits) - 1)); }
};

}  // namespace dovetail::collision::detail
