#pragma once
// Error-free transformations of floating-point sums and products (Shewchuk,
// "Adaptive precision floating-point arithmetic and fast robust geometric
// predicates", 1997), shared by the exact predicates and the convex hull's
// exact comparisons. With round to nearest and no overflow, each gives the
// rounded result and its exact error.

#include <cmath>

#include "dovetail/collision/types.h"

namespace dovetail::collision::detail {

/// s + e = a + b exactly.
inline void two_sum(Real a, Real b, Real& s, Real& e) {
  s = a + b;
  const Real b_virtual = s - a;
  const Real a_virtual = s - b_virtual;
  e = (a - a_virtual) + (b - b_virtual);
}

/// s + e = a + b exactly, when |a| >= |b| or a == 0.
inline void fast_two_sum(Real a, Real b, Real& s, Real& e) {
  s = a + b;
  e = b - (s - a);
}

/// d + e = a - b exactly.
inline void two_diff(Real a, Real b, Real& d, Real& e) {
  d = a - b;
  const Real b_virtual = a - d;
  const Real a_virtual = d + b_virtual;
  e = (a - a_virtual) + (b_virtual - b);
}

/// p + e = a * b exactly (inside the documented range of the predicates).
inline void two_product(Real a, Real b, Real& p, Real& e) {
  p = a * b;
  e = std::fma(a, b, -p);
}

/// h := h + b for a nonoverlapping expansion h (m components, of increasing
/// magnitude), zero components eliminated (grow-expansion); returns the new
/// length. h needs room for m + 1 components.
inline int grow_expansion(Real* h, int m, Real b) {
  Real q = b;
  int k = 0;
  for (int i = 0; i < m; ++i) {
    Real s, e;
    two_sum(q, h[i], s, e);
    q = s;
    if (e != 0) h[k++] = e;
  }
  if (q != 0 || k == 0) h[k++] = q;
  return k;
}

}  // namespace dovetail::collision::detail
