#pragma once
// The bounds of a small point set rotated by R, for the world boxes of parts
// with small hulls: every coordinate is one row of R times the point,
// (R(k,0) x + R(k,1) y) + R(k,2) z, and the bounds are exact minima and
// maxima of those doubles, so the two forms below give equal values (a
// zero bound may differ in sign between them; one build always uses the
// same form).

#include <limits>
#include <utility>

#include "dovetail/collision/types.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace dovetail::collision::detail {

/// (lo, hi): per axis k, the least and greatest rotated coordinate k of the n
/// points (x[i], y[i], z[i]). R must be finite.
inline std::pair<Vec3, Vec3> rotated_bounds(const Mat3& R, const Real* x, const Real* y,
                                            const Real* z, std::size_t n) {
  constexpr Real kInf = std::numeric_limits<Real>::infinity();
  Vec3 lo = Vec3::Constant(kInf), hi = Vec3::Constant(-kInf);
  std::size_t i = 0;
#if defined(__SSE2__)
  // Two points at a time; six independent maxima and minima.
  __m128d r[3][3], l[3], h[3];
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) r[k][j] = _mm_set1_pd(R(k, j));
    l[k] = _mm_set1_pd(kInf);
    h[k] = _mm_set1_pd(-kInf);
  }
  for (; i + 2 <= n; i += 2) {
    const __m128d px = _mm_loadu_pd(x + i), py = _mm_loadu_pd(y + i), pz = _mm_loadu_pd(z + i);
    for (int k = 0; k < 3; ++k) {
      const __m128d c = _mm_add_pd(_mm_add_pd(_mm_mul_pd(r[k][0], px), _mm_mul_pd(r[k][1], py)),
                                   _mm_mul_pd(r[k][2], pz));
      h[k] = _mm_max_pd(h[k], c);
      l[k] = _mm_min_pd(l[k], c);
    }
  }
  for (int k = 0; k < 3; ++k) {
    alignas(16) Real lh[2], hh[2];
    _mm_store_pd(lh, l[k]);
    _mm_store_pd(hh, h[k]);
    lo[k] = std::min(lh[0], lh[1]);
    hi[k] = std::max(hh[0], hh[1]);
  }
#endif
  for (; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      const Real c = (R(k, 0) * x[i] + R(k, 1) * y[i]) + R(k, 2) * z[i];
      lo[k] = std::min(lo[k], c);
      hi[k] = std::max(hi[k], c);
    }
  }
  return {lo, hi};
}

}  // namespace dovetail::collision::detail
