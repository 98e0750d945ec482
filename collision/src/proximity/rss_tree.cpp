#include "proximity/rss_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "polygon/hierarchy_common.h"
#include "polygon/principal_axes.h"
#include "proximity/tri_distance.h"

namespace dovetail::collision::detail {

namespace {

Vec3 to_vec(const float f[3]) { return Vec3(f[0], f[1], f[2]); }

/// x rounded to the nearest float, through memory. GCC 12's SLP vectorizer
/// was seen to drop the round trip (double)(float)x when both stay in
/// registers (-O2 and -O3), which would measure the radius against axes
/// other than the stored ones.
float to_float(double x) {
  volatile float f = static_cast<float>(x);
  return f;
}

/// Smallest float >= x (round_up, immune to the same folding).
float to_float_up(double x) {
  float f = to_float(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

/// The RSS of a set of points with rectangle axes (u, v) rounded to float:
/// the rectangle spans the points' projections, shrunk by a fraction of the
/// half thickness where that lowers the volume (the sphere covers the
/// corners); the radius is then measured against the stored floats.
void fit_rss(const std::vector<Vec3>& points, const Vec3& u_fit, const Vec3& v_fit, Real slack,
             RssTree::Node& out) {
  for (int k = 0; k < 3; ++k) {
    out.axis[0][k] = to_float(u_fit[k]);
    out.axis[1][k] = to_float(v_fit[k]);
  }
  const Vec3 u = to_vec(out.axis[0]);
  const Vec3 v = to_vec(out.axis[1]);
  const Vec3 n = u.cross(v).normalized();
  // Projections relative to a point of the set: u and v are only nearly
  // orthonormal after rounding, and coordinates relative to the origin would
  // carry that error (about 1e-7 of the distance) into the centre.
  const Vec3 origin = points.front();
  Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& p : points) {
    const Vec3 d = p - origin;
    const Vec3 c(d.dot(u), d.dot(v), d.dot(n));
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const Vec3 mid = (lo + hi) * 0.5;
  const Vec3 half = (hi - lo) * 0.5;
  Real best_volume = std::numeric_limits<Real>::infinity();
  for (const Real fraction : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const Real shrink = fraction * half.z();
    const Vec3 centre = origin + u * mid.x() + v * mid.y() + n * mid.z();
    const float hu = to_float_up(std::max(Real{0}, half.x() - shrink));
    const float hv = to_float_up(std::max(Real{0}, half.y() - shrink));
    // The radius that covers every point from this rectangle.
    Real r2 = 0;
    for (const Vec3& p : points) {
      const Vec3 d = p - centre;
      const Real x = std::clamp(d.dot(u), -Real{hu}, Real{hu});
      const Real y = std::clamp(d.dot(v), -Real{hv}, Real{hv});
      r2 = std::max(r2, (d - u * x - v * y).squaredNorm());
    }
    const Real r = std::sqrt(r2) + slack;
    const Real volume = 8 * Real{hu} * hv * r + 2 * std::numbers::pi * r * r * (Real{hu} + hv) +
                        4.0 / 3.0 * std::numbers::pi * r * r * r;
    if (volume < best_volume) {
      best_volume = volume;
      out.centre = centre;
      out.half[0] = hu;
      out.half[1] = hv;
      out.radius = to_float_up(r);
    }
    if (!(half.z() > 0)) break;
  }
}

}  // namespace

RssTree::RssTree(const Mesh& mesh, int max_leaf_size) {
  max_abs_ = max_abs_coordinate(mesh);
  const BinaryLayout layout = build_binary_layout(mesh, max_leaf_size);
  leaves_ = layout.leaves;
  depth_ = layout.depth;
  const std::vector<Moments> moments = node_moments(layout, mesh);
  // Rounding of the radius computation, far below any feature.
  const Real slack = 0x1.0p-44 * max_abs_;
  nodes_.resize(layout.nodes.size());
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const LayoutNode& node = layout.nodes[i];
    points.clear();
    for (std::uint32_t s = node.begin; s < node.end; ++s) {
      for (std::uint32_t v : mesh.triangles[layout.triangles[s].index])
        points.push_back(mesh.vertices[v]);
    }
    // The rectangle spans the two major axes: a single triangle's longest
    // edge and its in-plane normal, otherwise the covariance's two largest
    // eigenvectors (covariance_axes sorts them last).
    if (node.end - node.begin == 1) {
      const Mat3 axes = triangle_axes(mesh, layout.triangles[node.begin].index);
      fit_rss(points, axes.col(0), axes.col(1), slack, nodes_[i]);
    } else {
      const Mat3 axes = covariance_axes(moments[i]);
      fit_rss(points, axes.col(2), axes.col(1), slack, nodes_[i]);
    }
    nodes_[i].link = NodeLink::from(node);
  }
  for (const BuildTriangle& t : layout.triangles) order_.push_back(t.index);
}

std::size_t RssTree::bytes() const {
  return sizeof(*this) + nodes_.capacity() * sizeof(Node) +
         order_.capacity() * sizeof(std::uint32_t);
}

Rss RssTree::rss(std::uint32_t n) const {
  const Node& node = nodes_[n];
  return {node.centre,  to_vec(node.axis[0]), to_vec(node.axis[1]),
          node.half[0], node.half[1],         node.radius};
}

Real rss_lower_bound(const Rss& x, const Rss& y) {
  constexpr int kProjections = 1;
  const Vec3 d = y.centre - x.centre;
  const Real m00 = x.u.dot(y.u), m01 = x.u.dot(y.v);
  const Real m10 = x.v.dot(y.u), m11 = x.v.dot(y.v);
  const Real dxu = d.dot(x.u), dxv = d.dot(x.v);
  const Real dyu = d.dot(y.u), dyv = d.dot(y.v);
  // Rectangle coordinates (s on x, t on y) of the current pair of points;
  // start from y's centre projected on x.
  Real s0 = std::clamp(dxu, -x.hu, x.hu);
  Real s1 = std::clamp(dxv, -x.hv, x.hv);
  Real t0 = 0, t1 = 0;
  for (int k = 0; k < kProjections; ++k) {
    t0 = std::clamp(m00 * s0 + m10 * s1 - dyu, -y.hu, y.hu);
    t1 = std::clamp(m01 * s0 + m11 * s1 - dyv, -y.hv, y.hv);
    s0 = std::clamp(m00 * t0 + m01 * t1 + dxu, -x.hu, x.hu);
    s1 = std::clamp(m10 * t0 + m11 * t1 + dxv, -x.hv, x.hv);
  }
  // Gap between the projections of both rectangles on w.
  const Vec3 w = d + y.u * t0 + y.v * t1 - x.u * s0 - x.v * s1;
  const Real w2 = w.squaredNorm();
  Real gap = 0;
  if (w2 > 0) {
    const Real extent = x.hu * std::abs(w.dot(x.u)) + x.hv * std::abs(w.dot(x.v)) +
                        y.hu * std::abs(w.dot(y.u)) + y.hv * std::abs(w.dot(y.v));
    gap = std::max(Real{0}, (w.dot(d) - extent) / std::sqrt(w2));
  }
  return gap - x.radius - y.radius;
}

// ---------------------------------------------------------------- queries

namespace {

/// The simultaneous traversal of two RSS trees, for the minimum distance
/// (kTolerance = false: prune with the best distance so far) or for a
/// tolerance verdict (prune with the tolerance, stop at the first pair
/// within it). The pair of child volumes with the smaller bound goes first.
template <bool kTolerance>
class RssTraversal {
 public:
  RssTraversal(const RssTree& a, const RssTree& b, const Mesh& mesh_a, const Mesh& mesh_b,
               const Transform& X_AB)
      : a_(a),
        b_(b),
        mesh_a_(mesh_a),
        mesh_b_(mesh_b),
        X_AB_(X_AB),
        // As in the OBB tree: the query margin plus the rounding of fitted frames.
        margin_(query_margin(a.max_abs(), b.max_abs(), X_AB) +
                0x1.0p-40 * (a.max_abs() + b.max_abs())) {}

  /// Distance mode: relative and absolute error accepted.
  void set_error(Real relative, Real absolute) {
    scale_ = 1 + relative;
    absolute_ = absolute;
  }

  /// Tolerance mode: the tolerance.
  void set_tolerance(Real tolerance) { tolerance_ = tolerance; }

  void run() {
    const Rss ra = rss_a(0), rb = rss_b(0);
    const Real bound = lower_bound(ra, rb);
    if (!pruned(bound)) visit(0, ra, 0, rb);
  }

  Real best = std::numeric_limits<Real>::infinity();
  TriangleDistance best_pair;
  std::uint32_t triangle_a = 0, triangle_b = 0;
  bool found = false;
  CollideStats stats;

 private:
  Rss rss_a(std::uint32_t n) const { return a_.rss(n); }

  Rss rss_b(std::uint32_t n) const {
    Rss r = b_.rss(n);
    r.centre = X_AB_.apply(r.centre);
    r.u = X_AB_.R * r.u;
    r.v = X_AB_.R * r.v;
    return r;
  }

  Real lower_bound(const Rss& ra, const Rss& rb) {
    ++stats.volume_tests;
    return rss_lower_bound(ra, rb) - margin_;
  }

  bool pruned(Real bound) const {
    if constexpr (kTolerance) {
      return found || bound > tolerance_;
    } else {
      return best <= 0 || bound * scale_ + absolute_ >= best;
    }
  }

  static Real size(const Rss& r) { return r.hu + r.hv + r.radius; }

  void visit(std::uint32_t a, const Rss& ra, std::uint32_t b, const Rss& rb) {
    const NodeLink la = a_.nodes()[a].link;
    const NodeLink lb = b_.nodes()[b].link;
    if (la.is_leaf() && lb.is_leaf()) {
      leaves(la, lb);
      return;
    }
    if (!la.is_leaf() && (lb.is_leaf() || size(ra) >= size(rb))) {
      const std::uint32_t c = la.first_child();
      const Rss r0 = rss_a(c), r1 = rss_a(c + 1);
      const Real d0 = lower_bound(r0, rb), d1 = lower_bound(r1, rb);
      if (d1 < d0) {
        if (!pruned(d1)) visit(c + 1, r1, b, rb);
        if (!pruned(d0)) visit(c, r0, b, rb);
      } else {
        if (!pruned(d0)) visit(c, r0, b, rb);
        if (!pruned(d1)) visit(c + 1, r1, b, rb);
      }
    } else {
      const std::uint32_t c = lb.first_child();
      const Rss r0 = rss_b(c), r1 = rss_b(c + 1);
      const Real d0 = lower_bound(ra, r0), d1 = lower_bound(ra, r1);
      if (d1 < d0) {
        if (!pruned(d1)) visit(a, ra, c + 1, r1);
        if (!pruned(d0)) visit(a, ra, c, r0);
      } else {
        if (!pruned(d0)) visit(a, ra, c, r0);
        if (!pruned(d1)) visit(a, ra, c + 1, r1);
      }
    }
  }

  void leaves(NodeLink la, NodeLink lb) {
    const std::uint32_t* slots_a = a_.order().data() + la.first_slot();
    const std::uint32_t* slots_b = b_.order().data() + lb.first_slot();
    for (int j = 0; j < lb.count(); ++j) {
      const TriangleIndices& tb = mesh_b_.triangles[slots_b[j]];
      const TriangleVertices b{X_AB_.apply(mesh_b_.vertices[tb[0]]),
                               X_AB_.apply(mesh_b_.vertices[tb[1]]),
                               X_AB_.apply(mesh_b_.vertices[tb[2]])};
      for (int i = 0; i < la.count(); ++i) {
        const TriangleIndices& ta = mesh_a_.triangles[slots_a[i]];
        const TriangleVertices a{mesh_a_.vertices[ta[0]], mesh_a_.vertices[ta[1]],
                                 mesh_a_.vertices[ta[2]]};
        ++stats.triangle_tests;
        const TriangleDistance d = triangle_distance(a, b);
        if constexpr (kTolerance) {
          if (d.distance <= tolerance_) {
            found = true;
            record(d, slots_a[i], slots_b[j]);
            return;
          }
        } else if (d.distance < best) {
          record(d, slots_a[i], slots_b[j]);
        }
      }
    }
  }

  void record(const TriangleDistance& d, std::uint32_t ia, std::uint32_t ib) {
    best = d.distance;
    best_pair = d;
    triangle_a = ia;
    triangle_b = ib;
  }

  const RssTree& a_;
  const RssTree& b_;
  const Mesh& mesh_a_;
  const Mesh& mesh_b_;
  const Transform& X_AB_;
  Real margin_;
  Real scale_ = 1, absolute_ = 0;
  Real tolerance_ = 0;
};

}  // namespace

DistanceResult RssTree::distance(const Mesh& mesh_a, const RssTree& b, const Mesh& mesh_b,
                                 const Transform& X_AB, const DistanceRequest& request) const {
  RssTraversal<false> traversal(*this, b, mesh_a, mesh_b, X_AB);
  traversal.set_error(request.relative_error, request.absolute_error);
  traversal.run();
  DistanceResult result;
  result.distance = traversal.best;
  result.p_A = traversal.best_pair.p;
  result.q_A = traversal.best_pair.q;
  result.triangle_a = traversal.triangle_a;
  result.triangle_b = traversal.triangle_b;
  result.stats = traversal.stats;
  return result;
}

ToleranceResult RssTree::within(const Mesh& mesh_a, const RssTree& b, const Mesh& mesh_b,
                                const Transform& X_AB, Real tolerance) const {
  RssTraversal<true> traversal(*this, b, mesh_a, mesh_b, X_AB);
  traversal.set_tolerance(tolerance);
  traversal.run();
  ToleranceResult result;
  result.within = traversal.found;
  if (traversal.found) {
    result.distance = traversal.best;
    result.p_A = traversal.best_pair.p;
    result.q_A = traversal.best_pair.q;
    result.triangle_a = traversal.triangle_a;
    result.triangle_b = traversal.triangle_b;
  }
  result.stats = traversal.stats;
  return result;
}

}  // namespace dovetail::collision::detail
