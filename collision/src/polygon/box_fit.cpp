#include "polygon/box_fit.h"

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>

#include "polygon/principal_axes.h"

namespace dovetail::collision::detail {

namespace {

/// A node's support holds at most this many vertices; its array has room
/// for two children's before they are reduced to their extremes.
constexpr int kSupportMax =
    2 * static_cast<int>(std::tuple_size_v<std::remove_cv_t<decltype(kBoxSearchDirections)>>);
// A leaf's vertices (up to three per triangle) fit without a reduction.
static_assert(3 * ((1 << NodeLink::kCountBits) - 1) <= kSupportMax);
// A node that is searched is no leaf: it has children whose frames to try.
static_assert(kBoxSearchMinTriangles > (1 << NodeLink::kCountBits) - 1);

/// Vertex indices that stand for a node in the search: all of a small
/// node's vertices, or a large node's extremes along kBoxSearchDirections. Either
/// way the search's box in the mesh's frame is the node's own.
struct Support {
  std::array<std::uint32_t, 2 * kSupportMax> vertex{};
  int count = 0;
};

class BoxFitter {
 public:
  BoxFitter(const BinaryLayout& layout, const Mesh& mesh, std::vector<FittedBox>& boxes)
      : layout_(layout), mesh_(mesh), boxes_(boxes), moments_(node_moments(layout, mesh)) {}

  /// Fits the boxes of `node` and its subtree (children first); returns the
  /// node's support.
  Support fit(std::uint32_t node) {
    const LayoutNode& n = layout_.nodes[node];
    Support s;
    if (n.is_leaf()) {
      for (std::uint32_t slot = n.begin; slot < n.end; ++slot) {
        for (std::uint32_t v : mesh_.triangles[layout_.triangles[slot].index]) add_unique(s, v);
      }
    } else {
      const Support left = fit(n.first_child);
      const Support right = fit(n.first_child + 1);
      for (int k = 0; k < left.count; ++k) s.vertex[s.count++] = left.vertex[k];
      for (int k = 0; k < right.count; ++k) s.vertex[s.count++] = right.vertex[k];
      if (s.count > kSupportMax) s = extremes(s);
    }
    const auto count = static_cast<int>(n.end - n.begin);
    const Mat3 start = count == 1 ? triangle_axes(mesh_, layout_.triangles[n.begin].index)
                                  : covariance_axes(moments_[node]);
    if (count < kBoxSearchMinTriangles) {
      boxes_[node] = boxes_in(std::array{start}, n)[0];
    } else {
      // The support can miss a vertex that a turned frame brings to the
      // fore: the searched box is kept only if, on all the node's vertices,
      // it is smaller than the starting one.
      const std::array<FittedBox, 2> fitted = boxes_in(std::array{start, search(start, n, s)}, n);
      const bool searched_smaller = box_search_cost(fitted[1].hi - fitted[1].lo) <
                                    box_search_cost(fitted[0].hi - fitted[0].lo);
      boxes_[node] = fitted[searched_smaller ? 1 : 0];
    }
    return s;
  }

 private:
  static void add_unique(Support& s, std::uint32_t v) {
    for (int k = 0; k < s.count; ++k)
      if (s.vertex[k] == v) return;
    s.vertex[s.count++] = v;
  }

  /// The extreme vertices of `s` along each direction, both ways.
  Support extremes(const Support& s) const {
    Support out;
    for (const Vec3& d : kBoxSearchDirections) {
      int lo = 0, hi = 0;
      Real min = std::numeric_limits<Real>::infinity(), max = -min;
      for (int k = 0; k < s.count; ++k) {
        const Real x = d.dot(mesh_.vertices[s.vertex[k]]);
        if (x < min) min = x, lo = k;
        if (x > max) max = x, hi = k;
      }
      add_unique(out, s.vertex[lo]);
      add_unique(out, s.vertex[hi]);
    }
    return out;
  }

  /// The boxes with the given frames around all the node's vertices, in one
  /// pass over them.
  template <std::size_t N>
  std::array<FittedBox, N> boxes_in(const std::array<Mat3, N>& frames, const LayoutNode& n) const {
    std::array<FittedBox, N> box;
    std::array<Mat3, N> to_box;
    for (std::size_t f = 0; f < N; ++f) {
      box[f] = {frames[f], Vec3::Constant(std::numeric_limits<Real>::infinity()),
                Vec3::Constant(-std::numeric_limits<Real>::infinity())};
      to_box[f] = frames[f].transpose();
    }
    for (std::uint32_t slot = n.begin; slot < n.end; ++slot) {
      for (std::uint32_t v : mesh_.triangles[layout_.triangles[slot].index]) {
        for (std::size_t f = 0; f < N; ++f) {
          const Vec3 p = to_box[f] * mesh_.vertices[v];
          box[f].lo = box[f].lo.cwiseMin(p);
          box[f].hi = box[f].hi.cwiseMax(p);
        }
      }
    }
    return box;
  }

  /// The frame `start` turned while that shrinks the box of the support.
  Mat3 search(const Mat3& start, const LayoutNode& n, const Support& s) const {
    const std::array<Mat3, 3> others = {Mat3::Identity(), boxes_[n.first_child].axes,
                                        boxes_[n.first_child + 1].axes};
    return search_box_frame(mesh_, start, others,
                            std::span<const std::uint32_t>(s.vertex.data(), s.count));
  }

  const BinaryLayout& layout_;
  const Mesh& mesh_;
  std::vector<FittedBox>& boxes_;
  std::vector<Moments> moments_;
};

}  // namespace

const std::array<Vec3, 13> kBoxSearchDirections = {
    Vec3(1, 0, 0),  Vec3(0, 1, 0),  Vec3(0, 0, 1),  Vec3(1, 1, 0),  Vec3(1, -1, 0),
    Vec3(1, 0, 1),  Vec3(1, 0, -1), Vec3(0, 1, 1),  Vec3(0, 1, -1), Vec3(1, 1, 1),
    Vec3(1, 1, -1), Vec3(1, -1, 1), Vec3(1, -1, -1)};

Real box_search_cost(const Vec3& e) {
  const Real area = e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  return e.x() * e.y() * e.z() + 0.01 * area * e.sum();
}

namespace {

/// Turns tried about each axis, largest first, each from the best frame so far.
constexpr std::array<Real, 4> kTurns = {0.3, 0.1, 0.03, 0.01};

/// Steps of one turn size at most, while each still shrinks the box.
constexpr int kMaxSteps = 4;

/// Per size in kTurns, the turns about each axis both ways.
std::array<std::array<Mat3, 6>, kTurns.size()> make_turns() {
  std::array<std::array<Mat3, 6>, kTurns.size()> out;
  for (std::size_t k = 0; k < kTurns.size(); ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int sign = 0; sign < 2; ++sign) {
        const Real angle = sign == 0 ? -kTurns[k] : kTurns[k];
        out[k][2 * axis + sign] =
            Eigen::AngleAxis<Real>(angle, Vec3::Unit(axis)).toRotationMatrix();
      }
    }
  }
  return out;
}

/// The cost of the box of `support` with the given axes.
Real support_cost(const Mesh& mesh, const Mat3& axes, std::span<const std::uint32_t> support) {
  const Mat3 to_box = axes.transpose();
  Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
  Vec3 hi = -lo;
  for (std::uint32_t v : support) {
    const Vec3 p = to_box * mesh.vertices[v];
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return box_search_cost(hi - lo);
}

}  // namespace

Mat3 search_box_frame(const Mesh& mesh, const Mat3& start, std::span<const Mat3> others,
                      std::span<const std::uint32_t> support) {
  static const std::array<std::array<Mat3, 6>, kTurns.size()> turns = make_turns();
  Mat3 best = start;
  Real best_cost = support_cost(mesh, best, support);
  const auto consider = [&](const Mat3& candidate) {
    const Real c = support_cost(mesh, candidate, support);
    if (c < best_cost) best_cost = c, best = candidate;
  };
  for (const Mat3& other : others) consider(other);
  for (const std::array<Mat3, 6>& size : turns) {
    for (int step = 0; step < kMaxSteps; ++step) {
      const Real before = best_cost;
      for (const Mat3& turn : size) consider(best * turn);
      if (!(best_cost < before)) break;
    }
  }
  // The products of rotations drift from orthonormal by rounding.
  best.col(0).normalize();
  best.col(1) = (best.col(1) - best.col(1).dot(best.col(0)) * best.col(0)).normalized();
  best.col(2) = best.col(0).cross(best.col(1));
  return best;
}

std::vector<FittedBox> fit_boxes(const BinaryLayout& layout, const Mesh& mesh) {
  std::vector<FittedBox> boxes(layout.nodes.size());
  if (!layout.nodes.empty()) BoxFitter(layout, mesh, boxes).fit(0);
  return boxes;
}

}  // namespace dovetail::collision::detail
