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
  return sizeof(*this) + nodes_.capacity() * sizeof(Node) +
         order_.capacity() * sizeof(std::uint32_t);
}

class AabbPolicy {
 public:
  using EncA = detail::NoEnclosure;
  struct EncB {
    Vec3 centre;  ///< B's box centre in A's frame
    Vec3 half;    ///< B's half extents along B's axes
  };

  EncA enclose_a(std::uint32_t) const { return {}; }

  AabbPolicy(const AabbTree& a, const AabbTree& b, const Transform& X_AB)
      : a_(a), b_(b), X_AB_(X_AB), margin_(detail::query_margin(a.max_abs_, b.max_abs_, X_AB)) {}

  EncB enclose_b(std::uint32_t n) const {
    const AabbTree::Node& node = b_.nodes_[n];
    const Vec3 lo(node.lo[0], node.lo[1], node.lo[2]);
    const Vec3 hi(node.hi[0], node.hi[1], node.hi[2]);
    return {X_AB_.apply((lo + hi) * 0.5), (hi - lo) * 0.5};
  }

  bool overlap(std::uint32_t n, const EncA&, std::uint32_t, const EncB& e) const {
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
  return detail::collide_with_policy<AabbPolicy>(*this, b, mesh_a, mesh_b, X_AB, request);
}

std::unique_ptr<SplitQuery> AabbTree::split(const Mesh& mesh_a, const AabbTree& b,
                                            const Mesh& mesh_b, const Transform& X_AB,
                                            const CollideRequest& request) const {
  return std::make_unique<detail::SplitTraversal<detail::PolicyContext<AabbPolicy>>>(
      mesh_a, mesh_b, X_AB, request, *this, b);
}

// ----------------------------------------------------------------- OBB tree

namespace {

/// Area-weighted first and second moments of a set of triangles; the moments
/// of a node are the sums of its children's.
struct Moments {
  Real area = 0;
  Vec3 first = Vec3::Zero();   ///< sum of area * centroid
  Mat3 second = Mat3::Zero();  ///< sum of area * second moment per unit area
  void add(const Moments& m) {
    area += m.area;
    first += m.first;
    second += m.second;
  }
};

Moments triangle_moments(const Vec3& p, const Vec3& q, const Vec3& r) {
  Moments m;
  m.area = 0.5 * (q - p).cross(r - p).norm();
  const Vec3 c = (p + q + r) / 3.0;
  m.first = m.area * c;
  m.second = m.area / 12.0 *
             (9.0 * c * c.transpose() + p * p.transpose() + q * q.transpose() + r * r.transpose());
  return m;
}

/// Box axes: eigenvectors of the covariance, made right-handed.
Mat3 covariance_axes(const Moments& m) {
  if (!(m.area > 0)) return Mat3::Identity();
  const Vec3 mean = m.first / m.area;
  const Mat3 covariance = m.second / m.area - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> solver;
  solver.computeDirect(covariance);
  Mat3 axes = solver.eigenvectors();
  axes.col(0).normalize();
  axes.col(1) = (axes.col(1) - axes.col(1).dot(axes.col(0)) * axes.col(0)).normalized();
  axes.col(2) = axes.col(0).cross(axes.col(1));
  if (!axes.allFinite()) return Mat3::Identity();
  return axes;
}

/// Axes of a single triangle: its longest edge, the in-plane normal to it and
/// the face normal (the tightest box of a triangle has a face in its plane).
Mat3 triangle_axes(const Mesh& mesh, std::uint32_t triangle) {
  const TriangleIndices& t = mesh.triangles[triangle];
  const Vec3 e[3] = {mesh.vertices[t[1]] - mesh.vertices[t[0]],
                     mesh.vertices[t[2]] - mesh.vertices[t[1]],
                     mesh.vertices[t[0]] - mesh.vertices[t[2]]};
  int longest = 0;
  for (int k = 1; k < 3; ++k)
    if (e[k].squaredNorm() > e[longest].squaredNorm()) longest = k;
  Mat3 axes;
  axes.col(0) = e[longest].normalized();
  axes.col(2) = e[0].cross(e[1]).normalized();
  axes.col(1) = axes.col(2).cross(axes.col(0));
  if (!axes.allFinite()) return Mat3::Identity();
  return axes;
}

}  // namespace

ObbTree::ObbTree(const Mesh& mesh, int max_leaf_size) {
  max_abs_ = detail::max_abs_coordinate(mesh);
  const detail::BinaryLayout layout = detail::build_binary_layout(mesh, max_leaf_size);
  leaves_ = layout.leaves;
  depth_ = layout.depth;
  const std::size_t n = layout.nodes.size();
  // Moments bottom-up (children follow their parent in the layout).
  std::vector<Moments> moments(n);
  for (std::size_t i = n; i-- > 0;) {
    const detail::LayoutNode& node = layout.nodes[i];
    if (node.is_leaf()) {
      for (std::uint32_t s = node.begin; s < node.end; ++s) {
        const TriangleIndices& t = mesh.triangles[layout.triangles[s].index];
        moments[i].add(
            triangle_moments(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]));
      }
    } else {
      moments[i] = moments[node.first_child];
      moments[i].add(moments[node.first_child + 1]);
    }
  }
  nodes_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const detail::LayoutNode& node = layout.nodes[i];
    Node& out = nodes_[i];
    out.axes = node.end - node.begin == 1 ? triangle_axes(mesh, layout.triangles[node.begin].index)
                                          : covariance_axes(moments[i]);
    const Mat3 to_box = out.axes.transpose();
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 hi = -lo;
    for (std::uint32_t s = node.begin; s < node.end; ++s) {
      for (std::uint32_t v : mesh.triangles[layout.triangles[s].index]) {
        const Vec3 p = to_box * mesh.vertices[v];
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
  return sizeof(*this) + nodes_.capacity() * sizeof(Node) +
         order_.capacity() * sizeof(std::uint32_t);
}

class ObbPolicy {
 public:
  using EncA = detail::NoEnclosure;
  struct EncB {
    Mat3 axes;  ///< B's box axes in A's frame
    Vec3 centre;
    Vec3 half;
  };

  EncA enclose_a(std::uint32_t) const { return {}; }

  ObbPolicy(const ObbTree& a, const ObbTree& b, const Transform& X_AB)
      : a_(a), b_(b), X_AB_(X_AB), margin_(detail::query_margin(a.max_abs_, b.max_abs_, X_AB)) {
    // Box frames are fitted, not exact: widen the margin by the size of the
    // rounding in expressing a box in another box's frame.
    margin_ += 0x1.0p-40 * (a.max_abs_ + b.max_abs_);
  }

  EncB enclose_b(std::uint32_t n) const {
    const ObbTree::Node& node = b_.nodes_[n];
    return {X_AB_.R * node.axes, X_AB_.apply(node.centre), node.half};
  }

  bool overlap(std::uint32_t n, const EncA&, std::uint32_t, const EncB& e) const {
    const ObbTree::Node& node = a_.nodes_[n];
    return detail::oriented_boxes_overlap(node.axes, node.centre, node.half, e.axes, e.centre,
                                          e.half, margin_);
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
  return detail::collide_with_policy<ObbPolicy>(*this, b, mesh_a, mesh_b, X_AB, request);
}

std::unique_ptr<SplitQuery> ObbTree::split(const Mesh& mesh_a, const ObbTree& b, const Mesh& mesh_b,
                                           const Transform& X_AB,
                                           const CollideRequest& request) const {
  return std::make_unique<detail::SplitTraversal<detail::PolicyContext<ObbPolicy>>>(
      mesh_a, mesh_b, X_AB, request, *this, b);
}

}  // namespace dovetail::collision
