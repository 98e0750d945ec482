#include "dovetail/collision/predicates.h"

#include <cmath>

#include "core/expansion.h"
#include "core/predicates_inline.h"

// Exact evaluation by floating-point expansions (Shewchuk, "Adaptive Precision
// Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997): a
// number is held exactly as an unevaluated sum of doubles, nonoverlapping and
// ordered by increasing magnitude, with zero components removed; the sign of
// the sum is the sign of its last (largest) component. Coordinate differences
// are formed exactly as two-component expansions and multiplied out, so the
// result is the determinant of the given doubles, not of rounded differences.
//
// Range of exactness. Two-sum and two-diff are exact for any finite doubles;
// two-product (rounded product plus its error by std::fma) is exact when the
// error term is representable. Both filters and the exact stage are exact as
// stated when
//   * every coordinate is an integer multiple of 2^-358 (true for zero and for
//     every double of magnitude >= 2^-306, about 7.7e-93): then every
//     degree-3 quantity is a multiple of 2^-1074, so products and their error
//     terms are representable even when they are subnormal, and
//   * every |coordinate| <= 2^300 (about 2e90): differences stay below 2^301
//     and the largest term, 6 * (2^301)^3, far below the overflow threshold.
// Mesh validation bounds coordinates by 1e30 (< 2^100). Coordinates closer to
// zero than 2^-306 and not on that grid may make a product underflow; the
// result is then still computed without UB, but its sign may be wrong when the
// exact determinant is below about 2^-1074.

namespace dovetail::collision {

namespace {

using detail::fast_two_sum;
using detail::two_diff;
using detail::two_product;
using detail::two_sum;

/// Capacities, in components, of the expansions formed below.
constexpr int kDifference = 2;
constexpr int kProduct2 = 8;  // difference x difference
constexpr int kMinor = 16;    // difference of two such products
constexpr int kTerm = 64;     // difference x minor
constexpr int kDet3 = 3 * kTerm;
constexpr int kDet2 = 2 * kProduct2;

/// Exact a - b as an expansion in h (capacity kDifference); returns its length.
int difference(Real a, Real b, Real* h) {
  Real d, e;
  two_diff(a, b, d, e);
  int n = 0;
  if (e != 0) h[n++] = e;
  if (d != 0) h[n++] = d;
  return n;
}

/// h = e * b (capacity 2 * m); returns the length of h. Keeps e's order and
/// nonoverlapping property.
int scale_expansion(const Real* e, int m, Real b, Real* h) {
  if (m == 0 || b == 0) return 0;
  int n = 0;
  Real q, low;
  two_product(e[0], b, q, low);
  if (low != 0) h[n++] = low;
  for (int i = 1; i < m; ++i) {
    Real high_i, low_i, sum;
    two_product(e[i], b, high_i, low_i);
    two_sum(q, low_i, sum, low);
    if (low != 0) h[n++] = low;
    fast_two_sum(high_i, sum, q, low);
    if (low != 0) h[n++] = low;
  }
  if (q != 0) h[n++] = q;
  return n;
}

/// h = e + f (capacity m + n); returns the length of h. Merges the two
/// expansions by magnitude, then carries the running sum up through them.
int sum_expansions(const Real* e, int m, const Real* f, int n, Real* h) {
  int i = 0;
  int j = 0;
  auto next_smallest = [&]() -> Real {
    if (j >= n || (i < m && std::abs(e[i]) < std::abs(f[j]))) return e[i++];
    return f[j++];
  };
  const int total = m + n;
  if (total == 0) return 0;
  int k = 0;
  Real q = next_smallest();
  if (total > 1) {
    Real low;
    fast_two_sum(next_smallest(), q, q, low);
    if (low != 0) h[k++] = low;
    for (int c = 2; c < total; ++c) {
      two_sum(q, next_smallest(), q, low);
      if (low != 0) h[k++] = low;
    }
  }
  if (q != 0) h[k++] = q;
  return k;
}

/// h = s * e for a short expansion s (length <= 2) and e of length <= kMaxE
/// (capacity 4 * kMaxE); returns the length of h.
template <int kMaxE>
int multiply_by_short(const Real* s, int ns, const Real* e, int ne, Real* h) {
  if (ns == 0) return 0;
  if (ns == 1) return scale_expansion(e, ne, s[0], h);
  Real first[2 * kMaxE];
  Real second[2 * kMaxE];
  const int n_first = scale_expansion(e, ne, s[0], first);
  const int n_second = scale_expansion(e, ne, s[1], second);
  return sum_expansions(first, n_first, second, n_second, h);
}

void negate(Real* e, int m) {
  for (int i = 0; i < m; ++i) e[i] = -e[i];
}

/// h = a * d - b * c for exact differences a, b, c, d (capacity kMinor).
int difference_of_products(const Real* a, int na, const Real* b, int nb, const Real* c, int nc,
                           const Real* d, int nd, Real* h) {
  Real ad[kProduct2];
  Real bc[kProduct2];
  const int n_ad = multiply_by_short<kDifference>(a, na, d, nd, ad);
  const int n_bc = multiply_by_short<kDifference>(b, nb, c, nc, bc);
  negate(bc, n_bc);
  return sum_expansions(ad, n_ad, bc, n_bc, h);
}

int sign_of(const Real* e, int m) {
  if (m == 0) return 0;
  return e[m - 1] > 0 ? 1 : -1;
}

}  // namespace

namespace detail {

bool orient3d_rounding_free(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, int& sign) {
  // Every operation of the plain evaluation, checked by its exact error term;
  // gives up at the first level that rounds.
  Real u[3], v[3], w[3], error;
  bool exact = true;
  for (int k = 0; k < 3; ++k) {
    two_diff(b[k], a[k], u[k], error);
    exact &= error == 0;
    two_diff(c[k], a[k], v[k], error);
    exact &= error == 0;
    two_diff(d[k], a[k], w[k], error);
    exact &= error == 0;
  }
  if (!exact) return false;
  Real normal[3];
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3;
    const int j = (k + 2) % 3;
    Real left, right;
    two_product(u[i], v[j], left, error);
    exact &= error == 0;
    two_product(u[j], v[i], right, error);
    exact &= error == 0;
    two_diff(left, right, normal[k], error);
    exact &= error == 0;
  }
  if (!exact) return false;
  Real terms[3];
  for (int k = 0; k < 3; ++k) {
    two_product(normal[k], w[k], terms[k], error);
    exact &= error == 0;
  }
  Real partial, det;
  two_sum(terms[0], terms[1], partial, error);
  exact &= error == 0;
  two_sum(partial, terms[2], det, error);
  exact &= error == 0;
  sign = (det > 0) - (det < 0);
  return exact;
}

bool orient3d_twice_precision(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                              int& sign) {
  // Rounded differences u, v, w and their exact tails (u_tail etc.).
  Real u[3], u_tail[3], v[3], v_tail[3], w[3], w_tail[3];
  for (int k = 0; k < 3; ++k) {
    two_diff(b[k], a[k], u[k], u_tail[k]);
    two_diff(c[k], a[k], v[k], v_tail[k]);
    two_diff(d[k], a[k], w[k], w_tail[k]);
  }
  // B = u . (v x w) as sum over k of high[k] + low[k]; first-order tail terms.
  Real high[3], low[3], first_order[3];
  Real perm = 0;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3;
    const int j = (k + 2) % 3;
    Real p, p_error, q, q_error, minor, minor_error, term_error;
    two_product(v[i], w[j], p, p_error);
    two_product(v[j], w[i], q, q_error);
    two_diff(p, q, minor, minor_error);
    const Real minor_low = minor_error + (p_error - q_error);
    two_product(u[k], minor, high[k], term_error);
    low[k] = term_error + u[k] * minor_low;
    perm = perm + std::abs(u[k]) * (std::abs(p) + std::abs(q));
    first_order[k] = u_tail[k] * minor + u[k] * ((v_tail[i] * w[j] - v_tail[j] * w[i]) +
                                                 (v[i] * w_tail[j] - v[j] * w_tail[i]));
  }
  Real s1, s1_error, s2, s2_error;
  two_sum(high[0], high[1], s1, s1_error);
  two_sum(s1, high[2], s2, s2_error);
  const Real lows = (((low[0] + low[1]) + low[2]) + s1_error) + s2_error;
  const Real tails = (first_order[0] + first_order[1]) + first_order[2];
  const Real det = s2 + (lows + tails);
  const Real bound = kOrient3dBoundTwice * perm;
  if (det > bound) {
    sign = 1;
  } else if (det < -bound) {
    sign = -1;
  } else {
    return false;
  }
  return true;
}

int orient3d_adaptive(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // Coincident points (shared vertices of mesh neighbours): zero, no arithmetic.
  if (a == b || a == c || a == d || b == c || b == d || c == d) return 0;
  int sign = 0;
  if (orient3d_rounding_free(a, b, c, d, sign)) return sign;
  if (orient3d_twice_precision(a, b, c, d, sign)) return sign;
  return orient3d_exact(a, b, c, d);
}

int orient3d_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // Exact differences u = b - a, v = c - a, w = d - a.
  Real u[3][kDifference], v[3][kDifference], w[3][kDifference];
  int nu[3], nv[3], nw[3];
  for (int k = 0; k < 3; ++k) {
    nu[k] = difference(b[k], a[k], u[k]);
    nv[k] = difference(c[k], a[k], v[k]);
    nw[k] = difference(d[k], a[k], w[k]);
  }
  // det = u . (v x w): minor k is (v x w)_k, then scaled by u_k.
  Real terms[3][kTerm];
  int n_terms[3];
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3;
    const int j = (k + 2) % 3;
    Real minor[kMinor];
    const int n_minor =
        difference_of_products(v[i], nv[i], v[j], nv[j], w[i], nw[i], w[j], nw[j], minor);
    n_terms[k] = multiply_by_short<kMinor>(u[k], nu[k], minor, n_minor, terms[k]);
  }
  Real partial[2 * kTerm];
  const int n_partial = sum_expansions(terms[0], n_terms[0], terms[1], n_terms[1], partial);
  Real det[kDet3];
  const int n_det = sum_expansions(partial, n_partial, terms[2], n_terms[2], det);
  return sign_of(det, n_det);
}

int orient2d_adaptive(Real ax, Real ay, Real bx, Real by, Real cx, Real cy) {
  const bool a_is_b = ax == bx && ay == by;
  const bool a_is_c = ax == cx && ay == cy;
  const bool b_is_c = bx == cx && by == cy;
  if (a_is_b || a_is_c || b_is_c) return 0;
  return orient2d_exact(ax, ay, bx, by, cx, cy);
}

int orient2d_exact(Real ax, Real ay, Real bx, Real by, Real cx, Real cy) {
  Real ux[kDifference], uy[kDifference], vx[kDifference], vy[kDifference];
  const int n_ux = difference(bx, ax, ux);
  const int n_uy = difference(by, ay, uy);
  const int n_vx = difference(cx, ax, vx);
  const int n_vy = difference(cy, ay, vy);
  // det = ux * vy - uy * vx.
  Real det[kDet2];
  const int n_det = difference_of_products(ux, n_ux, uy, n_uy, vx, n_vx, vy, n_vy, det);
  return sign_of(det, n_det);
}

}  // namespace detail

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return detail::orient3d_filtered(a, b, c, d);
}

int orient2d(Real ax, Real ay, Real bx, Real by, Real cx, Real cy) {
  return detail::orient2d_filtered(ax, ay, bx, by, cx, cy);
}

bool is_degenerate_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  // The cross product (b - a) x (c - a) is zero exactly when its three
  // components, the orientations of the yz, zx and xy projections, are.
  return orient2d(a.y(), a.z(), b.y(), b.z(), c.y(), c.z()) == 0 &&
         orient2d(a.z(), a.x(), b.z(), b.x(), c.z(), c.x()) == 0 &&
         orient2d(a.x(), a.y(), b.x(), b.y(), c.x(), c.y()) == 0;
}

}  // namespace dovetail::collision
