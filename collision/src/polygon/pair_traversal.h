#pragma once
// Simultaneous traversal of two hierarchies with tight volumes (the bounding
// volume test tree). B's volume is brought into A's frame once per B node
// (the policy's Enc) and re-used while A descends; the larger node descends.

#include <concepts>
#include <deque>
#include <span>
#include <vector>

#include "polygon/binary_layout.h"
#include "polygon/hierarchy_common.h"

namespace dovetail::collision::detail {

/// Policy interface:
///   using EncA, EncB;                      a node's volume expressed in the other's frame
///   EncA enclose_a(uint32_t a) const;      (an empty struct where a test needs none)
///   EncB enclose_b(uint32_t b) const;
///   bool overlap(uint32_t a, const EncA&, uint32_t b, const EncB&) const;
///   NodeLink link_a(uint32_t), link_b(uint32_t) const;
///   Real size_a(uint32_t), size_b(uint32_t) const;
///   const uint32_t* slots_a(), *slots_b() const;  leaf slot -> triangle index
/// optionally, for first-hit queries to enter the likelier pair first (HasNearness):
///   Real nearness(uint32_t a, const EncA&, uint32_t b, const EncB&) const;
/// and, for policies that keep a SeparationFront (HasGap):
///   Real gap(uint32_t a, const EncA&, uint32_t b, const EncB&) const;
///                                          > 0 exactly when overlap() is false
template <typename Policy>
concept HasGap = requires(const Policy& p, const typename Policy::EncA& ea,
                          const typename Policy::EncB& eb) {
  { p.gap(0u, ea, 0u, eb) } -> std::same_as<Real>;
};

/// Policies whose volumes bound the distance between their contents
/// (CollideRequest::max_size): small_pair(a, b, s) is true only when the
/// diameters of node a's and node b's volumes sum to at most s.
template <typename Policy>
concept HasDiameter = requires(const Policy& p) {
  { p.small_pair(0u, 0u, Real{0}) } -> std::same_as<bool>;
};

/// Policies that rank overlapping pairs for a first-hit query:
/// nearness(a, b) is smaller for a pair likelier to hold an intersection.
template <typename Policy>
concept HasNearness = requires(const Policy& p, const typename Policy::EncA& ea,
                               const typename Policy::EncB& eb) {
  { p.nearness(0u, ea, 0u, eb) } -> std::same_as<Real>;
};

template <typename Policy>
class PairTraversal {
 public:
  using EncA = typename Policy::EncA;
  using EncB = typename Policy::EncB;

  PairTraversal(const Policy& policy, LeafTester& tester) : p_(policy), tester_(tester) {}

  /// A pair of overlapping nodes with their enclosures.
  struct Entry {
    std::uint32_t a;
    EncA enc_a;
    std::uint32_t b;
    EncB enc_b;
  };

  void run() {
    const Entry root = root_entry();
    if (overlapping(root)) visit(root.a, root.enc_a, root.b, root.enc_b, 0);
  }

  /// Time-critical detection (CollideRequest::max_depth): a pair of
  /// overlapping volumes this many levels below the roots is a hit.
  void cut_at_depth(int max_depth) { max_depth_ = max_depth; }

  /// Detection within a tolerance (CollideRequest::max_size): a pair of
  /// overlapping volumes whose diameters sum to at most `max_size` is a hit.
  void cut_at_size(Real max_size) { max_size_ = max_size; }

  /// Overlapping node pairs breadth-first from the roots, until there are at
  /// least `target` or only leaf pairs remain.
  std::vector<Entry> frontier(std::size_t target) {
    std::deque<Entry> queue;
    const Entry root = root_entry();
    if (overlapping(root)) queue.push_back(root);
    for (std::size_t leaf_pairs = 0; queue.size() < target && leaf_pairs < queue.size();) {
      const Entry e = queue.front();
      queue.pop_front();
      if (p_.link_a(e.a).is_leaf() && p_.link_b(e.b).is_leaf()) {
        queue.push_back(e);
        ++leaf_pairs;
        continue;
      }
      leaf_pairs = 0;
      children(e, [&](const Entry& c) { queue.push_back(c); });
    }
    return {queue.begin(), queue.end()};
  }

  void run_from(const Entry& e) { visit(e.a, e.enc_a, e.b, e.enc_b, 0); }

  /// For a first-hit query with a policy that has nearness(): of two
  /// overlapping child pairs, enter the nearer first. It changes which hit is
  /// found, never whether one is.
  void enter_nearer_first() { nearer_first_ = true; }

  /// Records, for a first-hit query, the node pair `levels` above the leaf
  /// pair where the hit is found (or the highest pair visited, if fewer).
  void record_hint(TraversalHint* hint, int levels) {
    hint_ = hint;
    hint_levels_ = levels;
  }

  /// Writes the cut of what follows into `out` (SeparationFront): every node
  /// pair found apart, with its gap, and every leaf pair tested, depth first.
  void record_front(std::vector<SeparationFront::Entry>* out) { front_out_ = out; }

  /// The traversal from a front recorded at a pose from which B has since
  /// moved by at most `reach` in A's frame, in the front's order: an entry
  /// apart by more than that is still apart (kept, its gap less `reach`);
  /// the others are tested again and descended as from the roots.
  void run_from_front(std::span<const SeparationFront::Entry> front, Real reach) {
    for (const SeparationFront::Entry& f : front) {
      if (f.gap > reach) {
        if (front_out_) front_out_->push_back({f.node_a, f.node_b, f.gap - reach});
        continue;
      }
      const Entry e{f.node_a, p_.enclose_a(f.node_a), f.node_b, p_.enclose_b(f.node_b)};
      if (overlapping(e)) visit(e.a, e.enc_a, e.b, e.enc_b, 0);
      if (tester_.done()) return;
    }
  }

  /// A first-hit query that searches the hinted subtree pair first (when it
  /// still overlaps) and then `whole()`, the whole trees, only when that
  /// finds nothing. What the subtree pair adds to a recorded front is
  /// dropped: the whole traversal records it again.
  template <typename Whole>
  void run_hinted(TraversalHint& hint, std::size_t node_count_a, std::size_t node_count_b,
                  Whole&& whole) {
    // A hint at the roots would only repeat the traversal below.
    const bool at_roots = hint.node_a == 0 && hint.node_b == 0;
    if (hint.valid && !at_roots && hint.node_a < node_count_a && hint.node_b < node_count_b) {
      const Entry e{hint.node_a, p_.enclose_a(hint.node_a), hint.node_b, p_.enclose_b(hint.node_b)};
      if (overlapping(e)) run_from(e);
      if (tester_.done()) return;
      if (front_out_) front_out_->clear();
    }
    // Kept after a miss: parts that part briefly often meet again there, and
    // a stale hint costs at most one more search of its subtree pair.
    whole();
  }

 private:
  Entry root_entry() const { return {0, p_.enclose_a(0), 0, p_.enclose_b(0)}; }

  bool overlapping(const Entry& e) { return overlapping(e.a, e.enc_a, e.b, e.enc_b); }

  /// One volume test; a pair found apart joins the recorded front.
  bool overlapping(std::uint32_t a, const EncA& enc_a, std::uint32_t b, const EncB& enc_b) {
    tester_.count_volume_test();
    if constexpr (HasGap<Policy>) {
      if (front_out_) {
        const Real gap = p_.gap(a, enc_a, b, enc_b);
        if (!(gap > 0)) return true;
        front_out_->push_back({a, b, gap});
        return false;
      }
    }
    return p_.overlap(a, enc_a, b, enc_b);
  }

  /// Calls next(child entry) for every overlapping child pair of a non-leaf pair.
  template <typename Next>
  void children(const Entry& e, Next&& next) {
    const NodeLink la = p_.link_a(e.a);
    const NodeLink lb = p_.link_b(e.b);
    if (!la.is_leaf() && (lb.is_leaf() || p_.size_a(e.a) >= p_.size_b(e.b))) {
      for (std::uint32_t c = la.first_child(); c < la.first_child() + 2; ++c) {
        const Entry child{c, p_.enclose_a(c), e.b, e.enc_b};
        if (overlapping(child)) next(child);
        if (tester_.done()) return;
      }
    } else {
      for (std::uint32_t c = lb.first_child(); c < lb.first_child() + 2; ++c) {
        const Entry child{e.a, e.enc_a, c, p_.enclose_b(c)};
        if (overlapping(child)) next(child);
        if (tester_.done()) return;
      }
    }
  }

  void visit(std::uint32_t a, const EncA& enc_a, std::uint32_t b, const EncB& enc_b, int depth) {
    const NodeLink la = p_.link_a(a);
    const NodeLink lb = p_.link_b(b);
    if (depth == max_depth_ && !(la.is_leaf() && lb.is_leaf())) {
      tester_.volumes_hit();
      return;
    }
    if constexpr (HasDiameter<Policy>) {
      if (max_size_ > 0 && p_.small_pair(a, b, max_size_)) {
        tester_.volumes_hit();
        return;
      }
    }
    if (la.is_leaf() && lb.is_leaf()) {
      tester_.test_leaves(p_.slots_a() + la.first_slot(), la.count(),
                          p_.slots_b() + lb.first_slot(), lb.count());
      if (front_out_) front_out_->push_back({a, b, -1});
      if (hint_ && tester_.done()) {
        *hint_ = {a, b, true};
        hint_countdown_ = hint_levels_;
      }
      return;
    }
    const bool down_a = !la.is_leaf() && (lb.is_leaf() || p_.size_a(a) >= p_.size_b(b));
    if constexpr (HasNearness<Policy>) {
      if (nearer_first_) {
        const std::uint32_t c = down_a ? la.first_child() : lb.first_child();
        if (down_a) {
          visit_nearer_first(c, p_.enclose_a(c), b, enc_b, c + 1, p_.enclose_a(c + 1), b, enc_b,
                             depth + 1);
        } else {
          visit_nearer_first(a, enc_a, c, p_.enclose_b(c), a, enc_a, c + 1, p_.enclose_b(c + 1),
                             depth + 1);
        }
        if (tester_.done()) unwind(a, b);
        return;
      }
    }
    if (down_a) {
      for (std::uint32_t c = la.first_child(); c < la.first_child() + 2; ++c) {
        const EncA enc_c = p_.enclose_a(c);
        if (overlapping(c, enc_c, b, enc_b)) visit(c, enc_c, b, enc_b, depth + 1);
        if (tester_.done()) return unwind(a, b);
      }
    } else {
      for (std::uint32_t c = lb.first_child(); c < lb.first_child() + 2; ++c) {
        const EncB enc_c = p_.enclose_b(c);
        if (overlapping(a, enc_a, c, enc_c)) visit(a, enc_a, c, enc_c, depth + 1);
        if (tester_.done()) return unwind(a, b);
      }
    }
  }

  /// Tests two child pairs, then visits those that overlap, the nearer first.
  void visit_nearer_first(std::uint32_t a0, const EncA& ea0, std::uint32_t b0, const EncB& eb0,
                          std::uint32_t a1, const EncA& ea1, std::uint32_t b1, const EncB& eb1,
                          int depth) {
    const bool overlap0 = overlapping(a0, ea0, b0, eb0);
    const bool overlap1 = overlapping(a1, ea1, b1, eb1);
    if (overlap0 && overlap1 && p_.nearness(a1, ea1, b1, eb1) < p_.nearness(a0, ea0, b0, eb0)) {
      visit(a1, ea1, b1, eb1, depth);
      if (!tester_.done()) visit(a0, ea0, b0, eb0, depth);
      return;
    }
    if (overlap0) visit(a0, ea0, b0, eb0, depth);
    if (overlap1 && !tester_.done()) visit(a1, ea1, b1, eb1, depth);
  }

  /// On the way back up from a first hit: the hint climbs to (a, b) until it
  /// is hint_levels_ above the leaf pair.
  void unwind(std::uint32_t a, std::uint32_t b) {
    if (hint_ && hint_countdown_ > 0) {
      --hint_countdown_;
      *hint_ = {a, b, true};
    }
  }

  const Policy& p_;
  LeafTester& tester_;
  TraversalHint* hint_ = nullptr;
  std::vector<SeparationFront::Entry>* front_out_ = nullptr;
  int hint_levels_ = 0;
  int hint_countdown_ = 0;
  bool nearer_first_ = false;
  int max_depth_ = -1;  ///< negative: exact
  Real max_size_ = 0;   ///< 0: exact
};

/// Levels above the intersecting leaf pair a TraversalHint records.
inline constexpr int kHintLevels = 8;

/// Per-query state of a split PairTraversal query (see SplitTraversal).
template <typename Policy>
struct PolicyContext {
  using Entry = typename PairTraversal<Policy>::Entry;
  template <typename Tree>
  PolicyContext(const Transform& X_AB, const Tree& a, const Tree& b) : policy(a, b, X_AB) {}
  PairTraversal<Policy> make(LeafTester& tester) const {
    return PairTraversal<Policy>(policy, tester);
  }
  Policy policy;
};

/// A whole query over two trees of one policy type (the policy is built from
/// the trees and the pose): the traversal from the roots, or from the
/// request's SeparationFront where the policy keeps one; sorted result.
template <typename Policy, typename Tree>
CollideResult collide_with_policy(const Tree& a, const Tree& b, const Mesh& mesh_a,
                                  const Mesh& mesh_b, const Transform& X_AB,
                                  const CollideRequest& request) {
  CollideResult result;
  LeafTester tester(mesh_a, mesh_b, X_AB, request.all_pairs, result);
  const Policy policy(a, b, X_AB);
  PairTraversal<Policy> traversal(policy, tester);
  SeparationFront* front = nullptr;
  // A size cut stops a query at a hit, like a triangle pair does, and a
  // query that finds none is an exact one: hint and front work as usual.
  if constexpr (HasGap<Policy>) {
    if (request.max_depth < 0) front = request.front;
  }
  const bool from_front = front && front->valid && front->tree_a == &a && front->tree_b == &b &&
                          front->nodes_a == a.node_count() && front->nodes_b == b.node_count() &&
                          front->entries.size() <= 2 * front->root_entries;
  if (front) {
    front->scratch.clear();
    traversal.record_front(&front->scratch);
  }
  const auto whole = [&] {
    if constexpr (HasGap<Policy>) {
      if (from_front) return traversal.run_from_front(front->entries, b.reach(front->X_AB, X_AB));
    }
    traversal.run();
  };
  if (!request.all_pairs) {
    traversal.cut_at_size(request.max_size);
    // A front replays the order of the pose it was recorded at.
    if (request.nearer_first && !front) traversal.enter_nearer_first();
  }
  if (request.max_depth >= 0 && !request.all_pairs) {
    traversal.cut_at_depth(request.max_depth);
    traversal.run();
  } else if (request.hint && !request.all_pairs) {
    traversal.record_hint(request.hint, kHintLevels);
    traversal.run_hinted(*request.hint, a.node_count(), b.node_count(), whole);
  } else {
    whole();
  }
  if (front && !tester.done()) {  // the whole cut was visited
    front->entries.swap(front->scratch);
    front->X_AB = X_AB;
    front->tree_a = &a;
    front->tree_b = &b;
    front->nodes_a = a.node_count();
    front->nodes_b = b.node_count();
    if (!from_front) front->root_entries = front->entries.size();
    front->valid = true;
  }
  tester.finish();
  return result;
}

/// For policies whose test needs nothing cached on A's side.
struct NoEnclosure {};

/// The twelve separating axes after A's faces: B's face axes and the nine
/// edge-edge axes A_i x B_j (R: B's axes in A's frame, absR = |R|, T: B's
/// centre in A's frame). Returns the gap on the first axis that separates the
/// boxes (> 0), or 0 when none does. On an edge-edge axis, whose length is at
/// most 1, the gap is scaled by that length: never more than the true one.
inline Real boxes_gap_remaining_axes(const Mat3& R, const Mat3& absR, const Vec3& T, const Vec3& ea,
                                     const Vec3& eb, Real margin) {
  // B's face axes.
  for (int j = 0; j < 3; ++j) {
    const Real ra = absR(0, j) * ea[0] + absR(1, j) * ea[1] + absR(2, j) * ea[2];
    const Real t = R(0, j) * T[0] + R(1, j) * T[1] + R(2, j) * T[2];
    const Real gap = std::abs(t) - (ra + eb[j] + margin);
    if (gap > 0) return gap;
  }
  // Edge-edge axes A_i x B_j.
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const Real ra = ea[i1] * absR(i2, j) + ea[i2] * absR(i1, j);
      const Real rb = eb[j1] * absR(i, j2) + eb[j2] * absR(i, j1);
      const Real t = T[i2] * R(i1, j) - T[i1] * R(i2, j);
      const Real gap = std::abs(t) - (ra + rb + margin);
      if (gap > 0) return gap;
    }
  }
  return 0;
}

/// Separating-axis test of two boxes (Gottschalk et al., OBB-Tree, 15 axes):
/// box A with half extents ea in its own frame, box B with half extents eb,
/// axes the columns of R and centre T, both in A's frame. `margin` widens
/// every projected radius so that rounding never separates touching boxes.
/// (For finite or infinite numbers x - y > 0 exactly when x > y, so testing
/// the gap decides as comparing the two would; NaN separates nothing.)
inline bool boxes_overlap(const Mat3& R, const Vec3& T, const Vec3& ea, const Vec3& eb,
                          Real margin) {
  Mat3 absR;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) absR(i, j) = std::abs(R(i, j));
  }
  // A's face axes.
  for (int i = 0; i < 3; ++i) {
    const Real rb = absR(i, 0) * eb[0] + absR(i, 1) * eb[1] + absR(i, 2) * eb[2];
    if (std::abs(T[i]) - (ea[i] + rb + margin) > 0) return false;
  }
  return !(boxes_gap_remaining_axes(R, absR, T, ea, eb, margin) > 0);
}

}  // namespace dovetail::collision::detail
