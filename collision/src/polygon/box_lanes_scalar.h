#pragma once
// The scalar form of the box test and move (box_lanes.h), inline for the
// OBB tree's traversal. Never included by the AVX2 file: an inline function
// compiled there could stand in for this one on any processor.

#include <algorithm>
#include <array>
#include <cmath>

#include "dovetail/collision/types.h"
#include "polygon/box_lanes.h"

namespace dovetail::collision::detail {

/// The test one axis at a time, stopping at the first that separates. Each
/// value is written as the wide form computes it (box_lanes_avx2.cpp):
/// sums left to right, products in the same pairs.
inline double box_gap_scalar(const double* a, const BoxLanes& b, double margin) {
  const double* centre_a = a + 9;
  const double* half_a = a + 12;
  const double d[3] = {b.centre[0] - centre_a[0], b.centre[1] - centre_a[1],
                       b.centre[2] - centre_a[2]};
  double T[3], R[3][3], absR[3][3];
  // A's face axes: |T_i| > e^A_i + sum_j |R_ij| e^B_j, row i of R on the way.
  for (int i = 0; i < 3; ++i) {
    T[i] = d[0] * a[i] + d[1] * a[3 + i] + d[2] * a[6 + i];
    for (int j = 0; j < 3; ++j) {
      R[i][j] = a[i] * b.row[0][j] + a[3 + i] * b.row[1][j] + a[6 + i] * b.row[2][j];
      absR[i][j] = std::abs(R[i][j]);
    }
    const double rb = absR[i][0] * b.half[0] + absR[i][1] * b.half[1] + absR[i][2] * b.half[2];
    const double gap = std::abs(T[i]) - (half_a[i] + rb + margin);
    if (gap > 0) return gap;
  }
  // B's face axes: |b_j . d| > sum_i |R_ij| e^A_i + e^B_j.
  for (int j = 0; j < 3; ++j) {
    const double t = d[0] * b.row[0][j] + d[1] * b.row[1][j] + d[2] * b.row[2][j];
    const double ra = half_a[0] * absR[0][j] + half_a[1] * absR[1][j] + half_a[2] * absR[2][j];
    const double gap = std::abs(t) - (ra + b.half[j] + margin);
    if (gap > 0) return gap;
  }
  // Edge-edge axes a_i x b_j:
  // |T_i2 R_i1j - T_i1 R_i2j| > e^A_i1 |R_i2j| + e^A_i2 |R_i1j| + e^B_j1 |R_ij2| + e^B_j2 |R_ij1|.
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double t = T[i2] * R[i1][j] - T[i1] * R[i2][j];
      const double ra = half_a[i1] * absR[i2][j] + half_a[i2] * absR[i1][j];
      const double rb = b.half_next[j] * absR[i][j2] + b.half_after[j] * absR[i][j1];
      const double gap = std::abs(t) - (ra + rb + margin);
      if (gap > 0) return gap;
    }
  }
  return 0;
}

/// A triangle laid out for the box-triangle test.
inline TriangleLanes triangle_lanes(const std::array<Vec3, 3>& corners, Real margin) {
  TriangleLanes t{};
  const Vec3 edge1 = corners[1] - corners[0];
  const Vec3 edge2 = corners[2] - corners[0];
  const Vec3 normal = edge1.cross(edge2);
  for (int k = 0; k < 3; ++k) {
    t.corner[k] = corners[0][k];
    t.edge1[k] = edge1[k];
    t.edge2[k] = edge2[k];
    t.normal[k] = normal[k];
  }
  t.margin = margin;
  t.normal_margin = margin * normal.lpNorm<1>();
  return t;
}

/// One face axis of A at a time, then the normal. Each value is written as
/// the wide form computes it (box_lanes_avx2.cpp).
inline bool box_meets_triangle_scalar(const double* a, const TriangleLanes& t) {
  const double* centre_a = a + 9;
  const double* half_a = a + 12;
  const double d[3] = {t.corner[0] - centre_a[0], t.corner[1] - centre_a[1],
                       t.corner[2] - centre_a[2]};
  // On axis a_i the corners project to q0, q0 + a_i . edge1 and q0 + a_i . edge2.
  double radius = 0;  // of the box along the normal
  for (int i = 0; i < 3; ++i) {
    const double q0 = d[0] * a[i] + d[1] * a[3 + i] + d[2] * a[6 + i];
    const double q1 = q0 + (t.edge1[0] * a[i] + t.edge1[1] * a[3 + i] + t.edge1[2] * a[6 + i]);
    const double q2 = q0 + (t.edge2[0] * a[i] + t.edge2[1] * a[3 + i] + t.edge2[2] * a[6 + i]);
    const double qn = t.normal[0] * a[i] + t.normal[1] * a[3 + i] + t.normal[2] * a[6 + i];
    const double reach = half_a[i] + t.margin;
    if (std::min(q0, std::min(q1, q2)) > reach || std::max(q0, std::max(q1, q2)) < -reach) {
      return false;
    }
    radius = radius + half_a[i] * std::abs(qn);
  }
  const double s = t.normal[0] * d[0] + t.normal[1] * d[1] + t.normal[2] * d[2];
  return !(std::abs(s) > radius + t.normal_margin);
}

inline void box_move_scalar(const double* box, const double* R_AB, const double* t_AB,
                            BoxLanes& out) {
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      out.row[k][j] = R_AB[k] * box[j] + R_AB[3 + k] * box[3 + j] + R_AB[6 + k] * box[6 + j];
    }
    out.row[k][3] = 0.0;
  }
  box_move_rest(box, R_AB, t_AB, out);
}

}  // namespace dovetail::collision::detail
