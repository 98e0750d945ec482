#pragma once
/// \file convex_simplex.h
/// Private: the point of a simplex (1 to 4 points) nearest the origin, by the
/// signed-volume method of Montanari, Petrinic and Barbieri (2017): the
/// barycentric coordinates of the origin's projection come from signed
/// volumes (areas in the coordinate plane where the simplex's shadow is
/// largest); when one is not positive, the nearest point lies on the face
/// opposite that vertex, which is searched in turn. Used by GJK and by the
/// separating-plane search.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "dovetail/collision/types.h"

namespace dovetail::collision::detail {

/// The point of a sub-simplex nearest the origin: v = sum lambda_k w[index_k].
struct Nearest {
  Vec3 v = Vec3::Zero();
  Real vv = 0;
  int count = 0;
  int index[4] = {0, 0, 0, 0};
  Real lambda[4] = {0, 0, 0, 0};
};

inline Nearest make_nearest(const Vec3* s, int count, const int* index, const Real* lambda) {
  Nearest r;
  r.count = 0;
  for (int k = 0; k < count; ++k) {
    if (!(lambda[k] > 0)) continue;
    r.index[r.count] = index[k];
    r.lambda[r.count] = lambda[k];
    r.v += lambda[k] * s[index[k]];
    ++r.count;
  }
  r.vv = r.v.squaredNorm();
  return r;
}

inline Nearest nearest_point(const Vec3* s, int i) {
  const Real one = 1;
  return make_nearest(s, 1, &i, &one);
}

/// Segment: the origin projected on the line, clamped to the ends.
inline Nearest nearest_segment(const Vec3* s, int i0, int i1) {
  const Vec3& p = s[i0];
  const Vec3 d = s[i1] - p;
  const Real dd = d.squaredNorm();
  const Real t = dd > 0 ? -p.dot(d) / dd : 0;
  if (!(t > 0)) return nearest_point(s, i0);
  if (t >= 1) return nearest_point(s, i1);
  const int index[2] = {i0, i1};
  const Real lambda[2] = {1 - t, t};
  return make_nearest(s, 2, index, lambda);
}

/// 2-D signed area of (p, q, r) in coordinates (i, j).
inline Real area2(const Vec3& p, const Vec3& q, const Vec3& r, int i, int j) {
  return (q[i] - p[i]) * (r[j] - p[j]) - (q[j] - p[j]) * (r[i] - p[i]);
}

/// Keeps the nearer of two candidates (the first on ties).
inline void keep_nearer(Nearest& best, bool& have, const Nearest& candidate) {
  if (!have || candidate.vv < best.vv) {
    best = candidate;
    have = true;
  }
}

/// Triangle: barycentric coordinates of the origin's projection from signed
/// areas in the coordinate plane where the triangle's shadow is largest.
inline Nearest nearest_triangle(const Vec3* s, int i0, int i1, int i2) {
  const Vec3& p0 = s[i0];
  const Vec3& p1 = s[i1];
  const Vec3& p2 = s[i2];
  const Vec3 e1 = p1 - p0, e2 = p2 - p0;
  const Vec3 n = e1.cross(e2);
  const Real nn = n.squaredNorm();
  // Projection of the origin on the plane; the largest normal component picks the shadow.
  int k = 0;
  if (std::abs(n.y()) > std::abs(n[k])) k = 1;
  if (std::abs(n.z()) > std::abs(n[k])) k = 2;
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  const Real degenerate = 64 * 0x1p-53 * e1.norm() * e2.norm();
  if (nn > 0 && std::abs(n[k]) > degenerate) {
    const Vec3 p = n * (p0.dot(n) / nn);
    const Real total = area2(p0, p1, p2, i, j);
    const Real c0 = area2(p, p1, p2, i, j);
    const Real c1 = area2(p0, p, p2, i, j);
    const Real c2 = area2(p0, p1, p, i, j);
    const bool s0 = c0 * total > 0, s1 = c1 * total > 0, s2 = c2 * total > 0;
    if (s0 && s1 && s2) {
      const int index[3] = {i0, i1, i2};
      const Real sum = c0 + c1 + c2;
      const Real lambda[3] = {c0 / sum, c1 / sum, c2 / sum};
      return make_nearest(s, 3, index, lambda);
    }
    // Outside: the nearest point is on an edge whose opposite coordinate is not positive.
    Nearest best;
    bool have = false;
    if (!s0) keep_nearer(best, have, nearest_segment(s, i1, i2));
    if (!s1) keep_nearer(best, have, nearest_segment(s, i0, i2));
    if (!s2) keep_nearer(best, have, nearest_segment(s, i0, i1));
    return best;
  }
  // Degenerate triangle: the best of its edges.
  Nearest best;
  bool have = false;
  keep_nearer(best, have, nearest_segment(s, i0, i1));
  keep_nearer(best, have, nearest_segment(s, i0, i2));
  keep_nearer(best, have, nearest_segment(s, i1, i2));
  return best;
}

inline Real det3(const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(b.cross(c)); }

/// Tetrahedron: signed volumes with the origin in place of each vertex.
inline Nearest nearest_tetrahedron(const Vec3* s) {
  const Vec3& p0 = s[0];
  const Vec3& p1 = s[1];
  const Vec3& p2 = s[2];
  const Vec3& p3 = s[3];
  const Vec3 e1 = p1 - p0, e2 = p2 - p0, e3 = p3 - p0;
  const Real total = det3(e1, e2, e3);
  const Real degenerate = 64 * 0x1p-53 * e1.norm() * e2.norm() * e3.norm();
  if (std::abs(total) > degenerate) {
    const Real c0 = det3(p1, p2, p3);
    const Real c1 = det3(-p0, e2, e3);
    const Real c2 = det3(e1, -p0, e3);
    const Real c3 = det3(e1, e2, -p0);
    const bool s0 = c0 * total > 0, s1 = c1 * total > 0, s2 = c2 * total > 0, s3 = c3 * total > 0;
    if (s0 && s1 && s2 && s3) {
      const int index[4] = {0, 1, 2, 3};
      const Real sum = c0 + c1 + c2 + c3;
      const Real lambda[4] = {c0 / sum, c1 / sum, c2 / sum, c3 / sum};
      Nearest r = make_nearest(s, 4, index, lambda);
      r.v = Vec3::Zero();  // the origin is inside
      r.vv = 0;
      return r;
    }
    Nearest best;
    bool have = false;
    if (!s0) keep_nearer(best, have, nearest_triangle(s, 1, 2, 3));
    if (!s1) keep_nearer(best, have, nearest_triangle(s, 0, 2, 3));
    if (!s2) keep_nearer(best, have, nearest_triangle(s, 0, 1, 3));
    if (!s3) keep_nearer(best, have, nearest_triangle(s, 0, 1, 2));
    return best;
  }
  // Flat tetrahedron: the best of its faces.
  Nearest best;
  bool have = false;
  keep_nearer(best, have, nearest_triangle(s, 1, 2, 3));
  keep_nearer(best, have, nearest_triangle(s, 0, 2, 3));
  keep_nearer(best, have, nearest_triangle(s, 0, 1, 3));
  keep_nearer(best, have, nearest_triangle(s, 0, 1, 2));
  return best;
}

inline Nearest nearest(const Vec3* s, int count) {
  switch (count) {
    case 1:
      return nearest_point(s, 0);
    case 2:
      return nearest_segment(s, 0, 1);
    case 3:
      return nearest_triangle(s, 0, 1, 2);
    default:
      return nearest_tetrahedron(s);
  }
}

/// One simplex vertex: a difference w of two hull points (A - B for GJK,
/// B - A for the separating-plane search), with the points and their indices.
struct SimplexPoint {
  Vec3 w, a, b;
  std::uint32_t ia = 0, ib = 0;
};

/// Which difference of the two hulls a search works on.
enum class Difference { kAMinusB, kBMinusA };

/// The simplex point of vertex ia of A and vertex ib of B, B's vertex mapped
/// into A's frame by X_AB.apply (as every hull query maps it).
inline SimplexPoint simplex_point(const std::vector<Vec3>& vertices_a,
                                  const std::vector<Vec3>& vertices_b, const Transform& X_AB,
                                  std::uint32_t ia, std::uint32_t ib, Difference difference) {
  SimplexPoint s;
  s.ia = ia;
  s.ib = ib;
  s.a = vertices_a[ia];
  s.b = X_AB.apply(vertices_b[ib]);
  s.w = difference == Difference::kAMinusB ? Vec3(s.a - s.b) : Vec3(s.b - s.a);
  return s;
}

/// Up to four simplex vertices (with their differences w side by side for
/// the sub-distance) and the weights of the nearest point.
struct Simplex {
  SimplexPoint p[4];
  Vec3 w[4];
  Real lambda[4] = {0, 0, 0, 0};
  int size = 0;

  void add(const SimplexPoint& s) {
    p[size] = s;
    w[size] = s.w;
    ++size;
  }
  Nearest nearest() const { return detail::nearest(w, size); }
  /// True when the pair (ia, ib) is already a vertex.
  bool contains(std::uint32_t ia, std::uint32_t ib) const {
    for (int k = 0; k < size; ++k) {
      if (p[k].ia == ia && p[k].ib == ib) return true;
    }
    return false;
  }
  /// Keeps the vertices `r` uses, with their weights (r.index ascends, so
  /// moving them forward in place is safe).
  void reduce(const Nearest& r) {
    for (int k = 0; k < r.count; ++k) {
      if (r.index[k] != k) {
        p[k] = p[r.index[k]];
        w[k] = w[r.index[k]];
      }
      lambda[k] = r.lambda[k];
    }
    size = r.count;
  }

  /// Adds the vertex pairs a previous search left in its cache (the first
  /// `cached_size` of `ia`, `ib`), skipping pairs that are not vertices of
  /// hulls with `na` and `nb` vertices; `point(ia, ib)` makes a vertex.
  template <typename MakePoint>
  void load(const std::array<std::uint32_t, 4>& ia, const std::array<std::uint32_t, 4>& ib,
            int cached_size, std::uint32_t na, std::uint32_t nb, MakePoint&& point) {
    const int n = std::clamp(cached_size, 0, 4);
    for (int k = 0; k < n; ++k) {
      if (ia[k] < na && ib[k] < nb) add(point(ia[k], ib[k]));
    }
  }

  /// Leaves the vertex pairs in a cache for the next search.
  void store(std::array<std::uint32_t, 4>& ia, std::array<std::uint32_t, 4>& ib,
             int& cached_size) const {
    cached_size = size;
    for (int k = 0; k < size; ++k) {
      ia[k] = p[k].ia;
      ib[k] = p[k].ib;
    }
  }
};

}  // namespace dovetail::collision::detail
