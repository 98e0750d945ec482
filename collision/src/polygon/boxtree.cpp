#include "polygon/boxtree.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>

#include "polygon/box_fit.h"
#include "polygon/hierarchy_common.h"
#include "polygon/principal_axes.h"

namespace dovetail::collision {

namespace {

/// A frame's quaternion parts in 16-bit fixed point.
constexpr Real kQuaternionScale = 32767;

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
      : tree_(tree), mesh_(mesh), settings_(settings), prims_(detail::build_triangles(mesh)) {
    if (settings.max_leaf_size < 1 || settings.max_leaf_size > 4) {
      throw std::invalid_argument("Boxtree: max_leaf_size must be 1..4");
    }
    if (settings.frame_step < 2) throw std::invalid_argument("Boxtree: frame_step must be >= 2");
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
    tree_.order_.reserve(prims_.size() / 2);
    tree_.nodes_.reserve(prims_.size() * 2);
    tree_.nodes_.emplace_back();
    build_node(0, root, 0, prims_.size(), 1);
    tree_.nodes_.shrink_to_fit();
    tree_.order_.shrink_to_fit();
    tree_.frames_.shrink_to_fit();
  }

 private:
  /// Bounds of prims [begin, end) rounded outwards to floats.
  Box tight_bounds(std::size_t begin, std::size_t end) const {
    return tight_bounds(prims_.data() + begin, prims_.data() + end);
  }

  static Box tight_bounds(const detail::BuildTriangle* begin, const detail::BuildTriangle* end) {
    Box b;
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = std::numeric_limits<double>::infinity();
      b.hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (const detail::BuildTriangle* p = begin; p != end; ++p) {
      for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::min(b.lo[k], p->lo[k]);
        b.hi[k] = std::max(b.hi[k], p->hi[k]);
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
      BoxtreeNode& leaf = tree_.nodes_[node];
      for (std::size_t i = 0; i < n && i < 2; ++i) leaf.word[i] = prims_[begin + i].index;
      const auto rest = static_cast<std::uint32_t>(tree_.order_.size());
      if (rest > BoxtreeNode::kMaxIndex) throw std::length_error("Boxtree: too many triangles");
      for (std::size_t i = begin + 2; i < end; ++i) tree_.order_.push_back(prims_[i].index);
      leaf.bits = BoxtreeNode::kLeafAxis | static_cast<std::uint32_t>(n - 1) << 2 | rest << 4;
      ++tree_.leaves_;
      return;
    }
    if (n <= frame_limit_ && n >= static_cast<std::size_t>(settings_.frame_min_triangles)) {
      // Tried here; next in subtrees frame_step times smaller.
      const std::size_t limit = frame_limit_;
      frame_limit_ = n / static_cast<std::size_t>(settings_.frame_step);
      if (!frame_node(node, begin, end, depth)) split_node(node, box, begin, end, depth);
      frame_limit_ = limit;
      return;
    }
    split_node(node, box, begin, end, depth);
  }

  /// An inner node: an empty slab split off, or two children.
  void split_node(std::uint32_t node, const Box& box, std::size_t begin, std::size_t end,
                  std::size_t depth) {
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
        slab.word[0] = std::bit_cast<std::uint32_t>(static_cast<float>(tight.hi[slab_axis]));
        slab.bits = slab_axis | BoxtreeNode::kLeftOnly << 2 | child << 4;
        inner.hi[slab_axis] = tight.hi[slab_axis];
      } else {
        slab.word[1] = std::bit_cast<std::uint32_t>(static_cast<float>(tight.lo[slab_axis]));
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
    inner.word[0] = std::bit_cast<std::uint32_t>(static_cast<float>(left.hi[axis]));
    inner.word[1] = std::bit_cast<std::uint32_t>(static_cast<float>(right.lo[axis]));
    inner.bits = static_cast<std::uint32_t>(axis) | BoxtreeNode::kBothChildren << 2 | child << 4;
    build_node(child, left, begin, mid, depth + 1);
    build_node(child + 1, right, mid, end, depth + 1);
  }

  static double box_cost(const Box& b) {
    return detail::box_search_cost(Vec3(b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]));
  }

  /// Gives prims [begin, end) a frame of their own, their principal axes
  /// turned by the frame search, when their box in it is enough smaller: `node` becomes a frame
  /// node and its child's subtree is built in the new frame. Returns false (prims unchanged)
  /// otherwise.
  bool frame_node(std::uint32_t node, std::size_t begin, std::size_t end, std::size_t depth) {
    detail::Moments moments;
    for (std::size_t i = begin; i < end; ++i) {
      const TriangleIndices& t = mesh_.triangles[prims_[i].index];
      moments.add(detail::triangle_moments(mesh_.vertices[t[0]], mesh_.vertices[t[1]],
                                           mesh_.vertices[t[2]]));
    }
    BoxtreeNode head;
    const Eigen::Quaternion<Real> q(searched(detail::covariance_axes(moments), begin, end));
    const Real parts[4] = {q.w(), q.x(), q.y(), q.z()};
    for (int k = 0; k < 4; ++k) {
      const auto fixed = static_cast<std::int16_t>(std::lround(parts[k] * kQuaternionScale));
      head.word[k / 2] |= static_cast<std::uint32_t>(static_cast<std::uint16_t>(fixed))
                          << (16 * (k % 2));
    }
    const Mat3 to_frame = head.rotation().transpose();

    local_.assign(prims_.begin() + begin, prims_.begin() + end);
    for (detail::BuildTriangle& p : local_) {
      const TriangleIndices& t = mesh_.triangles[p.index];
      const Vec3 a = to_frame * mesh_.vertices[t[0]];
      const Vec3 b = to_frame * mesh_.vertices[t[1]];
      const Vec3 c = to_frame * mesh_.vertices[t[2]];
      p.lo = a.cwiseMin(b).cwiseMin(c);
      p.hi = a.cwiseMax(b).cwiseMax(c);
      p.centroid = (a + b + c) / 3.0;
    }
    const Box frame_box = tight_bounds(local_.data(), local_.data() + local_.size());
    if (!(box_cost(frame_box) < settings_.frame_gain * box_cost(tight_bounds(begin, end)))) {
      return false;
    }
    std::copy(local_.begin(), local_.end(), prims_.begin() + begin);
    if (tree_.frames_.size() > BoxtreeNode::kMaxIndex) {
      throw std::length_error("Boxtree: too many frames");
    }
    const std::uint32_t child = new_children(1);
    BoxtreeFrame frame;
    for (int k = 0; k < 3; ++k) {
      frame.lo[k] = static_cast<float>(frame_box.lo[k]);
      frame.hi[k] = static_cast<float>(frame_box.hi[k]);
    }
    frame.child = child;
    const auto index = static_cast<std::uint32_t>(tree_.frames_.size());
    tree_.frames_.push_back(frame);
    head.bits = BoxtreeNode::kFrame << 2 | index << 4;
    tree_.nodes_[node] = head;
    build_node(child, frame_box, begin, end, depth + 1);
    return true;
  }

  /// The frame search of the OBB tree (box_fit.h) from `start`, on the
  /// subtree's extreme vertices along the 26-DOP's directions.
  Mat3 searched(const Mat3& start, std::size_t begin, std::size_t end) {
    constexpr std::size_t kCount = detail::kBoxSearchDirections.size();
    std::array<Real, kCount> lo, hi;
    std::array<std::uint32_t, kCount> lowest{}, highest{};
    lo.fill(std::numeric_limits<Real>::infinity());
    hi.fill(-std::numeric_limits<Real>::infinity());
    if (seen_.empty()) seen_.assign(mesh_.vertices.size(), 0);
    ++stamp_;
    for (std::size_t i = begin; i < end; ++i) {
      for (std::uint32_t v : mesh_.triangles[prims_[i].index]) {
        if (seen_[v] == stamp_) continue;
        seen_[v] = stamp_;
        for (std::size_t d = 0; d < kCount; ++d) {
          const Real x = detail::kBoxSearchDirections[d].dot(mesh_.vertices[v]);
          if (x < lo[d]) lo[d] = x, lowest[d] = v;
          if (x > hi[d]) hi[d] = x, highest[d] = v;
        }
      }
    }
    support_.clear();
    for (std::size_t d = 0; d < kCount; ++d) {
      for (std::uint32_t v : {lowest[d], highest[d]}) {
        if (std::find(support_.begin(), support_.end(), v) == support_.end()) support_.push_back(v);
      }
    }
    const std::array<Mat3, 1> others = {Mat3::Identity()};
    return detail::search_box_frame(mesh_, start, others, support_);
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
  const Mesh& mesh_;
  const BoxtreeSettings& settings_;
  std::vector<detail::BuildTriangle> prims_;
  std::vector<detail::BuildTriangle> local_;
  std::vector<std::uint32_t> support_;
  std::vector<std::uint32_t> seen_;  ///< per vertex: the stamp of the last search that saw it
  std::uint32_t stamp_ = 0;
  /// A subtree of at most this many triangles is tried for a frame next.
  std::size_t frame_limit_ = settings_.frames ? std::numeric_limits<std::size_t>::max() : 0;
};

Mat3 BoxtreeNode::rotation() const {
  Real q[4];
  for (int k = 0; k < 4; ++k) {
    q[k] = static_cast<std::int16_t>(static_cast<std::uint16_t>(word[k / 2] >> (16 * (k % 2))));
  }
  const Real w = q[0], x = q[1], y = q[2], z = q[3];
  const Real s = 2 / (w * w + x * x + y * y + z * z);
  Mat3 R;
  R << 1 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y),  //
      s * (x * y + w * z), 1 - s * (x * x + z * z), s * (y * z - w * x),   //
      s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x * x + y * y);
  return R;
}

Boxtree::Boxtree(const Mesh& mesh, const BoxtreeSettings& settings) {
  max_abs_ = detail::max_abs_coordinate(mesh);
  BoxtreeBuilder(*this, mesh, settings).build();
}

std::size_t Boxtree::bytes() const {
  return sizeof(*this) + nodes_.capacity() * sizeof(BoxtreeNode) +
         order_.capacity() * sizeof(std::uint32_t) + frames_.capacity() * sizeof(BoxtreeFrame);
}

/// Simultaneous traversal of two boxtrees.
class BoxtreeTraversal {
 public:
  BoxtreeTraversal(const Boxtree& a, const Boxtree& b, const Transform& X_AB,
                   detail::LeafTester& tester)
      : a_(a), b_(b), X_AB_(X_AB), root_pose_(pose(0, 0)), tester_(tester) {
    margin_ = detail::query_margin(a.max_abs_, b.max_abs_, X_AB);
    // Subtree frames are rotations rounded to doubles: widen the margin by
    // the size of the rounding in expressing a box in another frame.
    margin_ += 0x1.0p-40 * (a.max_abs_ + b.max_abs_);
  }

  /// One tree's current node: its box in its own frame (0: the mesh's, k:
  /// the frame of the tree's node k - 1, a frame node) and the enclosure of
  /// that box in the other tree's current frame.
  struct Side {
    Box box;
    Box enc;
    std::uint32_t node;
    std::uint32_t frame;
  };
  /// A pair of overlapping nodes.
  struct Entry {
    Side a;
    Side b;
  };

  void run() {
    const Entry e = root_entry();
    if (full_overlap(e.a, e.b)) visit(e.a, e.b, root_pose_);
  }

  /// Overlapping node pairs breadth-first from the roots, until there are at
  /// least `target` or only leaf pairs remain.
  std::vector<Entry> frontier(std::size_t target) {
    std::deque<Entry> queue;
    const Entry root = root_entry();
    if (full_overlap(root.a, root.b)) queue.push_back(root);
    for (std::size_t leaf_pairs = 0; queue.size() < target && leaf_pairs < queue.size();) {
      const Entry e = queue.front();
      queue.pop_front();
      if (a_.nodes_[e.a.node].is_leaf() && b_.nodes_[e.b.node].is_leaf()) {
        queue.push_back(e);
        ++leaf_pairs;
        continue;
      }
      leaf_pairs = 0;
      expand(e.a, e.b, pose(e.a.frame, e.b.frame), [&](const Side& a, const Side& b, const Pose&) {
        queue.push_back({a, b});
      });
    }
    return {queue.begin(), queue.end()};
  }

  void run_from(const Entry& e) { visit(e.a, e.b, pose(e.a.frame, e.b.frame)); }

 private:
  /// A rotation by column (col[k]: axis k in the other frame), and each
  /// column's positive and negative parts, so that moving a face updates an
  /// enclosure without branches.
  struct Columns {
    double col[3][3], pos[3][3], neg[3][3];
    explicit Columns(const Mat3& M) {
      for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < 3; ++i) {
          col[k][i] = M(i, k);
          pos[k][i] = std::max(M(i, k), 0.0);
          neg[k][i] = std::min(M(i, k), 0.0);
        }
      }
    }
  };

  /// The pose between the two trees' current frames: ab holds B's axes in
  /// A's frame, ba A's in B's.
  struct Pose {
    Columns ab, ba;
    Vec3 t_AB, t_BA;
    Pose(const Mat3& R, const Vec3& t)
        : ab(R), ba(R.transpose()), t_AB(t), t_BA(-(R.transpose() * t)) {}
  };

  Pose pose(std::uint32_t frame_a, std::uint32_t frame_b) const {
    if (frame_a == 0 && frame_b == 0) return Pose(X_AB_.R, X_AB_.t);
    if (frame_b == 0) {
      const Mat3 to_a = a_.nodes_[frame_a - 1].rotation().transpose();
      return Pose(to_a * X_AB_.R, to_a * X_AB_.t);
    }
    const Mat3 R_b = X_AB_.R * b_.nodes_[frame_b - 1].rotation();
    if (frame_a == 0) return Pose(R_b, X_AB_.t);
    const Mat3 to_a = a_.nodes_[frame_a - 1].rotation().transpose();
    return Pose(to_a * R_b, to_a * X_AB_.t);
  }

  Entry root_entry() const {
    Entry e;
    e.a = root(a_);
    e.b = root(b_);
    e.a.enc = enclose(e.a.box, root_pose_.ba, root_pose_.t_BA);
    e.b.enc = enclose(e.b.box, root_pose_.ab, root_pose_.t_AB);
    return e;
  }

  static Side root(const Boxtree& tree) {
    Side s;
    s.node = 0;
    s.frame = 0;
    for (int k = 0; k < 3; ++k) {
      s.box.lo[k] = tree.root_lo_[k];
      s.box.hi[k] = tree.root_hi_[k];
    }
    return s;
  }

  /// The box `box` maps into by x -> M x + t, as a box (M by column).
  static Box enclose(const Box& box, const Columns& M, const Vec3& t) {
    Box enc;
    for (int i = 0; i < 3; ++i) {
      enc.lo[i] = enc.hi[i] = t[i];
      for (int j = 0; j < 3; ++j) {
        const double u = M.col[j][i] * box.lo[j], v = M.col[j][i] * box.hi[j];
        enc.lo[i] += std::min(u, v);
        enc.hi[i] += std::max(u, v);
      }
    }
    return enc;
  }

  /// Both boxes against the other's enclosure on every axis.
  bool full_overlap(const Side& a, const Side& b) const {
    tester_.count_volume_test();
    for (int k = 0; k < 3; ++k) {
      if (!overlap(a.box, b.enc, k) || !overlap(b.box, a.enc, k)) return false;
    }
    return true;
  }

  static bool descends_a(const BoxtreeNode& na, const BoxtreeNode& nb, const Side& a,
                         const Side& b) {
    return !na.is_leaf() && (nb.is_leaf() || size(a.box) >= size(b.box));
  }

  bool overlap(const Box& x, const Box& y, int k) const {
    return x.lo[k] <= y.hi[k] + margin_ && y.lo[k] - margin_ <= x.hi[k];
  }

  /// The child of `s` whose upper face on `axis` moved down to `split`: the
  /// enclosure's upper bounds drop where the axis maps positively, its lower
  /// bounds where negatively. Every value is computed from the parent's, none
  /// read back from the child being written (a partial store followed by a
  /// wide load of the same bytes would stall).
  static void move_upper(Side& child, const Side& s, int axis, double split, const Columns& M) {
    const double d = s.box.hi[axis] - split;
    child.box = s.box;
    child.box.hi[axis] = split;
    for (int i = 0; i < 3; ++i) {
      child.enc.hi[i] = s.enc.hi[i] - M.pos[axis][i] * d;
      child.enc.lo[i] = s.enc.lo[i] - M.neg[axis][i] * d;
    }
  }

  static void move_lower(Side& child, const Side& s, int axis, double split, const Columns& M) {
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

  void visit(const Side& a, const Side& b, const Pose& p) {
    const BoxtreeNode& na = a_.nodes_[a.node];
    const BoxtreeNode& nb = b_.nodes_[b.node];
    if (na.is_leaf() && nb.is_leaf()) {
      std::uint32_t tris_a[4], tris_b[4];
      leaf_triangles(a_, na, tris_a);
      leaf_triangles(b_, nb, tris_b);
      tester_.test_leaves(tris_a, na.leaf_count(), tris_b, nb.leaf_count());
      return;
    }
    expand(a, b, p, [&](const Side& a2, const Side& b2, const Pose& p2) { visit(a2, b2, p2); });
  }

  /// Calls next(a', b', pose') for each overlapping pair one step below
  /// (a, b): a frame node's child in its frame (both enclosures recomputed),
  /// or the children of the node descended.
  template <typename Next>
  void expand(const Side& a, const Side& b, const Pose& p, Next&& next) {
    const BoxtreeNode& na = a_.nodes_[a.node];
    const BoxtreeNode& nb = b_.nodes_[b.node];
    if (na.is_frame() || nb.is_frame()) {
      Side a2 = a, b2 = b;
      if (na.is_frame()) enter_frame(a_, a.node, a2);
      if (nb.is_frame()) enter_frame(b_, b.node, b2);
      const Pose p2 = pose(a2.frame, b2.frame);
      a2.enc = enclose(a2.box, p2.ba, p2.t_BA);
      b2.enc = enclose(b2.box, p2.ab, p2.t_AB);
      if (full_overlap(a2, b2)) next(a2, b2, p2);
      return;
    }
    if (descends_a(na, nb, a, b)) {
      descend(na, a, p.ba, b, [&](const Side& child) { next(child, b, p); });
    } else {
      descend(nb, b, p.ab, a, [&](const Side& child) { next(a, child, p); });
    }
  }

  static void leaf_triangles(const Boxtree& tree, const BoxtreeNode& n, std::uint32_t* out) {
    out[0] = n.word[0];
    out[1] = n.word[1];
    for (int k = 2; k < n.leaf_count(); ++k) out[k] = tree.order_[n.index() + k - 2];
  }

  static void enter_frame(const Boxtree& tree, std::uint32_t node, Side& s) {
    const BoxtreeFrame& f = tree.frames_[tree.nodes_[node].index()];
    s.node = f.child;
    s.frame = node + 1;
    for (int k = 0; k < 3; ++k) {
      s.box.lo[k] = f.lo[k];
      s.box.hi[k] = f.hi[k];
    }
  }

  template <typename Visit>
  void descend(const BoxtreeNode& n, const Side& s, const Columns& M, const Side& other,
               Visit&& next) {
    const int axis = static_cast<int>(n.axis());
    const std::uint32_t kind = n.kind();
    std::uint32_t child = n.index();
    if (kind != BoxtreeNode::kRightOnly) {
      Side left;
      left.node = child++;
      left.frame = s.frame;
      const double split = n.split_left();
      move_upper(left, s, axis, split, M);
      if (child_overlaps(left, true, split, axis, other)) next(left);
      if (tester_.done()) return;
    }
    if (kind != BoxtreeNode::kLeftOnly) {
      Side right;
      right.node = child;
      right.frame = s.frame;
      const double split = n.split_right();
      move_lower(right, s, axis, split, M);
      if (child_overlaps(right, false, split, axis, other)) next(right);
    }
  }

  const Boxtree& a_;
  const Boxtree& b_;
  const Transform& X_AB_;
  const Pose root_pose_;
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
