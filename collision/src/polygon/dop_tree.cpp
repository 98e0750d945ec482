#include "polygon/dop_tree.h"

#include <Eigen/LU>
#include <algorithm>
#include <limits>
#include <stdexcept>

#include "polygon/pair_traversal.h"

namespace dovetail::collision {

DopBasis::DopBasis(int k) {
  std::vector<Vec3> n = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<Vec3> corners = {{1, 1, 1}, {1, -1, 1}, {1, 1, -1}, {1, -1, -1}};
  const std::vector<Vec3> edges = {{1, 1, 0},  {1, -1, 0}, {1, 0, 1},
                                   {1, 0, -1}, {0, 1, 1},  {0, 1, -1}};
  if (k == 14 || k == 26) n.insert(n.end(), corners.begin(), corners.end());
  if (k == 18 || k == 26) n.insert(n.end(), edges.begin(), edges.end());
  if (k != 6 && k != 14 && k != 18 && k != 26)
    throw std::invalid_argument("DOP-tree: k must be 6, 14, 18 or 26");
  axes = static_cast<int>(n.size());
  std::copy(n.begin(), n.end(), normal.begin());

  // Faces of the convex hull of the unit directions: triples with every other
  // direction on one side of their plane. Coplanar quadruples give
  // overlapping cones, which is harmless: any cone containing a direction
  // gives a valid bound.
  const int m = 2 * axes;
  std::vector<Vec3> unit(m);
  for (int d = 0; d < m; ++d) unit[d] = direction(d).normalized();
  for (int a = 0; a < m; ++a) {
    for (int b = a + 1; b < m; ++b) {
      for (int c = b + 1; c < m; ++c) {
        Vec3 plane = (unit[b] - unit[a]).cross(unit[c] - unit[a]);
        if (plane.norm() < 1e-9) continue;
        if (plane.dot(unit[a]) < 0) plane = -plane;
        bool face = true;
        for (int d = 0; d < m && face; ++d) face = plane.dot(unit[d] - unit[a]) <= 1e-9;
        if (!face) continue;
        Mat3 columns;
        columns << direction(a), direction(b), direction(c);
        if (std::abs(columns.determinant()) < 1e-9) continue;
        cones.push_back({{a, b, c}, columns.inverse()});
      }
    }
  }
}

DopTree::DopTree(const Mesh& mesh, int k, int max_leaf_size) : basis_(k) {
  max_abs_ = detail::max_abs_coordinate(mesh);
  detail::BinaryLayout layout = detail::build_binary_layout(mesh, max_leaf_size);
  leaves_ = layout.leaves;
  depth_ = layout.depth;
  const int axes = basis_.axes;
  const std::size_t n = layout.nodes.size();

  // Per-triangle DOPs, then every node bottom-up (children follow their parent).
  std::vector<double> tri_bounds(layout.triangles.size() * 2 * axes);
  for (std::size_t s = 0; s < layout.triangles.size(); ++s) {
    const TriangleIndices& t = mesh.triangles[layout.triangles[s].index];
    double* d = &tri_bounds[s * 2 * axes];
    for (int j = 0; j < axes; ++j) {
      const double p = basis_.normal[j].dot(mesh.vertices[t[0]]);
      const double q = basis_.normal[j].dot(mesh.vertices[t[1]]);
      const double r = basis_.normal[j].dot(mesh.vertices[t[2]]);
      d[j] = std::min({p, q, r});
      d[axes + j] = std::max({p, q, r});
    }
  }
  std::vector<double> node_bounds(n * 2 * axes);
  for (std::size_t i = n; i-- > 0;) {
    const detail::LayoutNode& node = layout.nodes[i];
    double* d = &node_bounds[i * 2 * axes];
    std::fill(d, d + axes, std::numeric_limits<double>::infinity());
    std::fill(d + axes, d + 2 * axes, -std::numeric_limits<double>::infinity());
    auto merge = [&](const double* from) {
      for (int j = 0; j < axes; ++j) {
        d[j] = std::min(d[j], from[j]);
        d[axes + j] = std::max(d[axes + j], from[axes + j]);
      }
    };
    if (node.is_leaf()) {
      for (std::uint32_t s = node.begin; s < node.end; ++s) merge(&tri_bounds[s * 2 * axes]);
    } else {
      merge(&node_bounds[node.first_child * 2 * axes]);
      merge(&node_bounds[(node.first_child + 1) * 2 * axes]);
    }
  }
  bounds_.resize(node_bounds.size());
  for (std::size_t i = 0; i < n; ++i) {
    for (int j = 0; j < axes; ++j) {
      bounds_[i * 2 * axes + j] = detail::round_down(node_bounds[i * 2 * axes + j]);
      bounds_[i * 2 * axes + axes + j] = detail::round_up(node_bounds[i * 2 * axes + axes + j]);
    }
  }
  links_.reserve(n);
  for (const detail::LayoutNode& node : layout.nodes)
    links_.push_back(detail::NodeLink::from(node));
  order_.reserve(layout.triangles.size());
  for (const detail::BuildTriangle& t : layout.triangles) order_.push_back(t.index);
}

std::size_t DopTree::bytes() const {
  return sizeof(*this) + bounds_.capacity() * sizeof(float) +
         links_.capacity() * sizeof(detail::NodeLink) + order_.capacity() * sizeof(std::uint32_t);
}

/// Per-query table that encloses one tree's DOPs (the source) in the other
/// tree's frame (the target): for every target axis i, the cone of source
/// directions containing the axis seen from the source frame, as three
/// weights and the source bounds they multiply. Built once per query; each
/// enclosure then costs 6 multiply-adds per axis.
class TumbleTable {
 public:
  struct Enc {
    std::array<double, 2 * DopBasis::kMaxAxes> d;  ///< lo[axes] then hi[axes] in the target frame
  };

  /// M and t map source coordinates to target coordinates.
  TumbleTable(const DopBasis& source, const DopBasis& target, const Mat3& M, const Vec3& t,
              Real margin)
      : axes_(target.axes) {
    const Mat3 M_inverse = M.transpose();
    for (int i = 0; i < axes_; ++i) {
      const Vec3& n = target.normal[i];
      offset_[i] = n.dot(t);
      margin_[i] = margin * n.lpNorm<1>();
      const Vec3 c = M_inverse * n;  // the target axis seen from the source frame
      // The most interior cone: largest smallest weight.
      const DopBasis::Cone* best = &source.cones.front();
      Vec3 best_w = Vec3::Zero();
      Real best_min = -std::numeric_limits<Real>::infinity();
      for (const DopBasis::Cone& cone : source.cones) {
        const Vec3 w = cone.inverse * c;
        if (w.minCoeff() > best_min) best_min = w.minCoeff(), best = &cone, best_w = w;
      }
      for (int m = 0; m < 3; ++m) {
        // max over the source DOP of c.y <= sum w_m * (bound of direction m);
        // a direction -normal[j] is bounded by -lo[j].
        const int dir = best->direction[m];
        const bool negative = dir >= axes_;
        const int j = negative ? dir - axes_ : dir;
        const double w = negative ? -best_w[m] : best_w[m];
        weight_[i][m] = w;
        hi_index_[i][m] = w > 0 ? axes_ + j : j;
        lo_index_[i][m] = w > 0 ? j : axes_ + j;
      }
    }
  }

  Enc enclose(const float* d) const {
    Enc e;
    for (int i = 0; i < axes_; ++i) {
      double lo = offset_[i], hi = offset_[i];
      for (int m = 0; m < 3; ++m) {
        lo += weight_[i][m] * d[lo_index_[i][m]];
        hi += weight_[i][m] * d[hi_index_[i][m]];
      }
      e.d[i] = lo - margin_[i];
      e.d[axes_ + i] = hi + margin_[i];
    }
    return e;
  }

  /// Whether a target-frame DOP `d` overlaps an enclosure on every axis.
  bool overlaps(const float* d, const Enc& e) const {
    for (int i = 0; i < axes_; ++i) {
      if (d[i] > e.d[axes_ + i] || e.d[i] > d[axes_ + i]) return false;
    }
    return true;
  }

 private:
  int axes_ = 0;
  std::array<double, DopBasis::kMaxAxes> offset_{}, margin_{};
  std::array<std::array<double, 3>, DopBasis::kMaxAxes> weight_{};
  std::array<std::array<int, 3>, DopBasis::kMaxAxes> hi_index_{}, lo_index_{};
};

/// The DOP-tree test, made symmetric: B's DOP tumbled into A's frame against
/// A's DOP, and A's DOP tumbled into B's frame against B's DOP. Each
/// enclosure is computed once per node and re-used while the other tree
/// descends; the second direction prunes elongated volumes that one
/// direction alone lets through.
class DopPolicy {
 public:
  using EncA = TumbleTable::Enc;
  using EncB = TumbleTable::Enc;

  DopPolicy(const DopTree& a, const DopTree& b, const Transform& X_AB)
      : a_(a),
        b_(b),
        X_AB_(X_AB),
        axes_(a.basis_.axes),
        margin_(detail::query_margin(a.max_abs_, b.max_abs_, X_AB)),
        b_in_a_(b.basis_, a.basis_, X_AB.R, X_AB.t, margin_),
        a_in_b_(a.basis_, b.basis_, X_AB.R.transpose(), -(X_AB.R.transpose() * X_AB.t), margin_) {}

  EncA enclose_a(std::uint32_t n) const { return a_in_b_.enclose(dop(a_, n)); }
  EncB enclose_b(std::uint32_t n) const { return b_in_a_.enclose(dop(b_, n)); }

  bool overlap(std::uint32_t a, const EncA& enc_a, std::uint32_t b, const EncB& enc_b) const {
    return b_in_a_.overlaps(dop(a_, a), enc_b) && a_in_b_.overlaps(dop(b_, b), enc_a);
  }

  /// Squared distance between the centres of the two DOPs' boxes (their
  /// first three axes are x, y, z), B's brought into A's frame.
  Real nearness(std::uint32_t a, const EncA&, std::uint32_t b, const EncB&) const {
    return (centre(dop(a_, a)) - X_AB_.apply(centre(dop(b_, b)))).squaredNorm();
  }

  detail::NodeLink link_a(std::uint32_t n) const { return a_.links_[n]; }
  detail::NodeLink link_b(std::uint32_t n) const { return b_.links_[n]; }
  Real size_a(std::uint32_t n) const { return size(dop(a_, n)); }
  Real size_b(std::uint32_t n) const { return size(dop(b_, n)); }
  const std::uint32_t* slots_a() const { return a_.order_.data(); }
  const std::uint32_t* slots_b() const { return b_.order_.data(); }

 private:
  const float* dop(const DopTree& t, std::uint32_t n) const { return &t.bounds_[n * 2 * axes_]; }
  Vec3 centre(const float* d) const {
    return Vec3(Real{d[0]} + d[axes_], Real{d[1]} + d[axes_ + 1], Real{d[2]} + d[axes_ + 2]) * 0.5;
  }
  Real size(const float* d) const {
    return (d[axes_] - d[0]) + (d[axes_ + 1] - d[1]) + (d[axes_ + 2] - d[2]);
  }

  const DopTree& a_;
  const DopTree& b_;
  const Transform& X_AB_;
  int axes_;
  Real margin_;
  TumbleTable b_in_a_;
  TumbleTable a_in_b_;
};

CollideResult DopTree::collide(const Mesh& mesh_a, const DopTree& b, const Mesh& mesh_b,
                               const Transform& X_AB, const CollideRequest& request) const {
  if (b.k() != k()) throw std::invalid_argument("DOP-tree: both trees need the same k");
  return detail::collide_with_policy<DopPolicy>(*this, b, mesh_a, mesh_b, X_AB, request);
}

}  // namespace dovetail::collision

namespace dovetail::collision {

std::unique_ptr<SplitQuery> DopTree::split(const Mesh& mesh_a, const DopTree& b, const Mesh& mesh_b,
                                           const Transform& X_AB,
                                           const CollideRequest& request) const {
  if (b.k() != k()) throw std::invalid_argument("DOP-tree: both trees need the same k");
  return std::make_unique<detail::SplitTraversal<detail::PolicyContext<DopPolicy>>>(
      mesh_a, mesh_b, X_AB, request, *this, b);
}

}  // namespace dovetail::collision
