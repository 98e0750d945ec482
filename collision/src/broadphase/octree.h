#pragma once
// Octree over the scene bounds; boxes that cross a split plane stay at the node.

#include <cstdint>
#include <vector>

#include "broadphase/proxy_pairs.h"
#include "dovetail/collision/broadphase.h"

namespace dovetail::collision {

/// Why: a grid suits boxes of one size; an octree adapts to where the boxes
/// are and how many there are, splitting a cell only when it holds more than
/// `leaf_size` boxes (up to `max_depth`), and merging it back when its subtree
/// holds no more than half that. A box lives at the deepest node whose region
/// holds it without touching a split plane, so two boxes in different children
/// of a node are strictly apart along that node's split axis, and a box can
/// only overlap boxes at its own node, its ancestors and its descendants.
///
/// Query: one depth-first pass; each node's boxes are tested with each other
/// and with the boxes of its ancestors that reach into its cell (the list is
/// filtered on the way down, so a box at the root is not tested against the
/// whole tree). Moves are incremental: a box that still fits its node, and no
/// child of it, stays put.
///
/// The root is a cube around the boxes present at the first pairs() (ignoring
/// far outliers); boxes outside it stay at the root, and the tree is rebuilt
/// when more than max(leaf_size, n / 32) further boxes have left it.
///
/// Nodes are a flat array; the eight children of a node are adjacent.
class Octree final : public Broadphase {
 public:
  Octree(int leaf_size = 8, int max_depth = 10);

  void add(ProxyId id, const Aabb& box) override;
  void remove(ProxyId id) override;
  void move(ProxyId id, const Aabb& box) override;
  void pairs(std::vector<ProxyPair>& out) override;

  std::size_t size() const override { return present_.size(); }
  BroadphaseStats stats() const override { return last_stats_; }

  /// Nodes in use (including empty children of split nodes).
  std::size_t node_count() const { return nodes_.size() - 8 * free_blocks_.size(); }

 private:
  detail::PairSortScratch sort_keys_;  ///< scratch of pairs()
  static constexpr std::uint32_t kNone = 0xffffffffu;
  struct Node {
    Vec3 lo = Vec3::Zero();  ///< cell bounds
    Vec3 hi = Vec3::Zero();
    Vec3 mid = Vec3::Zero();  ///< split point
    std::uint32_t first_child = kNone;
    std::uint32_t parent = kNone;
    std::int32_t depth = 0;
    std::uint32_t subtree = 0;  ///< boxes in this node and below
    std::vector<ProxyId> ids;
  };
  struct Entry {
    std::uint32_t node = kNone;
    std::uint32_t slot = 0;  ///< position in the node's ids
    std::uint32_t present_slot = kNone;
    bool outside = false;  ///< at the root because it is outside the root cell
  };

  bool inside(const Node& node, const Aabb& box) const;
  static std::uint32_t child_for(const Node& node, const Aabb& box);
  static bool reaches(const Aabb& box, const Node& node);

  void rebuild();
  void insert(ProxyId id);
  void detach(ProxyId id);
  void place(ProxyId id, std::uint32_t node);
  void split(std::uint32_t node);
  void collapse(std::uint32_t node);
  void gather(std::uint32_t node, std::uint32_t into);
  std::uint32_t allocate_children();
  void visit(std::uint32_t node, std::size_t candidates_begin, std::vector<ProxyPair>& out);

  int leaf_size_;
  int max_depth_;
  bool ready_ = false;
  std::size_t outside_ = 0;
  std::size_t outside_after_rebuild_ = 0;

  std::vector<Node> nodes_;  ///< nodes_[0] is the root once ready_
  std::vector<std::uint32_t> free_blocks_;
  std::vector<Aabb> boxes_;  ///< by id
  std::vector<Entry> entries_;
  std::vector<ProxyId> present_;
  /// A box of an ancestor reaching into the cell being visited, copied so
  /// that the query's inner loop reads boxes in order, not through ids.
  struct Candidate {
    Aabb box;
    ProxyId id;
  };
  std::vector<Candidate> candidates_;  ///< scratch of the query
  std::size_t found_ = 0;              ///< pairs found so far by the query
  std::vector<Real> scratch_;
  BroadphaseStats stats_, last_stats_;
};

}  // namespace dovetail::collision
