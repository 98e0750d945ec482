#include "proximity/tri_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dovetail/collision/tri_tri.h"

namespace dovetail::collision::detail {

namespace {

Real clamp01(Real x) { return std::clamp(x, Real{0}, Real{1}); }

/// Squared distance from v to the interior of triangle t when v projects
/// into the (closed) triangle along its normal n = (t1 - t0) x (t2 - t0),
/// with the projection in `on_t`; false when it projects outside (an edge
/// pair is then at least as close) or the normal vanished in rounding.
bool vertex_face(const Vec3& v, const TriangleVertices& t, const Vec3& n, Real n2, Vec3& on_t,
                 Real& d2) {
  if (!(n2 > 0)) return false;
  for (int k = 0; k < 3; ++k) {
    const Vec3& s = t[k];
    const Vec3& e = t[(k + 1) % 3];
    if ((e - s).cross(v - s).dot(n) < 0) return false;
  }
  const Real h = n.dot(v - t[0]);
  on_t = v - n * (h / n2);
  d2 = h * h / n2;
  return true;
}

}  // namespace

namespace {

/// Parameter in [0, 1] of the point of segment [o, o + d] closest to p.
Real closest_parameter(const Vec3& p, const Vec3& o, const Vec3& d) {
  const Real dd = d.dot(d);
  return dd > 0 ? clamp01((p - o).dot(d) / dd) : Real{0};
}

}  // namespace

Real segment_distance_squared(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1,
                              Vec3& x, Vec3& y) {
  // The distance is a convex function of the two parameters: its minimum is
  // where the lines are closest when that lies inside both segments, and on
  // the boundary (an endpoint against the other segment) otherwise. Every
  // candidate is a pair of points of the segments, never closer than the
  // true distance.
  const Vec3 d1 = p1 - p0;
  const Vec3 d2 = q1 - q0;
  Real best = std::numeric_limits<Real>::infinity();
  const auto consider = [&](const Vec3& u, const Vec3& v) {
    const Real d2_uv = (u - v).squaredNorm();
    if (d2_uv < best) {
      best = d2_uv;
      x = u;
      y = v;
    }
  };
  // The lines' closest points from the cross product n = d1 x d2, which stays
  // accurate to far smaller angles than the usual a e - b^2 (that loses all
  // digits below about 1e-8 rad); the refinement below and the endpoint
  // candidates absorb what error remains.
  const Vec3 n = d1.cross(d2);
  const Real n2 = n.squaredNorm();
  if (n2 > 0) {
    const Vec3 w = q0 - p0;
    const Real s = w.cross(d2).dot(n) / n2;
    const Real t = w.cross(d1).dot(n) / n2;
    if (s >= 0 && s <= 1 && t >= 0 && t <= 1) {
      // One refinement each way on the rounded parameters.
      const Vec3 on_q = q0 + d2 * closest_parameter(p0 + d1 * s, q0, d2);
      consider(p0 + d1 * closest_parameter(on_q, p0, d1), on_q);
      return best;
    }
  }
  consider(p0, q0 + d2 * closest_parameter(p0, q0, d2));
  consider(p1, q0 + d2 * closest_parameter(p1, q0, d2));
  consider(p0 + d1 * closest_parameter(q0, p0, d1), q0);
  consider(p0 + d1 * closest_parameter(q1, p0, d1), q1);
  return best;
}

Vec3 closest_point_on_triangle(const Vec3& p, const TriangleVertices& t) {
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  Vec3 best;
  Real best_d2;
  if (vertex_face(p, t, n, n.squaredNorm(), best, best_d2)) return best;
  best_d2 = std::numeric_limits<Real>::infinity();
  for (int k = 0; k < 3; ++k) {
    Vec3 x, y;
    const Real d2 = segment_distance_squared(p, p, t[k], t[(k + 1) % 3], x, y);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = y;
    }
  }
  return best;
}

Real feature_distance_squared(const TriangleVertices& a, const TriangleVertices& b, Vec3& p,
                              Vec3& q) {
  Real best = std::numeric_limits<Real>::infinity();
  Vec3 x, y;
  // The nine edge pairs.
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const Real d2 = segment_distance_squared(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3], x, y);
      if (d2 < best) {
        best = d2;
        p = x;
        q = y;
      }
    }
  }
  // The six vertices against the other triangle's interior.
  const Vec3 n_a = (a[1] - a[0]).cross(a[2] - a[0]);
  const Vec3 n_b = (b[1] - b[0]).cross(b[2] - b[0]);
  const Real n2_a = n_a.squaredNorm();
  const Real n2_b = n_b.squaredNorm();
  for (int k = 0; k < 3; ++k) {
    Real d2;
    if (vertex_face(b[k], a, n_a, n2_a, x, d2) && d2 < best) {
      best = d2;
      p = x;
      q = b[k];
    }
    if (vertex_face(a[k], b, n_b, n2_b, y, d2) && d2 < best) {
      best = d2;
      p = a[k];
      q = y;
    }
  }
  return best;
}

namespace {

/// A point where intersecting triangles meet: the feature pairs, and every
/// edge of one triangle where it crosses the other's plane against its
/// closest point on that triangle; the midpoint of the closest such pair.
Vec3 intersection_witness(const TriangleVertices& a, const TriangleVertices& b) {
  Vec3 p, q;
  Real best = feature_distance_squared(a, b, p, q);
  for (int side = 0; side < 2; ++side) {
    const TriangleVertices& x = side == 0 ? a : b;
    const TriangleVertices& y = side == 0 ? b : a;
    const Vec3 n = (y[1] - y[0]).cross(y[2] - y[0]);
    Real h[3];
    for (int k = 0; k < 3; ++k) h[k] = n.dot(x[k] - y[0]);
    for (int k = 0; k < 3; ++k) {
      const int l = (k + 1) % 3;
      if (h[k] == h[l] || (h[k] > 0 && h[l] > 0) || (h[k] < 0 && h[l] < 0)) continue;
      const Vec3 on_x = x[k] + (x[l] - x[k]) * (h[k] / (h[k] - h[l]));
      const Vec3 on_y = closest_point_on_triangle(on_x, y);
      const Real d2 = (on_x - on_y).squaredNorm();
      if (d2 < best) {
        best = d2;
        p = side == 0 ? on_x : on_y;
        q = side == 0 ? on_y : on_x;
      }
    }
  }
  return (p + q) * 0.5;
}

}  // namespace

TriangleDistance triangle_distance(const TriangleVertices& a, const TriangleVertices& b) {
  TriangleDistance out;
  if (triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2])) {
    out.p = out.q = intersection_witness(a, b);
    out.distance = 0;
    return out;
  }
  out.distance = std::sqrt(feature_distance_squared(a, b, out.p, out.q));
  if (out.distance == 0) out.distance = std::numeric_limits<Real>::denorm_min();
  return out;
}

}  // namespace dovetail::collision::detail
