#include "core/tri_intersection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/predicates_inline.h"
#include "proximity/tri_distance.h"

namespace dovetail::collision::detail {

namespace {

struct Point2 {
  Real x;
  Real y;
};

Real cross2(const Point2& o, const Point2& a, const Point2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

Vec3 unit_normal(const TriangleVertices& t) {
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const Real len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3::UnitZ();
}

Real coordinate_scale(const TriangleVertices& t_a, const TriangleVertices& t_b) {
  Real s = 1;
  for (const TriangleVertices* t : {&t_a, &t_b}) {
    for (const Vec3& p : *t) s = std::max(s, p.cwiseAbs().maxCoeff());
  }
  return s;
}

/// The points where closed triangle t meets a plane, from the exact sides
/// `sign` and the rounded signed distances `dist` of its vertices: vertices
/// on the plane and crossings of edges whose ends lie strictly on both sides.
std::vector<Vec3> plane_cut(const TriangleVertices& t, const std::array<int, 3>& sign,
                            const std::array<Real, 3>& dist) {
  std::vector<Vec3> points;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (sign[i] == 0) points.push_back(t[i]);
    if (sign[i] * sign[j] < 0) {
      const Real denom = dist[i] - dist[j];
      const Real s = denom != 0 ? std::clamp(dist[i] / denom, Real{0}, Real{1}) : Real{0.5};
      points.push_back(t[i] + s * (t[j] - t[i]));
    }
  }
  return points;
}

/// The extreme points of `points` along `dir`.
struct Interval {
  Real lo = std::numeric_limits<Real>::infinity();
  Real hi = -std::numeric_limits<Real>::infinity();
  Vec3 p_lo = Vec3::Zero();
  Vec3 p_hi = Vec3::Zero();
};

Interval extent(const std::vector<Vec3>& points, const Vec3& dir) {
  Interval iv;
  for (const Vec3& p : points) {
    const Real s = p.dot(dir);
    if (s < iv.lo) iv = {s, iv.hi, p, iv.p_hi};
    if (s > iv.hi) iv = {iv.lo, s, iv.p_lo, p};
  }
  return iv;
}

bool crosses(const std::array<int, 3>& s) {
  const bool pos = s[0] > 0 || s[1] > 0 || s[2] > 0;
  const bool neg = s[0] < 0 || s[1] < 0 || s[2] < 0;
  return pos && neg;
}

void finish_segment(TrianglePiece& piece) {
  if (piece.points.size() == 2 && piece.points[0] == piece.points[1]) piece.points.pop_back();
  piece.length = piece.points.size() == 2 ? (piece.points[1] - piece.points[0]).norm() : 0;
  piece.centroid = piece.points.size() == 2 ? Vec3(0.5 * (piece.points[0] + piece.points[1]))
                                            : piece.points.front();
}

/// Segment of two triangles in general position: each triangle meets the
/// other's plane in a segment on the planes' common line, and the pair's
/// intersection is the overlap of the two.
void transversal_piece(const TriangleVertices& t_a, const TriangleVertices& t_b,
                       const std::array<int, 3>& s_a, const std::array<int, 3>& s_b,
                       TrianglePiece& piece) {
  std::array<Real, 3> d_a;
  std::array<Real, 3> d_b;
  for (int i = 0; i < 3; ++i) {
    d_a[i] = (t_a[i] - t_b[0]).dot(piece.n_b);
    d_b[i] = (t_b[i] - t_a[0]).dot(piece.n_a);
  }
  const std::vector<Vec3> cut_a = plane_cut(t_a, s_a, d_a);
  const std::vector<Vec3> cut_b = plane_cut(t_b, s_b, d_b);
  Vec3 dir = piece.n_a.cross(piece.n_b);
  if (dir.norm() > 0) {
    dir.normalize();
  } else {
    dir = (cut_a.back() - cut_a.front()).normalized();
  }
  const Interval ia = extent(cut_a, dir);
  const Interval ib = extent(cut_b, dir);
  const Vec3 lo = ia.lo >= ib.lo ? ia.p_lo : ib.p_lo;
  const Vec3 hi = ia.hi <= ib.hi ? ia.p_hi : ib.p_hi;
  if (std::max(ia.lo, ib.lo) <= std::min(ia.hi, ib.hi)) {
    piece.points = {lo, hi};
  } else {
    // Empty only by rounding of a pair that touches at one point.
    piece.points = {Vec3(0.5 * (lo + hi))};
  }
  finish_segment(piece);
  const auto zeros = [](const std::array<int, 3>& s) {
    return (s[0] == 0) + (s[1] == 0) + (s[2] == 0);
  };
  piece.share = (zeros(s_a) == 2 ? 0.5 : 1.0) * (zeros(s_b) == 2 ? 0.5 : 1.0);

  // B's triangle resting on A's face (edge or vertex of B on it): A's normal;
  // A's feature on B's face: minus B's normal; otherwise both surfaces.
  const bool a_crosses = crosses(s_a);
  const bool b_crosses = crosses(s_b);
  if (a_crosses && !b_crosses) {
    piece.normal = piece.n_a;
  } else if (b_crosses && !a_crosses) {
    piece.normal = -piece.n_b;
  } else {
    const Vec3 n = piece.n_a - piece.n_b;
    piece.normal = n.norm() > 1e-12 ? Vec3(n.normalized()) : piece.n_a;
  }
}

/// Overlap polygon of coplanar triangles: T_b projected into T_a's plane and
/// clipped by T_a's three edge lines (closed, with a rounding allowance).
void coplanar_piece(const TriangleVertices& t_a, const TriangleVertices& t_b, Real allowance,
                    TrianglePiece& piece) {
  const Vec3 u = (t_a[1] - t_a[0]).normalized();
  const Vec3 v = piece.n_a.cross(u);
  const auto to_plane = [&](const Vec3& p) {
    const Vec3 d = p - t_a[0];
    return Point2{d.dot(u), d.dot(v)};
  };
  const std::array<Point2, 3> a = {to_plane(t_a[0]), to_plane(t_a[1]), to_plane(t_a[2])};
  std::vector<Point2> poly = {to_plane(t_b[0]), to_plane(t_b[1]), to_plane(t_b[2])};
  if (cross2(poly[0], poly[1], poly[2]) < 0) std::swap(poly[1], poly[2]);

  std::vector<Point2> next;
  for (int e = 0; e < 3; ++e) {
    const Point2& e0 = a[e];
    const Point2& e1 = a[(e + 1) % 3];
    const Real len = std::hypot(e1.x - e0.x, e1.y - e0.y);
    // Signed distance left of the edge; T_a is counter-clockwise, so left is inside.
    const auto side = [&](const Point2& p) { return cross2(e0, e1, p) / len; };
    next.clear();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Point2& p = poly[i];
      const Point2& q = poly[(i + 1) % poly.size()];
      const Real sp = side(p);
      const Real sq = side(q);
      const bool in_p = sp >= -allowance;
      const bool in_q = sq >= -allowance;
      if (in_p != in_q) {
        const Real s = std::clamp(sp / (sp - sq), Real{0}, Real{1});
        next.push_back({p.x + s * (q.x - p.x), p.y + s * (q.y - p.y)});
      }
      if (in_q) next.push_back(q);
    }
    poly.swap(next);
    if (poly.empty()) break;
  }

  // Drop repeated points (a corner clipped at a vertex).
  next.clear();
  for (const Point2& p : poly) {
    if (next.empty() || std::hypot(p.x - next.back().x, p.y - next.back().y) > allowance) {
      next.push_back(p);
    }
  }
  while (next.size() > 1 &&
         std::hypot(next.front().x - next.back().x, next.front().y - next.back().y) <= allowance) {
    next.pop_back();
  }
  poly.swap(next);
  if (poly.empty()) {
    // Only by rounding of a pair that touches at a point: B's vertex deepest inside T_a.
    Real best = -std::numeric_limits<Real>::infinity();
    for (const Vec3& p : t_b) {
      const Point2 q = to_plane(p);
      Real worst = std::numeric_limits<Real>::infinity();
      for (int e = 0; e < 3; ++e) worst = std::min(worst, cross2(a[e], a[(e + 1) % 3], q));
      if (worst > best) {
        best = worst;
        poly = {q};
      }
    }
  }

  // Area and centroid by the shoelace formula, about the first point.
  Real area2 = 0;
  Real cx = 0;
  Real cy = 0;
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
    const Real w = cross2(poly[0], poly[i], poly[i + 1]);
    area2 += w;
    cx += w * (poly[0].x + poly[i].x + poly[i + 1].x) / 3;
    cy += w * (poly[0].y + poly[i].y + poly[i + 1].y) / 3;
  }
  const auto to_space = [&](Real x, Real y) { return Vec3(t_a[0] + x * u + y * v); };
  piece.points.clear();
  for (const Point2& p : poly) piece.points.push_back(to_space(p.x, p.y));
  piece.area = 0.5 * std::abs(area2);

  Real longest = 0;
  for (std::size_t i = 0; i < piece.points.size(); ++i) {
    for (std::size_t j = i + 1; j < piece.points.size(); ++j) {
      longest = std::max(longest, (piece.points[i] - piece.points[j]).norm());
    }
  }
  if (piece.area > allowance * longest) {
    piece.centroid = to_space(cx / area2, cy / area2);
  } else {
    piece.area = 0;
    piece.length = longest;
    piece.share = 0.25;  // coplanar triangles touch along edges of both
    Vec3 sum = Vec3::Zero();
    for (const Vec3& p : piece.points) sum += p;
    piece.centroid = sum / static_cast<Real>(piece.points.size());
  }
  piece.normal = piece.n_a;
}

/// Closest distance between segments [p0, p1] and [q0, q1] (either may be a point).
Real segment_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  Vec3 x, y;
  return std::sqrt(segment_distance_squared(p0, p1, q0, q1, x, y));
}

/// Distance from `p` to the polygon of `piece` when p projects inside it, else infinity.
Real distance_above_polygon(const Vec3& p, const TrianglePiece& piece) {
  const std::vector<Vec3>& poly = piece.points;
  const Vec3& n = piece.n_a;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % poly.size()];
    if ((b - a).cross(p - a).dot(n) < 0) return std::numeric_limits<Real>::infinity();
  }
  return std::abs((p - poly[0]).dot(n));
}

}  // namespace

TrianglePiece intersect_triangles(const TriangleVertices& t_a, const TriangleVertices& t_b,
                                  Real coplanar_tolerance) {
  TrianglePiece piece;
  piece.n_a = unit_normal(t_a);
  piece.n_b = unit_normal(t_b);

  // Exact sides of each triangle's vertices against the other's plane.
  std::array<int, 3> s_a;
  std::array<int, 3> s_b;
  for (int i = 0; i < 3; ++i) {
    s_a[i] = orient3d_filtered(t_b[0], t_b[1], t_b[2], t_a[i]);
    s_b[i] = orient3d_filtered(t_a[0], t_a[1], t_a[2], t_b[i]);
  }

  // Coplanar: exactly, or every vertex within the tolerance of the other plane.
  bool coplanar = s_b[0] == 0 && s_b[1] == 0 && s_b[2] == 0;
  if (!coplanar) {
    Real far = 0;
    for (int i = 0; i < 3; ++i) {
      far = std::max(far, std::abs((t_a[i] - t_b[0]).dot(piece.n_b)));
      far = std::max(far, std::abs((t_b[i] - t_a[0]).dot(piece.n_a)));
    }
    coplanar = far <= coplanar_tolerance;
  }

  if (coplanar) {
    piece.coplanar = true;
    piece.opposed = piece.n_a.dot(piece.n_b) < 0;
    const Real allowance = 64 * std::numeric_limits<Real>::epsilon() * coordinate_scale(t_a, t_b);
    coplanar_piece(t_a, t_b, allowance, piece);
  } else {
    transversal_piece(t_a, t_b, s_a, s_b, piece);
  }
  return piece;
}

Real piece_distance(const TrianglePiece& p, const TrianglePiece& q) {
  Real best = std::numeric_limits<Real>::infinity();
  const auto edges = [](const TrianglePiece& x, auto&& visit) {
    const std::size_t n = x.points.size();
    if (n <= 2) {
      visit(x.points.front(), x.points.back());
      return;
    }
    for (std::size_t i = 0; i < n; ++i) visit(x.points[i], x.points[(i + 1) % n]);
  };
  edges(p, [&](const Vec3& p0, const Vec3& p1) {
    edges(q, [&](const Vec3& q0, const Vec3& q1) {
      best = std::min(best, segment_distance(p0, p1, q0, q1));
    });
  });
  if (p.area > 0) {
    for (const Vec3& x : q.points) best = std::min(best, distance_above_polygon(x, p));
  }
  if (q.area > 0) {
    for (const Vec3& x : p.points) best = std::min(best, distance_above_polygon(x, q));
  }
  return best;
}

}  // namespace dovetail::collision::detail
