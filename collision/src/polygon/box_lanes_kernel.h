#pragma once
// The lane test's steps (box_lanes.h), included by the file of each lane
// type. Internal linkage: each file compiles its own copy for its own
// instruction set, and the linker never trades one for the other.

#include "polygon/box_lanes.h"

namespace dovetail::collision::detail {
namespace {

/// x > y ? x : y, as the lanes' max: NaN in either gives the second.
inline double max1(double x, double y) { return x > y ? x : y; }

/// The largest of lanes 0 to 2, and 0 when none is above 0.
template <typename L>
double widest_gap(const typename L::V& g) {
  return max1(max1(max1(L::template lane<0>(g), L::template lane<1>(g)), L::template lane<2>(g)),
              0.0);
}

template <typename L>
double box_gap(const double* a, const BoxLanes& b, double margin) {
  using V = typename L::V;
  const double* centre_a = a + 9;
  const double* half_a = a + 12;
  const V m = L::broadcast(margin);
  // Rows of A's axes: lane i of row k is component k of a_i.
  const V a0 = L::load4(a), a1 = L::load4(a + 3), a2 = L::load4(a + 6);
  // T = A^T d, d from A's centre to B's (lane i: a_i . d).
  const double d0 = b.centre[0] - centre_a[0];
  const double d1 = b.centre[1] - centre_a[1];
  const double d2 = b.centre[2] - centre_a[2];
  const V T = L::add(L::add(L::mul(L::broadcast(d0), a0), L::mul(L::broadcast(d1), a1)),
                     L::mul(L::broadcast(d2), a2));
  // R = A^T B by rows (lane j: a_i . b_j), signed and absolute; |R| by
  // columns (lane i) for A's face axes.
  const V b0 = L::load4(b.row[0]), b1 = L::load4(b.row[1]), b2 = L::load4(b.row[2]);
  const auto row = [&](int i) {
    return L::add(L::add(L::mul(L::broadcast(a[i]), b0), L::mul(L::broadcast(a[3 + i]), b1)),
                  L::mul(L::broadcast(a[6 + i]), b2));
  };
  const V R[3] = {row(0), row(1), row(2)};
  const V absR[3] = {L::abs(R[0]), L::abs(R[1]), L::abs(R[2])};
  V column[3];
  L::transpose(absR, column);
  // A's face axes: |T_i| > e^A_i + sum_j |R_ij| e^B_j.
  const V rb = L::add(L::add(L::mul(column[0], L::broadcast(b.half[0])),
                             L::mul(column[1], L::broadcast(b.half[1]))),
                      L::mul(column[2], L::broadcast(b.half[2])));
  const V ea = L::load3(half_a);
  const double face_a = widest_gap<L>(L::sub(L::abs(T), L::add(L::add(ea, rb), m)));
  if (face_a > 0) return face_a;

  const V eA[3] = {L::broadcast(half_a[0]), L::broadcast(half_a[1]), L::broadcast(half_a[2])};
  // B's face axes: |b_j . d| > sum_i |R_ij| e^A_i + e^B_j.
  const V t_b = L::add(L::add(L::mul(L::broadcast(d0), b0), L::mul(L::broadcast(d1), b1)),
                       L::mul(L::broadcast(d2), b2));
  const V r_a =
      L::add(L::add(L::mul(eA[0], absR[0]), L::mul(eA[1], absR[1])), L::mul(eA[2], absR[2]));
  V gap = L::sub(L::abs(t_b), L::add(L::add(r_a, L::load4(b.half)), m));
  // Edge-edge axes a_i x b_j, lane j (i1, i2 = i + 1, i + 2 mod 3; j1, j2 likewise):
  // |T_i2 R_i1j - T_i1 R_i2j| > e^A_i1 |R_i2j| + e^A_i2 |R_i1j| + e^B_j1 |R_ij2| + e^B_j2 |R_ij1|.
  const V eb_next = L::load4(b.half_next), eb_after = L::load4(b.half_after);
  const V Ti[3] = {L::template spread<0>(T), L::template spread<1>(T), L::template spread<2>(T)};
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    const V t = L::sub(L::mul(Ti[i2], R[i1]), L::mul(Ti[i1], R[i2]));
    const V ra = L::add(L::mul(eA[i1], absR[i2]), L::mul(eA[i2], absR[i1]));
    const V rb_edge =
        L::add(L::mul(eb_next, L::turn2(absR[i])), L::mul(eb_after, L::turn1(absR[i])));
    gap = L::max(gap, L::sub(L::abs(t), L::add(L::add(ra, rb_edge), m)));
  }
  return widest_gap<L>(gap);
}

template <typename L>
void box_move(const double* box, const double* R_AB, const double* t_AB, BoxLanes& out) {
  using V = typename L::V;
  // Lane j of the box's row m: component m of its axis j (in B's frame).
  const V r0 = L::load4(box), r1 = L::load4(box + 3), r2 = L::load4(box + 6);
  for (int k = 0; k < 3; ++k) {
    // Row k of R_AB times the axes: component k of each axis in A's frame.
    const V row =
        L::add(L::add(L::mul(L::broadcast(R_AB[k]), r0), L::mul(L::broadcast(R_AB[3 + k]), r1)),
               L::mul(L::broadcast(R_AB[6 + k]), r2));
    L::store(out.row[k], L::clear3(row));
  }
  const double* c = box + 9;
  const double* half = box + 12;
  for (int k = 0; k < 3; ++k) {
    out.centre[k] = R_AB[k] * c[0] + R_AB[3 + k] * c[1] + R_AB[6 + k] * c[2] + t_AB[k];
    out.half[k] = half[k];
    out.half_next[k] = half[(k + 1) % 3];
    out.half_after[k] = half[(k + 2) % 3];
  }
  out.centre[3] = out.half[3] = out.half_next[3] = out.half_after[3] = 0.0;
}

}  // namespace
}  // namespace dovetail::collision::detail
