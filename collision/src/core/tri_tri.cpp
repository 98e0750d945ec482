#include "dovetail/collision/tri_tri.h"

#include <array>
#include <cmath>
#include <utility>

#include "core/predicates_inline.h"

// Guigue & Devillers, "Faster triangle-triangle intersection tests" (JGT
// 2003), with every decision the sign of an exact determinant.
//
// Let s(x) = orient3d(p2, q2, r2, x) be the side of x against T2's plane and
// t(x) = orient3d(p1, q1, r1, x) against T1's plane. After the plane-side
// rejections, both triangles are brought into a canonical form: T1 is rotated
// so that p1 is the apex, alone on one side (or on the plane while q1, r1 are
// strictly on one side), and q2, r2 are swapped if needed so that s(p1) >= 0
// >= s(q1), s(r1); the same is done for T2 against T1's plane (swapping q1, r1).
// The closed segments T1 n plane2 and T2 n plane1 then lie on the line
// L = plane1 n plane2; with L directed along n1 x n2, the first runs from its
// point on p1r1 to its point on p1q1, the second from its point on p2q2 to its
// point on p2r2. For a = q1 - p1, b = q2 - p2 one has
//   orient3d(p1, q1, p2, q2) = -tau * det[a, b, n1 x n2],  det[a, b, n1 x n2] = -(a.n2)(b.n1) < 0,
// where tau is the signed distance along L from the point on p1q1 to the point
// on p2q2 (likewise for r1, r2), so the segments overlap exactly when
//   orient3d(p1, q1, p2, q2) <= 0 and orient3d(p1, r1, p2, r2) >= 0.

namespace dovetail::collision {

namespace {

using Signs = std::array<int, 3>;
using Triangle = std::array<const Vec3*, 3>;

bool strictly_one_side(const Signs& s) { return s[0] != 0 && s[0] == s[1] && s[1] == s[2]; }

bool all_on_plane(const Signs& s) { return s[0] == 0 && s[1] == 0 && s[2] == 0; }

/// The vertex alone on its side of the other plane, and the side (+1/-1)
/// that the canonical form puts it on.
struct Apex {
  int index = 0;
  int side = 1;
};

/// Apex of a sign triple that is neither all zero nor all equal and nonzero.
Apex find_apex(const Signs& s) {
  // A vertex strictly on one side with both others on the other closed side.
  for (int i = 0; i < 3; ++i) {
    if (s[i] != 0 && s[(i + 1) % 3] != s[i] && s[(i + 2) % 3] != s[i]) return {i, s[i]};
  }
  // Otherwise two vertices are strictly on one side and the apex is on the plane.
  for (int i = 0; i < 3; ++i) {
    if (s[i] == 0) return {i, -s[(i + 1) % 3]};
  }
  return {};
}

Triangle rotated(const Triangle& t, int first) {
  return {t[first], t[(first + 1) % 3], t[(first + 2) % 3]};
}

/// A point of the coordinate plane that a projection keeps.
struct Point2 {
  Real x;
  Real y;
};

int orient(const Point2& a, const Point2& b, const Point2& c) {
  return detail::orient2d_filtered(a.x, a.y, b.x, b.y, c.x, c.y);
}

Point2 project(const Vec3& p, int drop_axis) {
  return {p[(drop_axis + 1) % 3], p[(drop_axis + 2) % 3]};
}

/// Orientation of t's projection along `drop_axis` (the exact normal component).
int projected_orientation(const Triangle& t, int drop_axis) {
  return orient(project(*t[0], drop_axis), project(*t[1], drop_axis), project(*t[2], drop_axis));
}

/// An axis along which t1 (else t2) projects to a non-degenerate triangle,
/// trying the largest components of the rounded normal first.
int projection_axis(const Triangle& t1, const Triangle& t2, const Real* normal_hint) {
  std::array<int, 3> order = {0, 1, 2};
  const auto larger = [&](int a, int b) {
    return std::abs(normal_hint[a]) > std::abs(normal_hint[b]);
  };
  if (larger(order[1], order[0])) std::swap(order[0], order[1]);
  if (larger(order[2], order[1])) std::swap(order[1], order[2]);
  if (larger(order[1], order[0])) std::swap(order[0], order[1]);
  for (const Triangle* t : {&t1, &t2}) {
    for (int axis : order) {
      if (projected_orientation(*t, axis) != 0) return axis;
    }
  }
  return 2;
}

/// True when all three points lie strictly right of the directed line a -> b.
bool strictly_right_of(const Point2& a, const Point2& b, const std::array<Point2, 3>& points) {
  for (const Point2& p : points) {
    if (orient(a, b, p) >= 0) return false;
  }
  return true;
}

/// True when no edge line of counter-clockwise `t` has all of `other` strictly outside.
bool no_separating_edge(const std::array<Point2, 3>& t, const std::array<Point2, 3>& other) {
  for (int i = 0; i < 3; ++i) {
    if (strictly_right_of(t[i], t[(i + 1) % 3], other)) return false;
  }
  return true;
}

std::array<Point2, 3> projected_ccw(const Triangle& t, int drop_axis) {
  std::array<Point2, 3> p = {project(*t[0], drop_axis), project(*t[1], drop_axis),
                             project(*t[2], drop_axis)};
  if (orient(p[0], p[1], p[2]) < 0) std::swap(p[1], p[2]);
  return p;
}

/// Closed coplanar triangles, compared in a projection that is one-to-one on
/// their plane. Two convex polygons are disjoint exactly when the origin lies
/// outside their Minkowski difference, i.e. strictly outside one of its edge
/// lines; those are the edge lines of the two triangles, so the triangles
/// intersect unless one of them has the other strictly outside an edge line.
bool coplanar_triangles_intersect(const Triangle& t1, const Triangle& t2, const Real* normal_hint) {
  const int axis = projection_axis(t1, t2, normal_hint);
  const std::array<Point2, 3> a = projected_ccw(t1, axis);
  const std::array<Point2, 3> b = projected_ccw(t2, axis);
  return no_separating_edge(a, b) && no_separating_edge(b, a);
}

/// Whether degenerate triangle `line` (its points on one line, with `sides`
/// against `t`'s plane neither all zero nor strictly one-sided) meets
/// triangle `t`: the line crosses t's plane at one point, which lies inside
/// `line`'s extent, and it meets t when that point is in t (closed): the
/// line through two of its points with different sides passes through t.
bool line_meets_triangle(const Triangle& line, const Signs& sides, const Triangle& t) {
  int u = 0;
  while (sides[u] == 0) ++u;
  int v = -1;
  for (int k = 0; k < 3; ++k) {
    if (sides[k] == -sides[u]) v = k;
  }
  if (v < 0) {
    for (int k = 0; k < 3; ++k) {
      if (sides[k] == 0) v = k;
    }
  }
  int positive = 0, negative = 0;
  for (int k = 0; k < 3; ++k) {
    const int o = detail::orient3d_filtered(*line[u], *line[v], *t[k], *t[(k + 1) % 3]);
    positive += o > 0;
    negative += o < 0;
  }
  return positive == 0 || negative == 0;
}

}  // namespace

bool triangles_intersect(const Vec3& p1, const Vec3& q1, const Vec3& r1, const Vec3& p2,
                         const Vec3& q2, const Vec3& r2) {
  // Sides of T1's vertices against T2's plane; reject when strictly on one side.
  Signs s1;
  detail::TrianglePlane(p2, q2, r2).sides(p1, q1, r1, s1.data());
  if (strictly_one_side(s1)) return false;

  // Sides of T2's vertices against T1's plane; the same rejection.
  const detail::TrianglePlane plane1(p1, q1, r1);
  Triangle t1 = {&p1, &q1, &r1};
  Triangle t2 = {&p2, &q2, &r2};
  Signs s2;
  plane1.sides(p2, q2, r2, s2.data());
  if (strictly_one_side(s2)) return false;

  // Every point lies on a degenerate triangle's "plane", so all-zero sides
  // mean: both triangles in one plane, or one triangle degenerate, its points
  // on a line that crosses the other's plane (a mesh has no degenerate
  // triangles, but a far pose can round one flat), or both degenerate. The
  // last gets the coplanar test: a defined verdict, but not an exact one
  // (two skew segments can be found to meet).
  const bool t1_on_plane2 = all_on_plane(s1);
  const bool t2_on_plane1 = all_on_plane(s2);
  if (t1_on_plane2 && t2_on_plane1) {
    return coplanar_triangles_intersect(t1, t2, plane1.approximate_normal());
  }
  if (t1_on_plane2) return line_meets_triangle(t2, s2, t1);
  if (t2_on_plane1) return line_meets_triangle(t1, s1, t2);

  // Canonical T1: apex first, on the positive side of T2's plane.
  const Apex apex1 = find_apex(s1);
  t1 = rotated(t1, apex1.index);
  if (apex1.side < 0) {
    std::swap(t2[1], t2[2]);
    std::swap(s2[1], s2[2]);
  }

  // Canonical T2: apex first, on the positive side of T1's plane.
  const Apex apex2 = find_apex(s2);
  t2 = rotated(t2, apex2.index);
  if (apex2.side < 0) std::swap(t1[1], t1[2]);

  // The two segments on the planes' common line overlap.
  return detail::orient3d_filtered(*t1[0], *t1[1], *t2[0], *t2[1]) <= 0 &&
         detail::orient3d_filtered(*t1[0], *t1[2], *t2[0], *t2[2]) >= 0;
}

}  // namespace dovetail::collision
