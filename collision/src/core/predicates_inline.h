#pragma once
/// \file predicates_inline.h
/// Private, inlinable fast paths of the exact predicates: a floating-point
/// evaluation with a proven error bound (the filter) that decides almost every
/// call, and an out-of-line exact evaluation (predicates.cpp) for the rest.
///
/// Error bound of the filters. Let eps = 2^-53 (unit roundoff of double,
/// round to nearest). Inside the range documented in predicates.cpp every
/// operation below satisfies fl(x op y) = (x op y)(1 + d), |d| <= eps: results
/// in the subnormal range are exact there, because every intermediate value
/// is an integer multiple of 2^-1074.
///
/// orient3d(a, b, c, d) is evaluated as (u x v) . w with u = b - a,
/// v = c - a, w = d - a:
///   n_x = u_y v_z - u_z v_y (and cyclically),  det = (n_x w_x + n_y w_y) + n_z w_z.
/// The exact determinant D is a signed sum of six terms U_i V_j W_k of the
/// exact differences. In the computed det each term carries at most eight
/// rounding factors (three differences, the inner product, the inner
/// subtraction, the outer product, two additions), so
///   |det - D| <= g8 * P,   g8 = 8 eps / (1 - 8 eps),   P = sum |U_i V_j W_k|.
/// The permanent perm = (na_x |w_x| + na_y |w_y|) + na_z |w_z| with
/// na_x = |u_y v_z| + |u_z v_y| (the same rounded products) has the same
/// eight factors per term, each >= 1 - eps, so perm >= (1 - eps)^8 P. With
/// bound = fl(kOrient3dBound * perm) >= (1 - eps)^9 kOrient3dBound P and
///   kOrient3dBound = (8 + 256 eps) eps >= g8 / (1 - eps)^9,
/// bound >= |det - D|, hence |det| > bound implies sign(det) = sign(D). When
/// bound falls into the subnormal range it is a multiple of 2^-1074 rounded by
/// at most 2^-1075, and so is |det|, so |det| > bound still implies
/// |det| >= kOrient3dBound * perm + 2^-1075 > |det - D|.
///
/// orient2d: det = (b_x - a_x)(c_y - a_y) - (b_y - a_y)(c_x - a_x), four
/// rounding factors per term (two differences, product, subtraction), the
/// permanent |l| + |r| likewise, so kOrient2dBound = (4 + 64 eps) eps
/// >= g4 / (1 - eps)^5 by the same argument.
///
/// Twice-precision filter (orient3d_twice_precision, in predicates.cpp), the
/// stage for inputs the first filter leaves open, such as rotated coplanar
/// faces. With rounded differences u = fl(b - a) etc. and exact tails
/// u' = (b - a) - u, |u'| <= eps |u|, let P = sum |u_i v_j w_k| over the six
/// terms. Then D = B + R1 + R2, where B = det[u, v, w], R1 = det[u', v, w] +
/// det[u, v', w] + det[u, v, w'] and |R2| <= (3 eps^2 + eps^3) P. B is
/// formed from exact products: minor_k = (p - q) exactly as minor + minor_low
/// up to (3 + 6 eps) eps^2 A_k (A_k = |v_i w_j| + |v_j w_i|), each term u_k
/// minor_k as high + low up to 8.01 eps^2 |u_k| A_k, the highs summed exactly
/// and the five lows in floating point (20.01 eps^2 P); R1 in floating point
/// costs at most 20.01 eps^2 P (seven roundings on terms totalling 2 eps P,
/// four on u' minor, plus |u'| |minor_k - minor| <= 2.01 eps^2 |u_k| A_k); the
/// two final additions add 8.01 eps^2 P + eps |det|. In all
///   |det - D| <= 59.1 eps^2 P + eps |det| / (1 - eps),
/// and with perm >= (1 - eps)^5 P (five roundings per term),
/// kOrient3dBoundTwice = 64 eps^2 gives |det| > bound => sign(det) = sign(D)
/// (a subnormal bound is handled as above). It decides unless |D| is below
/// about 1e-30 P.
///
/// TrianglePlane evaluates the same expression as orient3d, with u, v, n and
/// na computed once per triangle, and one permanent for three points built
/// from the componentwise maximum of their |w|: rounding is monotone, so that
/// permanent is at least each point's own one and the bound holds for all three.

#include <cmath>

#include "dovetail/collision/types.h"

namespace dovetail::collision::detail {

inline constexpr Real kEpsilon = 0x1p-53;
inline constexpr Real kOrient3dBound = (8.0 + 256.0 * kEpsilon) * kEpsilon;
inline constexpr Real kOrient2dBound = (4.0 + 64.0 * kEpsilon) * kEpsilon;
inline constexpr Real kOrient3dBoundTwice = 64.0 * kEpsilon * kEpsilon;

/// Sign of det[b - a, c - a, d - a] by exact expansion arithmetic alone.
int orient3d_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Sign of (b - a) x (c - a) in 2-D by exact expansion arithmetic alone.
int orient2d_exact(Real ax, Real ay, Real bx, Real by, Real cx, Real cy);

/// Stages after the first filter, cheapest first: coincident points, a
/// rounding-free plain evaluation, the twice-precision filter, the exact
/// evaluation. Same result as orient3d_exact.
int orient3d_adaptive(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Coincident points, then orient2d_exact.
int orient2d_adaptive(Real ax, Real ay, Real bx, Real by, Real cx, Real cy);

/// True, with the exact sign in `sign`, when the plain evaluation of
/// orient3d_filtered commits no rounding error (small integer or grid
/// coordinates, exactly coplanar ones included).
bool orient3d_rounding_free(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, int& sign);

/// True, with the exact sign in `sign`, when the twice-precision evaluation
/// decides (see kOrient3dBoundTwice).
bool orient3d_twice_precision(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                              int& sign);

/// Filtered orient3d: same result as orient3d_exact.
inline int orient3d_filtered(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Real ux = b.x() - a.x(), uy = b.y() - a.y(), uz = b.z() - a.z();
  const Real vx = c.x() - a.x(), vy = c.y() - a.y(), vz = c.z() - a.z();
  const Real wx = d.x() - a.x(), wy = d.y() - a.y(), wz = d.z() - a.z();
  const Real uyvz = uy * vz, uzvy = uz * vy;
  const Real uzvx = uz * vx, uxvz = ux * vz;
  const Real uxvy = ux * vy, uyvx = uy * vx;
  const Real det = ((uyvz - uzvy) * wx + (uzvx - uxvz) * wy) + (uxvy - uyvx) * wz;
  const Real perm = ((std::abs(uyvz) + std::abs(uzvy)) * std::abs(wx) +
                     (std::abs(uzvx) + std::abs(uxvz)) * std::abs(wy)) +
                    (std::abs(uxvy) + std::abs(uyvx)) * std::abs(wz);
  const Real bound = kOrient3dBound * perm;
  if (det > bound) return 1;
  if (det < -bound) return -1;
  return orient3d_adaptive(a, b, c, d);
}

/// Filtered orient2d: same result as orient2d_exact.
inline int orient2d_filtered(Real ax, Real ay, Real bx, Real by, Real cx, Real cy) {
  const Real left = (bx - ax) * (cy - ay);
  const Real right = (by - ay) * (cx - ax);
  const Real det = left - right;
  const Real bound = kOrient2dBound * (std::abs(left) + std::abs(right));
  if (det > bound) return 1;
  if (det < -bound) return -1;
  return orient2d_adaptive(ax, ay, bx, by, cx, cy);
}

/// The supporting plane of triangle (p, q, r), prepared once for exact side
/// tests of several points: side(x) = orient3d(p, q, r, x). Keeps references
/// to the three vertices, which must outlive it.
class TrianglePlane {
 public:
  TrianglePlane(const Vec3& p, const Vec3& q, const Vec3& r) : p_(p), q_(q), r_(r) {
    const Real ux = q.x() - p.x(), uy = q.y() - p.y(), uz = q.z() - p.z();
    const Real vx = r.x() - p.x(), vy = r.y() - p.y(), vz = r.z() - p.z();
    const Real uyvz = uy * vz, uzvy = uz * vy;
    const Real uzvx = uz * vx, uxvz = ux * vz;
    const Real uxvy = ux * vy, uyvx = uy * vx;
    n_[0] = uyvz - uzvy;
    n_[1] = uzvx - uxvz;
    n_[2] = uxvy - uyvx;
    n_abs_[0] = std::abs(uyvz) + std::abs(uzvy);
    n_abs_[1] = std::abs(uzvx) + std::abs(uxvz);
    n_abs_[2] = std::abs(uxvy) + std::abs(uyvx);
  }

  /// Rounded normal (q - p) x (r - p); only a hint, never used for a decision.
  const Real* approximate_normal() const { return n_; }

  /// Exact signs of orient3d(p, q, r, x) for x = a, b, c, written to `out`.
  void sides(const Vec3& a, const Vec3& b, const Vec3& c, int out[3]) const {
    const Vec3* const points[3] = {&a, &b, &c};
    Real det[3];
    Real w_max[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) {
      const Real wx = (*points[i]).x() - p_.x();
      const Real wy = (*points[i]).y() - p_.y();
      const Real wz = (*points[i]).z() - p_.z();
      det[i] = (n_[0] * wx + n_[1] * wy) + n_[2] * wz;
      w_max[0] = std::abs(wx) > w_max[0] ? std::abs(wx) : w_max[0];
      w_max[1] = std::abs(wy) > w_max[1] ? std::abs(wy) : w_max[1];
      w_max[2] = std::abs(wz) > w_max[2] ? std::abs(wz) : w_max[2];
    }
    const Real perm = (n_abs_[0] * w_max[0] + n_abs_[1] * w_max[1]) + n_abs_[2] * w_max[2];
    const Real bound = kOrient3dBound * perm;
    for (int i = 0; i < 3; ++i) out[i] = (det[i] > bound) - (det[i] < -bound);
    for (int i = 0; i < 3; ++i) {
      if (out[i] == 0) out[i] = orient3d_adaptive(p_, q_, r_, *points[i]);
    }
  }

 private:
  const Vec3& p_;
  const Vec3& q_;
  const Vec3& r_;
  Real n_[3];
  Real n_abs_[3];
};

}  // namespace dovetail::collision::detail
