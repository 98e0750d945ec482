#include "polygon/boxtree.h"

#include <algorithm>
#include <array>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>

#include "polygon/hierarchy_common.h"

namespace dovetail::collision {

namespace {

/// An axis-aligned box as [lo, hi] per axis; during traversal the same layout
/// holds a tree's box in its own frame or its enclosure in the other's.
struct Box {
  double lo[3];
  double hi[3];
};

double half_area(const Box& b) {
  const double x = b.hi[0] - b.lo[0], y = b.hi[1] - b.lo[1], z = b.hi[2] - b.lo[2];
  return x * y + y * z + z * x;
}

}  // namespace

class BoxtreeBuilder {
 public:
  BoxtreeBuilder(Boxtree& tree, const Mesh& mesh, const BoxtreeSettings& settings)
      : tree_(tree), settings_(settings), prims_(detail::build_triangles(mesh)) {
    if (settings.max_leaf_size < 1 || settings.max_leaf_size > 4) {
      throw std::invalid_argument("Boxtree: max_leaf_size must be 1..4");
    }
    if (prims_.size() > BoxtreeNode::kMaxIndex) {
      throw std::invalid_argument(mesh.source + ": too many triangles for a Boxtree");
    }
  }

  void build() {
    Box root = tight_bounds(0, prims_.size());
    for (int k = 0; k < 3; ++k) {
      tree_.root_lo_[k] = static_cast<float>(root.lo[k]);
      tree_.root_hi_[k] = static_cast<float>(root.hi[k]);
    }
    tree_.order_.resize(prims_.size());
    tree_.nodes_.reserve(prims_.size() * 2);
    tree_.nodes_.emplace_back();
    build_node(0, root, 0, prims_.size(), 1);
    tree_.nodes_.shrink_to_fit();
  }

 private:
  /// Bounds of prims [begin, end) rounded outwards to floats.
  Box tight_bounds(std::size_t begin, std::size_t end) const {
    Box b;
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = std::numeric_limits<double>::infinity();
      b.hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (std::size_t i = begin; i < end; ++i) {
      for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::min(b.lo[k], prims_[i].lo[k]);
        b.hi[k] = std::max(b.hi[k], prims_[i].hi[k]);
      }
    }
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = detail::round_down(b.lo[k]);
      b.hi[k] = detail::round_up(b.hi[k]);
    }
    return b;
  }

  std::uint32_t new_children(int count) {
    const auto first = static_cast<std::uint32_t>(tree_.nodes_.size());
    if (first + count > BoxtreeNode::kMaxIndex) throw std::length_error("Boxtree: too many nodes");
    tree_.nodes_.resize(tree_.nodes_.size() + count);
    return first;
  }

  void build_node(std::uint32_t node, Box box, std::size_t begin, std::size_t end,
                  std::size_t depth) {
    tree_.depth_ = std::max(tree_.depth_, depth);
    const std::size_t n = end - begin;
    if (n <= static_cast<std::size_t>(settings_.max_leaf_size)) {
      for (std::size_t i = begin; i < end; ++i) tree_.order_[i] = prims_[i].index;
      tree_.nodes_[node].bits = BoxtreeNode::kLeafAxis | static_cast<std::uint32_t>(n - 1) << 2 |
                                static_cast<std::uint32_t>(begin) << 4;
      ++tree_.leaves_;
      return;
    }

    // Split off the widest empty slab when it is a large part of the box.
    const Box tight = tight_bounds(begin, end);
    int slab_axis = -1;
    bool slab_high = false;
    double slab_gap = settings_.slab_threshold;
    for (int k = 0; k < 3; ++k) {
      const double extent = box.hi[k] - box.lo[k];
      if (extent <= 0) continue;
      const double gap_lo = (tight.lo[k] - box.lo[k]) / extent;
      const double gap_hi = (box.hi[k] - tight.hi[k]) / extent;
      if (gap_lo > slab_gap) slab_gap = gap_lo, slab_axis = k, slab_high = false;
      if (gap_hi > slab_gap) slab_gap = gap_hi, slab_axis = k, slab_high = true;
    }
    if (slab_axis >= 0) {
      const std::uint32_t child = new_children(1);
      BoxtreeNode& slab = tree_.nodes_[node];
      Box inner = box;
      if (slab_high) {
        slab.split_left = static_cast<float>(tight.hi[slab_axis]);
        slab.bits = slab_axis | BoxtreeNode::kLeftOnly << 2 | child << 4;
        inner.hi[slab_axis] = tight.hi[slab_axis];
      } else {
        slab.split_right = static_cast<float>(tight.lo[slab_axis]);
        slab.bits = slab_axis | BoxtreeNode::kRightOnly << 2 | child << 4;
        inner.lo[slab_axis] = tight.lo[slab_axis];
      }
      build_node(child, inner, begin, end, depth + 1);
      return;
    }

    const auto [axis, mid] = partition(box, begin, end, depth);
    const Box left_tight = tight_bounds(begin, mid);
    const Box right_tight = tight_bounds(mid, end);
    Box left = box, right = box;
    left.hi[axis] = std::min(box.hi[axis], left_tight.hi[axis]);
    right.lo[axis] = std::max(box.lo[axis], right_tight.lo[axis]);

    const std::uint32_t child = new_children(2);
    BoxtreeNode& inner = tree_.nodes_[node];
    inner.split_left = static_cast<float>(left.hi[axis]);
    inner.split_right = static_cast<float>(right.lo[axis]);
    inner.bits = static_cast<std::uint32_t>(axis) | BoxtreeNode::kBothChildren << 2 | child << 4;
    build_node(child, left, begin, mid, depth + 1);
    build_node(child + 1, right, mid, end, depth + 1);
  }

  /// Chooses axis and split by a binned surface-area cost of the two child
  /// boxes (each the parent box with one face moved) and partitions the prims;
  /// falls back to a median split when all centroids coincide or the tree grows deep.
  std::pair<int, std::size_t> partition(const Box& box, std::size_t begin, std::size_t end,
                                        std::size_t depth) {
    constexpr int kMaxBins = 32;
    const int bins = std::clamp(settings_.bins, 2, kMaxBins);
    Box centroids;
    for (int k = 0; k < 3; ++k) {
      centroids.lo[k] = std::numeric_limits<double>::infinity();
      centroids.hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (std::size_t i = begin; i < end; ++i) {
      for (int k = 0; k < 3; ++k) {
        centroids.lo[k] = std::min(centroids.lo[k], prims_[i].centroid[k]);
        centroids.hi[k] = std::max(centroids.hi[k], prims_[i].centroid[k]);
      }
    }

    int best_axis = -1, best_bin = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    constexpr std::size_t kMaxBalancedDepth = 48;
    if (depth < kMaxBalancedDepth) {
      for (int k = 0; k < 3; ++k) {
        const double extent = centroids.hi[k] - centroids.lo[k];
        if (!(extent > 0)) continue;
        const double scale = bins / extent;
        std::array<std::size_t, kMaxBins> count{};
        std::array<double, kMaxBins> bin_hi, bin_lo;
        bin_hi.fill(-std::numeric_limits<double>::infinity());
        bin_lo.fill(std::numeric_limits<double>::infinity());
        for (std::size_t i = begin; i < end; ++i) {
          const int b = std::min(
              bins - 1, static_cast<int>((prims_[i].centroid[k] - centroids.lo[k]) * scale));
          ++count[b];
          bin_hi[b] = std::max(bin_hi[b], prims_[i].hi[k]);
          bin_lo[b] = std::min(bin_lo[b], prims_[i].lo[k]);
        }
        std::array<double, kMaxBins> suffix_lo;
        std::array<std::size_t, kMaxBins> suffix_count;
        suffix_lo[bins - 1] = bin_lo[bins - 1];
        suffix_count[bins - 1] = count[bins - 1];
        for (int b = bins - 2; b >= 0; --b) {
          suffix_lo[b] = std::min(suffix_lo[b + 1], bin_lo[b]);
          suffix_count[b] = suffix_count[b + 1] + count[b];
        }
        double prefix_hi = -std::numeric_limits<double>::infinity();
        std::size_t prefix_count = 0;
        for (int b = 0; b + 1 < bins; ++b) {
          prefix_hi = std::max(prefix_hi, bin_hi[b]);
          prefix_count += count[b];
          if (prefix_count == 0 || suffix_count[b + 1] == 0) continue;
          Box left = box, right = box;
          left.hi[k] = std::min(box.hi[k], prefix_hi);
          right.lo[k] = std::max(box.lo[k], suffix_lo[b + 1]);
          const double cost =
              prefix_count * half_area(left) + suffix_count[b + 1] * half_area(right);
          if (cost < best_cost) best_cost = cost, best_axis = k, best_bin = b;
        }
      }
    }

    if (best_axis < 0) {
      // Median split along the box's longest axis.
      int axis = 0;
      for (int k = 1; k < 3; ++k) {
        if (box.hi[k] - box.lo[k] > box.hi[axis] - box.lo[axis]) axis = k;
      }
      const std::size_t mid = begin + (end - begin) / 2;
      std::nth_element(prims_.begin() + begin, prims_.begin() + mid, prims_.begin() + end,
                       [axis](const detail::BuildTriangle& x, const detail::BuildTriangle& y) {
                         return x.centroid[axis] < y.centroid[axis] ||
                                (x.centroid[axis] == y.centroid[axis] && x.index < y.index);
                       });
      return {axis, mid};
    }
    const double lo = centroids.lo[best_axis];
    const double scale = bins / (centroids.hi[best_axis] - centroids.lo[best_axis]);
    const auto split = std::partition(
        prims_.begin() + begin, prims_.begin() + end, [&](const detail::BuildTriangle& p) {
          return std::min(bins - 1, static_cast<int>((p.centroid[best_axis] - lo) * scale)) <=
                 best_bin;
        });
    return {best_axis, static_cast<std::size_t>(split - prims_.begin())};
  }

  Boxtree& tree_;
  const BoxtreeSettings& settings_;
  std::vector<detail::BuildTriangle> prims_;
};

Boxtree::Boxtree(const Mesh& mesh, const BoxtreeSettings& settings) {
  max_abs_ = detail::max_abs_coordinate(mesh);
  BoxtreeBuilder(*this, mesh, settings).build();
}

std::size_t Boxtree::bytes() const {
  return sizeof(*this) + nodes_.capacity() * sizeof(BoxtreeNode) +
         order_.capacity() * sizeof(std::uint32_t);
}

/// Simultaneous traversal of two boxtrees.
class BoxtreeTraversal {
 public:
  BoxtreeTraversal(const Boxtree& a, const Boxtree& b, const Transform& X_AB,
                   detail::LeafTester& tester)
      : a_(a),
        b_(b),
        R_AB_(X_AB.R),
        R_BA_(X_AB.R.transpose()),
        split_AB_(R_AB_),
        split_BA_(R_BA_),
        tester_(tester) {
    t_AB_ = X_AB.t;
    t_BA_ = -(R_BA_ * X_AB.t);
    margin_ = detail::query_margin(a.max_abs_, b.max_abs_, X_AB);
  }

  /// One tree's current node: its box in its own frame and the enclosure of
  /// that box in the other tree's frame.
  struct Side {
    Box box;
    Box enc;
    std::uint32_t node;
  };
  /// A pair of overlapping nodes.
  struct Entry {
    Side a;
    Side b;
  };

  void run() {
    const Entry e = root_entry();
    if (roots_overlap(e)) visit(e.a, e.b);
  }

  /// Overlapping node pairs breadth-first from the roots, until there are at
  /// least `target` or only leaf pairs remain.
  std::vector<Entry> frontier(std::size_t target) {
    std::deque<Entry> queue;
    const Entry root = root_entry();
    if (roots_overlap(root)) queue.push_back(root);
    for (std::size_t leaf_pairs = 0; queue.size() < target && leaf_pairs < queue.size();) {
      const Entry e = queue.front();
      queue.pop_front();
      const BoxtreeNode& na = a_.nodes_[e.a.node];
      const BoxtreeNode& nb = b_.nodes_[e.b.node];
      if (na.is_leaf() && nb.is_leaf()) {
        queue.push_back(e);
        ++leaf_pairs;
        continue;
      }
      leaf_pairs = 0;
      if (descends_a(na, nb, e.a, e.b)) {
        descend(na, e.a, split_BA_, e.b, [&](const Side& child) { queue.push_back({child, e.b}); });
      } else {
        descend(nb, e.b, split_AB_, e.a, [&](const Side& child) { queue.push_back({e.a, child}); });
      }
    }
    return {queue.begin(), queue.end()};
  }

  void run_from(const Entry& e) { visit(e.a, e.b); }

 private:
  Entry root_entry() const { return {root(a_, R_BA_, t_BA_), root(b_, R_AB_, t_AB_)}; }

  bool roots_overlap(const Entry& e) const {
    tester_.count_volume_test();
    for (int k = 0; k < 3; ++k) {
      if (!overlap(e.a.box, e.b.enc, k) || !overlap(e.b.box, e.a.enc, k)) return false;
    }
    return true;
  }

  static bool descends_a(const BoxtreeNode& na, const BoxtreeNode& nb, const Side& a,
                         const Side& b) {
    return !na.is_leaf() && (nb.is_leaf() || size(a.box) >= size(b.box));
  }

  static Side root(const Boxtree& tree, const Mat3& M, const Vec3& t) {
    Side s;
    s.node = 0;
    for (int k = 0; k < 3; ++k) {
      s.box.lo[k] = tree.root_lo_[k];
      s.box.hi[k] = tree.root_hi_[k];
    }
    for (int i = 0; i < 3; ++i) {
      s.enc.lo[i] = s.enc.hi[i] = t[i];
      for (int j = 0; j < 3; ++j) {
        const double u = M(i, j) * s.box.lo[j], v = M(i, j) * s.box.hi[j];
        s.enc.lo[i] += std::min(u, v);
        s.enc.hi[i] += std::max(u, v);
      }
    }
    return s;
  }

  bool overlap(const Box& x, const Box& y, int k) const {
    return x.lo[k] <= y.hi[k] + margin_ && y.lo[k] - margin_ <= x.hi[k];
  }

  /// The rotation from one tree's frame to the other's, split into its
  /// positive and negative parts so that moving a face updates the enclosure
  /// without branches.
  struct SplitRotation {
    double pos[3][3];  ///< pos[axis][i] = max(M(i, axis), 0)
    double neg[3][3];  ///< neg[axis][i] = min(M(i, axis), 0)
    explicit SplitRotation(const Mat3& M) {
      for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < 3; ++i) {
          pos[k][i] = std::max(M(i, k), 0.0);
          neg[k][i] = std::min(M(i, k), 0.0);
        }
      }
    }
  };

  /// The child of `s` whose upper face on `axis` moved down to `split`: the
  /// enclosure's upper bounds drop where the axis maps positively, its lower
  /// bounds where negatively. Every value is computed from the parent's, none
  /// read back from the child being written (a partial store followed by a
  /// wide load of the same bytes would stall).
  static void move_upper(Side& child, const Side& s, int axis, double split,
                         const SplitRotation& M) {
    const double d = s.box.hi[axis] - split;
    child.box = s.box;
    child.box.hi[axis] = split;
    for (int i = 0; i < 3; ++i) {
      child.enc.hi[i] = s.enc.hi[i] - M.pos[axis][i] * d;
      child.enc.lo[i] = s.enc.lo[i] - M.neg[axis][i] * d;
    }
  }

  static void move_lower(Side& child, const Side& s, int axis, double split,
                         const SplitRotation& M) {
    const double d = split - s.box.lo[axis];
    child.box = s.box;
    child.box.lo[axis] = split;
    for (int i = 0; i < 3; ++i) {
      child.enc.lo[i] = s.enc.lo[i] + M.pos[axis][i] * d;
      child.enc.hi[i] = s.enc.hi[i] + M.neg[axis][i] * d;
    }
  }

  /// After `child` moved one face on `axis`: its own box needs only that face
  /// compared with the other's enclosure; its enclosure moved on all axes.
  bool child_overlaps(const Side& child, bool upper, double split, int axis,
                      const Side& other) const {
    tester_.count_volume_test();
    if (upper ? split < other.enc.lo[axis] - margin_ : split > other.enc.hi[axis] + margin_) {
      return false;
    }
    return overlap(other.box, child.enc, 0) && overlap(other.box, child.enc, 1) &&
           overlap(other.box, child.enc, 2);
  }

  static double size(const Box& b) {
    return (b.hi[0] - b.lo[0]) + (b.hi[1] - b.lo[1]) + (b.hi[2] - b.lo[2]);
  }

  void visit(const Side& a, const Side& b) {
    const BoxtreeNode& na = a_.nodes_[a.node];
    const BoxtreeNode& nb = b_.nodes_[b.node];
    if (na.is_leaf() && nb.is_leaf()) {
      tester_.test_leaves(&a_.order_[na.index()], na.leaf_count(), &b_.order_[nb.index()],
                          nb.leaf_count());
      return;
    }
    if (descends_a(na, nb, a, b)) {
      descend(na, a, split_BA_, b, [&](const Side& child) { visit(child, b); });
    } else {
      descend(nb, b, split_AB_, a, [&](const Side& child) { visit(a, child); });
    }
  }

  template <typename Visit>
  void descend(const BoxtreeNode& n, const Side& s, const SplitRotation& M, const Side& other,
               Visit&& next) {
    const int axis = static_cast<int>(n.axis());
    const std::uint32_t kind = n.kind();
    std::uint32_t child = n.index();
    if (kind != BoxtreeNode::kRightOnly) {
      Side left;
      left.node = child++;
      const double split = n.split_left;
      move_upper(left, s, axis, split, M);
      if (child_overlaps(left, true, split, axis, other)) next(left);
      if (tester_.done()) return;
    }
    if (kind != BoxtreeNode::kLeftOnly) {
      Side right;
      right.node = child;
      const double split = n.split_right;
      move_lower(right, s, axis, split, M);
      if (child_overlaps(right, false, split, axis, other)) next(right);
    }
  }

  const Boxtree& a_;
  const Boxtree& b_;
  Mat3 R_AB_, R_BA_;
  SplitRotation split_AB_, split_BA_;
  Vec3 t_AB_, t_BA_;
  double margin_ = 0;
  detail::LeafTester& tester_;
};

namespace {

/// Per-query state of a split boxtree query (see SplitTraversal).
struct BoxtreeContext {
  using Entry = BoxtreeTraversal::Entry;
  BoxtreeContext(const Transform& X_AB, const Boxtree& a, const Boxtree& b)
      : X(X_AB), tree_a(a), tree_b(b) {}
  BoxtreeTraversal make(detail::LeafTester& tester) const {
    return BoxtreeTraversal(tree_a, tree_b, X, tester);
  }
  const Transform& X;
  const Boxtree& tree_a;
  const Boxtree& tree_b;
};

}  // namespace

std::unique_ptr<SplitQuery> Boxtree::split(const Mesh& mesh_a, const Boxtree& b, const Mesh& mesh_b,
                                           const Transform& X_AB,
                                           const CollideRequest& request) const {
  return std::make_unique<detail::SplitTraversal<BoxtreeContext>>(mesh_a, mesh_b, X_AB, request,
                                                                  *this, b);
}

CollideResult Boxtree::collide(const Mesh& mesh_a, const Boxtree& b, const Mesh& mesh_b,
                               const Transform& X_AB, const CollideRequest& request) const {
  CollideResult result;
  detail::LeafTester tester(mesh_a, mesh_b, X_AB, request.all_pairs, result);
  BoxtreeTraversal(*this, b, X_AB, tester).run();
  tester.finish();
  return result;
}

}  // namespace dovetail::collision
