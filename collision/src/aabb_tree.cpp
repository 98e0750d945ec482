#include "aabb_tree.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>

#include "pair_traversal.h"

namespace dovetail::collision {

// ---------------------------------------------------------------- AABB tree

AabbTree::AabbTree(const Mesh& mesh, int max_leaf_size) {
  max_abs_ = detail::max_abs_coordinate(mesh);
  const detail::BinaryLayout layout = detail::build_binary_layout(mesh, max_leaf_size);
  leaves_ = layout.leaves;
  depth_ = layout.depth;
  const std::size_t n = layout.nodes.size();
  std::vector<Vec3> lo(n, Vec3::Constant(std::numeric_limits<Real>::infinity()));
  std::vector<Vec3> hi(n, Vec3::Constant(-std::numeric_limits<Real>::infinity()));
  for (std::size_t i = n; i-- > 0;) {
    const detail::LayoutNode& node = layout.nodes[i];
    if (node.is_leaf()) {
      for (std::uint32_t s = node.begin; s < node.end; ++s) {
        lo[i] = lo[i].cwiseMin(layout.triangles[s].lo);
        hi[i] = hi[i].cwiseMax(layout.triangles[s].hi);
      }
    } else {
      lo[i] = lo[node.first_child].cwiseMin(lo[node.first_child + 1]);
      hi[i] = hi[node.first_child].cwiseMax(hi[node.first_child + 1]);
    }
  }
  nodes_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      nodes_[i].lo[k] = detail::round_down(lo[i][k]);
      nodes_[i].hi[k] = detail::round_up(hi[i][k]);
    }
    nodes_[i].link = detail::NodeLink::from(layout.nodes[i]);
  }
  for (const detail::BuildTriangle& t : layout.triangles) order_.push_back(t.index);
}

std::size_t AabbTree::bytes() const {
  return sizeof(*this) + nodes_.capacity() * sizeof(Node) + order_.capacity() * sizeof(std::uint32_t);
}

class AabbPolicy {
 public:
  struct Enc {
    Vec3 centre;  ///< B's box centre in A's frame
    Vec3 half;    ///< B's half extents along B's axes
  };

  AabbPolicy(const AabbTree& a, const AabbTree& b, const Transform& X_AB)
      : a_(a), b_(b), X_AB_(X_AB), margin_(detail::query_margin(a.max_abs_, b.max_abs_, X_AB)) {}

  Enc enclose_b(std::uint32_t n) const {
    const AabbTree::Node& node = b_.nodes_[n];
    const Vec3 lo(node.lo[0], node.lo[1], node.lo[2]);
    const Vec3 hi(node.hi[0], node.hi[1], node.hi[2]);
    return {X_AB_.apply((lo + hi) * 0.5), (hi - lo) * 0.5};
  }

  bool overlap(std::uint32_t n, const Enc& e) const {
    const AabbTree::Node& node = a_.nodes_[n];
    const Vec3 lo(node.lo[0], node.lo[1], node.lo[2]);
    const Vec3 hi(node.hi[0], node.hi[1], node.hi[2]);
    return detail::boxes_overlap(X_AB_.R, e.centre - (lo + hi) * 0.5, (hi - lo) * 0.5, e.half,
                                 margin_);
  }

  detail::NodeLink link_a(std::uint32_t n) const { return a_.nodes_[n].link; }
  detail::NodeLink link_b(std::uint32_t n) const { return b_.nodes_[n].link; }
  Real size_a(std::uint32_t n) const { return size(a_.nodes_[n]); }
  Real size_b(std::uint32_t n) const { return size(b_.nodes_[n]); }
  const std::uint32_t* slots_a() const { return a_.order_.data(); }
  const std::uint32_t* slots_b() const { return b_.order_.data(); }

 private:
  static Real size(const AabbTree::Node& n) {
    return (n.hi[0] - n.lo[0]) + (n.hi[1] - n.lo[1]) + (n.hi[2] - n.lo[2]);
  }
  const AabbTree& a_;
  const AabbTree& b_;
  const Transform& X_AB_;
  Real margin_;
};

CollideResult AabbTree::collide(const Mesh& mesh_a, const AabbTree& b, const Mesh& mesh_b,
                                const Transform& X_AB, const CollideRequest& request) const {
  CollideResult result;
  detail::LeafTester tester(mesh_a, mesh_b, X_AB, request.all_pairs, result);
  const AabbPolicy policy(*this, b, X_AB);
  detail::PairTraversal<AabbPolicy>(policy, tester).run();
  tester.finish();
  return result;
}

// ----------------------------------------------------------------- OBB tree

namespace {

/// Box axes from the area-weighted covariance of a set of triangles.
Mat3 covariance_axes(const Mesh& mesh, const std::vector<detail::BuildTriangle>& tris,
                     std::uint32_t begin, std::uint32_t end) {
  Vec3 mean = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  Real area_sum = 0;
  for (std::uint32_t s = begin; s < end; ++s) {
    const TriangleIndices& t = mesh.triangles[tris[s].index];
    const Vec3& p = mesh.vertices[t[0]];
    const Vec3& q = mesh.vertices[t[1]];
    const Vec3& r = mesh.vertices[t[2]];
    const Real area = 0.5 * (q - p).cross(r - p).norm();
    const Vec3 c = (p + q + r) / 3.0;
    mean += area * c;
    // Second moment of a triangle about the origin, per unit area.
    second += area / 12.0 * (9.0 * c * c.transpose() + p * p.transpose() + q * q.transpose() +
                              r * r.transpose());
    area_sum += area;
  }
  if (!(area_sum > 0)) return Mat3::Identity();
  mean /= area_sum;
  const Mat3 covariance = second / area_sum - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);
  Mat3 axes = solver.eigenvectors();
  if (!axes.allFinite()) return Mat3::Identity();
  axes.col(2) = axes.col(0).cross(axes.col(1)).normalized();  // right-handed
  return axes;
}

}  // namespace

ObbTree::ObbTree(const Mesh& mesh, int max_leaf_size) {
  max_abs_ = detail::max_abs_coordinate(mesh);
  const detail::BinaryLayout layout = detail::build_binary_layout(mesh, max_leaf_size);
  leaves_ = layout.leaves;
  depth_ = layout.depth;
  nodes_.resize(layout.nodes.size());
  for (std::size_t i = 0; i < layout.nodes.size(); ++i) {
    const detail::LayoutNode& node = layout.nodes[i];
    Node& out = nodes_[i];
    out.axes = covariance_axes(mesh, layout.triangles, node.begin, node.end);
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 hi = -lo;
    for (std::uint32_t s = node.begin; s < node.end; ++s) {
      for (std::uint32_t v : mesh.triangles[layout.triangles[s].index]) {
        const Vec3 p = out.axes.transpose() * mesh.vertices[v];
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
    out.centre = out.axes * ((lo + hi) * 0.5);
    out.half = (hi - lo) * 0.5;
    out.link = detail::NodeLink::from(node);
  }
  for (const detail::BuildTriangle& t : layout.triangles) order_.push_back(t.index);
}

std::size_t ObbTree::bytes() const {
  return sizeof(*this) + nodes_.capacity() * sizeof(Node) + order_.capacity() * sizeof(std::uint32_t);
}

class ObbPolicy {
 public:
  struct Enc {
    Mat3 axes;  ///< B's box axes in A's frame
    Vec3 centre;
    Vec3 half;
  };

  ObbPolicy(const ObbTree& a, const ObbTree& b, const Transform& X_AB)
      : a_(a), b_(b), X_AB_(X_AB), margin_(detail::query_margin(a.max_abs_, b.max_abs_, X_AB)) {
    // Box frames are fitted, not exact: widen the margin by the size of the
    // rounding in expressing a box in another box's frame.
    margin_ += 0x1.0p-40 * (a.max_abs_ + b.max_abs_);
  }

  Enc enclose_b(std::uint32_t n) const {
    const ObbTree::Node& node = b_.nodes_[n];
    return {X_AB_.R * node.axes, X_AB_.apply(node.centre), node.half};
  }

  bool overlap(std::uint32_t n, const Enc& e) const {
    const ObbTree::Node& node = a_.nodes_[n];
    const Mat3 R = node.axes.transpose() * e.axes;
    const Vec3 T = node.axes.transpose() * (e.centre - node.centre);
    return detail::boxes_overlap(R, T, node.half, e.half, margin_);
  }

  detail::NodeLink link_a(std::uint32_t n) const { return a_.nodes_[n].link; }
  detail::NodeLink link_b(std::uint32_t n) const { return b_.nodes_[n].link; }
  Real size_a(std::uint32_t n) const { return a_.nodes_[n].half.sum(); }
  Real size_b(std::uint32_t n) const { return b_.nodes_[n].half.sum(); }
  const std::uint32_t* slots_a() const { return a_.order_.data(); }
  const std::uint32_t* slots_b() const { return b_.order_.data(); }

 private:
  const ObbTree& a_;
  const ObbTree& b_;
  const Transform& X_AB_;
  Real margin_;
};

CollideResult ObbTree::collide(const Mesh& mesh_a, const ObbTree& b, const Mesh& mesh_b,
                               const Transform& X_AB, const CollideRequest& request) const {
  CollideResult result;
  detail::LeafTester tester(mesh_a, mesh_b, X_AB, request.all_pairs, result);
  const ObbPolicy policy(*this, b, X_AB);
  detail::PairTraversal<ObbPolicy>(policy, tester).run();
  tester.finish();
  return result;
}

}  // namespace dovetail::collision
