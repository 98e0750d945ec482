// The lane test four doubles wide. This file alone is compiled for AVX2
// (without FMA: a fused multiply-add would round differently from the
// scalar lanes); it is called only where the processor has AVX2.
#include <immintrin.h>

#include "polygon/box_lanes_kernel.h"

namespace dovetail::collision::detail {
namespace {

struct Avx2Lanes {
  using V = __m256d;
  static V load4(const double* p) { return _mm256_loadu_pd(p); }
  static V load3(const double* p) {
    return _mm256_maskload_pd(p, _mm256_setr_epi64x(-1, -1, -1, 0));
  }
  static V broadcast(double x) { return _mm256_set1_pd(x); }
  static void store(double* p, V a) { _mm256_storeu_pd(p, a); }
  static V clear3(V a) { return _mm256_blend_pd(a, _mm256_setzero_pd(), 0b1000); }
  static V add(V a, V b) { return _mm256_add_pd(a, b); }
  static V sub(V a, V b) { return _mm256_sub_pd(a, b); }
  static V mul(V a, V b) { return _mm256_mul_pd(a, b); }
  static V max(V a, V b) { return _mm256_max_pd(a, b); }
  static V abs(V a) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a); }
  /// out[j] lane i = rows[i] lane j, for lanes 0 to 2.
  static void transpose(const V (&rows)[3], V (&out)[3]) {
    const V t0 = _mm256_unpacklo_pd(rows[0], rows[1]);  // r0[0] r1[0] r0[2] r1[2]
    const V t1 = _mm256_unpackhi_pd(rows[0], rows[1]);  // r0[1] r1[1] r0[3] r1[3]
    const V t2 = _mm256_unpacklo_pd(rows[2], rows[2]);  // r2[0] r2[0] r2[2] r2[2]
    const V t3 = _mm256_unpackhi_pd(rows[2], rows[2]);  // r2[1] r2[1] r2[3] r2[3]
    out[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    out[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    out[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
  }
  static V turn1(V a) { return _mm256_permute4x64_pd(a, 0b11'00'10'01); }
  static V turn2(V a) { return _mm256_permute4x64_pd(a, 0b11'01'00'10); }
  template <int i>
  static double lane(V a) {
    alignas(32) double out[4];
    _mm256_store_pd(out, a);
    return out[i];
  }
  /// Every lane takes lane i.
  template <int i>
  static V spread(V a) {
    return broadcast(lane<i>(a));
  }
};

}  // namespace

BoxLaneOps box_lane_ops_avx2() {
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2")) return {nullptr, nullptr};
  return {box_gap<Avx2Lanes>, box_move<Avx2Lanes>};
}

}  // namespace dovetail::collision::detail
