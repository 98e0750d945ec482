// The OBB tree's box test and box move four doubles wide (box_lanes.h).
// This file alone is compiled for AVX2, without FMA: a fused multiply-add
// would round differently from the scalar code. It is called only where the
// processor has AVX2. Every value is the scalar code's expression, operation
// for operation, so both give the same bits.
#include <immintrin.h>

#include <cmath>

#include "polygon/box_lanes.h"

namespace dovetail::collision::detail {
namespace {

using V = __m256d;

V add(V a, V b) { return _mm256_add_pd(a, b); }
V sub(V a, V b) { return _mm256_sub_pd(a, b); }
V mul(V a, V b) { return _mm256_mul_pd(a, b); }
V abs(V a) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a); }
V spread(double x) { return _mm256_set1_pd(x); }
/// (x0 a) + (x1 b) + (x2 c), summed left to right.
V sum3(double x0, V a, double x1, V b, double x2, V c) {
  return add(add(mul(spread(x0), a), mul(spread(x1), b)), mul(spread(x2), c));
}
/// Lanes 0 to 2 above 0, as bits 0 to 2.
int positive(V a) {
  return _mm256_movemask_pd(_mm256_cmp_pd(a, _mm256_setzero_pd(), _CMP_GT_OQ)) & 7;
}

double box_gap_avx2(const double* a, const BoxLanes& b, double margin) {
  const double* centre_a = a + 9;
  const double* half_a = a + 12;
  const V m = spread(margin);
  // Rows of A's axes (lane i of row k: component k of a_i) and of B's (lane j).
  const V a0 = _mm256_loadu_pd(a), a1 = _mm256_loadu_pd(a + 3), a2 = _mm256_loadu_pd(a + 6);
  const V b0 = _mm256_loadu_pd(b.row[0]), b1 = _mm256_loadu_pd(b.row[1]),
          b2 = _mm256_loadu_pd(b.row[2]);
  const double d0 = b.centre[0] - centre_a[0];
  const double d1 = b.centre[1] - centre_a[1];
  const double d2 = b.centre[2] - centre_a[2];
  const V T = sum3(d0, a0, d1, a1, d2, a2);  // lane i: a_i . d
  // R = A^T B by rows (lane j: a_i . b_j), and |R| by columns (lane i).
  const V R[3] = {sum3(a[0], b0, a[3], b1, a[6], b2), sum3(a[1], b0, a[4], b1, a[7], b2),
                  sum3(a[2], b0, a[5], b1, a[8], b2)};
  const V absR[3] = {abs(R[0]), abs(R[1]), abs(R[2])};
  const V t0 = _mm256_unpacklo_pd(absR[0], absR[1]);  // r0[0] r1[0] r0[2] r1[2]
  const V t1 = _mm256_unpackhi_pd(absR[0], absR[1]);  // r0[1] r1[1] r0[3] r1[3]
  const V t2 = _mm256_unpacklo_pd(absR[2], absR[2]);  // r2[0] r2[0] r2[2] r2[2]
  const V t3 = _mm256_unpackhi_pd(absR[2], absR[2]);  // r2[1] r2[1] r2[3] r2[3]
  const V column0 = _mm256_permute2f128_pd(t0, t2, 0x20);
  const V column1 = _mm256_permute2f128_pd(t1, t3, 0x20);
  const V column2 = _mm256_permute2f128_pd(t0, t2, 0x31);

  alignas(32) double gaps[16];
  // A's face axes: |T_i| > e^A_i + sum_j |R_ij| e^B_j.
  const V rb = add(add(mul(column0, spread(b.half[0])), mul(column1, spread(b.half[1]))),
                   mul(column2, spread(b.half[2])));
  const V ea = _mm256_maskload_pd(half_a, _mm256_setr_epi64x(-1, -1, -1, 0));
  const V face_a = sub(abs(T), add(add(ea, rb), m));
  if (const int bits = positive(face_a)) {
    _mm256_store_pd(gaps, face_a);
    return gaps[__builtin_ctz(bits)];
  }
  // B's face axes: |b_j . d| > sum_i |R_ij| e^A_i + e^B_j.
  const double eA[3] = {half_a[0], half_a[1], half_a[2]};
  const V face_b = sub(
      abs(sum3(d0, b0, d1, b1, d2, b2)),
      add(add(sum3(eA[0], absR[0], eA[1], absR[1], eA[2], absR[2]), _mm256_loadu_pd(b.half)), m));
  _mm256_store_pd(gaps, face_b);
  int bits = positive(face_b);
  // Edge-edge axes a_i x b_j, lane j (i1, i2 = i + 1, i + 2 mod 3; j1, j2 likewise):
  // |T_i2 R_i1j - T_i1 R_i2j| > e^A_i1 |R_i2j| + e^A_i2 |R_i1j| + e^B_j1 |R_ij2| + e^B_j2 |R_ij1|.
  alignas(32) double Ti[4];
  _mm256_store_pd(Ti, T);
  const V eb_next = _mm256_loadu_pd(b.half_next), eb_after = _mm256_loadu_pd(b.half_after);
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    const V t = sub(mul(spread(Ti[i2]), R[i1]), mul(spread(Ti[i1]), R[i2]));
    const V ra = add(mul(spread(eA[i1]), absR[i2]), mul(spread(eA[i2]), absR[i1]));
    const V r_j2 = _mm256_permute4x64_pd(absR[i], 0b11'01'00'10);  // lane j: |R_i,j+2|
    const V r_j1 = _mm256_permute4x64_pd(absR[i], 0b11'00'10'01);  // lane j: |R_i,j+1|
    const V rb_edge = add(mul(eb_next, r_j2), mul(eb_after, r_j1));
    const V gap = sub(abs(t), add(add(ra, rb_edge), m));
    _mm256_store_pd(gaps + 4 * (i + 1), gap);
    bits |= positive(gap) << (3 * (i + 1));
  }
  if (bits == 0) return 0;
  // The first separating axis in the scalar code's order.
  const int k = __builtin_ctz(bits);
  return gaps[4 * (k / 3) + k % 3];
}

void box_move_avx2(const double* box, const double* R_AB, const double* t_AB, BoxLanes& out) {
  // Lane j of the box's row m: component m of its axis j, in B's frame.
  const V r0 = _mm256_loadu_pd(box), r1 = _mm256_loadu_pd(box + 3), r2 = _mm256_loadu_pd(box + 6);
  for (int k = 0; k < 3; ++k) {
    const V row = sum3(R_AB[k], r0, R_AB[3 + k], r1, R_AB[6 + k], r2);
    _mm256_storeu_pd(out.row[k], _mm256_blend_pd(row, _mm256_setzero_pd(), 0b1000));
  }
  box_move_rest(box, R_AB, t_AB, out);
}

bool box_meets_triangle_avx2(const double* a, const TriangleLanes& t) {
  const double* centre_a = a + 9;
  const double* half_a = a + 12;
  const V a0 = _mm256_loadu_pd(a), a1 = _mm256_loadu_pd(a + 3), a2 = _mm256_loadu_pd(a + 6);
  const double d[3] = {t.corner[0] - centre_a[0], t.corner[1] - centre_a[1],
                       t.corner[2] - centre_a[2]};
  // Lane i: the corners' projections on a_i, and the normal's.
  const V q0 = sum3(d[0], a0, d[1], a1, d[2], a2);
  const V q1 = add(q0, sum3(t.edge1[0], a0, t.edge1[1], a1, t.edge1[2], a2));
  const V q2 = add(q0, sum3(t.edge2[0], a0, t.edge2[1], a1, t.edge2[2], a2));
  const V qn = sum3(t.normal[0], a0, t.normal[1], a1, t.normal[2], a2);
  const V half = _mm256_maskload_pd(half_a, _mm256_setr_epi64x(-1, -1, -1, 0));
  const V reach = add(half, spread(t.margin));
  const V lo = _mm256_min_pd(q0, _mm256_min_pd(q1, q2));
  const V hi = _mm256_max_pd(q0, _mm256_max_pd(q1, q2));
  const V minus_reach = _mm256_xor_pd(reach, spread(-0.0));
  if (positive(sub(lo, reach)) != 0 || positive(sub(minus_reach, hi)) != 0) return false;
  alignas(32) double r[4];
  _mm256_store_pd(r, mul(half, abs(qn)));
  const double radius = ((0.0 + r[0]) + r[1]) + r[2];
  const double s = t.normal[0] * d[0] + t.normal[1] * d[1] + t.normal[2] * d[2];
  return !(std::abs(s) > radius + t.normal_margin);
}

}  // namespace

BoxLaneOps box_lane_ops_avx2() {
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2")) return {nullptr, nullptr, nullptr};
  return {box_gap_avx2, box_move_avx2, box_meets_triangle_avx2};
}

}  // namespace dovetail::collision::detail
